//! Comments blanked out of shader source, for the scanners that read source text before a
//! compiler does (shader-def discovery, the imports and full paths naga_oil resolves, the
//! nesting limits, whether a WGSL file needs naga_oil at all). Every comment byte becomes a
//! space and every newline stays, so byte offsets, line numbers and the columns of everything
//! outside comments are those of the original text.

use std::borrow::Cow;

/// The comment syntax of a shading language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommentSyntax {
    /// WGSL and WESL: `//` to the end of the line, and `/* */` blocks that nest
    /// (`/* a /* b */ c */` is one comment).
    Wgsl,
    /// GLSL: `//` to the end of the line, and `/* */` blocks that end at the first `*/`.
    Glsl,
}

/// `source` with its comments replaced by spaces (see the module docs). A `"` opens a quoted
/// run that ends at the next `"` or at the end of the line (naga_oil's `#import "path"`,
/// GLSL's `#include "path"`); comment markers inside it are text, as naga_oil and the GLSL
/// preprocessor read them. An unclosed block comment runs to the end of the source. Text
/// without comments is returned as it is, without a copy.
///
/// ```
/// use lodkit::shaders::{CommentSyntax, blank_comments};
/// let src = "a // #ifdef X\n/* #ifdef Y /* nested */ */ b";
/// let blank = blank_comments(src, CommentSyntax::Wgsl);
/// assert!(!blank.contains("ifdef"));
/// assert_eq!(blank.lines().map(str::trim).collect::<Vec<_>>(), ["a", "b"]);
/// assert_eq!((blank.len(), blank.find('b')), (src.len(), src.find('b')));
/// ```
pub fn blank_comments(source: &str, syntax: CommentSyntax) -> Cow<'_, str> {
    if !source.contains("//") && !source.contains("/*") {
        return Cow::Borrowed(source);
    }
    let bytes = source.as_bytes();
    let mut out = bytes.to_vec();
    let blank = |out: &mut [u8], range: std::ops::Range<usize>| {
        for b in &mut out[range] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    };
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                let rest = &bytes[i + 1..];
                let end = rest.iter().position(|&b| b == b'"' || b == b'\n');
                i += 1 + end.map_or(rest.len(), |n| n + usize::from(rest[n] == b'"'));
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                let end = bytes[i..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(bytes.len(), |n| i + n);
                blank(&mut out, i..end);
                i = end;
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                let end = block_end(bytes, i + 2, syntax);
                blank(&mut out, i..end);
                i = end;
            }
            _ => i += 1,
        }
    }
    // Only whole UTF-8 sequences were replaced (comments start and end at ASCII bytes, and
    // every byte between them became a space), so the text is still UTF-8.
    Cow::Owned(
        String::from_utf8(out)
            .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()),
    )
}

/// The end (exclusive) of the block comment whose body starts at `from`.
fn block_end(bytes: &[u8], from: usize, syntax: CommentSyntax) -> usize {
    let mut open = 1usize;
    let mut i = from;
    while i < bytes.len() {
        if bytes[i..].starts_with(b"*/") {
            open -= 1;
            i += 2;
            if open == 0 {
                return i;
            }
        } else if syntax == CommentSyntax::Wgsl && bytes[i..].starts_with(b"/*") {
            open += 1;
            i += 2;
        } else {
            i += 1;
        }
    }
    bytes.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blanked(s: &str, syntax: CommentSyntax) -> String {
        blank_comments(s, syntax).into_owned()
    }

    #[test]
    fn comments_become_spaces_and_everything_else_stays_in_place() {
        let src = "fn f() {} // #ifdef A é\n/* #{B}\n@if(C) */ let x = 1;\n";
        let out = blanked(src, CommentSyntax::Wgsl);
        assert_eq!(out.len(), src.len());
        assert_eq!(out.lines().count(), src.lines().count());
        assert_eq!(
            out,
            "fn f() {}               \n       \n          let x = 1;\n"
        );
        assert_eq!(out.find("let"), src.find("let"));
    }

    #[test]
    fn wgsl_block_comments_nest_and_glsl_ones_do_not() {
        let src = "/* a /* b */ c */ d";
        assert_eq!(
            blanked(src, CommentSyntax::Wgsl),
            format!("{} d", " ".repeat(17))
        );
        assert_eq!(
            blanked(src, CommentSyntax::Glsl),
            format!("{} c */ d", " ".repeat(12))
        );
    }

    #[test]
    fn quoted_text_keeps_its_slashes_and_unclosed_comments_run_to_the_end() {
        let src = "#include \"a//b.glsl\" // why\n#import \"x/*y\"\n/* open";
        let out = blanked(src, CommentSyntax::Glsl);
        assert_eq!(
            out,
            "#include \"a//b.glsl\"       \n#import \"x/*y\"\n       "
        );
        assert!(matches!(
            blank_comments("fn f() {}", CommentSyntax::Wgsl),
            Cow::Borrowed(_)
        ));
    }
}
