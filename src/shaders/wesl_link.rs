//! Linking a user's WESL shader against lodkit's WESL package with wesl-rs (crate `wesl` 0.4.0,
//! the newest that builds on Rust 1.95; it has no naga of its own), so that the WGSL it links can
//! be validated by naga like any composed shader. Feature `wesl`.
//!
//! Shader defs map as Bevy 0.20 maps them: a bool def is a condition (`@if(NAME)`), an int or
//! uint def sets the condition and becomes `const NAME = v;` in the virtual module `constants`
//! (`import constants::NAME;`). WESL files found under the include folders are user modules,
//! `package::<path>` relative to their folder.

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use naga_oil::compose::ShaderDefValue;
use wesl::{ModulePath, VirtualResolver, Wesl};

use super::diagnostic::{Diagnostic, DiagnosticKind};
use super::{ShaderError, closest, read_source, registry};

/// The module path the user's shader is linked as.
const ROOT: &str = "package::main";

/// A `.wesl` file of the user's, importable as `package::<path>`.
#[derive(Debug, Clone)]
pub(crate) struct WeslUserModule {
    pub module_path: String,
    pub file: String,
    pub source: Arc<str>,
}

/// Every `.wesl` file under `dir` whose path contains none of `exclude`, as user modules
/// relative to it.
pub(crate) fn collect_user_modules(
    dir: &Path,
    exclude: &[String],
    out: &mut Vec<WeslUserModule>,
) -> Result<(), ShaderError> {
    let mut files = Vec::new();
    super::loading::collect_files(dir, "wesl", exclude, &mut files)?;
    files.sort();
    for file in files {
        let rel = file.strip_prefix(dir).unwrap_or(&file).with_extension("");
        let parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        out.push(WeslUserModule {
            module_path: format!("package::{}", parts.join("::")),
            file: file.display().to_string(),
            source: Arc::from(read_source(&file)?),
        });
    }
    Ok(())
}

/// WGSL linked by wesl-rs, and the original name of every declaration it renamed.
pub(crate) struct Linked {
    pub wgsl: String,
    renames: Vec<(String, String)>,
    /// Whether a module of the user's (an include folder's) was linked in.
    pub with_user_modules: bool,
}

impl Linked {
    /// `text` with linker-mangled names replaced by the names the user wrote.
    fn unmangle(&self, text: &str) -> String {
        let mut out = String::with_capacity(text.len());
        let mut word = String::new();
        let flush = |word: &mut String, out: &mut String| {
            match self.renames.iter().find(|(m, _)| m == word) {
                Some((_, original)) => out.push_str(original),
                None => out.push_str(word),
            }
            word.clear();
        };
        for c in text.chars() {
            if c.is_alphanumeric() || c == '_' {
                word.push(c);
            } else {
                flush(&mut word, &mut out);
                out.push(c);
            }
        }
        flush(&mut word, &mut out);
        out
    }
}

