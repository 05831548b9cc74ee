//! Frame-sequential LOD: combine, reproject and visibility on the GPU (WGSL and GLSL twins) against
//! their Rust twins on hand-derived cases, and the scheduler's properties.

use glam::{Mat4, UVec2, Vec2, Vec3, Vec4};
use lodkit::combine::{DepthConvention, LodSample, combine_samples};
use lodkit::frame_sequential::{Drive, ID_QUARANTINE_FRAMES, Schedule, TransitionScheduler};
use lodkit::reproject::{
    in_viewport, new_to_old_matrix, reproject, reproject_base, reproject_refine,
};
use lodkit::shaders::SourceLanguage;
use lodkit::visibility::{
    VisibilityPattern, check_visibility, visibility_texel, visibility_texture, visibility_threshold,
};
use proptest::prelude::*;

use crate::harness::{Probe, Word, assert_twin, floats, run_with, words};

const GLSL: SourceLanguage = SourceLanguage::Glsl(naga::ShaderStage::Compute);

fn sample(c: f32, id: u32, depth: f32) -> LodSample {
    LodSample {
        color: Vec4::new(c, 1.0 - c, 0.25, 1.0),
        id,
        depth,
    }
}

/// (newer, older) pairs: the paper's three cases, ties, big ids, sky.
pub(crate) fn combine_cases() -> Vec<(LodSample, LodSample)> {
    vec![
        (sample(0.9, 0, 0.5), sample(0.1, 0, 0.2)), // 1. both n-instances: newer, even if older is closer
        (sample(0.9, 5, 0.5), sample(0.1, 0, 0.2)), // 2. t vs n: older closer -> older
        (sample(0.9, 5, 0.2), sample(0.1, 0, 0.5)), // 2. t vs n: newer closer -> newer
        (sample(0.9, 0, 0.5), sample(0.1, 9, 0.3)), // 2. n vs t: older closer
        (sample(0.9, 5, 0.6), sample(0.1, 9, 0.3)), // 2. two different t-instances
        (sample(0.9, 5, 0.5), sample(0.1, 5, 0.2)), // 3. same t-instance: average, no depth test
        (sample(0.9, 70_000, 0.1), sample(0.3, 70_000, 0.9)), // 3. id above 65,535
        (sample(0.9, 70_000, 0.4), sample(0.3, 70_001, 0.3)), // adjacent big ids are distinct
        (sample(0.9, 7, 0.4), sample(0.1, 0, 0.4)), // depth tie: newer
        (sample(0.9, 0, 1.0), sample(0.1, 7, 1.0)), // sky (far plane) on both
        (sample(0.9, u32::MAX, 0.5), sample(0.1, u32::MAX, 0.5)),
    ]
}

pub(crate) fn combine_inputs(cases: &[(LodSample, LodSample)]) -> Vec<u32> {
    cases
        .iter()
        .flat_map(|(n, o)| {
            let mut w = words(&n.color.to_array());
            w.extend([n.id, n.depth.to_bits()]);
            w.extend(words(&o.color.to_array()));
            w.extend([o.id, o.depth.to_bits()]);
            w
        })
        .collect()
}

/// The WGSL probe of `combine_samples` over [`combine_inputs`] (12 words in, a color out).
pub(crate) const COMBINE_PROBE: Probe<'static> = Probe {
    header: "#import lodkit::combine::{LodSample, combine_samples}",
    body: COMBINE_WGSL,
    inputs: 12,
    outputs: 4,
    texture: None,
    rgba: &[],
    urgba: &[],
};

const COMBINE_WGSL: &str = "let newer = LodSample(vec4<f32>(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u)), inp_u(4u), inp_f(5u));
    let older = LodSample(vec4<f32>(inp_f(6u), inp_f(7u), inp_f(8u), inp_f(9u)), inp_u(10u), inp_f(11u));
    let c = combine_samples(newer, older);
    out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);";

const COMBINE_GLSL: &str = "lodkit_LodSample newer = lodkit_LodSample(vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u)), inp_u(4u), inp_f(5u));
    lodkit_LodSample older = lodkit_LodSample(vec4(inp_f(6u), inp_f(7u), inp_f(8u), inp_f(9u)), inp_u(10u), inp_f(11u));
    vec4 c = lodkit_combine_samples(newer, older);
    out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);";

