//! Composition and diagnostics never panic or abort on user input: deeply nested expressions,
//! non-ASCII text next to imported names (a full-width parenthesis typed through an IME), and
//! random mutations of shaders that import lodkit. Every error renders, and its location lies
//! inside the file it names.

use lodkit::shaders::{
    ComposeDescriptor, DiagnosticKind, ShaderError, ShaderLibrary, SourceLanguage, naga,
};
use proptest::prelude::*;

const WGSL: &str = "#import lodkit::normal_distance::foreshortened_normal_distance
#import lodkit::screen_door::screen_door_keep

@fragment
fn main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let d = foreshortened_normal_distance(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0));
    if (!screen_door_keep(p.xy, 0.5)) { discard; }
    return vec4(d);
}
";

const WESL: &str = "import lodkit::normal_distance::foreshortened_normal_distance;
import lodkit::screen_door::screen_door_keep;

@fragment
fn main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let d = foreshortened_normal_distance(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0));
    if (!screen_door_keep(p.xy, 0.5)) { discard; }
    return vec4(d);
}
";

const GLSL: &str = "#version 450
#extension GL_GOOGLE_include_directive : require
#include \"lodkit/normal_distance.glsl\"
layout(location = 0) out vec4 color;
void main() {
    float d = lodkit_foreshortened_normal_distance(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0));
    color = vec4(d);
}
";

/// Imported names after which an inserted character is most likely to reach the diagnostic
/// remapping (naga_oil decorates these names in place).
const ANCHORS: [&str; 3] = [
    "foreshortened_normal_distance",
    "screen_door_keep",
    "lodkit_foreshortened_normal_distance",
];

fn compose(source: &str, file: &str, language: SourceLanguage) -> Result<(), ShaderError> {
    let mut library = ShaderLibrary::new().expect("the library composes");
    library
        .compose(&ComposeDescriptor {
            source,
            file_path: file,
            language,
            ..Default::default()
        })
        .map(|_| ())
}

/// Renders the error both ways and checks that its location is inside the named file's text.
fn assert_reportable(e: &ShaderError, source: &str) {
    let _ = e.to_string();
    if let Some(d) = e.diagnostic() {
        let rendered = d.render();
        assert!(!rendered.is_empty());
        // Spans in the user's file (not in a lodkit module) are byte ranges of its text.
        if let Some(span) = d.span().filter(|_| d.file.starts_with("user.")) {
            assert!(
                span.end <= source.len(),
                "span {span:?} past the end: {rendered}"
            );
            assert!(source.is_char_boundary(span.start), "{rendered}");
            assert!(source.is_char_boundary(span.end), "{rendered}");
        }
    }
}

#[test]
fn full_width_parenthesis_after_an_imported_name_is_a_parse_error() {
    let source = WGSL.replacen(
        "foreshortened_normal_distance(vec3",
        "foreshortened_normal_distance\u{ff08}vec3",
        1,
    );
    let e = compose(&source, "ime.wgsl", SourceLanguage::Wgsl).expect_err("not valid WGSL");
    assert_reportable(&e, &source);
    let d = e.diagnostic().expect("a source diagnostic");
    assert_eq!(d.kind, DiagnosticKind::Parse);
    let at = d.span().unwrap().start;
    assert_eq!(
        &source[at..at + 3],
        "\u{ff08}",
        "points at the full-width parenthesis"
    );
}

#[test]
fn glsl_nested_twenty_thousand_deep_is_an_error_not_a_stack_overflow() {
    let n = 20_000;
    let source = format!(
        "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() {{ float x = {}1.0{}; o = vec4(x); }}\n",
        "(".repeat(n),
        ")".repeat(n)
    );
    // The default test thread stack is 2 MiB: the limit must hold there too.
    let e = compose(
        &source,
        "deep.frag",
        SourceLanguage::Glsl(naga::ShaderStage::Fragment),
    )
    .expect_err("too deep");
    let d = e.diagnostic().expect("a source diagnostic");
    assert_eq!(d.kind, DiagnosticKind::Limit);
    assert_eq!(d.location.map(|l| l.line), Some(3));
    // Right at the limit it still parses.
    let depth = lodkit::shaders::MAX_NESTING - 4; // main's body and vec4(...) add levels
    let ok = source
        .replace(&"(".repeat(n), &"(".repeat(depth))
        .replace(&")".repeat(n), &")".repeat(depth));
    compose(
        &ok,
        "deep.frag",
        SourceLanguage::Glsl(naga::ShaderStage::Fragment),
    )
    .expect("nesting within the limit composes");
}

