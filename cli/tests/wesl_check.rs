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
