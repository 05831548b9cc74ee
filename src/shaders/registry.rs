//! The embedded shader library: every file under `shader_lib/`, described from its own source.

use std::sync::OnceLock;

use super::comments::{CommentSyntax, blank_comments};

/// `(path relative to shader_lib/, source)` for every `.wgsl`, `.wesl` and `.glsl` file, sorted
/// by path.
static FILES: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/shader_lib.rs"));

/// Shading language of a library file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Language {
    /// WGSL, composed with naga_oil (`#import lodkit::<topic>`).
    Wgsl,
    /// GLSL 450, included textually (`#include "lodkit/<topic>.glsl"`).
    Glsl,
    /// WESL (`import lodkit::<topic>::item;`, `@if` conditions), generated from the WGSL module:
    /// Bevy 0.20, wesl-js, wesl-rs.
    Wesl,
}

/// What a library file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ModuleKind {
    /// An importable module (`shader_lib/wgsl/lodkit/*.wgsl`, its WESL form or its GLSL twin).
    Module,
    /// A complete entry-point shader built from modules (`shader_lib/passes/`).
    Pass,
}

/// A function a module exports.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct FunctionInfo {
    /// Name as written in the source (`lodkit_`-prefixed in GLSL twins).
    pub name: String,
    /// The declaration up to the opening brace, e.g. `fn f(a: f32) -> f32`.
    pub signature: String,
    /// The `///` doc comment above the function, lines joined by spaces.
    pub doc: String,
}

/// A shader def a module reads (`#ifdef NAME`, `#if NAME == ...`, `#{NAME}`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct ShaderDefInfo {
    /// Name of the def.
    pub name: String,
    /// What the file header says about it (type, default, meaning); empty when undocumented.
    pub doc: String,
}

/// One embedded file of the shader library, described from its own source.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ModuleInfo {
    /// Path relative to `shader_lib/`, e.g. `wgsl/lodkit/normal_distance.wgsl`.
    pub path: &'static str,
    /// Language of the file.
    pub language: Language,
    /// Module or complete pass.
    pub kind: ModuleKind,
    /// `lodkit::<topic>` for modules and their GLSL twins; `None` for passes.
    pub import_path: Option<String>,
    /// Path to `#include` for GLSL twins (`lodkit/<topic>.glsl`); `None` otherwise.
    pub include_path: Option<String>,
    /// For WESL modules, the asset path Bevy 0.20 registers them under so that
    /// `import lodkit::<topic>::...` resolves (`embedded://lodkit/<topic>.wesl`,
    /// with `Shader::from_wesl(source, path)`); `None` otherwise.
    pub embedded_path: Option<String>,
    /// First line of the header, after the module name.
    pub summary: String,
    /// Functions defined at file scope, in source order.
    pub functions: Vec<FunctionInfo>,
    /// Constants defined at file scope, in source order.
    pub constants: Vec<String>,
    /// Shader defs the file reads.
    pub shader_defs: Vec<ShaderDefInfo>,
    /// The whole source text.
    #[serde(skip)]
    pub source: &'static str,
}

impl ModuleInfo {
    /// Looks up an exported function by name.
    pub fn function(&self, name: &str) -> Option<&FunctionInfo> {
        self.functions.iter().find(|f| f.name == name)
    }
}

/// Every file of the shader library, described: modules by import path (each WGSL module followed
/// by its GLSL twin and its WESL form), then passes. Parsed once, on first use.
pub fn modules() -> &'static [ModuleInfo] {
    static MODULES: OnceLock<Vec<ModuleInfo>> = OnceLock::new();
    MODULES.get_or_init(|| {
        let mut all: Vec<ModuleInfo> = FILES
            .iter()
            .map(|(path, src)| describe(path, src))
            .collect();
        all.sort_by_key(|m| {
            (
                m.kind == ModuleKind::Pass,
                m.import_path.clone(),
                m.language,
                m.path,
            )
        });
        all
    })
}

