//! Composition and diagnostics never panic or abort on user input: deeply nested expressions,
//! non-ASCII text next to imported names (a full-width parenthesis typed through an IME), and
//! random mutations of shaders that import lodkit. Every error renders, and its location lies
//! inside the file it names.

use lodkit::shaders::{
    ComposeDescriptor, DiagnosticKind, ExportOptions, ExportTarget, ShaderError, ShaderLibrary,
    SourceLanguage, naga,
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

#[test]
fn glsl_chains_under_the_expression_limit_parse_on_the_parser_thread() {
    // The limit counts every chained operator; just under it naga's parser and its lowering
    // recurse about that deep, and the parser thread's stack holds it in a debug build.
    let n = lodkit::shaders::MAX_EXPRESSION_DEPTH - 64;
    // `unit` adds `per` to the count (its operators and keywords) and one recursion level.
    let chain = |prefix: &str, unit: &str, per: usize, suffix: &str| {
        format!(
            "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() {{ float v = 0.0; {prefix}{}{suffix} o = vec4(v); }}\n",
            unit.repeat(n / per)
        )
    };
    for (what, source) in [
        ("sum", chain("v = ", "1.0 + ", 1, "1.0;")),
        ("negation", chain("v = ", "- ", 1, "1.0;")),
        ("ternary", chain("v = ", "true ? 1.0 : ", 2, "1.0;")),
        ("assignment", chain("", "v = ", 1, "1.0;")),
        (
            "else if",
            chain("", "if (v > 0.0) v = 1.0; else ", 1, "v = 2.0;"),
        ),
        ("nested if", chain("", "if (v > 0.0) ", 1, "v = 2.0;")),
    ] {
        let stage = SourceLanguage::Glsl(naga::ShaderStage::Fragment);
        let mut library = ShaderLibrary::new().expect("the library composes");
        let composed = library.compose(&ComposeDescriptor {
            source: &source,
            file_path: "chain.frag",
            language: stage,
            ..Default::default()
        });
        match composed {
            // Every back end writes it too (they recurse as deep).
            Ok(composed) => {
                for target in [ExportTarget::SpirV, ExportTarget::Glsl, ExportTarget::Wgsl] {
                    let options = ExportOptions::default();
                    lodkit::shaders::export(&composed, target, &options)
                        .unwrap_or_else(|e| panic!("{what} to {target:?}: {e}"));
                }
            }
            Err(e) => {
                let d = e.diagnostic().expect("a source diagnostic");
                assert_ne!(d.kind, DiagnosticKind::Limit, "{what} is under the limit");
            }
        }
    }
}

#[test]
fn wgsl_and_wesl_chains_are_bounded_and_compose_under_the_limit() {
    // A 200,000-term sum or negation chain overflowed naga's WGSL front end and wesl-rs (8 MiB
    // main thread); 4,000 overflowed wesl-rs there too.
    let limit = lodkit::shaders::MAX_EXPRESSION_DEPTH;
    for (language, file) in [
        (SourceLanguage::Wgsl, "chain.wgsl"),
        (SourceLanguage::Wesl, "chain.wesl"),
    ] {
        for (what, unit) in [("sum", "1.0 + "), ("negation", "- ")] {
            let source = |n: usize| format!("fn f() -> f32 {{ return {}1.0; }}\n", unit.repeat(n));
            let deep = source(200_000);
            let e = compose(&deep, file, language).expect_err("past the limit");
            assert_reportable(&e, &deep);
            let d = e.diagnostic().expect("a source diagnostic");
            assert_eq!(d.kind, DiagnosticKind::Limit, "{what} in {file}");
            // Just under the limit it composes, on this 2 MiB test thread's behalf. (wesl-rs
            // 0.4 prints `- -x` back as `--x`, which naga reads as a decrement: an error, not
            // a limit.)
            match compose(&source(limit - 64), file, language) {
                Err(e) if language == SourceLanguage::Wesl && what == "negation" => {
                    let d = e.diagnostic().expect("a source diagnostic");
                    assert_ne!(d.kind, DiagnosticKind::Limit, "{what} in {file}");
                }
                r => r.unwrap_or_else(|e| panic!("{what} in {file} under the limit: {e}")),
            }
        }
    }
}

/// A tower of function-like macros, each wrapping the one below `fan` times, with `unit` (a
/// bracket pair, a doubling, or an unbalanced opener) at the bottom.
fn macro_tower(levels: usize, fan: usize, unit: usize) -> String {
    let bottom = match unit {
        0 => "#define M0(x) (x)\n".to_owned(),
        1 => "#define M0(x) x + x\n".to_owned(),
        _ => "#define O (\n#define M0(x) O x\n".to_owned(),
    };
    let mut src = format!("#version 450\n{bottom}");
    for i in 1..=levels {
        let below = format!("M{}(", i - 1);
        src += &format!(
            "#define M{i}(x) {}x{}\n",
            below.repeat(fan),
            ")".repeat(fan)
        );
    }
    src + &format!(
        "layout(location = 0) out vec4 o;\nvoid main() {{ float v = M{levels}(1.0); o = vec4(v); }}\n"
    )
}

/// An identifier with non-ASCII letters in it (WGSL and GLSL identifiers are Unicode).
fn identifier() -> impl Strategy<Value = String> {
    let first = prop::sample::select(vec!['g', 'ä', 'ß', 'é', 'λ', '中', 'ñ', 'Ж', '_']);
    let rest = prop::sample::select(vec!['a', 'ö', 'ß', '1', '_', 'ê', '字', 'ø', 'x']);
    (first, prop::collection::vec(rest, 1..6))
        .prop_map(|(f, r)| std::iter::once(f).chain(r).collect::<String>())
        .prop_filter("not a reserved word's shape", |s| s != "_")
}

/// A user module folder holding `module` as `my/m.wgsl`, and a library that imports it.
fn library_with_module(module: &str) -> Result<ShaderLibrary, ShaderError> {
    let dir = crate::support::scratch("mods");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.wgsl"), module).unwrap();
    let mut library = ShaderLibrary::new().expect("the library composes");
    library.add_import_dirs(&[dir.to_path_buf()])?;
    Ok(library)
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

    #[test]
    fn macro_towers_end_in_a_module_or_a_limit_error(levels in 1usize..7, fan in 1usize..13, unit in 0usize..3) {
        let source = macro_tower(levels, fan, unit);
        let stage = SourceLanguage::Glsl(naga::ShaderStage::Fragment);
        if let Err(e) = compose(&source, "user.frag", stage) {
            assert_reportable(&e, &source);
        }
    }

    #[test]
    fn non_ascii_identifiers_in_user_modules_never_panic(name in identifier(), broken in any::<bool>()) {
        // A parse error (a missing `;`) or a validation error (a vec2 where an f32 goes), or none.
        let body = if broken { "return vec2(x);" } else { "return x * 2.0" };
        let module = format!("#define_import_path my::m\nfn {name}(x: f32) -> f32 {{ {body} }}\n");
        let shader = format!(
            "#import my::m::{name}\n@fragment fn main() -> @location(0) vec4<f32> {{ return vec4<f32>({name}(1.0)); }}\n"
        );
        match library_with_module(&module) {
            Ok(mut library) => {
                let composed = library.compose(&ComposeDescriptor {
                    source: &shader,
                    file_path: "user.wgsl",
                    ..Default::default()
                });
                if let Err(e) = composed {
                    assert_reportable(&e, &shader);
                }
            }
            Err(e) => assert_reportable(&e, &module),
        }
    }

    #[test]
    fn non_ascii_identifiers_in_user_shaders_never_panic(name in identifier(), error in 0usize..3, wesl in any::<bool>()) {
        // Valid, a validation error (an f32 where a u32 goes), or a parse error (a stray `)`).
        let value = ["1.0", "1u", "1.0)"][error];
        let (head, language, file) = if wesl {
            ("import lodkit::unpopping::unpopping_alpha;", SourceLanguage::Wesl, "user.wesl")
        } else {
            ("#import lodkit::unpopping::unpopping_alpha", SourceLanguage::Wgsl, "user.wgsl")
        };
        let source = format!(
            "{head}\n@fragment fn main() -> @location(0) vec4<f32> {{\n    let {name}: f32 = {value};\n    return vec4<f32>(unpopping_alpha({name}, true));\n}}\n"
        );
        if let Err(e) = compose(&source, file, language) {
            assert_reportable(&e, &source);
        }
    }
}