#[test]
fn combine_samples_twins_match_on_hand_derived_cases() {
    let gpu = lodkit_test_gpu!(device);
    let cases = combine_cases();
    let inputs = combine_inputs(&cases);
    for (convention, defs) in [
        (DepthConvention::Standard, &[][..]),
        (DepthConvention::Reversed, &["LODKIT_REVERSE_Z"][..]),
    ] {
        let want: Vec<f32> = cases
            .iter()
            .flat_map(|(n, o)| combine_samples(*n, *o, convention).to_array())
            .collect();
        for (language, header, body) in [
            (
                SourceLanguage::Wgsl,
                "#import lodkit::combine::{LodSample, combine_samples}",
                COMBINE_WGSL,
            ),
            (GLSL, "#include \"lodkit/combine.glsl\"", COMBINE_GLSL),
        ] {
            let probe = Probe {
                header,
                body,
                inputs: 12,
                outputs: 4,
                texture: None,
                rgba: &[],
                urgba: &[],
            };
            let got = floats(&run_with(gpu, &probe, &inputs, language, defs));
            assert_eq!(got, want, "{language:?} {convention:?}");
        }
    }
    // The hand-derived expectations themselves (independent of the twins).
    let c = |i: usize| combine_samples(cases[i].0, cases[i].1, DepthConvention::Standard);
    assert_eq!(c(0), cases[0].0.color, "case 1: newer");
    assert_eq!(c(1), cases[1].1.color, "case 2: closer (older)");
    assert_eq!(c(2), cases[2].0.color, "case 2: closer (newer)");
    assert_eq!(
        c(5),
        0.5 * (cases[5].0.color + cases[5].1.color),
        "case 3: average"
    );
    assert_eq!(
        c(6),
        0.5 * (cases[6].0.color + cases[6].1.color),
        "id > 65535 stays exact"
    );
    assert_eq!(
        c(7),
        cases[7].1.color,
        "70000 and 70001 are different instances"
    );
    assert_eq!(c(8), cases[8].0.color, "tie keeps the newer");
    let r = |i: usize| combine_samples(cases[i].0, cases[i].1, DepthConvention::Reversed);
    assert_eq!(
        r(1),
        cases[1].0.color,
        "reversed Z: the larger depth is closer"
    );
}

struct Camera {
    view: Mat4,
    proj: Mat4,
}

fn reproject_cases() -> Vec<(Mat4, Vec2, f32)> {
    let std_proj = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.1, 100.0);
    let rev_inf = glam::camera::rh::proj::directx::perspective_infinite_reverse(1.0, 1.5, 0.1);
    let at = |eye: Vec3, proj| Camera {
        view: glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y),
        proj,
    };
    let pairs = [
        (
            at(Vec3::new(0.0, 0.0, 5.0), std_proj),
            at(Vec3::new(0.0, 0.0, 5.0), std_proj),
        ), // still
        (
            at(Vec3::new(0.3, 0.1, 5.0), std_proj),
            at(Vec3::new(0.0, 0.0, 5.0), std_proj),
        ), // moved
        (
            at(Vec3::new(4.0, 0.0, 3.0), std_proj),
            at(Vec3::new(-4.0, 0.0, 3.0), std_proj),
        ), // large turn
        (
            at(Vec3::new(0.2, 0.0, 5.0), rev_inf),
            at(Vec3::new(0.0, 0.0, 5.0), rev_inf),
        ), // reversed-Z, infinite
    ];
    let mut cases = Vec::new();
    for (new, old) in &pairs {
        let m = new_to_old_matrix(&new.view, &new.proj, &old.view, &old.proj);
        for (uv, depth) in [
            (Vec2::new(0.5, 0.5), 0.95),
            (Vec2::new(0.1, 0.8), 0.9),
            (Vec2::new(0.99, 0.02), 0.5),
            (Vec2::new(0.0, 0.0), 0.99),
        ] {
            cases.push((m, uv, depth));
        }
    }
    // Sky pixels: far plane (1.0 standard) and infinity (0.0 reversed infinite).
    let (new, old) = &pairs[1];
    cases.push((
        new_to_old_matrix(&new.view, &new.proj, &old.view, &old.proj),
        Vec2::new(0.4, 0.6),
        1.0,
    ));
    let (new, old) = &pairs[3];
    cases.push((
        new_to_old_matrix(&new.view, &new.proj, &old.view, &old.proj),
        Vec2::new(0.4, 0.6),
        0.0,
    ));
    // A pixel that lands behind the older camera: it looked the other way.
    let new = at(Vec3::new(0.0, 0.0, 5.0), std_proj);
    let away = glam::camera::rh::view::look_at_mat4(
        Vec3::new(0.0, 0.0, 4.5),
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::Y,
    );
    cases.push((
        new_to_old_matrix(&new.view, &new.proj, &away, &std_proj),
        Vec2::new(0.5, 0.5),
        0.9,
    ));
    // A pixel at the right edge after the camera slid 3 units right: off the older buffer's side.
    let slid = glam::camera::rh::view::look_at_mat4(
        Vec3::new(3.0, 0.0, 5.0),
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::Y,
    );
    let before =
        glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
    cases.push((
        new_to_old_matrix(&slid, &std_proj, &before, &std_proj),
        Vec2::new(0.98, 0.5),
        0.99,
    ));
    cases
}

