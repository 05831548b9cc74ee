//! The shader library: every module under `shader_lib/` embedded and described, composition of
//! user shaders that import it (naga_oil), validation (naga) and export to every naga back end.
//!
//! - [`modules`] lists what the library holds: import path, language, functions with their doc
//!   line, shader defs.
//! - [`add_to_composer`] adds every lodkit module to a naga_oil `Composer` you already own.
//! - [`ShaderLibrary`] composes your WGSL (`#import lodkit::...`) or GLSL
//!   (`#include "lodkit/....glsl"`) into a validated `naga::Module`.
//! - [`export`] writes it as SPIR-V, MSL, HLSL, GLSL 450, GLSL ES or WGSL.
//!
//! Errors are [`ShaderError`]s; problems in source carry a [`Diagnostic`] with file, line and
//! column.

mod compose;
mod diagnostic;
mod export;
mod glsl;
mod imports;
mod registry;

use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use compose::{
    ComposeDescriptor, Composed, LibraryDescriptor, ShaderDefs, ShaderLibrary, SourceLanguage,
    add_to_composer, validate,
};
pub use diagnostic::{Diagnostic, DiagnosticKind, Location};
pub use export::{ExportOptions, ExportTarget, Exported, export};
pub use naga_oil::compose::ShaderDefValue;
pub use registry::{
    FunctionInfo, Language, ModuleInfo, ModuleKind, ShaderDefInfo, find_glsl_include, find_module,
    glsl_twin, import_paths, modules,
};

/// Source of the pass `shader_lib/passes/<name>.wgsl`, if there is one.
pub fn find_pass_source(name: &str) -> Option<&'static str> {
    let path = format!("passes/{name}.wgsl");
    modules().iter().find(|m| m.path == path).map(|m| m.source)
}

/// Everything that can go wrong composing, validating or exporting a shader.
#[derive(Debug, thiserror::Error)]
pub enum ShaderError {
    /// A file or folder could not be read.
    #[error("cannot read `{}`: {source}", path.display())]
    Io {
        /// The path that failed.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A problem in shader source, with its location.
    #[error("{0}")]
    Source(Box<Diagnostic>),
    /// The entry point to export is missing, or must be chosen among several.
    #[error("{0}")]
    EntryPoint(String),
    /// A back end could not write the module.
    #[error("cannot export to {target}: {message}")]
    Export {
        /// The back end.
        target: ExportTarget,
        /// What it said.
        message: String,
    },
}

impl ShaderError {
    /// The diagnostic, when the error is a problem in source.
    pub fn diagnostic(&self) -> Option<&Diagnostic> {
        match self {
            Self::Source(d) => Some(d),
            _ => None,
        }
    }
}

/// Reads a shader file as UTF-8. A file that is not UTF-8 is a [`DiagnosticKind::InvalidUtf8`]
/// diagnostic pointing at the first bad byte.
pub fn read_source(path: &Path) -> Result<String, ShaderError> {
    let bytes = std::fs::read(path).map_err(|source| ShaderError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bad = e.as_bytes()[at];
        let text: Arc<str> = Arc::from(String::from_utf8_lossy(e.as_bytes()).as_ref());
        let d = Diagnostic::new(
            DiagnosticKind::InvalidUtf8,
            path.display().to_string(),
            format!("file is not valid UTF-8 (byte 0x{bad:02x} at offset {at})"),
        )
        .with_span(text, at..at + 1)
        .with_label("invalid byte")
        .with_hint("save the file as UTF-8");
        ShaderError::Source(Box::new(d))
    })
}

/// The candidate closest to `name` by edit distance, if it is close enough to be a typo.
pub(crate) fn closest<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
) -> Option<&'a str> {
    candidates
        .filter(|c| *c != name)
        .map(|c| (strsim::levenshtein(name, c), c))
        .filter(|(d, c)| *d <= 3.max(c.len() / 5))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}
