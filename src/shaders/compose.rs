//! [`ShaderLibrary`]: a naga_oil `Composer` that knows every lodkit module and the user's own.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use naga_oil::compose::{Composer, NagaModuleDescriptor, ShaderDefValue, ShaderType};

use super::diagnostic::{Diagnostic, DiagnosticKind, from_composer_error, validation_diagnostic};
use super::imports::{declared_imports, import_site, longest_prefix, module_prefix};
use super::loading::{Unavailable, add_modules, collect_files, split_duplicates};
use super::registry::{self, Language, ModuleKind};
use super::{ShaderError, closest, glsl, read_source};

mod on_demand;
mod plain;
mod validate;

use validate::validation_error;
pub use validate::{parse_capabilities, validate};

/// Shader defs by name, as naga_oil takes them (`-D NAME=VALUE` on the command line).
pub type ShaderDefs = HashMap<String, ShaderDefValue>;

/// Language (and for GLSL, stage) of a top-level shader.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SourceLanguage {
    /// WGSL; stages come from its entry points. Imports lodkit with `#import lodkit::<topic>`.
    #[default]
    Wgsl,
    /// GLSL 450 of one stage. Includes lodkit with `#include "lodkit/<topic>.glsl"`.
    Glsl(naga::ShaderStage),
    /// WESL, linked by wesl-rs against lodkit's WESL package (`import lodkit::<topic>::item;`)
    /// and the `.wesl` files of the include folders (`package::<path>`). Bool shader defs are
    /// `@if` conditions; int and uint defs set the condition and are `constants::NAME`.
    /// Needs the `wesl` feature.
    Wesl,
}

/// A top-level shader to compose.
#[derive(Clone, Debug, Default)]
pub struct ComposeDescriptor<'a> {
    /// The shader's source text.
    pub source: &'a str,
    /// Path used in diagnostics (and, for GLSL, to find `#include`s next to the file).
    pub file_path: &'a str,
    /// Language of `source`.
    pub language: SourceLanguage,
    /// Shader defs for this composition.
    pub shader_defs: ShaderDefs,
}

/// Options for a [`ShaderLibrary`].
#[derive(Clone, Debug, Default)]
pub struct LibraryDescriptor {
    /// Capabilities the validator allows (default: naga's defaults, the WebGPU baseline).
    pub capabilities: naga::valid::Capabilities,
}

/// A composed and validated module.
#[derive(Debug)]
pub struct Composed {
    /// The naga IR.
    pub module: naga::Module,
    /// What naga's validator found out about it (needed by every back end).
    pub info: naga::valid::ModuleInfo,
}

/// The entry object: a naga_oil [`Composer`] that knows every lodkit WGSL module, plus the
/// user's modules and include folders. A lodkit module enters the composer when a shader or a
/// user module first imports it (with the modules it imports), so composing one shader parses
/// only the modules it uses. The composer itself is built when first needed: a WGSL shader
/// without naga_oil directives (no `#import`, `#ifdef`, `#{NAME}`, `module::item` paths, ...)
/// is parsed and validated by naga alone.
///
/// ```
/// use lodkit::shaders::{ComposeDescriptor, ShaderLibrary};
/// let mut library = ShaderLibrary::new().unwrap();
/// let composed = library
///     .compose(&ComposeDescriptor {
///         source: "#import lodkit::normal_distance::foreshortened_normal_distance\n\
///                  @fragment fn main() -> @location(0) vec4<f32> {\n\
///                  return vec4<f32>(foreshortened_normal_distance(vec3(0.0, 0.0, 1.0), vec3(0.6, 0.0, 0.8)));\n}",
///         file_path: "example.wgsl",
///         ..Default::default()
///     })
///     .unwrap();
/// assert_eq!(composed.module.entry_points.len(), 1);
/// ```
pub struct ShaderLibrary {
    composer: OnceLock<Composer>,
    capabilities: naga::valid::Capabilities,
    include_dirs: Vec<PathBuf>,
    user_modules: Vec<String>,
    unavailable: Unavailable,
    #[cfg(feature = "wesl")]
    wesl_modules: Vec<super::wesl_link::WeslUserModule>,
    memo: Option<super::memo::ValidationMemo>,
}

impl std::fmt::Debug for ShaderLibrary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShaderLibrary")
            .field("include_dirs", &self.include_dirs)
            .field("user_modules", &self.user_modules)
            .finish_non_exhaustive()
    }
}

