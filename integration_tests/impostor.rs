//! `lodkit::impostor` on the GPU (WGSL, its WESL form and the GLSL twin, compute and fragment
//! routes) against the Rust twins: the octahedral and hemi maps, frame directions and bases, the
//! frames blended for a view and their weights, and the ray and uv geometry.

use glam::{UVec2, Vec2, Vec3};
use lodkit::impostor::*;

use crate::harness::{Probe, Word, assert_twin, run_on, twin_runs};

/// One case: a direction, a map point, a frame of an `n x n` grid, the shape, a ray and a
/// height.
#[derive(Clone, Copy, Debug)]
struct Case {
    d: Vec3,
    e: Vec2,
    frame: UVec2,
    n: u32,
    hemi: bool,
    origin: Vec3,
    ray: Vec3,
    height: f32,
}

impl Case {
    fn words(&self) -> Vec<u32> {
        let f = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut w = f(&self.d.to_array());
        w.extend(f(&self.e.to_array()));
        w.extend([self.frame.x, self.frame.y, self.n, u32::from(self.hemi)]);
        w.extend(f(&self.origin.to_array()));
        w.extend(f(&self.ray.to_array()));
        w.push(self.height.to_bits());
        w
    }
}

/// The axes and poles (exact zeros in the maps), the horizon, the lower hemisphere, grid
/// corners and edges, then a deterministic spread. Rays run against the frame direction with
/// dot(ray, dir) <= -0.2, where the ray-plane intersection is well conditioned.
fn cases() -> Vec<Case> {
    let mut state = 0x2545_f491_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state as f32 / u32::MAX as f32) * 2.0 - 1.0
    };
    let fixed = [
        Vec3::Y,
        -Vec3::Y,
        Vec3::X,
        -Vec3::X,
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(1.0, 0.0, 1.0).normalize(),
        Vec3::new(0.3, -0.9, 0.1).normalize(),
        Vec3::new(-0.6, 0.05, 0.8).normalize(),
    ];
    let sizes = [2u32, 3, 8, 13];
    let mut out = Vec::new();
    for i in 0..160 {
        let hemi = i % 2 == 1;
        // A hemi impostor is seen from above the horizon (below, every view sits on the rim).
        let up = |v: Vec3| {
            if hemi {
                Vec3::new(v.x, v.y.abs(), v.z)
            } else {
                v
            }
        };
        let d = fixed
            .get(i)
            .copied()
            .unwrap_or_else(|| up(Vec3::new(next(), next(), next())).normalize_or(Vec3::Y));
        let e = Vec2::new(next(), next());
        let n = sizes[i % sizes.len()];
        let frame = UVec2::new(i as u32 % n, (i as u32 / 4) % n);
        let dir = impostor_frame_dir(frame, n, hemi);
        let origin = Vec3::new(next(), next(), next()) * 3.0;
        let mut ray = Vec3::new(next(), next(), next()) - dir * 1.5;
        let along = ray.dot(dir);
        if along > -0.2 {
            ray -= dir * (along + 0.2);
        }
        out.push(Case {
            d,
            e,
            frame,
            n,
            hemi,
            origin,
            ray,
            height: next(),
        });
    }
    out
}

const INPUTS: usize = 16;

const MAPS_WGSL_HEADER: &str = "#import lodkit::impostor::{impostor_octa_encode, impostor_octa_decode, impostor_hemi_encode, impostor_hemi_decode, impostor_frame_dir, impostor_frame_basis}";
const MAPS_WGSL: &str = "let d = vec3<f32>(inp_f(0u), inp_f(1u), inp_f(2u));
    let e = vec2<f32>(inp_f(3u), inp_f(4u));
    let frame = vec2<u32>(inp_u(5u), inp_u(6u));
    let a = impostor_octa_encode(d);
    let b = impostor_octa_decode(e);
    let c = impostor_hemi_encode(d);
    let h = impostor_hemi_decode(e);
    let dir = impostor_frame_dir(frame, inp_u(7u), inp_u(8u) != 0u);
    let m = impostor_frame_basis(dir);
    out_f(0u, a.x); out_f(1u, a.y);
    out_f(2u, b.x); out_f(3u, b.y); out_f(4u, b.z);
    out_f(5u, c.x); out_f(6u, c.y);
    out_f(7u, h.x); out_f(8u, h.y); out_f(9u, h.z);
    out_f(10u, dir.x); out_f(11u, dir.y); out_f(12u, dir.z);
    out_f(13u, m[0].x); out_f(14u, m[0].y); out_f(15u, m[0].z);
    out_f(16u, m[1].x); out_f(17u, m[1].y); out_f(18u, m[1].z);
    out_f(19u, m[2].x); out_f(20u, m[2].y); out_f(21u, m[2].z);";
