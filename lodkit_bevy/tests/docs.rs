//! The Bevy snippet in lodkit's `docs/engines.md` is the example's code: every line of it (but
//! comments) appears in the example (as a line or the end of one), in the same order.

use std::path::Path;

const MARKER: &str = "<!-- lodkit_bevy snippet: ";

/// The lines of `text` without comments, surrounding spaces or blank lines.
fn code_lines(text: &str) -> Vec<&str> {
    text.lines()
        .map(|l| l.split_once("//").map_or(l, |(code, _)| code).trim())
        .filter(|l| !l.is_empty())
        .collect()
}

#[test]
fn framebuffer_lod_snippet_is_the_example() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let guide = std::fs::read_to_string(root.join("../docs/engines.md")).expect("docs/engines.md");
    let start = guide
        .find(MARKER)
        .expect("the snippet marker in docs/engines.md");
    let rest = &guide[start + MARKER.len()..];
    let (file, rest) = rest.split_once(" -->").expect("a closed marker");
    let block = rest
        .split_once("```rust,ignore\n")
        .and_then(|(_, b)| b.split_once("```"))
        .map(|(b, _)| b)
        .expect("a rust,ignore block after the marker");
    let source = std::fs::read_to_string(root.join(file)).expect("the snippet's file");
    let source = code_lines(&source);
    let mut at = 0;
    for line in code_lines(block) {
        match source[at..].iter().position(|l| l.contains(line)) {
            Some(i) => at += i + 1,
            None => panic!("docs/engines.md's snippet line `{line}` is not in {file} (in order)"),
        }
    }
}