/// Links `source` (the file `file`) against lodkit's WESL modules and `user_modules`, with
/// `defs`, and returns the WGSL. Errors point into the file they are in. `validate` runs
/// wesl-rs's own checks (names defined, no duplicates or cycles, call arities) on every module
/// linked and on the result; without them a link only fails where it cannot go on.
pub(crate) fn link(
    source: &str,
    file: &str,
    defs: &[(String, ShaderDefValue)],
    user_modules: &[WeslUserModule],
    validate: bool,
) -> Result<Linked, ShaderError> {
    let sources = Sources {
        root: (file.to_owned(), Arc::from(source)),
        user: user_modules,
    };
    let path = |p: &str| -> ModulePath { p.parse().expect("lodkit's module paths parse") };
    let mut resolver = VirtualResolver::new();
    resolver.add_module(path(ROOT), source.to_owned().into());
    for (_, import, source) in registry::wesl_module_sources() {
        resolver.add_module(path(&import), source.into());
    }
    // Brackets or operator chains nested past the limits would recurse the WESL parser off the
    // stack.
    for (text, name) in std::iter::once((source, file))
        .chain(user_modules.iter().map(|m| (&*m.source, m.file.as_str())))
    {
        if let Some(nesting) = super::limits::wgsl_too_deep(text) {
            return Err(super::limits::limit_error(name, text, nesting));
        }
    }
    // A user module at the root's own path (a `main.wesl` in an include folder) would replace
    // the file being linked: the file being linked wins.
    for m in user_modules.iter().filter(|m| m.module_path != ROOT) {
        let Ok(p) = m.module_path.parse::<ModulePath>() else {
            return Err(source_error(Diagnostic::new(
                DiagnosticKind::Parse,
                m.file.clone(),
                format!("`{}` is not a WESL module path", m.module_path),
            )));
        };
        resolver.add_module(p, m.source.to_string().into());
    }
    let constants: String = defs
        .iter()
        .filter_map(|(name, value)| match value {
            ShaderDefValue::Bool(_) => None,
            ShaderDefValue::Int(v) => Some(format!("const {name} = {v};\n")),
            ShaderDefValue::UInt(v) => Some(format!("const {name} = {v}u;\n")),
        })
        .collect();
    if !constants.is_empty() {
        resolver.add_module(path("constants"), constants.into());
    }
    let mut compiler = Wesl::new("").set_custom_resolver(resolver);
    compiler.set_options(wesl::CompileOptions {
        imports: true,
        condcomp: true,
        strip: true,
        // Keep every declaration of the user's file, so a file of helper functions validates
        // too; imported modules contribute what is used.
        keep_root: true,
        mangle_root: false,
        validate,
        ..Default::default()
    });
    for (name, value) in defs {
        compiler.set_feature(name, !matches!(value, ShaderDefValue::Bool(false)));
    }
    finish(&compiler, &sources)
}

fn finish(compiler: &Wesl<VirtualResolver<'_>>, sources: &Sources) -> Result<Linked, ShaderError> {
    use wesl::SourceMap;
    let root: ModulePath = ROOT.parse().expect("root path parses");
    let result = compiler
        .compile(&root)
        .map_err(|e| source_error(sources.diagnostic(e)))?;
    let wgsl = result.to_string();
    // Anything but the root, lodkit's modules and the defs' constants counts as the user's.
    let with_user_modules = result.modules.iter().any(|m| {
        let m = m.to_string();
        m != ROOT && m != "constants" && !m.starts_with("lodkit::")
    });
    let mut renames: Vec<(String, String)> = Vec::new();
    if let Some(map) = &result.sourcemap {
        for word in wgsl.split(|c: char| !(c.is_alphanumeric() || c == '_')) {
            if word.is_empty() || renames.iter().any(|(m, _)| m == word) {
                continue;
            }
            if let Some((_, original)) = map.get_decl(word).filter(|(_, o)| *o != word) {
                renames.push((word.to_owned(), original.to_owned()));
            }
        }
    }
    Ok(Linked {
        wgsl,
        renames,
        with_user_modules,
    })
}

fn source_error(d: Diagnostic) -> ShaderError {
    ShaderError::Source(Box::new(d))
}

/// The texts linked: the user's file, the user's modules, lodkit's modules.
struct Sources<'a> {
    root: (String, Arc<str>),
    user: &'a [WeslUserModule],
}