/// Adds every lodkit WGSL module to `composer`, dependencies first, skipping any it already has.
/// This is how an engine that owns its own naga_oil `Composer` (Bevy-style) gets
/// `#import lodkit::...` to resolve.
pub fn add_to_composer(composer: &mut Composer) -> Result<(), ShaderError> {
    let sources: Vec<(String, Arc<str>)> = registry::modules()
        .iter()
        .filter(|m| m.language == Language::Wgsl && m.kind == ModuleKind::Module)
        .map(|m| (format!("shader_lib/{}", m.path), Arc::from(m.source)))
        .collect();
    add_modules(composer, sources, true, None)
}

impl ShaderLibrary {
    /// A library of every lodkit module (loaded when first imported) and naga's default
    /// capabilities.
    pub fn new() -> Result<Self, ShaderError> {
        Self::with_descriptor(&LibraryDescriptor::default())
    }

    /// A library of every lodkit module (loaded when first imported) and the given options.
    pub fn with_descriptor(desc: &LibraryDescriptor) -> Result<Self, ShaderError> {
        Ok(Self {
            composer: OnceLock::new(),
            capabilities: desc.capabilities,
            include_dirs: Vec::new(),
            user_modules: Vec::new(),
            unavailable: Unavailable::new(),
            #[cfg(feature = "wesl")]
            wesl_modules: Vec::new(),
            memo: None,
        })
    }

    /// The underlying naga_oil composer (lodkit's modules enter it as shaders import them;
    /// [`add_to_composer`] adds them all). Built here if no shader needed it yet.
    pub fn composer(&self) -> &Composer {
        self.composer
            .get_or_init(|| new_composer(self.capabilities))
    }

    /// The underlying naga_oil composer, to add modules of your own by hand.
    pub fn composer_mut(&mut self) -> &mut Composer {
        composer_in(&mut self.composer, self.capabilities)
    }

    /// Whether naga_oil's composer has been built: a library builds it when the first shader
    /// or module needs composition (or [`composer`](Self::composer) is called). Building it
    /// costs milliseconds (naga_oil compiles its preprocessor's regular expressions), more than
    /// parsing and validating a small shader.
    pub fn has_composer(&self) -> bool {
        self.composer.get().is_some()
    }

    /// Import paths of the user modules added so far, in the order they were added.
    pub fn user_modules(&self) -> &[String] {
        &self.user_modules
    }

    /// Adds user folders: every `.wgsl` file under them that declares `#define_import_path`
    /// becomes importable (imports among them are ordered), GLSL `#include`s are searched in
    /// them, and (feature `wesl`) their `.wesl` files are `package::<path>` modules. An import
    /// cycle, or a module reusing a lodkit import path, is an error naming the file and line.
    /// A module that does not compose, or an import path declared by several files, fails only
    /// the shaders that import it, with that diagnostic. Returns the import paths added.
    pub fn add_import_dirs(&mut self, dirs: &[PathBuf]) -> Result<Vec<String>, ShaderError> {
        self.add_import_dirs_excluding(dirs, &[])
    }

    /// [`Self::add_import_dirs`], leaving out every file whose path contains one of `exclude`
    /// (e.g. the stand-in of a module an engine swaps by build feature).
    pub fn add_import_dirs_excluding(
        &mut self,
        dirs: &[PathBuf],
        exclude: &[String],
    ) -> Result<Vec<String>, ShaderError> {
        let mut files = Vec::new();
        for dir in dirs {
            if !dir.is_dir() {
                return Err(ShaderError::Io {
                    path: dir.clone(),
                    source: std::io::Error::new(std::io::ErrorKind::NotFound, "not a folder"),
                });
            }
            collect_files(dir, "wgsl", exclude, &mut files)?;
            #[cfg(feature = "wesl")]
            super::wesl_link::collect_user_modules(dir, exclude, &mut self.wesl_modules)?;
            self.include_dirs.push(dir.clone());
        }
        files.sort();
        let mut sources = Vec::new();
        for file in files {
            let text = read_source(&file)?;
            if let Some(e) = super::limits::wgsl_too_deep(&text) {
                return Err(super::limits::limit_error(
                    &file.display().to_string(),
                    &text,
                    e,
                ));
            }
            if registry::define_import_path(&text).is_some() {
                sources.push((file.display().to_string(), Arc::from(text)));
            }
        }
        if sources.is_empty() {
            return Ok(Vec::new());
        }
        self.load_lodkit_for(sources.iter().map(|(_, text)| &**text))?;
        split_duplicates(&mut sources, &mut self.unavailable);
        // naga_oil parses each module: on a deep stack, as `compose` does.
        let composer = composer_in(&mut self.composer, self.capabilities);
        let unavailable = &mut self.unavailable;
        super::limits::on_deep_stack_once(|| {
            add_modules(composer, sources, false, Some(unavailable))
        })
        .unwrap_or_else(|()| Err(deep_stack_failed("the user modules")))?;
        // What the composer gained: the modules that were added (others are unavailable).
        let mut names: Vec<String> = self
            .composer()
            .module_sets
            .keys()
            .filter(|n| registry::find_module(n).is_none() && !self.user_modules.contains(n))
            .cloned()
            .collect();
        names.sort();
        self.user_modules.extend(names.iter().cloned());
        Ok(names)
    }

