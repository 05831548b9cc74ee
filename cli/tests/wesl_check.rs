//! `lodkit check` on WESL: a user's `.wesl` file that imports `lodkit::...` is linked by wesl-rs
//! and validated by naga, with the same exit codes, file:line:col diagnostics and misspelt-import
//! hints as naga_oil WGSL.

use crate::cli::check_one;

const GOOD: &[u8] = b"import lodkit::normal_distance::foreshortened_normal_distance;
import lodkit::screen_door::screen_door_keep;

@fragment
fn main(@builtin(position) p: vec4<f32>, @location(0) n: vec3<f32>) -> @location(0) vec4<f32> {
    if !screen_door_keep(p.xy, 0.5) {
        discard;
    }
    return vec4<f32>(foreshortened_normal_distance(n, vec3<f32>(0.0, 0.0, 1.0)));
}
";

#[test]
fn good_wesl_exits_0_with_and_without_conditions() {
    let (code, stderr, diag) = check_one("good.wesl", GOOD, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(diag.is_null());
    let (code, stderr, _) = check_one("good.wesl", GOOD, &["-D", "LODKIT_SCREEN_DOOR_BLUE_NOISE"]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn wesl_syntax_error_names_line_and_column() {
    let src = b"import lodkit::unpopping::unpopping_alpha;\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    let x = 1.0 +;\n    return vec4<f32>(x);\n}\n";
    let (code, stderr, diag) = check_one("broken.wesl", src, &[]);
    assert_eq!(code, 1, "{stderr}");
    assert_eq!(diag["kind"], "parse", "{diag}");
    assert_eq!(diag["file"], "broken.wesl", "{diag}");
    assert_eq!(diag["line"].as_u64(), Some(4), "{stderr}");
    assert!(stderr.contains("broken.wesl:4:"), "{stderr}");
}

#[test]
fn misspelt_wesl_import_names_the_closest_lodkit_module() {
    let src = b"import lodkit::normal_distanse::foreshortened_normal_distance;\n@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(foreshortened_normal_distance(vec3(0.0), vec3(1.0))); }\n";
    let (code, stderr, diag) = check_one("typo.wesl", src, &[]);
    assert_eq!(code, 1, "{stderr}");
    assert_eq!(diag["kind"], "unknown-import", "{diag}");
    assert_eq!(
        diag["hint"], "did you mean `lodkit::normal_distance`?",
        "{diag}"
    );
    assert_eq!(
        (diag["line"].as_u64(), diag["column"].as_u64()),
        (Some(1), Some(8)),
        "{stderr}"
    );
}

#[test]
fn wesl_type_error_points_at_the_argument_as_written() {
    let src = b"import lodkit::normal_distance::foreshortened_normal_distance;\n\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    let d = foreshortened_normal_distance(1.0, vec3<f32>(0.0, 0.0, 1.0));\n    return vec4<f32>(d);\n}\n";
    let (code, stderr, diag) = check_one("typed.wesl", src, &[]);
    assert_eq!(code, 1, "{stderr}");
    assert_eq!(diag["file"], "typed.wesl", "{diag}");
    // Line 5, column 43: the `1.0` in the user's text (the linked WGSL is reformatted and its
    // names mangled; the diagnostic maps back).
    assert_eq!(
        (diag["line"].as_u64(), diag["column"].as_u64()),
        (Some(5), Some(43)),
        "{stderr}"
    );
    assert!(!stderr.contains("lodkit__"), "no mangled names: {stderr}");
}

/// Every lodkit pass converts to WESL (`lodkit export --to wesl`, as a Bevy 0.20 project holds
/// its shaders) and the WESL form checks under every combination of the defs it tests. A pass
/// whose `#ifdef` blocks declare what later code uses would convert to blocks it cannot leave.
#[test]
fn every_pass_exports_to_wesl_that_checks_under_every_def_set() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let passes = concat!(env!("CARGO_MANIFEST_DIR"), "/../shader_lib/passes");
    let mut converted = Vec::new();
    for entry in std::fs::read_dir(passes).expect("shader_lib/passes") {
        let path = entry.expect("an entry").path();
        let out = dir
            .path()
            .join(path.file_stem().expect("a name"))
            .with_extension("wesl");
        let status = crate::cli::lodkit()
            .args(["export", "--to", "wesl"])
            .arg(&path)
            .arg("-o")
            .arg(&out)
            .output()
            .expect("run lodkit");
        assert!(
            status.status.success(),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&status.stderr)
        );
        converted.push(out);
    }
    assert_eq!(converted.len(), 9, "lodkit's passes");
    let check = crate::cli::lodkit()
        .args(["check", "--permute"])
        .args(&converted)
        .output()
        .expect("run lodkit");
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        check.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&check.stderr)
    );
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok: ")).count(),
        9,
        "{stdout}"
    );
}

/// A value condition has no WESL form: `export --to wesl` names its line and exits 1.
#[test]
fn export_to_wesl_names_the_line_without_a_wesl_form() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let file = dir.path().join("valued.wgsl");
    std::fs::write(
        &file,
        "@fragment\nfn main() -> @location(0) vec4<f32> {\n#if SAMPLES == 4\n    return vec4<f32>(1.0);\n#else\n    return vec4<f32>(0.0);\n#endif\n}\n",
    )
    .expect("write the shader");
    let out = crate::cli::lodkit()
        .args(["export", "--to", "wesl"])
        .arg(&file)
        .args(["-o", "-"])
        .output()
        .expect("run lodkit");
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("valued.wgsl:3:"), "{stderr}");
}