impl Sources<'_> {
    /// File name and text of the module `path` (`package::main`, `lodkit::topic`, ...).
    fn module(&self, path: &str) -> Option<(String, Arc<str>)> {
        if path == ROOT {
            return Some(self.root.clone());
        }
        if let Some(m) = self.user.iter().find(|m| m.module_path == path) {
            return Some((m.file.clone(), m.source.clone()));
        }
        registry::wesl_module_sources()
            .find(|(_, import, _)| import == path)
            .map(|(file, _, source)| (format!("shader_lib/{file}"), Arc::from(source)))
    }

    /// A diagnostic for a wesl-rs error: in the module it names, at its span when it has one;
    /// an unknown import points at the import in the user's file and names the closest module.
    fn diagnostic(&self, error: wesl::Error) -> Diagnostic {
        let diag = match error {
            wesl::Error::Error(d) => d,
            other => wesl::Diagnostic::from(other),
        };
        let (kind, missing) = classify(&diag.error);
        let message = diag.error.to_string();
        let module = diag.detail.module_path.as_ref().map(ToString::to_string);
        let (file, text) = module
            .as_deref()
            .and_then(|m| self.module(m))
            .unwrap_or_else(|| self.root.clone());
        let mut d = Diagnostic::new(kind, file.clone(), message);
        let span: Option<Range<usize>> = diag.detail.span.map(|s| s.start..s.end);
        if let Some(span) = span.filter(|s| s.end <= text.len()) {
            d = d.with_span(text, span);
        } else if let Some(missing) = &missing {
            // Import errors carry no span: find the import in the user's file.
            let (root_file, root_text) = &self.root;
            let tail = missing.split("::").last().unwrap_or(missing);
            let at = root_text
                .find(missing.as_str())
                .map(|i| i..i + missing.len())
                .or_else(|| {
                    root_text
                        .match_indices(tail)
                        .find(|(i, _)| root_text[..*i].rfind("import").is_some())
                        .map(|(i, _)| i..i + tail.len())
                });
            d = Diagnostic::new(kind, root_file.clone(), d.message.clone());
            if let Some(at) = at {
                d = d.with_span(root_text.clone(), at);
            }
            if let Some(best) = closest(
                missing,
                registry::wesl_modules().filter_map(|m| m.import_path.as_deref()),
            ) {
                d = d.with_hint(format!("did you mean `{best}`?"));
            }
        }
        if let Some(decl) = &diag.detail.declaration {
            d = d.with_note(format!("in `{decl}`"));
        }
        d
    }
}

/// The diagnostic kind of a wesl-rs error, and for a missing module the path that was asked for.
fn classify(error: &wesl::Error) -> (DiagnosticKind, Option<String>) {
    use wesl::{Error, ImportError, ResolveError};
    let not_found = |e: &ResolveError| match e {
        ResolveError::ModuleNotFound(p, _) => Some(p.to_string()),
        ResolveError::FileNotFound(p, _) => Some(p.display().to_string()),
        ResolveError::Error(d) => classify(&d.error).1,
    };
    match error {
        Error::ParseError(_) => (DiagnosticKind::Parse, None),
        Error::ValidateError(_) => (DiagnosticKind::Validation, None),
        Error::CondCompError(_) => (DiagnosticKind::Preprocessor, None),
        Error::ResolveError(e) => (DiagnosticKind::UnknownImport, not_found(e)),
        Error::ImportError(ImportError::ResolveError(e)) => {
            (DiagnosticKind::UnknownImport, not_found(e))
        }
        Error::ImportError(ImportError::MissingDecl(module, item)) => (
            DiagnosticKind::UnknownImport,
            Some(format!("{module}::{item}")),
        ),
        Error::ImportError(_) => (DiagnosticKind::Parse, None),
        Error::Error(d) => classify(&d.error),
        _ => (DiagnosticKind::Parse, None),
    }
}