#[test]
fn reproject_twins_match_including_reversed_z_sky_and_outside() {
    let gpu = lodkit_test_gpu!(device);
    let cases = reproject_cases();
    // The refinement looks for the surface at new depth 0.97 on the same ray, given its old depth.
    let old_depth = |m: &Mat4, uv: Vec2| reproject(uv, 0.97, m).z;
    let inputs: Vec<u32> = cases
        .iter()
        .flat_map(|(m, uv, d)| {
            let mut w = words(&m.to_cols_array());
            w.extend(words(&[uv.x, uv.y, *d, old_depth(m, *uv)]));
            w
        })
        .collect();
    let want: Vec<Vec3> = cases
        .iter()
        .map(|(m, uv, d)| reproject(*uv, *d, m))
        .collect();
    let refined: Vec<Vec3> = cases
        .iter()
        .map(|(m, uv, d)| reproject_refine(reproject_base(*uv, m), *d, old_depth(m, *uv), m))
        .collect();
    let wgsl_body = "let m = mat4x4<f32>(vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u)), vec4(inp_f(4u), inp_f(5u), inp_f(6u), inp_f(7u)),
                                  vec4(inp_f(8u), inp_f(9u), inp_f(10u), inp_f(11u)), vec4(inp_f(12u), inp_f(13u), inp_f(14u), inp_f(15u)));
        let r = reproject(vec2(inp_f(16u), inp_f(17u)), inp_f(18u), m);
        out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_u(3u, u32(in_viewport(r.xy)));
        let q = reproject_refine(reproject_base(vec2(inp_f(16u), inp_f(17u)), m), inp_f(18u), inp_f(19u), m);
        out_f(4u, q.x); out_f(5u, q.y); out_f(6u, q.z);";
    let glsl_body = "mat4 m = mat4(vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u)), vec4(inp_f(4u), inp_f(5u), inp_f(6u), inp_f(7u)),
                           vec4(inp_f(8u), inp_f(9u), inp_f(10u), inp_f(11u)), vec4(inp_f(12u), inp_f(13u), inp_f(14u), inp_f(15u)));
        vec3 r = lodkit_reproject(vec2(inp_f(16u), inp_f(17u)), inp_f(18u), m);
        out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_u(3u, uint(lodkit_in_viewport(r.xy)));
        vec3 q = lodkit_reproject_refine(lodkit_reproject_base(vec2(inp_f(16u), inp_f(17u)), m), inp_f(18u), inp_f(19u), m);
        out_f(4u, q.x); out_f(5u, q.y); out_f(6u, q.z);";
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::reproject::{reproject, reproject_base, reproject_refine, in_viewport}",
            wgsl_body,
        ),
        (GLSL, "#include \"lodkit/reproject.glsl\"", glsl_body),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 20,
            outputs: 7,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        for (i, (g, (w, q))) in got.chunks(7).zip(want.iter().zip(&refined)).enumerate() {
            let gv = Vec3::from_slice(&floats(&g[..3]));
            assert!(
                (gv - *w).abs().max_element() <= 1e-4 * w.abs().max_element().max(1.0),
                "{language:?} case {i}: {gv} vs {w}"
            );
            let gq = Vec3::from_slice(&floats(&g[4..7]));
            assert!(
                (gq - *q).abs().max_element() <= 1e-3 * q.abs().max_element().max(1.0),
                "{language:?} case {i}: refined {gq} vs {q}"
            );
            assert_eq!(
                g[3] == 1,
                in_viewport(w.truncate()),
                "{language:?} case {i}: in_viewport"
            );
        }
    }
    // Hand-derived: refining finds the surface at new depth 0.97 on every ray in front of the
    // older camera; a still camera maps every pixel to itself; the sky stays finite; the turned
    // camera puts the point outside.
    for (i, ((m, uv, _), q)) in cases.iter().zip(&refined).enumerate() {
        let at = reproject(*uv, 0.97, m);
        if in_viewport(at.truncate()) {
            assert!(
                (*q - at).abs().max_element() < 1e-3,
                "case {i}: {q} vs {at}"
            );
        }
    }
    let still = &cases[0];
    assert!(
        (reproject(still.1, still.2, &still.0) - Vec3::new(0.5, 0.5, 0.95))
            .abs()
            .max_element()
            < 1e-5
    );
    assert!(
        want.iter().all(|w| w.is_finite()),
        "sky pixels must reproject to finite positions"
    );
    let n = want.len();
    assert!(
        in_viewport(want[n - 3].truncate()),
        "sky at infinity stays on screen after a small move"
    );
    assert_eq!(
        want[n - 2].truncate(),
        Vec2::splat(-1.0),
        "a point behind the older camera is flagged"
    );
    assert!(
        !in_viewport(want[n - 1].truncate()),
        "the slide moves the edge pixel out of the older view"
    );
}

