//! Shader functions on the GPU (WGSL and the GLSL twin) against their Rust twins.

use glam::Vec3;
use lodkit::fullscreen::fullscreen_vertex;
use lodkit::normal_distance::{NORMAL_DISTANCE_MIN_Z, foreshortened_normal_distance};

use lodkit::shaders::SourceLanguage;

use crate::harness::{Probe, assert_close, floats, run_glsl, run_wgsl, run_with, words};

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
    let gpu = lodkit_test_gpu!(device);
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
    let gpu = lodkit_test_gpu!(device);
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
    let gpu = lodkit_test_gpu!(device);
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
    let gpu = lodkit_test_gpu!(device);
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

#[test]
fn alpha_mask_twins_match_on_a_real_mask() {
    use glam::{Vec2, Vec4};
    use lodkit::alpha_mask::*;
    let gpu = lodkit_test_gpu!();
    // An 8x8 mask: a disk, so covered and uncovered texels border each other everywhere.
    let size = 8u32;
    let texels: Vec<f32> = (0..size * size)
        .map(|i| {
            let c = Vec2::new((i % size) as f32 + 0.5, (i / size) as f32 + 0.5) - 4.0;
            if c.length() < 3.2 { 1.0 } else { 0.0 }
        })
        .collect();
    let mask = AlphaMask { size, texels };
    // Points over and around the mask's rectangle (x -1..1, y 0..2), with and without a rect.
    let rect = alpha_mask_rect(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 2.0));
    let noise = lodkit::noise::white_noise(3 * 200, 9);
    let cases: Vec<(Vec3, Vec4)> = noise
        .chunks(3)
        .enumerate()
        .map(|(i, r)| {
            let p = Vec3::new(r[0] * 2.6 - 1.3, r[1] * 2.6 - 0.3, r[2] - 0.5);
            (p, if i % 10 == 9 { Vec4::ZERO } else { rect })
        })
        .collect();
    let inputs: Vec<u32> = cases
        .iter()
        .flat_map(|(p, r)| words(&[p.x, p.y, p.z, r.x, r.y, r.z, r.w]))
        .collect();
    let want: Vec<u32> = cases
        .iter()
        .flat_map(|(p, r)| {
            let uv = alpha_mask_uv(*p, *r);
            let t = alpha_mask_texel(uv, glam::UVec2::splat(size));
            let mut w = words(&[uv.x, uv.y]);
            w.extend([
                u32::from(alpha_mask_inside(uv)),
                t.x,
                t.y,
                u32::from(alpha_mask_keep(&mask, *p, *r)),
            ]);
            w
        })
        .collect();
    let wgsl = "let p = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
        let r = vec4(inp_f(3u), inp_f(4u), inp_f(5u), inp_f(6u));
        let uv = alpha_mask_uv(p, r);
        let t = alpha_mask_texel(uv, textureDimensions(probe_tex, 0));
        out_f(0u, uv.x); out_f(1u, uv.y); out_u(2u, u32(alpha_mask_inside(uv)));
        out_u(3u, t.x); out_u(4u, t.y); out_u(5u, u32(alpha_mask_keep(probe_tex, p, r)));";
    let glsl = "vec3 p = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
        vec4 r = vec4(inp_f(3u), inp_f(4u), inp_f(5u), inp_f(6u));
        vec2 uv = lodkit_alpha_mask_uv(p, r);
        uvec2 t = lodkit_alpha_mask_texel(uv, uvec2(textureSize(sampler2D(probe_tex, probe_sampler), 0)));
        out_f(0u, uv.x); out_f(1u, uv.y); out_u(2u, uint(lodkit_alpha_mask_inside(uv)));
        out_u(3u, t.x); out_u(4u, t.y);
        out_u(5u, uint(lodkit_alpha_mask_keep(sampler2D(probe_tex, probe_sampler), p, r)));";
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::alpha_mask::{alpha_mask_uv, alpha_mask_inside, alpha_mask_texel, alpha_mask_keep}",
            wgsl,
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/alpha_mask.glsl\"",
            glsl,
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 7,
            outputs: 6,
            texture: Some((size, &mask.texels)),
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        for (i, (g, w)) in got.chunks(6).zip(want.chunks(6)).enumerate() {
            assert_eq!(
                &g[2..],
                &w[2..],
                "{language:?} case {i}: inside, texel, keep"
            );
            let (g, w) = (floats(&g[..2]), floats(&w[..2]));
            assert!(
                (g[0] - w[0]).abs() < 1e-6 && (g[1] - w[1]).abs() < 1e-6,
                "{language:?} case {i}: uv {g:?} vs {w:?}"
            );
        }
    }
    // Hand-derived: the mask's center is covered, its corner not, and without a rect all is kept.
    let keep = |p: Vec3, r: Vec4| alpha_mask_keep(&mask, p, r);
    assert!(keep(Vec3::new(0.0, 1.0, 0.0), rect) && !keep(Vec3::new(-0.95, 1.95, 0.0), rect));
    assert!(keep(Vec3::new(-0.95, 1.95, 0.0), Vec4::ZERO));
    let kept = want.chunks(6).filter(|w| w[5] == 1).count();
    assert!(
        kept > 40 && kept < 170,
        "{kept} of 200 kept: the cases miss the disk's edge"
    );
}

