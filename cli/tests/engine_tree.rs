//! `lodkit check -I` over a real engine's shader tree: a path two files declare (an engine's
//! stand-in and real module, picked by a build feature) or a module that does not compose fails
//! only the shaders that import it; `--exclude` leaves files out; `--capabilities` validates
//! shaders that need native features.

use std::path::Path;

use crate::cli::{fixture, run};

const GOOD: &[u8] = b"#import lodkit::unpopping::unpopping_alpha
@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(unpopping_alpha(0.5, true)); }
";
const REAL: &[u8] = b"#define_import_path engine::thing\nfn thing() -> f32 { return 1.0; }\n";
const DUMMY: &[u8] = b"#define_import_path engine::thing\nfn thing() -> f32 { return 0.0; }\n";
const BROKEN: &[u8] = b"#define_import_path engine::broken\nfn broken() -> f32 { return 1.0 +; }\n";
const USES_THING: &[u8] = b"#import engine::thing::thing
@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(thing()); }
";
const USES_BROKEN: &[u8] = b"#import engine::broken::broken
@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(broken()); }
";

fn tree() -> crate::support::Scratch {
    fixture(&[
        ("engine/real/thing.wgsl", REAL),
        ("engine/dummy/thing.wgsl", DUMMY),
        ("engine/broken.wgsl", BROKEN),
        ("good.wgsl", GOOD),
        ("uses_thing.wgsl", USES_THING),
        ("uses_broken.wgsl", USES_BROKEN),
    ])
}

#[test]
fn problems_in_engine_modules_fail_only_their_importers() {
    let dir = tree();
    let (code, stdout, stderr) = run(&dir, &["check", "-I", "engine", "good.wgsl"]);
    assert_eq!(code, 0, "{stdout}{stderr}");

    let (code, _, stderr) = run(&dir, &["check", "-I", "engine", "uses_thing.wgsl"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("duplicate-module"), "{stderr}");
    assert!(
        stderr.contains("uses_thing.wgsl:1:9"),
        "at the import: {stderr}"
    );
    for file in ["engine/real/thing.wgsl", "engine/dummy/thing.wgsl"] {
        assert!(stderr.contains(file), "names {file}: {stderr}");
    }
    assert!(stderr.contains("--exclude"), "{stderr}");

    let (code, _, stderr) = run(&dir, &["check", "-I", "engine", "uses_broken.wgsl"]);
    assert_eq!(code, 1, "{stderr}");
    // The module's own error, where it is.
    assert!(stderr.contains("engine/broken.wgsl:2:34"), "{stderr}");
}

#[test]
fn exclude_leaves_out_the_stand_in() {
    let dir = tree();
    let args = [
        "check",
        "-I",
        "engine",
        "--exclude",
        "dummy/",
        "uses_thing.wgsl",
        "good.wgsl",
    ];
    let (code, stdout, stderr) = run(&dir, &args);
    assert_eq!(code, 0, "{stdout}{stderr}");
}

#[test]
fn capabilities_let_native_shaders_validate() {
    let f64_shader =
        b"@compute @workgroup_size(1) fn main() { var x: f64 = 1.0lf; x = x * 2.0lf; }\n";
    let dir = fixture(&[("wide.wgsl", f64_shader)]);
    let (code, _, stderr) = run(&dir, &["check", "wide.wgsl"]);
    assert_eq!(code, 1, "f64 needs a capability: {stderr}");
    for caps in ["f64", "FLOAT64", "all", "immediates,float64"] {
        let (code, _, stderr) = run(&dir, &["check", "--capabilities", caps, "wide.wgsl"]);
        assert_eq!(code, 0, "--capabilities {caps}: {stderr}");
    }
    let (code, _, stderr) = run(
        Path::new("."),
        &["check", "--capabilities", "warp-drive", "x.wgsl"],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("unknown capability `warp-drive`") && stderr.contains("float64"),
        "{stderr}"
    );
}