#[test]
fn visibility_twins_match_with_a_real_texture() {
    let gpu = lodkit_test_gpu!();
    let tex = visibility_texture(VisibilityPattern::BlueNoise, 64, 5);
    let points: Vec<Vec3> = lodkit::noise::white_noise(3 * 200, 9)
        .chunks(3)
        .map(|c| Vec3::new(c[0] * 4.0 - 2.0, c[1] * 4.0 - 2.0, c[2] * 4.0 - 2.0))
        .collect();
    let taus = [0.0f32, 0.1, 0.5, 0.9, 1.0];
    let inputs: Vec<u32> = points
        .iter()
        .flat_map(|p| words(&[p.x, p.y, p.z]))
        .collect();
    let want: Vec<u32> = points
        .iter()
        .flat_map(|p| {
            let t = visibility_texel(UVec2::splat(64), *p);
            let keeps = taus.iter().fold(0u32, |m, &tau| {
                (m << 1) | u32::from(check_visibility(&tex, *p, tau))
            });
            [t.x, t.y, keeps, visibility_threshold(0.3, true).to_bits()]
        })
        .collect();
    let wgsl_body = "let p = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
        let t = visibility_texel(vec2<u32>(64u), p);
        var keeps = 0u;
        for (var i = 0u; i < 5u; i++) {
            let tau = array<f32, 5>(0.0, 0.1, 0.5, 0.9, 1.0)[i];
            keeps = (keeps << 1u) | u32(check_visibility(probe_tex, p, tau));
        }
        out_u(0u, t.x); out_u(1u, t.y); out_u(2u, keeps); out_f(3u, visibility_threshold(0.3, true));";
    let glsl_body = "vec3 p = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
        uvec2 t = lodkit_visibility_texel(uvec2(64u), p);
        float taus[5] = float[5](0.0, 0.1, 0.5, 0.9, 1.0);
        uint keeps = 0u;
        for (uint i = 0u; i < 5u; i++) {
            keeps = (keeps << 1u) | uint(lodkit_check_visibility(sampler2D(probe_tex, probe_sampler), p, taus[i]));
        }
        out_u(0u, t.x); out_u(1u, t.y); out_u(2u, keeps); out_f(3u, lodkit_visibility_threshold(0.3, true));";
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::visibility::{visibility_texel, check_visibility, visibility_threshold}",
            wgsl_body,
        ),
        (GLSL, "#include \"lodkit/visibility.glsl\"", glsl_body),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 3,
            outputs: 4,
            texture: Some((64, &tex.texels)),
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        // Texel and flags exact; the threshold (unpopping_alpha: clamp, 2 x s, min, all
        // correctly rounded) equal as a float.
        let kinds = [Word::Exact, Word::Exact, Word::Exact, Word::Float(0.0)];
        assert_twin(&got, &want, &kinds, &format!("{language:?} visibility"));
    }
}

