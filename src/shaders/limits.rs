//! Limits on shader source that keep the front ends off the end of the stack: naga's GLSL parser
//! recurses once per nesting level of an expression and has no limit of its own, so a GLSL file
//! with thousands of nested parentheses would overflow the stack and abort the process.

use std::ops::Range;

/// The deepest nesting of `(`, `[` and `{` lodkit accepts in GLSL source: 256 levels, the same
/// order as naga's WGSL front end allows, and far beyond any real shader. At this depth naga's
/// GLSL parser stays within a 2 MiB thread stack in a debug build.
pub const MAX_NESTING: usize = 256;

/// Stack of the thread naga's GLSL parser runs on: room for about 50,000 nesting levels (a
/// debug build spends about 4 KiB per level), which macros that expand to brackets can reach
/// past [`MAX_NESTING`]. Reserved, not committed: pages are touched only as deep as it goes.
pub(crate) const GLSL_PARSER_STACK: usize = 256 << 20;

/// Where the nesting went past [`MAX_NESTING`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct TooDeep {
    /// Byte range of the bracket that went one level too deep.
    pub at: Range<usize>,
}

impl TooDeep {
    pub fn message(&self) -> String {
        format!("brackets nested more than {MAX_NESTING} levels deep")
    }
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
                    return Some(TooDeep { at: i..i + 1 });
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
}
