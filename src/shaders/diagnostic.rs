//! Diagnostics a person can act on: what went wrong, in which file, at which line and column.

use std::fmt;
use std::ops::Range;
use std::sync::Arc;

use codespan_reporting::diagnostic::{Diagnostic as CsDiagnostic, Label};
use codespan_reporting::files::{Files, SimpleFile};
use codespan_reporting::term::{self, termcolor::NoColor};
use naga_oil::compose::{Composer, ComposerError, ComposerErrorInner};

/// What kind of problem a [`Diagnostic`] reports. Its [`code`](Self::code) is stable for tools.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum DiagnosticKind {
    /// The source does not parse, or the front end rejects it (unknown names, wrong argument
    /// types in a call).
    Parse,
    /// An `#import` or `#include` names a module that does not exist.
    UnknownImport,
    /// Modules import each other in a cycle.
    ImportCycle,
    /// Two modules declare the same `#define_import_path`.
    DuplicateModule,
    /// The file is not valid UTF-8.
    InvalidUtf8,
    /// A preprocessor directive is malformed (`#ifdef`, `#endif`, shader defs).
    Preprocessor,
    /// The module parses but naga's validator rejects it (types, uniformity, layout).
    Validation,
    /// The source goes past a limit lodkit sets so that parsing cannot exhaust the stack
    /// (brackets nested deeper than [`MAX_NESTING`](crate::shaders::MAX_NESTING)).
    Limit,
}

impl DiagnosticKind {
    /// Stable short code, e.g. `unknown-import`.
    pub fn code(self) -> &'static str {
        match self {
            Self::Parse => "parse",
            Self::UnknownImport => "unknown-import",
            Self::ImportCycle => "import-cycle",
            Self::DuplicateModule => "duplicate-module",
            Self::InvalidUtf8 => "invalid-utf8",
            Self::Preprocessor => "preprocessor",
            Self::Validation => "validation",
            Self::Limit => "limit",
        }
    }
}

/// A 1-based line and column (columns count characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Location {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1, in characters.
    pub column: usize,
}

/// A problem in shader source, with where it is and, when we can tell, how to fix it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Diagnostic {
    /// What kind of problem.
    pub kind: DiagnosticKind,
    /// One-line description.
    pub message: String,
    /// File the problem is in (as given by the caller, or the library path of a lodkit module).
    pub file: String,
    /// Line and column of the problem, when it has one.
    #[serde(flatten)]
    pub location: Option<Location>,
    /// A suggested fix, e.g. ``did you mean `lodkit::visibility`?``.
    pub hint: Option<String>,
    /// Further context (the error's causes, the list of known modules, ...).
    pub notes: Vec<String>,
    #[serde(skip)]
    span: Option<Range<usize>>,
    #[serde(skip)]
    label: Option<String>,
    #[serde(skip)]
    source: Option<Arc<str>>,
}

impl Diagnostic {
    /// A diagnostic with no location yet.
    pub fn new(kind: DiagnosticKind, file: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
            file: file.into(),
            location: None,
            hint: None,
            notes: Vec::new(),
            span: None,
            label: None,
            source: None,
        }
    }

    /// Points the diagnostic at bytes `span` of `source` (clamped to the text) and computes its
    /// line and column.
    pub fn with_span(mut self, source: Arc<str>, span: Range<usize>) -> Self {
        // Spans from the front ends may cut a multibyte character: widen them to whole ones.
        let end = span.end.min(source.len());
        let end = (end..=source.len())
            .find(|&i| source.is_char_boundary(i))
            .unwrap_or(source.len());
        let start = span.start.min(end);
        let start = (0..=start)
            .rev()
            .find(|&i| source.is_char_boundary(i))
            .unwrap_or(0);
        let file = SimpleFile::new(self.file.as_str(), &*source);
        self.location = file.location((), start).ok().map(|l| Location {
            line: l.line_number,
            column: l.column_number,
        });
        self.span = Some(start..end.max(start));
        self.source = Some(source);
        self
    }

    /// Text shown under the caret.
    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// Adds a suggested fix.
    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// Byte range in the file the diagnostic points at.
    pub fn span(&self) -> Option<Range<usize>> {
        self.span.clone()
    }

    /// Human rendering: `error[code]: message`, `--> file:line:col`, the source line and a caret.
    pub fn render(&self) -> String {
        let mut diagnostic = CsDiagnostic::error()
            .with_code(self.kind.code())
            .with_message(&self.message);
        let mut notes: Vec<String> = self.notes.clone();
        if let Some(hint) = &self.hint {
            notes.insert(0, format!("help: {hint}"));
        }
        diagnostic = diagnostic.with_notes(notes);
        let mut out = NoColor::new(Vec::new());
        match (&self.source, &self.span) {
            (Some(source), Some(span)) => {
                let file = SimpleFile::new(self.file.as_str(), &**source);
                let label = Label::primary((), span.clone())
                    .with_message(self.label.clone().unwrap_or_default());
                let diagnostic = diagnostic.with_labels(vec![label]);
                let _ = term::emit_to_write_style(
                    &mut out,
                    &term::Config::default(),
                    &file,
                    &diagnostic,
                );
            }
            _ => {
                let file = SimpleFile::new(self.file.as_str(), "");
                let diagnostic =
                    diagnostic.with_message(format!("{}: {}", self.file, self.message));
                let _ = term::emit_to_write_style(
                    &mut out,
                    &term::Config::default(),
                    &file,
                    &diagnostic,
                );
            }
        }
        String::from_utf8_lossy(&out.into_inner()).into_owned()
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.location {
            Some(l) => write!(f, "{}:{}:{}: {}", self.file, l.line, l.column, self.message)?,
            None => write!(f, "{}: {}", self.file, self.message)?,
        }
        if let Some(hint) = &self.hint {
            write!(f, " ({hint})")?;
        }
        Ok(())
    }
}