#[test]
fn visibility_textures_are_valid_and_blue_noise_is_blue() {
    for pattern in [
        VisibilityPattern::WhiteNoise,
        VisibilityPattern::BlueNoise,
        VisibilityPattern::Radial,
    ] {
        let t = visibility_texture(pattern, 64, 1);
        assert_eq!(t.texels.len(), 64 * 64);
        assert!(
            t.texels.iter().all(|&v| v > 0.0 && v < 1.0),
            "{pattern:?}: texels must lie in (0, 1)"
        );
        assert_eq!(
            t,
            visibility_texture(pattern, 64, 1),
            "{pattern:?} is deterministic"
        );
    }
    let low =
        |s: &[f32]| s[..4].iter().sum::<f32>() / 4.0 / (s.iter().sum::<f32>() / s.len() as f32);
    let blue = lodkit::noise::radial_power_spectrum(
        &visibility_texture(VisibilityPattern::BlueNoise, 64, 1).texels,
        64,
    );
    let white = lodkit::noise::radial_power_spectrum(
        &visibility_texture(VisibilityPattern::WhiteNoise, 64, 1).texels,
        64,
    );
    let (b, w) = (low(&blue), low(&white));
    crate::harness::say(&format!(
        "64x64 visibility textures, low-frequency power / mean: blue {b:.4}, white {w:.4}"
    ));
    assert!(b < 0.1 * w, "blue {b} vs white {w}");
}

#[test]
fn schedule_ends_and_ids_are_quarantined() {
    let mut s = TransitionScheduler::new();
    let a = s.insert(0);
    s.begin_transition(a, 1, Drive::Time { seconds: 0.1 })
        .unwrap();
    let id = s.draw(a).unwrap().id;
    assert_ne!(id, 0);
    for _ in 0..4 {
        s.advance(0.05);
    }
    assert!(!s.in_transition(a));
    assert_eq!(s.draw(a).unwrap().lod, 1);
    // Right after release, a new transition gets a fresh id, not the released one.
    let b = s.insert(0);
    s.begin_transition(b, 1, Drive::Progress).unwrap();
    assert_ne!(s.draw(b).unwrap().id, id);
    assert!(
        s.begin_transition(b, 2, Drive::Progress).is_err(),
        "already in transition"
    );
    assert!(
        s.begin_transition(a, 0, Drive::Time { seconds: f32::NAN })
            .is_err()
    );
    s.remove(b).unwrap();
    assert!(s.draw(b).is_err(), "stale key");
    // Default is the same as new(): ids start at 1.
    let mut d = TransitionScheduler::default();
    let k = d.insert(0);
    d.begin_transition(k, 1, Drive::Time { seconds: 1.0 })
        .unwrap();
    assert_eq!(d.draw(k).unwrap().id, 1);
    // set_progress leaves time-driven transitions alone.
    d.set_progress(k, 0.9).unwrap();
    assert_eq!(d.draw(k).unwrap().progress, 0.0);
}

proptest! {
    #[test]
    fn tau_schedule_properties(p in 0.0f32..=1.0, q in 0.0f32..=1.0) {
        let (lo, hi) = if p <= q { (p, q) } else { (q, p) };
        prop_assert!(visibility_threshold(lo, true) <= visibility_threshold(hi, true), "incoming non-decreasing");
        prop_assert!(visibility_threshold(lo, false) >= visibility_threshold(hi, false), "outgoing non-increasing");
        prop_assert_eq!((visibility_threshold(0.5, true), visibility_threshold(0.5, false)), (1.0, 1.0));
        prop_assert_eq!((visibility_threshold(0.0, true), visibility_threshold(0.0, false)), (0.0, 1.0));
        prop_assert_eq!((visibility_threshold(1.0, true), visibility_threshold(1.0, false)), (1.0, 0.0));
        // With texels in (0, 1), tau 0 keeps nothing and tau 1 everything.
        let tex = visibility_texture(VisibilityPattern::WhiteNoise, 8, 3);
        prop_assert!(tex.texels.iter().all(|&v| v > 0.0 && v < 1.0));
    }

    #[test]
    fn ids_are_never_reused_while_live(ops in prop::collection::vec((0u8..4, 0usize..8, 0.0f32..0.3), 1..200)) {
        let mut s = TransitionScheduler::new();
        let keys: Vec<_> = (0..8).map(|_| s.insert(0)).collect();
        let mut released_at: std::collections::HashMap<u32, u64> = Default::default();
        for (op, k, dt) in ops {
            let key = keys[k];
            match op {
                0 => { let _ = s.begin_transition(key, 1 + (k % 2) as u8, Drive::Time { seconds: 0.2 }); }
                1 => { let _ = s.begin_transition(key, 0, Drive::Progress); }
                2 => { let _ = s.set_progress(key, dt * 4.0); }
                _ => {
                    let before = s.live_ids();
                    s.advance(dt);
                    let after = s.live_ids();
                    for id in before.iter().filter(|id| !after.contains(id)) {
                        released_at.insert(*id, s.frame());
                    }
                }
            }
            let live = s.live_ids();
            let mut sorted = live.clone();
            sorted.sort();
            sorted.dedup();
            prop_assert_eq!(sorted.len(), live.len(), "two live t-instances share an id");
            prop_assert!(!live.contains(&0));
            for id in &live {
                if let Some(&at) = released_at.get(id) {
                    prop_assert!(s.frame() >= at + ID_QUARANTINE_FRAMES, "id {} reused {} frames after release", id, s.frame() - at);
                }
            }
        }
    }
}

