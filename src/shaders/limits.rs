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
/// stack ([`GLSL_PARSER_STACK`]) in a debug build.
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

/// The first token of `text`, expanded by naga's own preprocessor with `defines`, at which an
/// expression or statement nests past [`MAX_NESTING`] brackets or [`MAX_EXPRESSION_DEPTH`]
/// (see there), or past [`MAX_EXPANDED_TOKENS`] tokens in all. Run it after
/// [`super::macros::too_large`], which bounds what the expansion costs. Preprocessor errors are
/// left to the parser, which reports them.
pub(crate) fn expression_too_deep(text: &str, defines: &[(String, String)]) -> Option<TooDeep> {
    use pp_rs::token::{Punct, TokenValue};
    /// One open bracket: the operators and keywords chained inside it since its last `;` or
    /// `,`, and the `else`s of the `else if` chain going on in it (a chain spans statements:
    /// it goes on while the token after a statement is `else`).
    #[derive(Default)]
    struct Level {
        chained: usize,
        elses: usize,
        statement_ended: bool,
    }
    let mut pp = pp_rs::pp::Preprocessor::new(text);
    for (name, value) in defines {
        let _ = pp.add_define(name, value);
    }
    let mut levels = vec![Level::default()];
    let mut depth = 0usize; // levels.len() - 1 + every level's chained + elses
    let mut brackets = 0usize;
    let mut count = 0u64;
    for token in pp {
        let Ok(token) = token else { continue };
        let at = token.location.start as usize..token.location.end as usize;
        count += 1;
        if count > MAX_EXPANDED_TOKENS {
            let what = format!("macros expand the file past {MAX_EXPANDED_TOKENS} tokens");
            return Some(TooDeep { at, what });
        }
        let top = levels.last_mut().expect("the file level is never closed");
        let is_else = matches!(&token.value, TokenValue::Ident(w) if w == "else");
        if std::mem::take(&mut top.statement_ended) && !is_else {
            depth -= top.elses;
            top.elses = 0;
        }
        match token.value {
            TokenValue::Punct(Punct::LeftParen | Punct::LeftBracket | Punct::LeftBrace) => {
                brackets += 1;
                if brackets > MAX_NESTING {
                    let mut e = TooDeep::brackets(at);
                    e.what += " after macro expansion";
                    return Some(e);
                }
                levels.push(Level::default());
                depth += 1;
            }
            TokenValue::Punct(
                p @ (Punct::RightParen | Punct::RightBracket | Punct::RightBrace),
            ) => {
                if levels.len() > 1 {
                    let closed = levels.pop().expect("more than one level");
                    depth -= 1 + closed.chained + closed.elses;
                    brackets -= 1;
                    // A block is a statement: an `else` may follow it.
                    let parent = levels.last_mut().expect("the file level stays");
                    parent.statement_ended = p == Punct::RightBrace;
                }
                continue;
            }
            TokenValue::Punct(Punct::Semicolon | Punct::Comma) => {
                depth -= top.chained;
                top.chained = 0;
                top.statement_ended = true;
                continue;
            }
            TokenValue::Punct(Punct::Dot) => continue,
            TokenValue::Punct(_) => {
                top.chained += 1;
                depth += 1;
            }
            TokenValue::Ident(_) if is_else => {
                top.elses += 1;
                depth += 1;
            }
            TokenValue::Ident(ref word)
                if matches!(word.as_str(), "if" | "for" | "while" | "do") =>
            {
                top.chained += 1;
                depth += 1;
            }
            _ => continue,
        }
        if depth > MAX_EXPRESSION_DEPTH {
            let what = format!(
                "an expression or statement nests more than {MAX_EXPRESSION_DEPTH} levels deep \
                 (brackets, chained operators, `else if`s)"
            );
            return Some(TooDeep { at, what });
        }
    }
    None
}

/// The first bracket of `source` that opens level `MAX_NESTING + 1`, skipping `//` and `/* */`
/// comments; `None` when the source stays within the limit.
pub(crate) fn too_deep(source: &str) -> Option<TooDeep> {
    let bytes = source.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = source[i..].find('\n').map_or(bytes.len(), |n| i + n);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i = source[i + 2..]
                    .find("*/")
                    .map_or(bytes.len(), |n| i + 2 + n + 2);
                continue;
            }
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