/// Points and segments for the silhouette functions: the point on the segment's line, at its
/// ends, on either side, a zero-length segment, and a deterministic spread in pixels.
fn silhouette_cases() -> Vec<[f32; 6]> {
    let mut cases = vec![
        [1.0, 1.0, 2.0, 0.0, 2.0, 2.0],
        [1.0, 1.0, 2.0, 2.0, 2.0, 0.0],
        [1.0, 1.0, 0.0, 0.0, 0.0, 2.0],
        [1.0, 1.0, 2.0, 1.0, 2.0, 2.0],
        [1.0, 1.0, 2.0, 0.0, 2.0, 1.0],
        [1.0, 1.0, 1.0, 4.0, 1.0, 4.0],
        [10.5, 20.5, 10.5, 0.0, 10.5, 40.0],
    ];
    let mut state = 0x2545_f491_u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state as f32 / u32::MAX as f32) * 64.0
    };
    for _ in 0..96 {
        cases.push(std::array::from_fn(|_| next()));
    }
    cases
}

/// `lodkit::silhouette`'s crossing (exactly) and distance, WGSL and GLSL, against the Rust twins.
#[test]
fn silhouette_wgsl_and_glsl_match_rust_twins() {
    use glam::Vec2;
    use lodkit::silhouette::{silhouette_crossing, silhouette_distance};
    let gpu = lodkit_test_gpu!(device);
    let cases = silhouette_cases();
    let inputs = words(&cases.concat());
    let wgsl = Probe {
        header: "#import lodkit::silhouette::{silhouette_crossing, silhouette_distance}",
        body: "let p = vec2<f32>(inp_f(0u), inp_f(1u));
               let a = vec2<f32>(inp_f(2u), inp_f(3u));
               let b = vec2<f32>(inp_f(4u), inp_f(5u));
               out_u(0u, bitcast<u32>(silhouette_crossing(p, a, b)));
               out_f(1u, silhouette_distance(p, a, b));",
        inputs: 6,
        outputs: 2,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    let glsl = Probe {
        header: "#include \"lodkit/silhouette.glsl\"",
        body: "vec2 p = vec2(inp_f(0u), inp_f(1u));
               vec2 a = vec2(inp_f(2u), inp_f(3u));
               vec2 b = vec2(inp_f(4u), inp_f(5u));
               out_u(0u, uint(lodkit_silhouette_crossing(p, a, b)));
               out_f(1u, lodkit_silhouette_distance(p, a, b));",
        inputs: 6,
        outputs: 2,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    let v = |c: &[f32; 6], k: usize| Vec2::new(c[k], c[k + 1]);
    let crossings: Vec<i32> = cases
        .iter()
        .map(|c| silhouette_crossing(v(c, 0), v(c, 2), v(c, 4)))
        .collect();
    let distances: Vec<f32> = cases
        .iter()
        .map(|c| silhouette_distance(v(c, 0), v(c, 2), v(c, 4)))
        .collect();
    assert_eq!(&crossings[..5], &[1, -1, 0, 1, 0], "hand-made cases");
    assert!(crossings.iter().any(|&c| c != 0) && crossings[7..].contains(&0));
    for (language, out) in [
        ("WGSL", run_wgsl(gpu, &wgsl, &inputs)),
        ("GLSL", run_glsl(gpu, &glsl, &inputs)),
    ] {
        let got: Vec<i32> = out.chunks_exact(2).map(|w| w[0] as i32).collect();
        assert_eq!(got, crossings, "{language} silhouette_crossing");
        let got: Vec<u32> = out.chunks_exact(2).map(|w| w[1]).collect();
        assert_close(
            &floats(&got),
            &distances,
            1e-4,
            &format!("{language} silhouette_distance"),
        );
    }
}