    /// Adds one user module from source (it must declare `#define_import_path`).
    pub fn add_module(&mut self, file_path: &str, source: &str) -> Result<String, ShaderError> {
        let Some(name) = registry::define_import_path(source) else {
            return Err(ShaderError::Source(Box::new(Diagnostic::new(
                DiagnosticKind::Parse,
                file_path,
                "a module needs a `#define_import_path` line",
            ))));
        };
        if let Some(e) = super::limits::wgsl_too_deep(source) {
            return Err(super::limits::limit_error(file_path, source, e));
        }
        self.load_lodkit_for([source])?;
        let composer = composer_in(&mut self.composer, self.capabilities);
        let sources = vec![(file_path.to_owned(), Arc::from(source))];
        super::limits::on_deep_stack_once(|| add_modules(composer, sources, false, None))
            .unwrap_or_else(|()| Err(deep_stack_failed(file_path)))?;
        self.user_modules.push(name.clone());
        Ok(name)
    }

    /// Composes a top-level shader against the library and validates it. A shader def set to
    /// `Bool(false)` is left out, so `#ifdef` sees it as off in WGSL and GLSL alike.
    pub fn compose(&mut self, desc: &ComposeDescriptor) -> Result<Composed, ShaderError> {
        // The front ends recurse once per nesting level of an expression, and so do validation
        // and the lowering of long operator chains: within the limits (`limits`) they run on a
        // thread with a deep stack, whatever thread the engine calls from.
        // (GLSL is checked after its includes and macros, WESL with its modules when linked.)
        if desc.language == SourceLanguage::Wgsl
            && let Some(e) = super::limits::wgsl_too_deep(desc.source)
        {
            return Err(super::limits::limit_error(desc.file_path, desc.source, e));
        }
        super::limits::on_deep_stack_once(|| self.compose_here(desc))
            .unwrap_or_else(|()| Err(deep_stack_failed(desc.file_path)))
    }

    fn compose_here(&mut self, desc: &ComposeDescriptor) -> Result<Composed, ShaderError> {
        let mut defs = desc.shader_defs.clone();
        defs.retain(|_, v| *v != ShaderDefValue::Bool(false));
        let desc = &ComposeDescriptor {
            shader_defs: defs,
            ..desc.clone()
        };
        let module = match desc.language {
            SourceLanguage::Wgsl if !plain::needs_composer(desc.source) => {
                return self.compose_plain(desc);
            }
            SourceLanguage::Wgsl => return self.compose_wgsl_validated(desc),
            SourceLanguage::Glsl(stage) => return self.compose_glsl(desc, stage),
            SourceLanguage::Wesl => {
                // Linked first without wesl-rs's own checks, which naga repeats on the linked
                // shader (names defined, no duplicates or cycles, call arities) and which cost
                // more than naga's validation. A shader that fails, or that links a module of
                // the user's (whose unused declarations only wesl-rs reads), is linked again
                // with them: verdicts and diagnostics are those of the checked link, whose WGSL
                // is the same text.
                if let Ok((module, false)) = self.compose_wesl(desc, false) {
                    return match super::memo::validate(
                        self.memo.as_mut(),
                        &module,
                        self.capabilities,
                    ) {
                        Ok(info) => Ok(Composed { module, info }),
                        Err(e) => {
                            self.compose_wesl(desc, true)?;
                            Err(validation_error(&e, desc.file_path))
                        }
                    };
                }
                self.compose_wesl(desc, true)?.0
            }
        };
        let info = super::memo::validate(self.memo.as_mut(), &module, self.capabilities)
            .map_err(|e| validation_error(&e, desc.file_path))?;
        Ok(Composed { module, info })
    }

