//! A WGSL file without naga_oil directives is checked by naga alone (no composer is built); the
//! same file with a directive added at its end goes through naga_oil. Both must report the same
//! problem at the same line and column, with the same message, in every format.

use crate::cli::{fixture, run};

/// Broken directive-free shaders: parse errors, an unknown name, validation errors with notes.
const BROKEN: &[(&str, &str)] = &[
    ("semicolon.wgsl", "fn f() -> f32 {\n    return 1.0\n}\n"),
    (
        "unknown_name.wgsl",
        "@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(undefined_name);\n}\n",
    ),
    (
        "no_return.wgsl",
        "// a comment with a # and a::b is no directive\nfn f() -> f32 {\n    let x = 1.0;\n}\n",
    ),
    (
        "uniform_stride.wgsl",
        "@group(0) @binding(0) var<uniform> u: array<f32>;\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(u[0]);\n}\n",
    ),
    (
        "mixed_types.wgsl",
        "fn f(a: f32, b: i32) -> f32 {\n    return a + b;\n}\n",
    ),
];

/// A trailing `#ifdef` that changes nothing but sends the file through naga_oil.
const DIRECTIVE: &str = "#ifdef LODKIT_TEST_NEVER_SET\n#endif\n";

#[test]
fn directive_free_files_report_what_the_composer_reports() {
    for (name, source) in BROKEN {
        let plain = fixture(&[(name, source.as_bytes())]);
        let composed = fixture(&[(name, format!("{source}{DIRECTIVE}").as_bytes())]);
        for format in ["human", "json", "github"] {
            let args = ["check", "--format", format, name];
            let (plain_code, plain_out, plain_err) = run(&plain, &args);
            let (code, out, err) = run(&composed, &args);
            assert_eq!(plain_code, 1, "{name} ({format}): {plain_err}");
            assert_eq!(
                (plain_code, &plain_out, &plain_err),
                (code, &out, &err),
                "{name}: --format {format}"
            );
        }
        // The place is where naga-cli puts it: a line and column inside the file.
        let (_, out, _) = run(&plain, &["check", "--format", "json", name]);
        let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
        let d = &doc["files"][0]["diagnostics"][0];
        assert!(d["line"].as_u64().is_some_and(|l| l >= 1), "{name}: {d}");
    }
}

#[test]
fn a_def_still_switches_code_in_a_file_with_directives() {
    let source = "#ifdef BREAK\nfn f() -> f32 { }\n#endif\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(1.0);\n}\n";
    let dir = fixture(&[("switch.wgsl", source.as_bytes())]);
    let (code, _, err) = run(&dir, &["check", "switch.wgsl"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = run(&dir, &["check", "-D", "BREAK", "switch.wgsl"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("switch.wgsl:2:"), "{err}");
}

#[test]
fn user_modules_are_ordered_by_the_paths_they_use_without_importing() {
    // naga_oil resolves `my::b::f()` written in full without an `#import`: `my::a` must be
    // added after `my::b` though its file sorts first and it imports nothing.
    let a = "#define_import_path my::a\nfn g() -> f32 { return my::b::f(); }\n";
    let b = "#define_import_path my::b\nfn f() -> f32 { return 1.0; }\n";
    let shader = "#import my::a::g\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(g());\n}\n";
    let dir = fixture(&[
        ("modules/a.wgsl", a.as_bytes()),
        ("modules/b.wgsl", b.as_bytes()),
        ("shader.wgsl", shader.as_bytes()),
    ]);
    let (code, _, err) = run(&dir, &["check", "-I", "modules", "shader.wgsl"]);
    assert_eq!(code, 0, "{err}");
}