const MAPS_GLSL_HEADER: &str = "#include \"lodkit/impostor.glsl\"";
const MAPS_GLSL: &str = "vec3 d = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
    vec2 e = vec2(inp_f(3u), inp_f(4u));
    uvec2 frame = uvec2(inp_u(5u), inp_u(6u));
    vec2 a = lodkit_impostor_octa_encode(d);
    vec3 b = lodkit_impostor_octa_decode(e);
    vec2 c = lodkit_impostor_hemi_encode(d);
    vec3 h = lodkit_impostor_hemi_decode(e);
    vec3 dir = lodkit_impostor_frame_dir(frame, inp_u(7u), inp_u(8u) != 0u);
    mat3 m = lodkit_impostor_frame_basis(dir);
    out_f(0u, a.x); out_f(1u, a.y);
    out_f(2u, b.x); out_f(3u, b.y); out_f(4u, b.z);
    out_f(5u, c.x); out_f(6u, c.y);
    out_f(7u, h.x); out_f(8u, h.y); out_f(9u, h.z);
    out_f(10u, dir.x); out_f(11u, dir.y); out_f(12u, dir.z);
    out_f(13u, m[0].x); out_f(14u, m[0].y); out_f(15u, m[0].z);
    out_f(16u, m[1].x); out_f(17u, m[1].y); out_f(18u, m[1].z);
    out_f(19u, m[2].x); out_f(20u, m[2].y); out_f(21u, m[2].z);";

fn maps_want(c: &Case) -> Vec<f32> {
    let dir = impostor_frame_dir(c.frame, c.n, c.hemi);
    let m = impostor_frame_basis(dir);
    let mut w = impostor_octa_encode(c.d).to_array().to_vec();
    w.extend(impostor_octa_decode(c.e).to_array());
    w.extend(impostor_hemi_encode(c.d).to_array());
    w.extend(impostor_hemi_decode(c.e).to_array());
    w.extend(dir.to_array());
    w.extend(m.to_cols_array());
    w
}

/// Every output is at most ~1 in magnitude and comes from a handful of operations each within
/// WGSL's 2.5 ulp (divisions, inverseSqrt: 2 ulp; the rest correctly rounded): ten such steps
/// stay under 3e-6 at magnitude 1 (ulp 1.2e-7); 4e-6 holds them with a margin.
const DIRECTION_TOL: f32 = 4e-6;