#[test]
fn no_history_matrix_sends_every_pixel_to_the_newer_buffer() {
    let m = lodkit::gpu::frame_sequential::CombinePass::NO_HISTORY;
    for (uv, d) in [
        (Vec2::new(0.5, 0.5), 0.5),
        (Vec2::ZERO, 0.0),
        (Vec2::ONE, 1.0),
    ] {
        assert!(!in_viewport(reproject(uv, d, &m).truncate()));
    }
}

proptest! {
    /// Whatever frame a transition begins on, its first frame draws the outgoing LOD whole (tau
    /// 1 under Fig. 2's schedule, -1, the inverted pattern at threshold 1, under the
    /// complementary one) and the LODs alternate from there.
    #[test]
    fn transitions_alternate_with_their_own_phase(start in 0u64..9, frames in 1usize..12, paper: bool) {
        let (schedule, whole) = if paper { (Schedule::Paper, 1.0) } else { (Schedule::Complementary, -1.0) };
        let mut s = TransitionScheduler::with_schedule(schedule);
        let key = s.insert(0);
        for _ in 0..start {
            s.advance(1.0 / 60.0);
        }
        s.begin_transition(key, 1, Drive::Time { seconds: 10.0 }).unwrap();
        let first = s.draw(key).unwrap();
        prop_assert!(!first.incoming && first.lod == 0 && first.tau == whole, "{first:?}");
        for k in 1..frames {
            s.advance(1.0 / 60.0);
            let d = s.draw(key).unwrap();
            prop_assert_eq!(d.incoming, k % 2 == 1);
            prop_assert_eq!(d.lod, u8::from(d.incoming));
        }
    }
}

/// The frame a transition reaches progress 1 draws the incoming LOD whole under both schedules,
/// even where the phase would draw the outgoing one, which is shown nowhere by then.
#[test]
fn the_last_frame_draws_the_incoming_lod_whole() {
    for schedule in [Schedule::Paper, Schedule::Complementary] {
        let mut s = TransitionScheduler::with_schedule(schedule);
        let key = s.insert(0);
        s.begin_transition(key, 1, Drive::Progress).unwrap();
        for (frame, progress) in [(1, 0.4), (2, 1.0)] {
            s.advance(1.0 / 60.0);
            s.set_progress(key, progress).unwrap();
            let d = s.draw(key).unwrap();
            // Frame 1 is the incoming phase; frame 2 the outgoing one, but at progress 1.
            assert!(
                d.incoming && d.lod == 1,
                "{schedule:?} frame {frame}: {d:?}"
            );
        }
        let last = s.draw(key).unwrap();
        assert_eq!((last.tau, last.progress), (1.0, 1.0), "{schedule:?}");
        s.advance(1.0 / 60.0);
        assert!(!s.in_transition(key));
    }
}

proptest! {
    /// With a steady frame time, the threshold a LOD is drawn with for the next frame is exactly
    /// the one it has there, under both schedules, so the older buffer is shown as the frame
    /// displayed wants it.
    #[test]
    fn tau_next_is_the_next_frames_tau_at_a_steady_frame_time(
        seconds in 0.05f32..2.0, dt in 0.001f32..0.1, complementary: bool,
    ) {
        let schedule = if complementary { Schedule::Complementary } else { Schedule::Paper };
        let mut s = TransitionScheduler::with_schedule(schedule);
        let key = s.insert(0);
        s.advance(dt);
        s.begin_transition(key, 1, Drive::Time { seconds }).unwrap();
        let mut draw = s.draw(key).unwrap();
        while s.in_transition(key) {
            s.advance(dt);
            let Ok(next) = s.draw(key) else { break };
            if !s.in_transition(key) {
                break;
            }
            prop_assert_eq!(draw.tau_next, schedule.threshold(next.progress, draw.incoming));
            draw = next;
        }
    }
}