/// Replaces naga_oil's decorated names (`itemX_naga_oil_mod_X<base32>X`) with `module::item`.
pub(crate) fn undecorate(text: &str) -> String {
    const PRE: &str = "X_naga_oil_mod_X";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(PRE) {
        let head = &rest[..i];
        // The item is the identifier run before the marker; the character that ends it may be
        // multibyte, so the run starts after that whole character, not one byte after it.
        let item_start = head
            .char_indices()
            .rev()
            .find(|&(_, c)| !is_identifier_char(c))
            .map_or(0, |(j, c)| j + c.len_utf8());
        let tail = &rest[i + PRE.len()..];
        let end = tail
            .find(|c: char| !(c.is_ascii_uppercase() || ('2'..='7').contains(&c)))
            .unwrap_or(tail.len());
        // The run ends with the closing `X` (which is also a base32 letter): drop exactly one.
        let encoded = tail[..end].strip_suffix('X').unwrap_or(&tail[..end]);
        let decoded = data_encoding::BASE32_NOPAD
            .decode(encoded.as_bytes())
            .ok()
            .and_then(|b| String::from_utf8(b).ok())
            .filter(|module| !module.is_empty());
        match decoded {
            Some(module) => {
                out.push_str(&head[..item_start]);
                out.push_str(&module);
                out.push_str("::");
                out.push_str(&head[item_start..]);
                rest = &tail[end..];
            }
            None => {
                out.push_str(&rest[..i + PRE.len()]);
                rest = tail;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Whether `c` may stand in an identifier (WGSL and GLSL identifiers are Unicode XID runs; naga_oil
/// refuses the non-ASCII ones, but its messages quote them).
fn is_identifier_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Masks naga_oil's module index out of a span and makes it relative to the module's source.
fn local_span(range: Range<usize>, offset: usize) -> Range<usize> {
    const SPAN_MASK: usize = (1 << 21) - 1;
    (range.start & SPAN_MASK).saturating_sub(offset)..(range.end & SPAN_MASK).saturating_sub(offset)
}

/// Extends an empty span at `pos` over the import path written there.
fn path_token(source: &str, pos: usize) -> Range<usize> {
    let len = source
        .get(pos..)
        .map(|s| {
            s.find(|c: char| !(is_identifier_char(c) || c == ':'))
                .unwrap_or(s.len())
        })
        .unwrap_or(0);
    pos..pos + len
}

/// Maps byte `at` of naga_oil's rewritten source (imported names decorated in place) to the
/// same place in the text the user wrote. Lines are preserved by naga_oil; within a line the
/// decorations before `at` are taken out. Where the line was rewritten otherwise (qualified
/// `a::b::f` calls), the column is clamped to the original line.
fn remap_offset(rewritten: &str, original: &str, at: usize) -> usize {
    const PRE: &str = "X_naga_oil_mod_X";
    let mut at = at.min(rewritten.len());
    while !rewritten.is_char_boundary(at) {
        at -= 1;
    }
    let line_start = rewritten[..at].rfind('\n').map_or(0, |i| i + 1);
    let line_index = rewritten[..line_start].matches('\n').count();
    let mut column = at - line_start;
    let mut prefix = &rewritten[line_start..at];
    while let Some(i) = prefix.find(PRE) {
        let tail = &prefix[i + PRE.len()..];
        let end = tail
            .find(|c: char| !(c.is_ascii_uppercase() || ('2'..='7').contains(&c)))
            .unwrap_or(tail.len());
        let closing = usize::from(tail[end..].starts_with('X'));
        let removed = PRE.len() + end + closing;
        column -= removed.min(column);
        // `end + closing` is a char boundary: the run and its closing `X` are ASCII.
        prefix = &tail[end + closing..];
    }
    let original_line_start: usize = original
        .split_inclusive('\n')
        .take(line_index)
        .map(str::len)
        .sum();
    let line_len = original[original_line_start.min(original.len())..]
        .split('\n')
        .next()
        .map_or(0, str::len);
    let mut out = (original_line_start + column.min(line_len)).min(original.len());
    while !original.is_char_boundary(out) {
        out -= 1;
    }
    out
}

/// Turns a naga_oil error into a diagnostic pointing at the user's (or our) source.
/// `original` is the text of the top-level shader as the user wrote it: spans into naga_oil's
/// rewritten copy of it are mapped back onto it.
pub(crate) fn from_composer_error(
    err: &ComposerError,
    composer: &Composer,
    original: Option<&str>,
) -> Diagnostic {
    let file = err.source.path(composer).clone();
    let rewritten = err.source.source(composer);
    let offset = err.source.offset();
    let (source, remap): (Arc<str>, Option<&str>) = match (&err.source, original) {
        (naga_oil::compose::ErrSource::Constructing { .. }, Some(original)) => {
            (Arc::from(original), Some(rewritten.as_str()))
        }
        _ => (Arc::from(rewritten.as_str()), None),
    };
    let local_span = |range: Range<usize>, offset: usize| {
        let r = local_span(range, offset);
        match remap {
            Some(rw) => remap_offset(rw, &source, r.start)..remap_offset(rw, &source, r.end),
            None => r,
        }
    };
    let message = undecorate(&err.inner.to_string());
    let at = |kind, span: Range<usize>| {
        Diagnostic::new(kind, file.clone(), message.clone()).with_span(source.clone(), span)
    };
    match &err.inner {
        ComposerErrorInner::ImportNotFound(name, pos) => Diagnostic::new(
            DiagnosticKind::UnknownImport,
            file.clone(),
            format!("unknown import `{name}`"),
        )
        .with_span(source.clone(), path_token(&source, *pos))
        .with_label("no module has this import path"),
        ComposerErrorInner::ImportParseError(_, pos) => at(DiagnosticKind::Parse, *pos..*pos + 1),
        ComposerErrorInner::WgslParseError(e) => {
            wgsl_parse_diagnostic(e, file.clone(), source.clone(), |s| local_span(s, offset))
        }
        ComposerErrorInner::GlslParseError(e) => {
            let first = e.errors.first();
            let span = first.and_then(|e| e.meta.to_range()).unwrap_or(0..0);
            let msg = first.map(|e| e.kind.to_string()).unwrap_or_default();
            Diagnostic::new(DiagnosticKind::Parse, file.clone(), undecorate(&msg))
                .with_span(source.clone(), local_span(span, offset))
        }
        ComposerErrorInner::ShaderValidationError(v)
        | ComposerErrorInner::HeaderValidationError(v) => {
            validation_diagnostic(v, file.clone(), source.clone(), |s| local_span(s, offset))
        }
        ComposerErrorInner::NotEnoughEndIfs(pos)
        | ComposerErrorInner::TooManyEndIfs(pos)
        | ComposerErrorInner::ElseWithoutCondition(pos)
        | ComposerErrorInner::UnknownShaderDef { pos, .. }
        | ComposerErrorInner::UnknownShaderDefOperator { pos, .. }
        | ComposerErrorInner::InvalidShaderDefComparisonValue { pos, .. }
        | ComposerErrorInner::DefineInModule(pos)
        | ComposerErrorInner::InvalidShaderDefDefinitionValue { pos, .. }
        | ComposerErrorInner::GlslInvalidVersion(pos) => {
            at(DiagnosticKind::Preprocessor, *pos..*pos)
        }
        ComposerErrorInner::DecorationInSource(range) => at(DiagnosticKind::Parse, range.clone()),
        _ => Diagnostic::new(DiagnosticKind::Parse, file, message),
    }
}

/// A naga WGSL parse error as a diagnostic: the first label's span (through `map`) and text,
/// the error's notes. The same whether naga_oil or naga alone parsed the shader.
pub(crate) fn wgsl_parse_diagnostic(
    err: &naga::front::wgsl::ParseError,
    file: String,
    source: Arc<str>,
    map: impl Fn(Range<usize>) -> Range<usize>,
) -> Diagnostic {
    let (span, label) = err
        .labels()
        .next()
        .map(|(s, l)| (s.to_range().unwrap_or(0..0), l.to_owned()))
        .unwrap_or((0..0, String::new()));
    let d = Diagnostic::new(DiagnosticKind::Parse, file, undecorate(&err.to_string()))
        .with_span(source, map(span))
        .with_label(label);
    err.notes().fold(d, |d, n| d.with_note(undecorate(n)))
}

/// A naga validation error as a diagnostic: the first span is the primary one, the error's chain of
/// causes becomes the notes.
pub(crate) fn validation_diagnostic(
    err: &naga::WithSpan<naga::valid::ValidationError>,
    file: String,
    source: Arc<str>,
    map: impl Fn(Range<usize>) -> Range<usize>,
) -> Diagnostic {
    let mut causes = Vec::new();
    let mut cause: Option<&dyn std::error::Error> = std::error::Error::source(err.as_inner());
    while let Some(c) = cause {
        causes.push(undecorate(&c.to_string()));
        cause = c.source();
    }
    let message = match causes.last() {
        Some(root) => format!("{}: {root}", undecorate(&err.as_inner().to_string())),
        None => undecorate(&err.as_inner().to_string()),
    };
    let mut d = Diagnostic::new(DiagnosticKind::Validation, file, message);
    if let Some((span, label)) = err.spans().next() {
        d = d
            .with_span(source, map(span.to_range().unwrap_or(0..0)))
            .with_label(undecorate(label));
    }
    causes.into_iter().fold(d, Diagnostic::with_note)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undecorate_restores_module_paths() {
        let name =
            naga_oil::compose::Composer::decorated_name(Some("lodkit::combine"), "combine_samples");
        assert_eq!(
            undecorate(&format!("call to `{name}` failed")),
            "call to `lodkit::combine::combine_samples` failed"
        );
        assert_eq!(undecorate("nothing to do"), "nothing to do");
        // A module path whose base32 form itself ends in `X`.
        let name = naga_oil::compose::Composer::decorated_name(Some("mesh::draw"), "f");
        assert_eq!(undecorate(&format!("`{name}`")), "`mesh::draw::f`");
    }

    #[test]
    fn undecorate_steps_over_whole_multibyte_characters() {
        let name = naga_oil::compose::Composer::decorated_name(Some("my::mod"), "f");
        // The character before the name ends the identifier run: 2, 3 and 4 bytes long.
        assert_eq!(undecorate(&format!("·{name}")), "·my::mod::f");
        assert_eq!(undecorate(&format!("€{name}")), "€my::mod::f");
        assert_eq!(undecorate(&format!("😀{name}")), "😀my::mod::f");
        // Non-ASCII letters are identifier characters and stay with the item.
        assert_eq!(undecorate(&format!("`größe{name}`")), "`my::mod::größef`");
        assert_eq!(
            undecorate("`größe` X_naga_oil_mod_X"),
            "`größe` X_naga_oil_mod_X"
        );
    }

    #[test]
    fn remap_takes_decorations_out_of_the_column() {
        let name = naga_oil::compose::Composer::decorated_name(Some("lodkit::x"), "f");
        let original = "a\n  let d = f(1.0);\n";
        let rewritten = format!("a\n  let d = {name}(1.0);\n");
        let at = rewritten.find("1.0").unwrap();
        assert_eq!(
            remap_offset(&rewritten, original, at),
            original.find("1.0").unwrap()
        );
    }

    #[test]
    fn span_past_the_end_is_clamped() {
        let d = Diagnostic::new(DiagnosticKind::Parse, "f.wgsl", "x")
            .with_span(Arc::from("ab\ncd"), 10..20);
        assert_eq!(d.location, Some(Location { line: 2, column: 3 }));
        assert!(d.render().contains("f.wgsl:2:3"));
    }
}