#[test]
fn glsl_nesting_built_by_macros_is_an_error_not_a_stack_overflow() {
    let n = 20_000;
    let source = format!(
        "#version 450\n#define O (\n#define C )\nlayout(location = 0) out vec4 o;\nvoid main() {{ float x = {}1.0{}; o = vec4(x); }}\n",
        "O ".repeat(n),
        " C".repeat(n)
    );
    // The brackets only appear after macro expansion: naga's parser meets them on its own
    // deep-stack thread and must come back with a result, not abort the process.
    let stage = SourceLanguage::Glsl(naga::ShaderStage::Fragment);
    if let Err(e) = compose(&source, "macros.frag", stage) {
        assert_reportable(&e, &source);
    }
}

#[test]
fn wesl_nested_twenty_thousand_deep_is_an_error() {
    let n = 20_000;
    let source = format!(
        "import lodkit::unpopping::unpopping_alpha;\nfn f() -> f32 {{ return unpopping_alpha({}0.5{}, true); }}\n",
        "(".repeat(n),
        ")".repeat(n)
    );
    let e = compose(&source, "deep.wesl", SourceLanguage::Wesl).expect_err("too deep");
    let d = e.diagnostic().expect("a source diagnostic");
    assert_eq!(d.kind, DiagnosticKind::Limit);
    assert_eq!(d.location.map(|l| l.line), Some(2));
}

#[test]
fn wgsl_nested_twenty_thousand_deep_is_an_error() {
    let n = 20_000;
    let source = format!(
        "fn f() -> f32 {{ return {}1.0{}; }}\n",
        "(".repeat(n),
        ")".repeat(n)
    );
    let e = compose(&source, "deep.wgsl", SourceLanguage::Wgsl).expect_err("too deep");
    assert_reportable(&e, &source);
}

/// A character a user may type by accident, non-ASCII ones included.
fn noise() -> impl Strategy<Value = String> {
    let chars = prop::sample::select(vec![
        '\u{ff08}', '\u{ff09}', '\u{3000}', 'é', '€', '😀', '\u{200b}', '\u{301}', '中', '(', ')',
        '{', '}', ';', ':', '<', '>', '#', '"', '/', '*', '\n', ' ', 'x', '0', '.',
    ]);
    prop::collection::vec(chars, 1..4).prop_map(|v| v.into_iter().collect())
}

/// Inserts `text` right after an imported name (when `anchor` picks one present) or at byte
/// `at` (rounded down to a char boundary).
fn mutate(source: &str, anchor: usize, at: usize, text: &str, delete: usize) -> String {
    let mut pos = match ANCHORS
        .get(anchor)
        .and_then(|a| source.find(a).map(|i| i + a.len()))
    {
        Some(p) => p,
        None => at % (source.len() + 1),
    };
    while !source.is_char_boundary(pos) {
        pos -= 1;
    }
    let mut end = (pos + delete).min(source.len());
    while !source.is_char_boundary(end) {
        end += 1;
    }
    format!("{}{}{}", &source[..pos], text, &source[end..])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn mutated_wgsl_never_panics(anchor in 0usize..6, at in any::<usize>(), text in noise(), delete in 0usize..3) {
        let source = mutate(WGSL, anchor, at, &text, delete);
        if let Err(e) = compose(&source, "user.wgsl", SourceLanguage::Wgsl) {
            assert_reportable(&e, &source);
        }
    }

    #[test]
    fn mutated_wesl_never_panics(anchor in 0usize..6, at in any::<usize>(), text in noise(), delete in 0usize..3) {
        let source = mutate(WESL, anchor, at, &text, delete);
        if let Err(e) = compose(&source, "user.wesl", SourceLanguage::Wesl) {
            assert_reportable(&e, &source);
        }
    }

    #[test]
    fn mutated_glsl_never_panics(anchor in 0usize..6, at in any::<usize>(), text in noise(), delete in 0usize..3) {
        let source = mutate(GLSL, anchor, at, &text, delete);
        if let Err(e) = compose(&source, "user.frag", SourceLanguage::Glsl(naga::ShaderStage::Fragment)) {
            assert_reportable(&e, &source);
        }
    }
}
