//! Limits on shader source that keep the front ends off the end of the stack and within seconds:
//! naga's GLSL parser recurses once per nesting level of an expression (brackets, prefix
//! operators, `?:`, `=`, `else if`, and the lowering of long operator chains) and has no limit of
//! its own, so a GLSL file with thousands of nested parentheses would overflow the stack and abort
//! the process; GLSL macros can stand for far more nesting, and far more text, than they show.
//!
//! GLSL goes through three checks before naga parses it: the brackets as written
//! ([`too_deep`]), bounds on what the macros expand to ([`super::macros::too_large`], from the
//! `#define`s alone, before expanding anything), and the nesting of the expanded token stream
//! ([`expression_too_deep`], which expands with the same preprocessor naga uses).

use std::ops::Range;

/// The deepest nesting of `(`, `[` and `{` lodkit accepts in GLSL source: 256 levels, the same
/// order as naga's WGSL front end allows, and far beyond any real shader. At this depth naga's
/// GLSL parser stays within a 2 MiB thread stack in a debug build.
pub const MAX_NESTING: usize = 256;

/// Stack of the thread naga's GLSL parser runs on: room for about 50,000 nesting levels (a
/// debug build spends about 4 KiB per level), which macros that expand to brackets can reach
/// past [`MAX_NESTING`]. Reserved, not committed: pages are touched only as deep as it goes.
pub(crate) const GLSL_PARSER_STACK: usize = 256 << 20;

/// The deepest recursion lodkit lets naga's GLSL parser reach, counted on the expanded tokens of
/// one expression or statement: its brackets, plus the operators chained at each bracket level,
/// plus the `if`/`else`/loop keywords of statements nested without braces. Parsing and lowering
/// recurse at most once per counted token; at this depth they stay within the parser thread's
/// stack (`GLSL_PARSER_STACK`, 256 MiB) in a debug build.
pub const MAX_EXPRESSION_DEPTH: usize = 4096;

/// The most tokens GLSL macros may expand a file to (about 40 MB of text): beyond any real
/// shader, and expanded in well under a second.
pub const MAX_EXPANDED_TOKENS: u64 = 4 << 20;

/// The deepest nesting of macro calls inside other calls' arguments (the preprocessor expands
/// arguments recursively).
pub const MAX_MACRO_CALL_NESTING: u64 = 256;

/// Runs `f` on a thread with a [`GLSL_PARSER_STACK`] stack (or here, when no thread can be
/// started); `Err` when it panicked.
pub(crate) fn on_deep_stack<T: Send>(f: impl Fn() -> T + Sync) -> Result<T, ()> {
    std::thread::scope(|scope| {
        let spawned = std::thread::Builder::new()
            .name("lodkit-deep-stack".into())
            .stack_size(GLSL_PARSER_STACK)
            .spawn_scoped(scope, &f);
        match spawned {
            Ok(handle) => handle.join().map_err(|_| ()),
            Err(_) => Ok(f()),
        }
    })
}

/// [`on_deep_stack`] for work that runs once (it may borrow mutably); `Err` when it panicked
/// or no thread could be started.
pub(crate) fn on_deep_stack_once<T: Send>(f: impl FnOnce() -> T + Send) -> Result<T, ()> {
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("lodkit-deep-stack".into())
            .stack_size(GLSL_PARSER_STACK)
            .spawn_scoped(scope, f)
            .map_err(|_| ())?
            .join()
            .map_err(|_| ())
    })
}

/// The `limit` error for `source` (the file `file`) at `e`.
pub(crate) fn limit_error(file: &str, source: &str, e: TooDeep) -> super::ShaderError {
    use super::diagnostic::{Diagnostic, DiagnosticKind};
    let d = Diagnostic::new(DiagnosticKind::Limit, file, e.what)
        .with_span(std::sync::Arc::from(source), e.at)
        .with_label("nested too deep")
        .with_hint("split the expression into local variables");
    super::ShaderError::Source(Box::new(d))
}

/// Where a limit was passed, and which.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct TooDeep {
    /// Byte range of the token that went past the limit.
    pub at: Range<usize>,
    /// What went past which limit.
    pub what: String,
}

impl TooDeep {
    fn brackets(at: Range<usize>) -> Self {
        let what = format!("brackets nested more than {MAX_NESTING} levels deep");
        Self { at, what }
    }

    pub fn message(&self) -> String {
        self.what.clone()
    }
}

/// A token as the nesting count sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tok {
    /// `(`, `[` or `{`.
    Open,
    /// `)`, `]`, or `}` (`brace`).
    Close { brace: bool },
    /// `;` or `,`: ends an expression at its level.
    Separator,
    /// An operator the parser or its lowering recurses on (`+`, `-`, `!`, `?`, `=`, `<`, ...).
    Operator,
    /// `else`: an `else if` chain nests one level per `else`.
    Else,
    /// `if`, `for`, `while`, `do`, `loop`, `switch`: a statement that nests the next.
    Keyword,
    /// Anything else.
    Other,
}