#[test]
fn impostor_maps_match_rust_twins() {
    let gpu = lodkit_test_gpu!(device);
    let cases = cases();
    let inputs: Vec<u32> = cases.iter().flat_map(Case::words).collect();
    let want: Vec<u32> = cases.iter().flat_map(maps_want).map(f32::to_bits).collect();
    let kinds = [Word::Float(DIRECTION_TOL); 22];
    // The hand-derived values first, on the Rust twin: +y at the centre, +x at (1, 0), -y in a
    // corner; the hemi map's +x at (1, 1).
    assert_eq!(impostor_octa_encode(Vec3::Y), Vec2::ZERO);
    assert_eq!(impostor_octa_encode(Vec3::X), Vec2::X);
    assert_eq!(impostor_hemi_encode(Vec3::X), Vec2::ONE);
    assert_eq!(impostor_hemi_encode(Vec3::Z), Vec2::new(1.0, -1.0));
    assert_eq!(
        impostor_hemi_encode(-Vec3::Y),
        Vec2::ONE,
        "straight below: the +x horizon"
    );
    for (route, language, header, body) in twin_runs(
        gpu,
        (MAPS_WGSL_HEADER, MAPS_WGSL),
        (MAPS_GLSL_HEADER, MAPS_GLSL),
    ) {
        let probe = Probe {
            header,
            body,
            inputs: INPUTS,
            outputs: 22,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = run_on(gpu, route, &probe, &inputs, language, &[]);
        assert_twin(
            &got,
            &want,
            &kinds,
            &format!("{route:?} {language:?} impostor maps"),
        );
    }
}

const BLEND_WGSL_HEADER: &str = "#import lodkit::impostor::{ImpostorBlend, impostor_blend, impostor_frame_dir, impostor_frame_basis, impostor_ray_at_height, impostor_frame_uv, impostor_atlas_uv}";
const BLEND_WGSL: &str = "let d = vec3<f32>(inp_f(0u), inp_f(1u), inp_f(2u));
    let frame = vec2<u32>(inp_u(5u), inp_u(6u));
    let n = inp_u(7u);
    let hemi = inp_u(8u) != 0u;
    let blend = impostor_blend(d, n, hemi);
    out_u(0u, blend.frames[0].x); out_u(1u, blend.frames[0].y); out_u(2u, blend.frames[1].x); out_u(3u, blend.frames[1].y);
    out_u(4u, blend.frames[2].x); out_u(5u, blend.frames[2].y);
    out_f(6u, blend.weights.x); out_f(7u, blend.weights.y); out_f(8u, blend.weights.z);
    let dir = impostor_frame_dir(frame, n, hemi);
    let p = impostor_ray_at_height(vec3<f32>(inp_f(9u), inp_f(10u), inp_f(11u)), vec3<f32>(inp_f(12u), inp_f(13u), inp_f(14u)), dir, inp_f(15u));
    out_f(9u, p.x); out_f(10u, p.y); out_f(11u, p.z);
    let uv = impostor_frame_uv(impostor_frame_basis(dir), p);
    out_f(12u, uv.x); out_f(13u, uv.y);
    let atlas = impostor_atlas_uv(frame, n, uv);
    out_f(14u, atlas.x); out_f(15u, atlas.y);";
const BLEND_GLSL: &str = "vec3 d = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
    uvec2 frame = uvec2(inp_u(5u), inp_u(6u));
    uint n = inp_u(7u);
    bool hemi = inp_u(8u) != 0u;
    lodkit_ImpostorBlend blend = lodkit_impostor_blend(d, n, hemi);
    out_u(0u, blend.frames[0].x); out_u(1u, blend.frames[0].y); out_u(2u, blend.frames[1].x); out_u(3u, blend.frames[1].y);
    out_u(4u, blend.frames[2].x); out_u(5u, blend.frames[2].y);
    out_f(6u, blend.weights.x); out_f(7u, blend.weights.y); out_f(8u, blend.weights.z);
    vec3 dir = lodkit_impostor_frame_dir(frame, n, hemi);
    vec3 p = lodkit_impostor_ray_at_height(vec3(inp_f(9u), inp_f(10u), inp_f(11u)), vec3(inp_f(12u), inp_f(13u), inp_f(14u)), dir, inp_f(15u));
    out_f(9u, p.x); out_f(10u, p.y); out_f(11u, p.z);
    vec2 uv = lodkit_impostor_frame_uv(lodkit_impostor_frame_basis(dir), p);
    out_f(12u, uv.x); out_f(13u, uv.y);
    vec2 atlas = lodkit_impostor_atlas_uv(frame, n, uv);
    out_f(14u, atlas.x); out_f(15u, atlas.y);";

/// The map point of `d` in grid units and whether it lies within `NEAR` of a cell edge or of
/// the diagonal that splits the cell: there the GPU may pick the neighbouring triangle (the
/// weights are continuous across it, the frame of weight ~0 is not).
fn near_split(d: Vec3, n: u32, hemi: bool) -> bool {
    const NEAR: f32 = 1e-4;
    let last = (n - 1) as f32;
    let g = (impostor_encode(d, hemi) * 0.5 + 0.5).clamp(Vec2::ZERO, Vec2::ONE) * last;
    let f = g - g.floor().min(Vec2::splat(last - 1.0));
    let edge = |x: f32| (x - x.round()).abs() < NEAR;
    edge(g.x) || edge(g.y) || (f.x + f.y - 1.0).abs() < NEAR
}

#[test]
fn impostor_blend_and_rays_match_rust_twins() {
    let gpu = lodkit_test_gpu!(device);
    let cases = cases();
    let inputs: Vec<u32> = cases.iter().flat_map(Case::words).collect();
    let mut want = Vec::new();
    for c in &cases {
        let b = impostor_blend(c.d, c.n, c.hemi);
        want.extend(b.frames.iter().flat_map(|f| [f.x, f.y]));
        want.extend(b.weights.to_array().map(f32::to_bits));
        let dir = impostor_frame_dir(c.frame, c.n, c.hemi);
        let p = impostor_ray_at_height(c.origin, c.ray, dir, c.height);
        let uv = impostor_frame_uv(&impostor_frame_basis(dir), p);
        let atlas = impostor_atlas_uv(c.frame, c.n, uv);
        want.extend(p.to_array().map(f32::to_bits));
        want.extend(uv.to_array().map(f32::to_bits));
        want.extend(atlas.to_array().map(f32::to_bits));
    }
    // Weights: the map point (DIRECTION_TOL) times (n - 1) / 2 <= 6 grid units: 3e-5. The ray
    // point: t = (h - dot(o, dir)) / dot(ray, dir) with |o| <= 3 sqrt(3), dot(ray, dir) <= -0.2,
    // |ray| <= 3.5: |t ray| <= ~110, each term within a few ulp of the direction's error times
    // that: 1e-3 absolute; the uvs halve it.
    let mut kinds = vec![Word::Exact; 6];
    kinds.extend([Word::Float(3e-5); 3]);
    kinds.extend([Word::Float(1e-3); 3]);
    kinds.extend([Word::Float(5e-4); 4]);
    // The blend's triangle is held exactly away from ties only: near a split both sides are
    // right, so there the frames and weights of the GPU's pick are compared through the
    // direction they blend to.
    let ties: Vec<bool> = cases.iter().map(|c| near_split(c.d, c.n, c.hemi)).collect();
    assert!(
        ties.iter().filter(|t| **t).count() <= cases.len() / 10,
        "the cases sit on splits too often to test the blend"
    );
    for (route, language, header, body) in twin_runs(
        gpu,
        (BLEND_WGSL_HEADER, BLEND_WGSL),
        (MAPS_GLSL_HEADER, BLEND_GLSL),
    ) {
        let probe = Probe {
            header,
            body,
            inputs: INPUTS,
            outputs: 16,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = run_on(gpu, route, &probe, &inputs, language, &[]);
        let who = format!("{route:?} {language:?} impostor blend");
        let mut got_fixed = got.clone();
        for (i, c) in cases.iter().enumerate() {
            let g = &got[i * 16..i * 16 + 16];
            let w = &want[i * 16..i * 16 + 16];
            if g[..6] != w[..6] && ties[i] {
                let blended = |v: &[u32]| {
                    (0..3)
                        .map(|k| {
                            impostor_frame_dir(UVec2::new(v[2 * k], v[2 * k + 1]), c.n, c.hemi)
                                * f32::from_bits(v[6 + k])
                        })
                        .sum::<Vec3>()
                };
                let apart = (blended(g) - blended(w)).length();
                assert!(
                    apart < 1e-3,
                    "{who}: case {i} near a split blends {apart} away"
                );
                got_fixed[i * 16..i * 16 + 9].copy_from_slice(&w[..9]);
            }
        }
        assert_twin(&got_fixed, &want, &kinds, &who);
    }
}

#[test]
fn impostor_layout_refuses_what_no_atlas_holds() {
    let good = ImpostorLayout {
        frames: 12,
        frame_size: 64,
        shape: ImpostorShape::Hemi,
        center: [0.0; 3],
        radius: 1.0,
    };
    assert_eq!(good.validate(), Ok(()));
    for (bad, field) in [
        (ImpostorLayout { frames: 1, ..good }, "frames"),
        (
            ImpostorLayout {
                frame_size: 48,
                ..good
            },
            "frame_size",
        ),
        (
            ImpostorLayout {
                frames: 64,
                frame_size: 512,
                ..good
            },
            "frames x frame_size",
        ),
        (
            ImpostorLayout {
                radius: 0.0,
                ..good
            },
            "radius",
        ),
        (
            ImpostorLayout {
                center: [f32::NAN, 0.0, 0.0],
                ..good
            },
            "center",
        ),
    ] {
        match bad.validate() {
            Err(ImpostorError::BadLayout { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{bad:?}: {other:?}"),
        }
    }
}
