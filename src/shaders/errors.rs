//! Errors of composition, validation and export, and reading shader files.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::diagnostic::{Diagnostic, DiagnosticKind};
use super::export::ExportTarget;

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