/// The WGSL module with import path `import_path` (e.g. `lodkit::normal_distance`).
pub fn find_module(import_path: &str) -> Option<&'static ModuleInfo> {
    modules().iter().find(|m| {
        m.language == Language::Wgsl
            && m.kind == ModuleKind::Module
            && m.import_path.as_deref() == Some(import_path)
    })
}

/// The library path (`wgsl/lodkit/<topic>.wgsl`) and source of the WGSL module with import
/// path `import_path`: what [`find_module`] finds, without describing the whole library first
/// (the cold start of a check that composes one shader).
#[cfg(feature = "compose")]
pub(crate) fn find_module_source(import_path: &str) -> Option<(&'static str, &'static str)> {
    FILES
        .iter()
        .filter(|(path, _)| path.ends_with(".wgsl") && !path.starts_with("passes/"))
        .find(|(_, source)| define_import_path(source).as_deref() == Some(import_path))
        .map(|&(path, source)| (path, source))
}

/// `(library path, import path, source)` of every WESL module (`wesl/lodkit/<topic>.wesl`,
/// imported as `lodkit::<topic>`): what [`wesl_modules`] lists, without describing the whole
/// library first (the cold start of a check that links one WESL shader).
#[cfg(feature = "wesl")]
pub(crate) fn wesl_module_sources() -> impl Iterator<Item = (&'static str, String, &'static str)> {
    FILES.iter().filter_map(|&(path, source)| {
        let topic = path.strip_prefix("wesl/lodkit/")?.strip_suffix(".wesl")?;
        Some((path, format!("lodkit::{topic}"), source))
    })
}

/// The GLSL twin whose include path is `include_path` (e.g. `lodkit/normal_distance.glsl`).
pub fn find_glsl_include(include_path: &str) -> Option<&'static ModuleInfo> {
    modules()
        .iter()
        .find(|m| m.include_path.as_deref() == Some(include_path))
}

/// The WESL form of the module with import path `import_path` (e.g. `lodkit::visibility`).
pub fn find_wesl_module(import_path: &str) -> Option<&'static ModuleInfo> {
    wesl_modules().find(|m| m.import_path.as_deref() == Some(import_path))
}

/// The WESL modules, each with the `embedded://` path Bevy 0.20 registers it under.
pub fn wesl_modules() -> impl Iterator<Item = &'static ModuleInfo> {
    modules()
        .iter()
        .filter(|m| m.language == Language::Wesl && m.kind == ModuleKind::Module)
}

/// The GLSL twin of a WGSL module (same topic), if there is one.
pub fn glsl_twin(wgsl: &ModuleInfo) -> Option<&'static ModuleInfo> {
    let topic = wgsl.import_path.as_deref()?.strip_prefix("lodkit::")?;
    find_glsl_include(&format!("lodkit/{topic}.glsl"))
}

/// Import paths of all WGSL modules, sorted.
pub fn import_paths() -> Vec<&'static str> {
    modules()
        .iter()
        .filter(|m| m.language == Language::Wgsl && m.kind == ModuleKind::Module)
        .filter_map(|m| m.import_path.as_deref())
        .collect()
}