    /// Links a WESL shader (with wesl-rs's checks when `checked`) and parses the WGSL; `true`
    /// beside the module when a module of the user's was linked in.
    #[cfg(feature = "wesl")]
    fn compose_wesl(
        &mut self,
        desc: &ComposeDescriptor,
        checked: bool,
    ) -> Result<(naga::Module, bool), ShaderError> {
        let mut defs: Vec<(String, ShaderDefValue)> = desc
            .shader_defs
            .iter()
            .map(|(k, v)| (k.clone(), *v))
            .collect();
        defs.sort_by(|a, b| a.0.cmp(&b.0));
        let linked = super::wesl_link::link(
            desc.source,
            desc.file_path,
            &defs,
            &self.wesl_modules,
            checked,
        )?;
        let module = naga::front::wgsl::parse_str(&linked.wgsl).map_err(|e| {
            ShaderError::Source(Box::new(super::wesl_link::front_end_diagnostic(
                &e,
                &linked,
                desc.file_path,
                desc.source,
            )))
        })?;
        Ok((module, linked.with_user_modules))
    }

    #[cfg(not(feature = "wesl"))]
    fn compose_wesl(
        &mut self,
        desc: &ComposeDescriptor,
        _checked: bool,
    ) -> Result<(naga::Module, bool), ShaderError> {
        Err(ShaderError::Source(Box::new(Diagnostic::new(
            DiagnosticKind::Parse,
            desc.file_path,
            "linking WESL needs lodkit's `wesl` feature (the `lodkit` command has it)",
        ))))
    }

    fn compose_wgsl(&mut self, desc: &ComposeDescriptor) -> Result<naga::Module, ShaderError> {
        self.load_lodkit_for([desc.source])?;
        self.check_imports(desc)?;
        let composed = composer_in(&mut self.composer, self.capabilities).make_naga_module(
            NagaModuleDescriptor {
                source: desc.source,
                file_path: desc.file_path,
                shader_type: ShaderType::Wgsl,
                shader_defs: desc.shader_defs.clone(),
                additional_imports: &[],
            },
        );
        composed.map_err(|e| {
            let d = from_composer_error(&e, self.composer(), Some(desc.source));
            ShaderError::Source(Box::new(self.with_import_hint(d)))
        })
    }

    /// Whether the composer has the module `import_path` (no composer: no module).
    fn contains_module(&self, import_path: &str) -> bool {
        self.composer
            .get()
            .is_some_and(|c| c.contains_module(import_path))
    }

    /// Every `#import` must name a module the composer has, used or not (naga_oil itself only
    /// complains about imports that are used).
    fn check_imports(&self, desc: &ComposeDescriptor) -> Result<(), ShaderError> {
        for (import, line_at) in declared_imports(desc.source) {
            if let Some(d) = self.unavailable_import(&import, desc, line_at) {
                return Err(ShaderError::Source(Box::new(d)));
            }
            let found = longest_prefix(&import, |p| self.contains_module(p).then_some(()));
            if found.is_none() {
                let name = module_prefix(&import);
                // Search from this statement on: an earlier import may contain the name too.
                let site = import_site(&desc.source[line_at..], name);
                let span = if site.is_empty() {
                    line_at..line_at + "#import".len()
                } else {
                    site.start + line_at..site.end + line_at
                };
                let d = Diagnostic::new(
                    DiagnosticKind::UnknownImport,
                    desc.file_path,
                    format!("unknown import `{name}`"),
                )
                .with_span(Arc::from(desc.source), span)
                .with_label("no module has this import path");
                return Err(ShaderError::Source(Box::new(self.with_import_hint(d))));
            }
        }
        Ok(())
    }

    /// The diagnostic for importing a user module that could not be added, at the import in
    /// the user's file, with the module's own problem as notes.
    fn unavailable_import(
        &self,
        import: &str,
        desc: &ComposeDescriptor,
        line_at: usize,
    ) -> Option<Diagnostic> {
        let (candidate, problem) = longest_prefix(import, |p| self.unavailable.get(p))?;
        let site = import_site(&desc.source[line_at..], candidate);
        let span = site.start + line_at..site.end + line_at;
        let mut d = Diagnostic::new(
            problem.kind,
            desc.file_path,
            format!("cannot import `{candidate}`: {}", problem.message),
        )
        .with_span(Arc::from(desc.source), span)
        .with_note(problem.render().trim_end().to_owned());
        if let Some(hint) = &problem.hint {
            d = d.with_hint(hint.clone());
        }
        Some(d)
    }

    fn with_import_hint(&self, mut d: Diagnostic) -> Diagnostic {
        if d.kind == DiagnosticKind::UnknownImport {
            let name = d
                .message
                .trim_start_matches("unknown import `")
                .trim_end_matches('`')
                .to_owned();
            let known: Vec<String> = registry::import_paths()
                .into_iter()
                .map(str::to_owned)
                .chain(self.user_modules.iter().cloned())
                .collect();
            let module_part = module_prefix(&name);
            if let Some(best) = closest(module_part, known.iter().map(String::as_str)) {
                d = d.with_hint(format!("did you mean `{best}`?"));
            }
            d = d.with_note(format!(
                "lodkit modules: {}",
                registry::import_paths().join(", ")
            ));
        }
        d
    }

