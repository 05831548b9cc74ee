//! The `lodkit` command line: exit codes, diagnostics with file:line:col, JSON output.

use std::path::Path;

use crate::support::Scratch;
use std::process::{Command, Output};

pub(crate) fn lodkit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lodkit"))
}

/// A fresh temporary folder holding `files` (name, bytes), removed when dropped.
pub(crate) fn fixture(files: &[(&str, &[u8])]) -> Scratch {
    let dir = Scratch::folder();
    for (name, bytes) in files {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    dir
}

pub(crate) fn run(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let Output {
        status,
        stdout,
        stderr,
    } = lodkit().current_dir(dir).args(args).output().unwrap();
    let code = status.code().expect("exited, not killed");
    (
        code,
        String::from_utf8_lossy(&stdout).into_owned(),
        String::from_utf8_lossy(&stderr).into_owned(),
    )
}

const GOOD: &[u8] = b"#import lodkit::normal_distance::foreshortened_normal_distance

@fragment
fn main(@location(0) n: vec3<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(foreshortened_normal_distance(n, vec3<f32>(0.0, 0.0, 1.0)));
}
";

/// Checks one file and returns (exit code, human stderr, parsed JSON diagnostic).
pub(crate) fn check_one(
    name: &str,
    bytes: &[u8],
    extra: &[&str],
) -> (i32, String, serde_json::Value) {
    let dir = fixture(&[(name, bytes)]);
    let mut args = vec!["check"];
    args.extend_from_slice(extra);
    args.push(name);
    let (code, _, stderr) = run(&dir, &args);
    let mut json_args = args.clone();
    json_args.insert(1, "--format=json");
    let (json_code, stdout, _) = run(&dir, &json_args);
    assert_eq!(
        code, json_code,
        "human and JSON runs disagree on the exit code"
    );
    let doc: serde_json::Value = serde_json::from_str(&stdout).expect("--format json prints JSON");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let diag = doc["files"][0]["diagnostics"][0].clone();
    (code, stderr, diag)
}

#[test]
fn good_shader_exits_0() {
    let (code, _, diag) = check_one("good.wgsl", GOOD, &[]);
    assert_eq!(code, 0);
    assert!(diag.is_null());
}

#[test]
fn syntax_error_names_line_and_column() {
    let src = b"@fragment\nfn main() -> @location(0) vec4<f32> {\n    let x = 1.0 +;\n    return vec4<f32>(x);\n}\n";
    let (code, stderr, diag) = check_one("syntax.wgsl", src, &[]);
    assert_eq!(code, 1);
    assert!(stderr.contains("syntax.wgsl:3:18"), "{stderr}");
    assert!(
        stderr.contains("let x = 1.0 +;") && stderr.contains('^'),
        "source line and caret: {stderr}"
    );
    assert_eq!(
        (diag["line"].as_u64(), diag["column"].as_u64()),
        (Some(3), Some(18))
    );
    assert_eq!(diag["kind"], "parse");
}

#[test]
fn unknown_lodkit_import_is_reported_even_when_unused() {
    let src = b"#import lodkit::teleport::beam\n@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }\n";
    let (code, stderr, diag) = check_one("unknown.wgsl", src, &[]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("unknown.wgsl:1:9") && stderr.contains("lodkit::teleport"),
        "{stderr}"
    );
    assert_eq!(diag["kind"], "unknown-import");
    assert!(
        diag["hint"].is_null(),
        "no module is close to `teleport`: {diag}"
    );
}

#[test]
fn misspelt_import_gets_a_did_you_mean() {
    let src = b"// tree shader\n#import lodkit::normal_distanse::foreshortened_normal_distance\n@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }\n";
    let (code, stderr, diag) = check_one("tree.wgsl", src, &[]);
    assert_eq!(code, 1);
    assert!(stderr.contains("tree.wgsl:2:9"), "{stderr}");
    assert!(
        stderr.contains("did you mean `lodkit::normal_distance`?"),
        "{stderr}"
    );
    assert_eq!(diag["hint"], "did you mean `lodkit::normal_distance`?");
    assert_eq!(
        (diag["line"].as_u64(), diag["column"].as_u64()),
        (Some(2), Some(9))
    );
}

#[test]
fn type_error_in_a_lodkit_call_points_at_the_argument() {
    let src = b"#import lodkit::normal_distance::foreshortened_normal_distance\n\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    let d = foreshortened_normal_distance(1.0, vec3<f32>(0.0, 0.0, 1.0));\n    return vec4<f32>(d);\n}\n";
    let (code, stderr, diag) = check_one("typed.wgsl", src, &[]);
    assert_eq!(code, 1);
    // Column 43 is the `1.0` in the text as written (not in naga_oil's rewritten copy).
    assert!(stderr.contains("typed.wgsl:5:43"), "{stderr}");
    assert!(
        stderr.contains("vec3<f32>"),
        "names the expected type: {stderr}"
    );
    assert!(
        !stderr.contains("naga_oil_mod"),
        "decorated names leak: {stderr}"
    );
    assert_eq!(
        (diag["line"].as_u64(), diag["column"].as_u64()),
        (Some(5), Some(43))
    );
}

#[test]
fn missing_file_exits_2() {
    let (code, stderr, diag) = check_one("present.wgsl", GOOD, &["absent.wgsl"]);
    // `present.wgsl` comes last in the argument list; the first file is the missing one.
    assert_eq!(code, 2);
    assert!(
        stderr.contains("absent.wgsl") && stderr.contains("No such file"),
        "{stderr}"
    );
    assert_eq!(diag["kind"], "io");
}

#[test]
fn non_utf8_file_names_the_byte() {
    let src =
        b"@fragment\nfn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); } // caf\xe9\n";
    let (code, stderr, diag) = check_one("latin1.wgsl", src, &[]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("latin1.wgsl:2:70") && stderr.contains("0xe9"),
        "{stderr}"
    );
    assert_eq!(diag["kind"], "invalid-utf8");
}

#[test]
fn non_ascii_names_in_a_user_module_are_an_error_not_a_crash() {
    // naga_oil refuses identifiers that need substitution under naga's writeback rules; mapping
    // that error back once panicked on the multibyte character before the decorated name.
    let module = "#define_import_path my::maß\nfn größe(x: f32) -> f32 { return x * 2.0; }\n";
    let main = "#import my::maß::größe\n@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(größe(1.0)); }\n";
    let dir = fixture(&[
        ("mods/m.wgsl", module.as_bytes()),
        ("main.wgsl", main.as_bytes()),
    ]);
    let (code, _, stderr) = run(&dir, &["check", "-I", "mods", "main.wgsl"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("error["), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn macros_nested_a_hundred_thousand_deep_are_a_limit_error() {
    // Eight lines that stand for 10^5 nested parentheses (and 10^6 with one more level).
    let mut defs = String::from("#version 450\n#define A(x) ((((((((((x))))))))))\n");
    for (name, inner) in [("B", "A"), ("C", "B"), ("D", "C"), ("E", "D"), ("F", "E")] {
        defs += &format!(
            "#define {name}(x) {}x{}\n",
            format!("{inner}(").repeat(10),
            ")".repeat(10)
        );
    }
    for top in ["E", "F"] {
        let src = format!(
            "{defs}layout(location = 0) out vec4 o;\nvoid main() {{ float v = {top}(1.0); o = vec4(v); }}\n"
        );
        let dir = fixture(&[("deep.frag", src.as_bytes())]);
        let (code, _, stderr) = run(&dir, &["check", "deep.frag"]);
        assert_eq!(code, 1, "{top}: {stderr}");
        assert!(
            stderr.contains("error[limit]") && stderr.contains("after macro expansion"),
            "{top}: {stderr}"
        );
        assert!(stderr.contains("deep.frag:9:"), "{top}: {stderr}");
    }
}

#[test]
fn import_cycle_among_user_modules_is_named() {
    let a = b"#define_import_path my::a\n#import my::b::fb\nfn fa() -> f32 { return fb(); }\n";
    let b = b"#define_import_path my::b\n#import my::a::fa\nfn fb() -> f32 { return fa(); }\n";
    let dir = fixture(&[("mods/a.wgsl", a), ("mods/b.wgsl", b), ("good.wgsl", GOOD)]);
    let (code, _, stderr) = run(&dir, &["check", "-I", "mods", "good.wgsl"]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("import cycle: my::a -> my::b -> my::a"),
        "{stderr}"
    );
    assert!(stderr.contains("mods/a.wgsl:2:9"), "{stderr}");
    let (code, stdout, _) = run(
        &dir,
        &["check", "--format", "json", "-I", "mods", "good.wgsl"],
    );
    assert_eq!(code, 1);
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(doc["diagnostics"][0]["kind"], "import-cycle");
}

#[test]
fn user_modules_and_shader_defs_compose() {
    let module = b"#define_import_path my::tint\n#import lodkit::normal_distance::foreshortened_normal_distance\nfn tint(n: vec3<f32>) -> f32 {\n#ifdef STRONG\n    return 2.0 * foreshortened_normal_distance(n, vec3(0.0, 0.0, 1.0));\n#else\n    return foreshortened_normal_distance(n, vec3(0.0, 0.0, 1.0));\n#endif\n}\n";
    let main = b"#import my::tint::tint\n@fragment fn main(@location(0) n: vec3<f32>) -> @location(0) vec4<f32> { return vec4<f32>(tint(n)); }\n";
    let dir = fixture(&[("mods/tint.wgsl", module), ("main.wgsl", main)]);
    assert_eq!(run(&dir, &["check", "-I", "mods", "main.wgsl"]).0, 0);
    assert_eq!(
        run(&dir, &["check", "-I", "mods", "-D", "STRONG", "main.wgsl"]).0,
        0
    );
    let (code, _, stderr) = run(&dir, &["check", "main.wgsl"]);
    assert_eq!(code, 1, "without -I the user module is unknown: {stderr}");
}

#[test]
fn glsl_shader_includes_a_twin() {
    let src = b"#version 450\n#extension GL_GOOGLE_include_directive : require\n#include \"lodkit/normal_distance.glsl\"\nlayout(location = 0) in vec3 n;\nlayout(location = 0) out vec4 color;\nvoid main() { color = vec4(lodkit_foreshortened_normal_distance(n, vec3(0.0, 0.0, 1.0))); }\n";
    assert_eq!(check_one("shade.frag", src, &[]).0, 0);
    let bad = b"#version 450\n#include \"lodkit/normal_distanse.glsl\"\nvoid main() {}\n";
    let (code, stderr, diag) = check_one("bad.frag", bad, &[]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("bad.frag:2:11") && stderr.contains("lodkit/normal_distance.glsl"),
        "{stderr}"
    );
    assert_eq!(diag["kind"], "unknown-import");
    let typo = b"#version 450\n#include \"lodkit/normal_distance.glsl\"\nlayout(location = 0) out vec4 color;\nvoid main() { color = vec4(lodkit_foreshortened_normal_distance(1.0)); }\n";
    let (code, stderr, diag) = check_one("typo.frag", typo, &[]);
    assert_eq!(code, 1, "{stderr}");
    assert_eq!(
        diag["file"], "typo.frag",
        "the error is in the user's file, not the include: {diag}"
    );
    assert_eq!(diag["line"].as_u64(), Some(4), "{diag}");
}

#[test]
fn glsl_without_a_stage_is_a_usage_error() {
    let (code, stderr, _) = check_one("shade.glsl", b"#version 450\nvoid main() {}\n", &[]);
    assert_eq!(code, 2);
    assert!(stderr.contains("--stage"), "{stderr}");
}

#[test]
fn modules_lists_every_module_as_json() {
    let (code, stdout, _) = run(Path::new("."), &["modules", "--format", "json"]);
    assert_eq!(code, 0);
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let paths: Vec<&str> = doc
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m["import_path"].as_str())
        .collect();
    assert!(
        paths.contains(&"lodkit::normal_distance") && paths.contains(&"lodkit::fullscreen"),
        "{paths:?}"
    );
    let nd = doc
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["path"] == "wgsl/lodkit/normal_distance.wgsl")
        .unwrap();
    assert_eq!(nd["functions"][1]["name"], "foreshortened_normal_distance");
    assert!(
        nd["functions"][1]["doc"]
            .as_str()
            .unwrap()
            .contains("Euclidean distance")
    );
}

#[test]
fn export_writes_every_target() {
    let dir = fixture(&[("good.wgsl", GOOD)]);
    for (to, needle) in [
        ("spv", &[0x03u8, 0x02, 0x23, 0x07][..]),
        ("msl", b"#include <metal_stdlib>"),
        ("hlsl", b"float4"),
        ("glsl", b"#version 450"),
        ("glsl-es", b"#version 300 es"),
        ("wgsl", b"@fragment"),
    ] {
        let out = format!("out.{to}");
        let (code, _, stderr) = run(&dir, &["export", "--to", to, "good.wgsl", "-o", &out]);
        assert_eq!(code, 0, "{to}: {stderr}");
        let bytes = std::fs::read(dir.join(&out)).unwrap();
        assert!(
            bytes.windows(needle.len()).any(|w| w == needle),
            "{to} output lacks {needle:?}"
        );
    }
    let (code, _, stderr) = run(
        &dir,
        &[
            "export",
            "--to",
            "glsl",
            "good.wgsl",
            "--entry",
            "nope",
            "-o",
            "x",
        ],
    );
    assert_eq!(code, 2, "a missing entry point is a usage error");
    assert!(stderr.contains("no entry point `nope`"), "{stderr}");
}

#[test]
fn a_def_set_to_false_is_off_for_ifdef() {
    let src = b"#ifdef BROKEN\nthis does not parse\n#endif\n@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }\n";
    let dir = fixture(&[("gate.wgsl", src)]);
    assert_eq!(
        run(&dir, &["check", "-D", "BROKEN=false", "gate.wgsl"]).0,
        0
    );
    assert_eq!(run(&dir, &["check", "-D", "BROKEN", "gate.wgsl"]).0, 1);
}

#[test]
fn a_user_module_may_not_reuse_a_lodkit_import_path() {
    let module = b"#define_import_path lodkit::combine\nfn x() -> f32 { return 1.0; }\n";
    let dir = fixture(&[("mods/combine.wgsl", module), ("good.wgsl", GOOD)]);
    let (code, _, stderr) = run(&dir, &["check", "-I", "mods", "good.wgsl"]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("duplicate-module") && stderr.contains("lodkit::combine"),
        "{stderr}"
    );
}

#[test]
fn an_include_line_may_end_with_a_comment() {
    let src = b"#version 450\n#include \"lodkit/normal_distance.glsl\" // the guard\nlayout(location = 0) out vec4 color;\nvoid main() { color = vec4(lodkit_foreshortened_normal_distance(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0))); }\n";
    assert_eq!(check_one("commented.frag", src, &[]).0, 0);
}

#[test]
fn wesl_writes_the_committed_package() {
    let scratch = fixture(&[]);
    let out = scratch.join("pkg");
    let (code, stdout, stderr) = run(Path::new("."), &["wesl", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let committed = crate::support::workspace_root().join("shader_lib/wesl/lodkit");
    for rel in ["wesl.toml", "visibility.wesl", "screen_door.wesl"] {
        assert_eq!(
            std::fs::read_to_string(out.join(rel)).unwrap(),
            std::fs::read_to_string(committed.join(rel)).unwrap(),
            "{rel}"
        );
    }
    // A file where the folder should be: exit 2 naming the path.
    let blocked_dir = fixture(&[("pkg", b"not a folder")]);
    let blocked = blocked_dir.join("pkg");
    let (code, _, stderr) = run(
        Path::new("."),
        &["wesl", "--out", blocked.to_str().unwrap()],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cannot write"), "{stderr}");
}