fn describe(path: &'static str, source: &'static str) -> ModuleInfo {
    let language = if path.ends_with(".glsl") {
        Language::Glsl
    } else if path.ends_with(".wesl") {
        Language::Wesl
    } else {
        Language::Wgsl
    };
    let kind = if path.starts_with("passes/") {
        ModuleKind::Pass
    } else {
        ModuleKind::Module
    };
    let stem = path
        .rsplit('/')
        .next()
        .and_then(|f| f.split('.').next())
        .unwrap_or_default();
    let (import_path, include_path) = match (kind, language) {
        (ModuleKind::Pass, _) => (None, None),
        (ModuleKind::Module, Language::Wgsl) => (define_import_path(source), None),
        (ModuleKind::Module, Language::Glsl) => (
            Some(format!("lodkit::{stem}")),
            path.strip_prefix("glsl/").map(str::to_owned),
        ),
        (ModuleKind::Module, Language::Wesl) => (Some(format!("lodkit::{stem}")), None),
    };
    let embedded_path = (language == Language::Wesl && kind == ModuleKind::Module)
        .then(|| format!("embedded://lodkit/{stem}.wesl"));
    let header = header_lines(source);
    let summary = header
        .first()
        .map(|l| match l.split_once(" — ") {
            Some((_, rest)) => rest.trim().to_owned(),
            None => l.trim().to_owned(),
        })
        .unwrap_or_default();
    let guard = format!("LODKIT_{}_GLSL", stem.to_ascii_uppercase());
    // A GLSL twin's include guard, and the switches of its hooks (`LODKIT_<TOPIC>_HOOKS`: the
    // functions that read a texture through a function the includer defines), are GLSL's own,
    // not shader defs of the module.
    let is_hook_switch =
        |d: &str| language == Language::Glsl && d.starts_with("LODKIT_") && d.ends_with("_HOOKS");
    let shader_defs = used_shader_defs(source, language)
        .into_iter()
        .filter(|d| *d != guard && !is_hook_switch(d))
        .map(|name| ShaderDefInfo {
            doc: header_def_doc(&header, &name),
            name,
        })
        .collect();
    ModuleInfo {
        path,
        language,
        kind,
        import_path,
        include_path,
        embedded_path,
        summary,
        functions: functions(source, language),
        constants: constants(source, language),
        shader_defs,
        source,
    }
}

/// The name after `#define_import_path`, if the source declares one.
pub(crate) fn define_import_path(source: &str) -> Option<String> {
    source.lines().find_map(|l| {
        l.trim()
            .strip_prefix("#define_import_path")
            .map(|rest| rest.trim().to_owned())
            .filter(|s| !s.is_empty())
    })
}

/// The leading `//` comment block, without the slashes.
fn header_lines(source: &str) -> Vec<&str> {
    source
        .lines()
        .take_while(|l| l.starts_with("//"))
        .map(|l| l.trim_start_matches('/').strip_prefix(' ').unwrap_or(""))
        .collect()
}

/// What the header's `Shader defs:` section says about `name`.
fn header_def_doc(header: &[&str], name: &str) -> String {
    let Some(start) = header.iter().position(|l| l.starts_with("Shader defs:")) else {
        return String::new();
    };
    header[start..]
        .iter()
        .map(|l| l.trim_start_matches("Shader defs:").trim())
        .find_map(|l| l.strip_prefix(name).map(|rest| rest.trim().to_owned()))
        .unwrap_or_default()
}

/// Shader defs the source tests or substitutes outside comments, in order of first use.
pub(crate) fn used_shader_defs(source: &str, language: Language) -> Vec<String> {
    let mut defs: Vec<String> = Vec::new();
    let mut push = |name: &str| {
        if !name.is_empty() && !defs.iter().any(|d| d == name) {
            defs.push(name.to_owned());
        }
    };
    let syntax = match language {
        Language::Glsl => CommentSyntax::Glsl,
        Language::Wgsl | Language::Wesl => CommentSyntax::Wgsl,
    };
    let code = blank_comments(source, syntax);
    for line in code.lines() {
        let t = line.trim_start();
        // naga_oil's `#else ifdef X` (and `#else if ...`) names its def without a second `#`.
        let (t, hash) = match t.strip_prefix("#else") {
            Some(rest) => (rest.trim_start(), ""),
            None => (t, "#"),
        };
        for directive in ["ifdef", "ifndef", "if"] {
            let Some(t) = t.strip_prefix(hash) else { break };
            if let Some(rest) = t.strip_prefix(directive) {
                if rest.starts_with(char::is_whitespace) {
                    push(identifier(rest.trim_start()));
                }
                break;
            }
        }
        let mut rest = line;
        // WESL conditions: every name in `@if(...)` / `@elif(...)`.
        for attr in ["@if(", "@elif("] {
            let mut rest = line;
            while let Some(i) = rest.find(attr) {
                let after = &rest[i + attr.len()..];
                let end = after.find(')').unwrap_or(after.len());
                for name in after[..end].split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
                    if name != "true" && name != "false" {
                        push(name);
                    }
                }
                rest = &after[end..];
            }
        }
        while let Some(i) = rest.find("#{") {
            let after = &rest[i + 2..];
            let end = after.find('}').unwrap_or(after.len());
            push(after[..end].trim());
            rest = &after[end..];
        }
    }
    defs
}