    fn compose_glsl(
        &mut self,
        desc: &ComposeDescriptor,
        stage: naga::ShaderStage,
    ) -> Result<Composed, ShaderError> {
        let expanded = glsl::expand_includes(desc.file_path, desc.source, &self.include_dirs)?;
        let defines: Vec<(String, String)> = desc
            .shader_defs
            .iter()
            .map(|(k, v)| {
                let v = match v {
                    ShaderDefValue::Bool(b) => u32::from(*b).to_string(),
                    ShaderDefValue::Int(i) => i.to_string(),
                    ShaderDefValue::UInt(u) => u.to_string(),
                };
                (k.clone(), v)
            })
            .collect();
        // naga's GLSL front end recurses once per nesting level with no limit of its own, and
        // macros can stand for any nesting: the brackets as written, then bounds on what the
        // macros expand to, then the expanded tokens themselves (see `limits`).
        let text = expanded.text.as_str();
        let too_deep = super::limits::too_deep(text)
            .or_else(|| super::macros::too_large(text, &defines))
            .or_else(|| super::limits::expression_too_deep(text, &defines));
        if let Some(nesting) = too_deep {
            let message = nesting.message();
            let d = expanded.diagnostic(DiagnosticKind::Limit, nesting.at, message);
            return Err(ShaderError::Source(Box::new(
                d.with_label("nested too deep")
                    .with_hint("split the expression into local variables"),
            )));
        }
        let options = naga::front::glsl::Options {
            stage,
            defines: defines.into_iter().collect(),
        };
        // Within the limits above naga's parser still recurses thousands of levels deep, and the
        // validator recurses once per nested block (a `?:` chain nests as deep): `compose` runs
        // this on a thread with a deep stack. A panic in naga is this file's error.
        let (capabilities, memo) = (self.capabilities, &mut self.memo);
        let parse_and_validate = || {
            let module = naga::front::glsl::Frontend::default().parse(&options, text)?;
            let info = super::memo::validate(memo.as_mut(), &module, capabilities);
            Ok((module, info))
        };
        let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse_and_validate));
        let parsed = parsed.map_err(|_| {
            ShaderError::Source(Box::new(expanded.diagnostic(
                DiagnosticKind::Parse,
                0..0,
                "naga's GLSL front end failed on this file (it panicked)".into(),
            )))
        })?;
        let (module, info) = parsed.map_err(|e: naga::front::glsl::ParseErrors| {
            let first = e.errors.first();
            let span = first.and_then(|e| e.meta.to_range()).unwrap_or(0..0);
            let message = first.map(|e| e.kind.to_string()).unwrap_or_default();
            let mut d = expanded.diagnostic(DiagnosticKind::Parse, span, message);
            for more in e.errors.iter().skip(1) {
                d = d.with_note(more.kind.to_string());
            }
            ShaderError::Source(Box::new(d))
        })?;
        let info = info.map_err(|e| {
            let span = e
                .spans()
                .next()
                .and_then(|(s, _)| s.to_range())
                .unwrap_or(0..0);
            let (file, source, range) = expanded.locate(span.clone()).unwrap_or((
                desc.file_path.to_owned(),
                Arc::from(""),
                0..0,
            ));
            let d = validation_diagnostic(&e, file, source, |_| range.clone());
            ShaderError::Source(Box::new(d))
        })?;
        Ok(Composed { module, info })
    }
}

/// A naga_oil composer validating with `capabilities`.
fn new_composer(capabilities: naga::valid::Capabilities) -> Composer {
    // Setting the field (not `with_capabilities`, which builds a second composer and so
    // compiles naga_oil's regular expressions twice) on a composer that has no modules yet.
    let mut composer = Composer::default();
    composer.capabilities = capabilities;
    composer
}

/// The composer in `cell`, built first if it is not there yet.
fn composer_in(
    cell: &mut OnceLock<Composer>,
    capabilities: naga::valid::Capabilities,
) -> &mut Composer {
    cell.get_or_init(|| new_composer(capabilities));
    cell.get_mut()
        .expect("the composer was built by get_or_init just above")
}

/// The error when the deep-stack thread that parses `what` panicked or could not start.
fn deep_stack_failed(what: &str) -> ShaderError {
    ShaderError::Source(Box::new(Diagnostic::new(
        DiagnosticKind::Parse,
        what,
        "naga or naga_oil failed on this file (it panicked, or no thread could be started)",
    )))
}