/// The nesting of an expression or statement: its brackets, the operators and keywords chained
/// at each bracket level since that level's last `;` or `,`, and the `else`s of the `else if`
/// chain going on at each level (a chain goes on while the token after a statement is `else`).
#[derive(Default)]
struct Nesting {
    levels: Vec<Level>,
    /// Open brackets plus every level's chained tokens and elses.
    depth: usize,
}

#[derive(Default)]
struct Level {
    chained: usize,
    elses: usize,
    statement_ended: bool,
}

impl Nesting {
    fn new() -> Self {
        Self {
            levels: vec![Level::default()],
            depth: 0,
        }
    }

    /// Counts `tok` (at bytes `at`); where a limit is passed, which.
    fn token(&mut self, tok: Tok, at: Range<usize>) -> Option<TooDeep> {
        let top = self
            .levels
            .last_mut()
            .expect("the file level is never closed");
        if std::mem::take(&mut top.statement_ended) && tok != Tok::Else {
            self.depth -= top.elses;
            top.elses = 0;
        }
        match tok {
            Tok::Open => {
                if self.levels.len() > MAX_NESTING {
                    return Some(TooDeep::brackets(at));
                }
                self.levels.push(Level::default());
                self.depth += 1;
            }
            Tok::Close { brace } => {
                if self.levels.len() > 1 {
                    let closed = self.levels.pop().expect("more than one level");
                    self.depth -= 1 + closed.chained + closed.elses;
                    // A block is a statement: it ends what was chained before it, and an
                    // `else` may follow it.
                    let parent = self.levels.last_mut().expect("the file level stays");
                    if brace {
                        self.depth -= parent.chained;
                        parent.chained = 0;
                    }
                    parent.statement_ended = brace;
                }
            }
            Tok::Separator => {
                self.depth -= top.chained;
                top.chained = 0;
                top.statement_ended = true;
            }
            Tok::Operator | Tok::Keyword => {
                top.chained += 1;
                self.depth += 1;
            }
            Tok::Else => {
                top.elses += 1;
                self.depth += 1;
            }
            Tok::Other => {}
        }
        (self.depth > MAX_EXPRESSION_DEPTH).then(|| {
            let what = format!(
                "an expression or statement nests more than {MAX_EXPRESSION_DEPTH} levels deep \
                 (brackets, chained operators, `else if`s)"
            );
            TooDeep { at, what }
        })
    }
}

/// What a word is to the nesting count.
fn word_tok(word: &str) -> Tok {
    match word {
        "else" => Tok::Else,
        "if" | "for" | "while" | "do" | "loop" | "switch" => Tok::Keyword,
        _ => Tok::Other,
    }
}

/// The first token of `text`, expanded by naga's own preprocessor with `defines`, at which an
/// expression or statement nests past [`MAX_NESTING`] brackets or [`MAX_EXPRESSION_DEPTH`]
/// (see there), or past [`MAX_EXPANDED_TOKENS`] tokens in all. Run it after
/// [`super::macros::too_large`], which bounds what the expansion costs. Preprocessor errors are
/// left to the parser, which reports them.
pub(crate) fn expression_too_deep(text: &str, defines: &[(String, String)]) -> Option<TooDeep> {
    use pp_rs::token::{Punct, TokenValue};
    let mut pp = pp_rs::pp::Preprocessor::new(text);
    for (name, value) in defines {
        let _ = pp.add_define(name, value);
    }
    let mut nesting = Nesting::new();
    for (count, token) in pp.enumerate() {
        let Ok(token) = token else { continue };
        let at = token.location.start as usize..token.location.end as usize;
        if count as u64 >= MAX_EXPANDED_TOKENS {
            let what = format!("macros expand the file past {MAX_EXPANDED_TOKENS} tokens");
            return Some(TooDeep { at, what });
        }
        let tok = match token.value {
            TokenValue::Punct(Punct::LeftParen | Punct::LeftBracket | Punct::LeftBrace) => {
                Tok::Open
            }
            TokenValue::Punct(Punct::RightParen | Punct::RightBracket) => {
                Tok::Close { brace: false }
            }
            TokenValue::Punct(Punct::RightBrace) => Tok::Close { brace: true },
            TokenValue::Punct(Punct::Semicolon | Punct::Comma) => Tok::Separator,
            TokenValue::Punct(Punct::Dot) => Tok::Other,
            TokenValue::Punct(_) => Tok::Operator,
            TokenValue::Ident(ref word) => word_tok(word),
            _ => Tok::Other,
        };
        if let Some(mut e) = nesting.token(tok, at) {
            if tok == Tok::Open {
                e.what += " after macro expansion";
            }
            return Some(e);
        }
    }
    None
}

