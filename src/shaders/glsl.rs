//! `#include` for GLSL shaders: the lodkit twins (`#include "lodkit/<topic>.glsl"`) and the user's
//! own headers, expanded textually with a map back to every original file for diagnostics.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::diagnostic::{Diagnostic, DiagnosticKind};
use super::{ShaderError, read_source, registry};

/// A GLSL source with its `#include`s expanded, and where each byte came from.
#[derive(Debug)]
pub(crate) struct Expanded {
    /// The expanded text, as naga's GLSL front end sees it.
    pub text: String,
    segments: Vec<Segment>,
}

#[derive(Debug)]
struct Segment {
    out_start: usize,
    len: usize,
    file: String,
    source: Arc<str>,
    file_start: usize,
}

impl Expanded {
    /// The file, its text and the range in it that expanded bytes `range` came from.
    pub fn locate(&self, range: Range<usize>) -> Option<(String, Arc<str>, Range<usize>)> {
        let seg = self
            .segments
            .iter()
            .rev()
            .find(|s| s.out_start <= range.start && range.start <= s.out_start + s.len)?;
        let start = seg.file_start + (range.start - seg.out_start);
        let end = seg.file_start + (range.end.min(seg.out_start + seg.len) - seg.out_start);
        Some((seg.file.clone(), seg.source.clone(), start..end.max(start)))
    }

    /// A diagnostic at expanded bytes `range`, pointing into the file they came from.
    pub fn diagnostic(
        &self,
        kind: DiagnosticKind,
        range: Range<usize>,
        message: String,
    ) -> Diagnostic {
        match self.locate(range) {
            Some((file, source, span)) => {
                Diagnostic::new(kind, file, message).with_span(source, span)
            }
            None => Diagnostic::new(kind, "<expanded>", message),
        }
    }
}

struct Expander<'a> {
    include_dirs: &'a [PathBuf],
    out: Expanded,
    seen: Vec<String>,
}

/// Expands `#include "..."` lines of `source` (the file `file`). Each file is included once; the
/// `GL_GOOGLE_include_directive` extension line is blanked (naga does not know it).
/// Search order: the including file's folder, then `include_dirs`, then the lodkit twins.
pub(crate) fn expand_includes(
    file: &str,
    source: &str,
    include_dirs: &[PathBuf],
) -> Result<Expanded, ShaderError> {
    let mut expander = Expander {
        include_dirs,
        out: Expanded {
            text: String::with_capacity(source.len()),
            segments: Vec::new(),
        },
        seen: vec![file.to_owned()],
    };
    expander.expand(file, Arc::from(source), false)?;
    Ok(expander.out)
}

impl Expander<'_> {
    fn push(&mut self, file: &str, source: &Arc<str>, range: Range<usize>) {
        self.out.segments.push(Segment {
            out_start: self.out.text.len(),
            len: range.len(),
            file: file.to_owned(),
            source: source.clone(),
            file_start: range.start,
        });
        self.out.text.push_str(&source[range]);
    }

    fn expand(&mut self, file: &str, source: Arc<str>, embedded: bool) -> Result<(), ShaderError> {
        let mut copied = 0;
        let mut line_start = 0;
        for line in source.split_inclusive('\n') {
            let start = line_start;
            line_start += line.len();
            let t = line.trim();
            let is_extension =
                t.starts_with("#extension") && t.contains("GL_GOOGLE_include_directive");
            let Some(rest) = t.strip_prefix("#include").filter(|_| !is_extension) else {
                if is_extension {
                    self.push(file, &source, copied..start);
                    self.out.text.push('\n');
                    copied = line_start;
                }
                continue;
            };
            self.push(file, &source, copied..start);
            copied = line_start;
            let rest = rest.split("//").next().unwrap_or_default();
            let name = rest
                .trim()
                .trim_matches(|c| c == '"' || c == '<' || c == '>');
            let name_at = start + line.find(name).unwrap_or(0);
            let (key, path, text, is_embedded) =
                self.resolve(file, &source, name, name_at..name_at + name.len(), embedded)?;
            if !self.seen.contains(&key) {
                self.seen.push(key);
                self.expand(&path, text, is_embedded)?;
            }
            self.out.text.push('\n');
        }
        self.push(file, &source, copied..source.len());
        Ok(())
    }

    fn resolve(
        &self,
        file: &str,
        source: &Arc<str>,
        name: &str,
        at: Range<usize>,
        embedded: bool,
    ) -> Result<(String, String, Arc<str>, bool), ShaderError> {
        // An embedded lodkit file has no folder on disk: its includes come from the library.
        let parent = Path::new(file)
            .parent()
            .filter(|_| !embedded)
            .map(Path::to_path_buf);
        for dir in parent.iter().chain(self.include_dirs) {
            let candidate = dir.join(name);
            if candidate.is_file() {
                let text = read_source(&candidate)?;
                let key = candidate
                    .canonicalize()
                    .unwrap_or(candidate.clone())
                    .display()
                    .to_string();
                return Ok((key, candidate.display().to_string(), Arc::from(text), false));
            }
        }
        if let Some(module) = registry::find_glsl_include(name) {
            let path = format!("shader_lib/{}", module.path);
            return Ok((path.clone(), path, Arc::from(module.source), true));
        }
        let mut d = Diagnostic::new(
            DiagnosticKind::UnknownImport,
            file,
            format!("cannot find include `{name}`"),
        )
        .with_span(source.clone(), at)
        .with_label("not found in the file's folder, the -I folders or the lodkit library");
        let twins: Vec<String> = registry::modules()
            .iter()
            .filter_map(|m| m.include_path.clone())
            .collect();
        if let Some(best) = super::closest(name, twins.iter().map(String::as_str)) {
            d = d.with_hint(format!("did you mean `{best}`?"));
        }
        Err(ShaderError::Source(Box::new(d)))
    }
}