/// A naga front-end error (usually a type error) in the WGSL that wesl-rs linked, pointed at the
/// declaration of the user's file it comes from: the linked text is reformatted, so the
/// declaration is found by name (root declarations keep their names). The error as naga
/// reports it in the linked WGSL follows as a note.
pub(crate) fn front_end_diagnostic(
    err: &naga::front::wgsl::ParseError,
    linked: &Linked,
    file: &str,
    source: &str,
) -> Diagnostic {
    let wgsl = linked.wgsl.as_str();
    let range = err
        .labels()
        .next()
        .and_then(|(span, _)| span.to_range())
        .map_or(0..0, |r| r.start.min(wgsl.len())..r.end.min(wgsl.len()));
    let mut d = Diagnostic::new(DiagnosticKind::Parse, file, linked.unmangle(err.message()));
    let line = wgsl[..range.start].rfind('\n').map_or(0, |i| i + 1);
    let line_text = linked.unmangle(wgsl[line..].lines().next().unwrap_or_default().trim());
    let labelled = wgsl.get(range.clone()).map(|t| linked.unmangle(t));
    let declaration = enclosing_declaration(wgsl, range.start)
        .map(|name| linked.unmangle(name))
        .and_then(|name| find_declaration(source, &name));
    match declaration {
        // The same statement in the user's text: point at the labelled expression in it.
        Some(decl) => match find_statement(source, decl.start, &line_text, labelled.as_deref()) {
            Some(at) => d = d.with_span(Arc::from(source), at),
            None => {
                d = d
                    .with_span(Arc::from(source), decl)
                    .with_label("in this declaration")
            }
        },
        None => d = d.with_note("in a declaration imported from a lodkit module"),
    }
    for (_, label) in err.labels() {
        if !label.is_empty() {
            d = d.with_note(linked.unmangle(label));
        }
    }
    d.with_note(format!("linked WGSL: `{line_text}`"))
}

/// Name of the module-scope declaration of `wgsl` that contains byte `offset`.
fn enclosing_declaration(wgsl: &str, offset: usize) -> Option<&str> {
    let mut start = None;
    let mut at = 0;
    for line in wgsl.split_inclusive('\n') {
        if at > offset {
            break;
        }
        if !line.starts_with(char::is_whitespace) && !line.starts_with('}') {
            start = Some(line);
        }
        at += line.len();
    }
    declared_name(start?)
}

/// The name a module-scope declaration line declares (`fn f(`, `struct S {`, `const K`, ...).
fn declared_name(line: &str) -> Option<&str> {
    let mut words = line
        .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == '@'))
        .filter(|w| !w.is_empty() && !w.starts_with('@'));
    loop {
        let w = words.next()?;
        // A named declaration (`const_assert` names nothing; `var` is below).
        if super::wesl::DECLARATION_KEYWORDS.contains(&w) && !matches!(w, "var" | "const_assert") {
            return words.next();
        }
        if w == "var" {
            // `var<storage, read> name` : skip the address space and access mode.
            return words.find(|w| {
                !matches!(
                    *w,
                    "private"
                        | "workgroup"
                        | "uniform"
                        | "storage"
                        | "read"
                        | "read_write"
                        | "write"
                        | "function"
                )
            });
        }
    }
}

/// Byte range of the name in the declaration of `name` in `source`, if there is one.
fn find_declaration(source: &str, name: &str) -> Option<Range<usize>> {
    let mut at = 0;
    for line in source.split_inclusive('\n') {
        let module_scope = !line.starts_with(char::is_whitespace);
        if module_scope && declared_name(line) == Some(name) {
            let i = line.find(name)?;
            return Some(at + i..at + i + name.len());
        }
        at += line.len();
    }
    None
}

/// Where the statement `statement` (as linked: one line, reformatted) is in `source` after byte
/// `from`, compared without whitespace; the span of `labelled` inside it when given, else of
/// the statement.
fn find_statement(
    source: &str,
    from: usize,
    statement: &str,
    labelled: Option<&str>,
) -> Option<Range<usize>> {
    let squash = |s: &str| s.chars().filter(|c| !c.is_whitespace()).collect::<String>();
    let want = squash(statement);
    if want.is_empty() {
        return None;
    }
    let mut at = 0;
    for line in source.split_inclusive('\n') {
        if at >= from && squash(line) == want {
            let start = at + line.len() - line.trim_start().len();
            if let Some(i) = labelled
                .filter(|l| !l.is_empty())
                .and_then(|l| line.find(l))
            {
                let l = labelled.unwrap_or_default();
                return Some(at + i..at + i + l.len());
            }
            return Some(start..at + line.trim_end().len());
        }
        at += line.len();
    }
    None
}