/// The first token of WGSL or WESL `source` at which an expression or statement nests past
/// [`MAX_NESTING`] brackets or [`MAX_EXPRESSION_DEPTH`] (see there). naga's WGSL front end and
/// wesl-rs recurse on long operator chains as naga's GLSL parser does. Comments and naga_oil's
/// `#` directive lines are skipped; every operator character counts (`->` twice), which only
/// makes the count larger.
pub(crate) fn wgsl_too_deep(source: &str) -> Option<TooDeep> {
    let mut nesting = Nesting::new();
    let code = super::blank_comments(source, super::CommentSyntax::Wgsl);
    let source = &*code;
    let mut chars = source.char_indices().peekable();
    let mut line_start = true;
    while let Some((i, c)) = chars.next() {
        let tok = match c {
            '\n' => {
                line_start = true;
                continue;
            }
            c if c.is_whitespace() => continue,
            '#' if line_start => {
                while chars.next_if(|&(_, c)| c != '\n').is_some() {}
                continue;
            }
            '(' | '[' | '{' => Tok::Open,
            ')' | ']' => Tok::Close { brace: false },
            '}' => Tok::Close { brace: true },
            ';' | ',' => Tok::Separator,
            '.' | ':' | '@' | '"' | '\'' => Tok::Other,
            c if c.is_alphanumeric() || c == '_' => {
                let mut end = i + c.len_utf8();
                while let Some((j, d)) = chars.next_if(|&(_, d)| d.is_alphanumeric() || d == '_') {
                    end = j + d.len_utf8();
                }
                word_tok(&source[i..end])
            }
            _ => Tok::Operator,
        };
        line_start = false;
        if let Some(e) = nesting.token(tok, i..i + c.len_utf8()) {
            return Some(e);
        }
    }
    None
}

/// The first bracket of `source` that opens level `MAX_NESTING + 1`, skipping `//` and `/* */`
/// comments; `None` when the source stays within the limit.
pub(crate) fn too_deep(source: &str) -> Option<TooDeep> {
    let code = super::blank_comments(source, super::CommentSyntax::Glsl);
    let bytes = code.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Some(TooDeep::brackets(i..i + 1));
                }
            }
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_bracket_past_the_limit() {
        let deep = format!(
            "{}1{}",
            "(".repeat(MAX_NESTING + 5),
            ")".repeat(MAX_NESTING + 5)
        );
        assert_eq!(too_deep(&deep).unwrap().at, MAX_NESTING..MAX_NESTING + 1);
        let ok = format!("{}1{}", "(".repeat(MAX_NESTING), ")".repeat(MAX_NESTING));
        assert_eq!(too_deep(&ok), None);
    }

    #[test]
    fn brackets_in_comments_do_not_count() {
        let commented = format!("// {}\n/* {} */ f()", "(".repeat(1000), "[".repeat(1000));
        assert_eq!(too_deep(&commented), None);
    }

    /// `n` copies of `unit` between a prefix and a suffix, in a fragment shader's `main`.
    fn chain(prefix: &str, unit: &str, n: usize, suffix: &str) -> String {
        format!(
            "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() {{ float v = 0.0; {prefix}{}{suffix} o = vec4(v); }}\n",
            unit.repeat(n)
        )
    }

    #[test]
    fn chains_the_parser_recurses_on_are_bounded() {
        let n = MAX_EXPRESSION_DEPTH + 10;
        for (what, source) in [
            ("sum", chain("v = ", "1.0 + ", n, "1.0;")),
            ("negation", chain("v = ", "- ", n, "1.0;")),
            ("ternary", chain("v = ", "true ? 1.0 : ", n, "1.0;")),
            ("assignment", chain("", "v = ", n, "1.0;")),
            (
                "else if",
                chain("", "if (v > 0.0) v = 1.0; else ", n, "v = 2.0;"),
            ),
            ("nested if", chain("", "if (v > 0.0) ", n, "v = 2.0;")),
        ] {
            let e = expression_too_deep(&source, &[]).unwrap_or_else(|| panic!("{what}"));
            assert!(e.what.contains("4096"), "{what}: {}", e.what);
        }
        // Sequential statements, if/else ones included, and long argument lists do not add up.
        let flat = chain(
            "",
            "if (v > 0.0) v = 1.0; else v = 2.0; v = v + 1.0; ",
            n,
            "",
        );
        assert_eq!(expression_too_deep(&flat, &[]), None);
        let args = chain("v = max(0.0, float[](", "-1.0, ", n, "1.0)[0]);");
        assert_eq!(expression_too_deep(&args, &[]), None);
    }
}