fn identifier(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// `///` lines directly above line `index`, joined.
fn doc_above(lines: &[&str], index: usize) -> String {
    let mut doc: Vec<&str> = lines[..index]
        .iter()
        .rev()
        .skip_while(|l| l.trim_start().starts_with('@'))
        .take_while(|l| l.trim_start().starts_with("///"))
        .map(|l| l.trim_start().trim_start_matches('/').trim())
        .collect();
    doc.reverse();
    doc.join(" ")
}

fn functions(source: &str, language: Language) -> Vec<FunctionInfo> {
    let lines: Vec<&str> = source.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let name = match language {
            Language::Wgsl | Language::Wesl => line
                .strip_prefix("fn ")
                .map(|rest| identifier(rest.trim_start())),
            Language::Glsl => glsl_function_name(line),
        };
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            continue;
        };
        let mut signature = String::new();
        for l in &lines[i..] {
            let part = l.split('{').next().unwrap_or_default();
            signature.push_str(part.trim().trim_end_matches('\\').trim_end());
            signature.push(' ');
            if l.contains('{') || l.contains(';') || l.starts_with("#define") {
                break;
            }
        }
        out.push(FunctionInfo {
            name: name.to_owned(),
            signature: signature.trim().to_owned(),
            doc: doc_above(&lines, i),
        });
    }
    out
}

/// `name` for a file-scope GLSL function definition `type name(...)` starting at column 0, or a
/// function-like macro `#define lodkit_name(...)` (how GLSL twins take textures); not for a
/// prototype, a hook the includer defines (the other way GLSL twins read textures).
fn glsl_function_name(line: &str) -> Option<&str> {
    if let Some(rest) = line.strip_prefix("#define ") {
        let name = identifier(rest);
        let exported = name.starts_with("lodkit_") && rest[name.len()..].starts_with('(');
        return exported.then_some(name);
    }
    // A prototype (`type name(...);`) declares a hook the includer defines: no function here.
    let prototype = line.trim_end().ends_with(");");
    if line.starts_with(char::is_whitespace)
        || line.starts_with('#')
        || line.starts_with("//")
        || prototype
    {
        return None;
    }
    let open = line.find('(')?;
    let mut words = line[..open].split_whitespace();
    let (ty, name) = (words.next()?, words.next()?);
    let keyword = matches!(
        ty,
        "return" | "if" | "for" | "while" | "struct" | "layout" | "const"
    );
    (!keyword && words.next().is_none()).then_some(name)
}

fn constants(source: &str, language: Language) -> Vec<String> {
    source
        .lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("const ")?;
            let name = match language {
                Language::Wgsl | Language::Wesl => identifier(rest),
                Language::Glsl => identifier(rest.split_whitespace().nth(1)?),
            };
            Some(name.to_owned())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// naga_oil's `#else ifdef B` reads B as much as `#ifdef A` reads A: a def used only there
    /// must be found, or `lodkit check` never sets it and its variant goes unchecked.
    #[test]
    fn every_directive_names_its_def_the_else_branches_too() {
        let source =
            "#ifdef A\nx\n#else ifdef B\ny\n#else ifndef D\n#else\nz\n#endif\n#if C == 3\n#endif\n";
        assert_eq!(
            used_shader_defs(source, Language::Wgsl),
            ["A", "B", "D", "C"]
        );
    }
}
