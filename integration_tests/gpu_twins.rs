//! Shader functions on the GPU (WGSL and the GLSL twin) against their Rust twins.

use glam::Vec3;
use lodkit::fullscreen::fullscreen_vertex;
use lodkit::normal_distance::{NORMAL_DISTANCE_MIN_Z, foreshortened_normal_distance};

use crate::harness::{Probe, assert_close, floats, run_glsl, run_wgsl, words};

/// Hand-picked pairs (identical, facing vs tilted, grazing, back-facing, just either side of the
/// guard) plus a deterministic spread of unit normals.
fn normal_pairs() -> Vec<(Vec3, Vec3)> {
    let tilt = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
    let mut pairs = vec![
        (Vec3::Z, Vec3::Z),
        (tilt(40.0), tilt(40.0)),
        (Vec3::new(0.3, -0.4, 0.866), Vec3::new(0.3, -0.4, 0.866)),
        (Vec3::Z, tilt(36.87)),
        (Vec3::Z, tilt(80.0)),
        (Vec3::Z, Vec3::X),       // exactly grazing: guarded
        (Vec3::X, Vec3::X),       // identical grazing normals
        (Vec3::X, -Vec3::X),      // opposite grazing normals
        (Vec3::Z, -Vec3::Z),      // back-facing
        (tilt(89.0), tilt(89.5)), // both near the guard
        (
            Vec3::new(0.0, 1.0, NORMAL_DISTANCE_MIN_Z * 1.01),
            Vec3::new(0.0, 1.0, NORMAL_DISTANCE_MIN_Z * 0.99),
        ),
        (Vec3::new(0.7, 0.7, 0.14), Vec3::new(-0.7, 0.7, 0.14)),
    ];
    let mut state = 0x9e37_79b9_u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state as f32 / u32::MAX as f32) * 2.0 - 1.0
    };
    for _ in 0..64 {
        let a = Vec3::new(next(), next(), next().abs() + 0.05).normalize();
        let b = Vec3::new(next(), next(), next().abs() + 0.05).normalize();
        pairs.push((a, b));
    }
    pairs
}

/// A WGSL probe that evaluates `expr` over normal pairs `a`, `b`.
fn normal_probe(expr: &str) -> Probe<'static> {
    let body = format!(
        "let a = vec3<f32>(inp_f(0u), inp_f(1u), inp_f(2u));
         let b = vec3<f32>(inp_f(3u), inp_f(4u), inp_f(5u));
         out_f(0u, {expr});"
    );
    Probe {
        header: "#import lodkit::normal_distance::foreshortened_normal_distance",
        body: Box::leak(body.into_boxed_str()),
        inputs: 6,
        outputs: 1,
        texture: None,
        rgba: &[],
        urgba: &[],
    }
}

fn normal_inputs(pairs: &[(Vec3, Vec3)]) -> Vec<u32> {
    let flat: Vec<f32> = pairs
        .iter()
        .flat_map(|(a, b)| [a.x, a.y, a.z, b.x, b.y, b.z])
        .collect();
    words(&flat)
}

#[test]
fn foreshortened_normal_distance_wgsl_matches_rust_twin() {
    let gpu = lodkit_test_gpu!();
    let pairs = normal_pairs();
    let probe = normal_probe("foreshortened_normal_distance(a, b)");
    let got = floats(&run_wgsl(gpu, &probe, &normal_inputs(&pairs)));
    let want: Vec<f32> = pairs
        .iter()
        .map(|(a, b)| foreshortened_normal_distance(*a, *b))
        .collect();
    assert_close(&got, &want, 1e-5, "WGSL foreshortened_normal_distance");
    assert_eq!(got[0], 0.0, "identical normals must be exactly 0");
    assert!(
        got.iter().all(|d| d.is_finite()),
        "grazing normals must stay finite"
    );
}

#[test]
fn foreshortened_normal_distance_glsl_matches_rust_twin() {
    let gpu = lodkit_test_gpu!();
    let pairs = normal_pairs();
    let probe = Probe {
        header: "#include \"lodkit/normal_distance.glsl\"",
        body: "vec3 a = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
               vec3 b = vec3(inp_f(3u), inp_f(4u), inp_f(5u));
               out_f(0u, lodkit_foreshortened_normal_distance(a, b));",
        inputs: 6,
        outputs: 1,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    let got = floats(&run_glsl(gpu, &probe, &normal_inputs(&pairs)));
    let want: Vec<f32> = pairs
        .iter()
        .map(|(a, b)| foreshortened_normal_distance(*a, *b))
        .collect();
    assert_close(
        &got,
        &want,
        1e-5,
        "GLSL lodkit_foreshortened_normal_distance",
    );
}

fn fullscreen_want() -> Vec<f32> {
    (0..3)
        .flat_map(|i| {
            let v = fullscreen_vertex(i);
            [
                v.position.x,
                v.position.y,
                v.position.z,
                v.position.w,
                v.uv.x,
                v.uv.y,
            ]
        })
        .collect()
}

#[test]
fn fullscreen_vertex_wgsl_and_glsl_match_rust_twin() {
    let gpu = lodkit_test_gpu!();
    let inputs = [0u32, 1, 2];
    let wgsl = Probe {
        header: "#import lodkit::fullscreen::fullscreen_vertex",
        body: "let v = fullscreen_vertex(inp_u(0u));
               out_f(0u, v.position.x); out_f(1u, v.position.y); out_f(2u, v.position.z);
               out_f(3u, v.position.w); out_f(4u, v.uv.x); out_f(5u, v.uv.y);",
        inputs: 1,
        outputs: 6,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    let glsl = Probe {
        header: "#include \"lodkit/fullscreen.glsl\"",
        body: "lodkit_FullscreenVertex v = lodkit_fullscreen_vertex(inp_u(0u));
               out_f(0u, v.position.x); out_f(1u, v.position.y); out_f(2u, v.position.z);
               out_f(3u, v.position.w); out_f(4u, v.uv.x); out_f(5u, v.uv.y);",
        inputs: 1,
        outputs: 6,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    let want = fullscreen_want();
    assert_eq!(
        floats(&run_wgsl(gpu, &wgsl, &inputs)),
        want,
        "WGSL fullscreen_vertex"
    );
    assert_eq!(
        floats(&run_glsl(gpu, &glsl, &inputs)),
        want,
        "GLSL lodkit_fullscreen_vertex"
    );
}

#[test]
fn probe_detects_a_wrong_twin() {
    // The harness must be able to fail: a deliberately different expression does not match.
    let gpu = lodkit_test_gpu!();
    let pairs = normal_pairs();
    let probe = normal_probe("distance(a, b)");
    let got = floats(&run_wgsl(gpu, &probe, &normal_inputs(&pairs)));
    let want: Vec<f32> = pairs
        .iter()
        .map(|(a, b)| foreshortened_normal_distance(*a, *b))
        .collect();
    let result = std::panic::catch_unwind(|| assert_close(&got, &want, 1e-5, "plain distance"));
    assert!(
        result.is_err(),
        "the comparison accepted a different function"
    );
}

#[test]
fn headless_context_reports_a_missing_backend_clearly() {
    let err = lodkit::gpu::GpuContext::new_headless(&lodkit::gpu::GpuOptions {
        backends: vec![wgpu::Backends::METAL],
        ..Default::default()
    })
    .expect_err("no Metal adapter on this platform");
    let text = err.to_string();
    assert!(
        text.contains("no GPU adapter") && text.contains("mesa-vulkan-drivers"),
        "{text}"
    );
}
