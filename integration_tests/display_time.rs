//! Display-time visibility of frame-sequential LOD: the flag functions of `lodkit::visibility`,
//! `lodkit::lod_buffer` and `lodkit::combine` and the whole per-pixel `combine_at` on the GPU
//! (WGSL and GLSL twins) against their Rust twins, and whole transitions through the LOD pass and
//! the combine pass, where the share of each LOD must follow its schedule on every frame.

use glam::{Mat4, Vec3, Vec4};
use lodkit::combine::{DepthConvention, LodSample, PixelSource, combine_shown};
use lodkit::frame_sequential::{Drive, InstanceKey, Schedule, TransitionScheduler};
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions, LodBuffers,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::lod_buffer::{
    LOD_BUFFER_MAX_ID, LOD_BUFFER_SHOWN_NEXT, LOD_BUFFER_SHOWN_NOW, lod_buffer_flags,
    lod_buffer_id, lod_buffer_shown, lod_buffer_word,
};
use lodkit::reproject::new_to_old_matrix;
use lodkit::shaders::SourceLanguage;
use lodkit::visibility::{
    VisibilityPattern, check_visibility, visibility_flags, visibility_texture,
    visibility_threshold_complementary,
};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem};
use lodkit_scenes::mesh::{GpuMesh, Mesh};

use crate::harness::{Probe, Word, assert_twin, floats, run_with, say, twin_mismatch, words};

/// Output words of the visibility-flags probe: two flags, two thresholds.
const KINDS: [Word; 4] = [Word::Exact, Word::Exact, Word::Float(0.0), Word::Float(0.0)];

const GLSL: SourceLanguage = SourceLanguage::Glsl(naga::ShaderStage::Compute);

#[test]
fn visibility_flags_twins_match_with_a_real_texture() {
    let gpu = lodkit_test_gpu!();
    let tex = visibility_texture(VisibilityPattern::BlueNoise, 64, 5);
    // (position, tau_now, tau_next, progress): both signs of tau, -0, the ends of a schedule.
    let points: Vec<Vec3> = lodkit::noise::white_noise(3 * 60, 4)
        .chunks(3)
        .map(|c| Vec3::new(c[0] * 4.0 - 2.0, c[1] * 4.0 - 2.0, c[2] * 4.0 - 2.0))
        .collect();
    let taus = [
        (0.3f32, 0.35f32),
        (-0.6, -0.55),
        (1.0, -0.0),
        (-1.0, 0.0),
        (0.5, -0.5),
    ];
    let cases: Vec<(Vec3, f32, f32, f32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (a, b) = taus[i % taus.len()];
            (*p, a, b, (i as f32 * 0.07) % 1.2 - 0.1)
        })
        .collect();
    let inputs: Vec<u32> = cases
        .iter()
        .flat_map(|(p, a, b, q)| words(&[p.x, p.y, p.z, *a, *b, *q]))
        .collect();
    let want: Vec<u32> = cases
        .iter()
        .flat_map(|(p, a, b, q)| {
            [
                visibility_flags(&tex, *p, *a, *b),
                u32::from(check_visibility(&tex, *p, *a)),
                visibility_threshold_complementary(*q, true).to_bits(),
                visibility_threshold_complementary(*q, false).to_bits(),
            ]
        })
        .collect();
    let wgsl = "let p = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
        out_u(0u, visibility_flags(probe_tex, p, inp_f(3u), inp_f(4u)));
        out_u(1u, u32(check_visibility(probe_tex, p, inp_f(3u))));
        out_f(2u, visibility_threshold_complementary(inp_f(5u), true));
        out_f(3u, visibility_threshold_complementary(inp_f(5u), false));";
    let glsl = "vec3 p = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
        out_u(0u, lodkit_visibility_flags(sampler2D(probe_tex, probe_sampler), p, inp_f(3u), inp_f(4u)));
        out_u(1u, uint(lodkit_check_visibility(sampler2D(probe_tex, probe_sampler), p, inp_f(3u))));
        out_f(2u, lodkit_visibility_threshold_complementary(inp_f(5u), true));
        out_f(3u, lodkit_visibility_threshold_complementary(inp_f(5u), false));";
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::visibility::{visibility_flags, check_visibility, visibility_threshold_complementary}",
            wgsl,
        ),
        (GLSL, "#include \"lodkit/visibility.glsl\"", glsl),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 6,
            outputs: 4,
            texture: Some((64, &tex.texels)),
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        // The flags are integers: exact. The thresholds are a clamp, `1 - p` and a negation,
        // each correctly rounded in WGSL as in Rust: equal, with +0 and -0 equal (a zero's sign
        // is not kept by every driver, and `visibility_shown` gives it no meaning).
        assert_twin(
            &got,
            &want,
            &KINDS,
            &format!("{language:?} visibility flags"),
        );
        // The failure class seen on a real GPU, reproduced here: a twin whose zeros carry the
        // other sign (what a driver that drops or keeps the sign gives) still matches, while a
        // twin with a sign flipped on a nonzero threshold does not.
        let flip = |w: &[u32], zeros: bool| -> Vec<u32> {
            w.chunks(4)
                .flat_map(|c| {
                    let f = |x: u32| {
                        let v = f32::from_bits(x);
                        if (v == 0.0) == zeros {
                            (-v).to_bits()
                        } else {
                            x
                        }
                    };
                    [c[0], c[1], f(c[2]), f(c[3])]
                })
                .collect()
        };
        assert!(
            twin_mismatch(&got, &flip(&want, true), &KINDS).is_none(),
            "{language:?}: a zero of the other sign must match"
        );
        assert!(
            twin_mismatch(&got, &flip(&want, false), &KINDS).is_some(),
            "{language:?}: a nonzero threshold of the other sign must not match"
        );
    }
    // Hand-derived: every flag combination occurs, and the complementary thresholds split the
    // texels between the two LODs.
    let seen = want.chunks(4).fold(0u32, |m, w| m | (1 << w[0]));
    assert_eq!(seen, 0b1111, "flags 0..=3 all occur: {seen:b}");
    for v in [0.01f32, 0.3, 0.5, 0.99] {
        for p in [0.0f32, 0.25, 0.5, 1.0] {
            let shown = |incoming| {
                lodkit::visibility::visibility_shown(
                    v,
                    visibility_threshold_complementary(p, incoming),
                )
            };
            assert_ne!(shown(true), shown(false), "v {v} at progress {p}");
        }
    }
}

#[test]
fn lod_buffer_flags_and_combine_shown_twins_match() {
    let gpu = lodkit_test_gpu!(device);
    let sample = |c: f32, id, depth| LodSample {
        color: Vec4::new(c, 1.0 - c, 0.25, 1.0),
        id,
        depth,
    };
    // (id, flags, newer, newer shown, older, older shown)
    let cases = [
        (
            7u32,
            1u32,
            sample(0.9, 7, 0.5),
            true,
            sample(0.1, 7, 0.2),
            false,
        ),
        (7, 2, sample(0.9, 7, 0.5), false, sample(0.1, 7, 0.2), true),
        (0, 0, sample(0.9, 7, 0.5), false, sample(0.1, 7, 0.2), false),
        (
            LOD_BUFFER_MAX_ID,
            3,
            sample(0.9, 5, 0.6),
            true,
            sample(0.1, 0, 0.3),
            true,
        ),
        (
            LOD_BUFFER_MAX_ID + 9,
            0,
            sample(0.9, 0, 0.6),
            true,
            sample(0.1, 9, 0.3),
            false,
        ),
        (
            1 << 20,
            2,
            sample(0.9, 9, 0.2),
            false,
            sample(0.1, 0, 0.3),
            true,
        ),
    ];
    let inputs: Vec<u32> = cases
        .iter()
        .flat_map(|(id, flags, n, ns, o, os)| {
            let mut w = vec![*id, *flags];
            w.extend(words(&n.color.to_array()));
            w.extend([n.id, n.depth.to_bits(), u32::from(*ns)]);
            w.extend(words(&o.color.to_array()));
            w.extend([o.id, o.depth.to_bits(), u32::from(*os)]);
            w
        })
        .collect();
    let want: Vec<u32> = cases
        .iter()
        .flat_map(|(id, flags, n, ns, o, os)| {
            let t = lod_buffer_word(*id, *flags);
            let mut w = vec![
                t,
                lod_buffer_id(t),
                lod_buffer_flags(t),
                u32::from(lod_buffer_shown(t, LOD_BUFFER_SHOWN_NOW)),
                u32::from(lod_buffer_shown(t, LOD_BUFFER_SHOWN_NEXT)),
            ];
            w.extend(words(
                &combine_shown(*n, *ns, *o, *os, DepthConvention::Standard).to_array(),
            ));
            w
        })
        .collect();
    let wgsl = "let t = lod_buffer_output_flags(vec4(0.0), inp_u(0u), inp_u(1u)).id;
        out_u(0u, t); out_u(1u, lod_buffer_id(t)); out_u(2u, lod_buffer_flags(t));
        out_u(3u, u32(lod_buffer_shown(t, LOD_BUFFER_SHOWN_NOW)));
        out_u(4u, u32(lod_buffer_shown(t, LOD_BUFFER_SHOWN_NEXT)));
        let n = LodSample(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u));
        let o = LodSample(vec4(inp_f(9u), inp_f(10u), inp_f(11u), inp_f(12u)), inp_u(13u), inp_f(14u));
        let c = combine_shown(n, inp_u(8u) != 0u, o, inp_u(15u) != 0u);
        out_f(5u, c.x); out_f(6u, c.y); out_f(7u, c.z); out_f(8u, c.w);";
    let glsl = "uint t = lodkit_lod_buffer_output_flags(vec4(0.0), inp_u(0u), inp_u(1u)).id;
        out_u(0u, t); out_u(1u, lodkit_lod_buffer_id(t)); out_u(2u, lodkit_lod_buffer_flags(t));
        out_u(3u, uint(lodkit_lod_buffer_shown(t, LODKIT_LOD_BUFFER_SHOWN_NOW)));
        out_u(4u, uint(lodkit_lod_buffer_shown(t, LODKIT_LOD_BUFFER_SHOWN_NEXT)));
        lodkit_LodSample n = lodkit_LodSample(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u));
        lodkit_LodSample o = lodkit_LodSample(vec4(inp_f(9u), inp_f(10u), inp_f(11u), inp_f(12u)), inp_u(13u), inp_f(14u));
        vec4 c = lodkit_combine_shown(n, inp_u(8u) != 0u, o, inp_u(15u) != 0u);
        out_f(5u, c.x); out_f(6u, c.y); out_f(7u, c.z); out_f(8u, c.w);";
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::lod_buffer::{lod_buffer_output_flags, lod_buffer_id, lod_buffer_flags, lod_buffer_shown, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT}\n#import lodkit::combine::{LodSample, combine_shown}",
            wgsl,
        ),
        (
            GLSL,
            "#include \"lodkit/lod_buffer.glsl\"\n#include \"lodkit/combine.glsl\"",
            glsl,
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 16,
            outputs: 9,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        // Words and flags exact; the color is a sample or 0.5 x (a + b), correctly rounded on
        // both sides: equal, +0 and -0 alike.
        let kinds = [[Word::Exact; 5].as_slice(), &[Word::Float(0.0); 4]].concat();
        assert_twin(
            &got,
            &want,
            &kinds,
            &format!("{language:?} lod buffer flags and combine_shown"),
        );
    }
    // Hand-derived: ids up to 2^30 - 1 survive, the flags sit above them, id 0 is always shown,
    // and a shown sample wins over a hidden one whatever the depths.
    let w: Vec<&[u32]> = want.chunks(9).collect();
    assert_eq!((w[3][1], w[3][2]), (LOD_BUFFER_MAX_ID, 3));
    assert_eq!(w[4][1], 8, "an id past 2^30 - 1 keeps its low 30 bits");
    assert_eq!((w[5][1], w[5][2], w[5][3], w[5][4]), (1 << 20, 2, 0, 1));
    assert_eq!((w[2][3], w[2][4]), (1, 1), "id 0 is shown in both frames");
    let color = |i: usize| Vec4::from_slice(&floats(&w[i][5..9]));
    assert_eq!(color(0), cases[0].2.color, "only the newer is shown");
    assert_eq!(color(1), cases[1].4.color, "only the older is shown");
    assert_eq!(
        color(2),
        0.5 * (cases[2].2.color + cases[2].4.color),
        "neither shown: the paper's rule (same id: average)"
    );
}

#[test]
fn combine_at_twins_match_on_two_lod_images() {
    use glam::UVec2;
    use lodkit::combine::{LodImage, combine_images, combine_ring_texel, combine_search_texel};
    let gpu = lodkit_test_gpu!();
    let (w, h) = (12u32, 10u32);
    let n = (w * h) as usize;
    let noise = lodkit::noise::white_noise(6 * n, 11);
    // Two buffers of a t-instance (id 5, flags of every kind), n-instances and sky, with depths
    // spread over the far part of the range where reprojection moves texels most.
    let image = |k: usize| {
        let r = |i: usize, j: usize| noise[(k * 3 + j) * n + i];
        LodImage {
            width: w,
            height: h,
            colors: (0..n)
                .map(|i| Vec4::new(r(i, 0), r(i, 1), 1.0 - r(i, 0), 1.0))
                .collect(),
            ids: (0..n)
                .map(|i| [0, 5, 5, 9][(r(i, 1) * 4.0) as usize % 4])
                .collect(),
            depths: (0..n)
                .map(|i| {
                    if r(i, 2) > 0.9 {
                        1.0
                    } else {
                        0.9 + 0.09 * r(i, 2)
                    }
                })
                .collect(),
            flags: (0..n).map(|i| (r(i, 2) * 37.0) as u32 % 4).collect(),
            // Object motion of up to two texels either way, none on a third of the pixels.
            motion: (0..n)
                .map(|i| {
                    let m = glam::Vec2::new(r(i, 0) - 0.5, r(i, 1) - 0.5) * 4.0;
                    let still = (i % 3 == 0) as u32 as f32;
                    (1.0 - still) * m / glam::Vec2::new(w as f32, h as f32)
                })
                .collect(),
        }
    };
    let (newer, older) = (image(0), image(1));
    let still = LodImage {
        motion: Vec::new(),
        ..newer.clone()
    };
    let proj = glam::camera::rh::proj::directx::perspective(0.9, w as f32 / h as f32, 0.1, 50.0);
    let eye =
        |x: f32| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 0.2, 3.0), Vec3::ZERO, Vec3::Y);
    let m = new_to_old_matrix(&eye(0.15), &proj, &eye(0.0), &proj);
    let want_still = combine_images(&still, &older, &m, DepthConvention::Standard);
    let want = combine_images(&newer, &older, &m, DepthConvention::Standard);
    let inputs: Vec<u32> = (0..n as u32)
        .flat_map(|p| {
            let mut words = words(&m.to_cols_array());
            words.extend([p % w, p / w]);
            words
        })
        .collect();
    let colors = |i: &LodImage| i.colors.clone();
    let depths = |i: &LodImage| -> Vec<Vec4> { i.depths.iter().map(|d| Vec4::splat(*d)).collect() };
    let words = |i: &LodImage| -> Vec<[u32; 4]> { (0..n).map(|p| [i.word(p), 0, 0, 0]).collect() };
    let (nc, oc) = (colors(&newer), colors(&older));
    let (nd, od) = (depths(&newer), depths(&older));
    let (nw, ow) = (words(&newer), words(&older));
    let motion: Vec<Vec4> = newer
        .motion
        .iter()
        .map(|v| v.extend(0.0).extend(0.0))
        .collect();
    let matrix = "mat4x4<f32>(vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u)), vec4(inp_f(4u), inp_f(5u), inp_f(6u), inp_f(7u)), vec4(inp_f(8u), inp_f(9u), inp_f(10u), inp_f(11u)), vec4(inp_f(12u), inp_f(13u), inp_f(14u), inp_f(15u)))";
    let wgsl = format!(
        "let px = vec2(inp_u(16u), inp_u(17u));
        let c = combine_at(probe_rgba0, probe_urgba0, probe_rgba2, probe_rgba1, probe_urgba1, probe_rgba3, px, {matrix});
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);
        let mo = textureLoad(probe_rgba4, px, 0).xy;
        let d = combine_at_moved(probe_rgba0, probe_urgba0, probe_rgba2, probe_rgba1, probe_urgba1, probe_rgba3, px, {matrix}, mo);
        out_f(4u, d.x); out_f(5u, d.y); out_f(6u, d.z); out_f(7u, d.w);
        let s = combine_search_texel(probe_urgba1, 5u, px, vec2(99u));
        let r = combine_ring_texel(px, vec2({w}u, {h}u), (px.x * 7u + px.y) % 9u);
        out_u(8u, s.x); out_u(9u, s.y); out_u(10u, r.x); out_u(11u, r.y);"
    );
    let glsl = format!(
        "uvec2 px = uvec2(inp_u(16u), inp_u(17u));
        vec4 c = lodkit_combine_at(sampler2D(probe_rgba0, probe_sampler), usampler2D(probe_urgba0, probe_sampler), sampler2D(probe_rgba2, probe_sampler), sampler2D(probe_rgba1, probe_sampler), usampler2D(probe_urgba1, probe_sampler), sampler2D(probe_rgba3, probe_sampler), px, {m});
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);
        vec2 mo = texelFetch(sampler2D(probe_rgba4, probe_sampler), ivec2(px), 0).xy;
        vec4 d = lodkit_combine_at_moved(sampler2D(probe_rgba0, probe_sampler), usampler2D(probe_urgba0, probe_sampler), sampler2D(probe_rgba2, probe_sampler), sampler2D(probe_rgba1, probe_sampler), usampler2D(probe_urgba1, probe_sampler), sampler2D(probe_rgba3, probe_sampler), px, {m}, mo);
        out_f(4u, d.x); out_f(5u, d.y); out_f(6u, d.z); out_f(7u, d.w);
        uvec2 s = lodkit_combine_search_texel(usampler2D(probe_urgba1, probe_sampler), 5u, px, uvec2(99u));
        uvec2 r = lodkit_combine_ring_texel(px, uvec2({w}u, {h}u), (px.x * 7u + px.y) % 9u);
        out_u(8u, s.x); out_u(9u, s.y); out_u(10u, r.x); out_u(11u, r.y);",
        m = matrix.replace("mat4x4<f32>", "mat4")
    );
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::combine::{combine_at, combine_at_moved, combine_search_texel, combine_ring_texel}",
            wgsl.as_str(),
        ),
        (GLSL, "#include \"lodkit/combine.glsl\"", glsl.as_str()),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 18,
            outputs: 12,
            texture: None,
            rgba: &[
                (w, h, &nc),
                (w, h, &oc),
                (w, h, &nd),
                (w, h, &od),
                (w, h, &motion),
            ],
            urgba: &[(w, h, &nw), (w, h, &ow)],
        };
        let got_words = run_with(gpu, &probe, &inputs, language, &[]);
        for (p, g) in got_words.chunks(12).enumerate() {
            let px = UVec2::new(p as u32 % w, p as u32 / w);
            let search = combine_search_texel(&older, 5, px, UVec2::splat(99));
            let ring = combine_ring_texel(px, UVec2::new(w, h), (px.x * 7 + px.y) % 9);
            assert_eq!(
                [g[8], g[9], g[10], g[11]],
                [search.x, search.y, ring.x, ring.y],
                "{language:?} combine_search_texel / combine_ring_texel at pixel {p}"
            );
        }
        let got = floats(&got_words);
        for (half, want, what) in [
            (0, &want_still, "combine_at"),
            (1, &want, "combine_at_moved"),
        ] {
            let mut compared = 0;
            for (p, (g, want)) in got.chunks(12).zip(want).enumerate() {
                if want.on_texel_edge {
                    continue;
                }
                compared += 1;
                let g = Vec4::from_slice(&g[4 * half..4 * half + 4]);
                assert!(
                    (g - want.color).abs().max_element() < 1e-5,
                    "{language:?} {what}, pixel {p}: {g} vs {} ({:?})",
                    want.color,
                    want.source
                );
            }
            assert!(
                compared * 10 > n * 9,
                "{language:?} {what}: only {compared} pixels compared"
            );
        }
    }
    // The motion moves the texel read on most pixels, so the two combines differ.
    let differ = want
        .iter()
        .zip(&want_still)
        .filter(|(a, b)| a.color != b.color)
        .count();
    assert!(
        differ * 4 > n,
        "the motion changed only {differ} of {n} pixels"
    );
    // The search where the moved read misses runs on some pixels and changes what they show.
    // The search finds the t-instance on some pixels. Where the older texel decides the color
    // (older or average), a GPU that had not searched would read the texel it started from, with
    // another random color: those pixels, compared above, prove the GPU found the same texel.
    let searched: Vec<usize> = (0..n).filter(|&p| want[p].searched).collect();
    let decisive = searched
        .iter()
        .filter(|&&p| !want[p].on_texel_edge)
        .filter(|&&p| matches!(want[p].source, PixelSource::Older | PixelSource::Average))
        .count();
    assert!(
        searched.len() * 50 > n && decisive >= 3,
        "the 3x3 search found the t-instance on {} of {n} pixels, {decisive} of them decisive",
        searched.len()
    );
    say(&format!(
        "3x3 search: the t-instance found on {} of {n} pixels, {decisive} where the older texel \
         decides the color",
        searched.len()
    ));
    // The images exercise every rule.
    use lodkit::combine::PixelSource::*;
    for source in [Newer, Older, Average, OutsideOlder] {
        assert!(
            want.iter().any(|p| p.source == source),
            "no pixel combined as {source:?}"
        );
    }
}

/// Frame `f` (at 60 frames a second) of a transition of `key` from LOD 0 to 1 that begins at
/// frame `start` and lasts `frames` frames: progress `(f - start) / frames`, and as the next
/// frame's progress the one `ahead` frames on where given (else the scheduler predicts it).
pub fn step_transition(
    s: &mut TransitionScheduler,
    key: InstanceKey,
    f: u64,
    start: u64,
    frames: u32,
    ahead: Option<u64>,
) {
    if f > 0 {
        s.advance(1.0 / 60.0);
    }
    if f == start {
        s.begin_transition(key, 1, Drive::Progress).unwrap();
    }
    if f >= start {
        let p = |f: u64| ((f - start) as f32 / frames as f32).min(1.0);
        s.set_progress(key, p(f)).unwrap();
        if let Some(ahead) = ahead {
            s.set_next_progress(key, p(f + ahead)).unwrap();
        }
    }
}

/// Blue share b / (r + b) of the object's pixels (LOD 0 pure red, LOD 1 pure blue, so lighting
/// cancels) and the number of object pixels.
pub fn blue_share(pixels: &[u8]) -> (f32, usize) {
    let object: Vec<(f32, f32)> = pixels
        .chunks(4)
        .map(|p| (f32::from(p[0]), f32::from(p[2])))
        .filter(|(r, b)| r + b > 12.0)
        .collect();
    let share = object.iter().map(|(r, b)| b / (r + b)).sum::<f32>() / object.len().max(1) as f32;
    (share, object.len())
}

/// One sphere as both LODs of a t-instance, in red (LOD 0) and blue (LOD 1), so both cover the
/// same pixels with the same visibility texels; the LOD pass and the combine pass for RGBA8 LOD
/// buffers, and a `w` x `w` target the combine writes.
pub struct SphereLods {
    pub renderer: LodBufferRenderer,
    pub combine: CombinePass,
    pub sphere: GpuMesh,
    pub colors: [Vec4; 2],
    pub proj: Mat4,
    pub target: wgpu::Texture,
    pub target_view: wgpu::TextureView,
}

impl SphereLods {
    pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

    pub fn new(gpu: &lodkit::gpu::GpuContext, w: u32) -> Self {
        let format = Self::FORMAT;
        let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 2);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let target =
            lodkit::gpu::resources::texture_2d(gpu, (w, w), format, usage, "combined").unwrap();
        Self {
            renderer: LodBufferRenderer::new(gpu, format, &vis, 1.0).unwrap(),
            combine: CombinePass::new(
                gpu,
                &CombinePassDescriptor {
                    target_format: format,
                    ..Default::default()
                },
            )
            .unwrap(),
            sphere: GpuMesh::new(gpu, &Mesh::sphere(24, 32)).unwrap(),
            colors: [Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 0.0, 1.0, 1.0)],
            proj: glam::camera::rh::proj::directx::perspective(0.9, 1.0, 0.1, 50.0),
            target_view: target.create_view(&Default::default()),
            target,
        }
    }

    /// Renders `item` into buffer `index` of `buffers` seen by `view`, over black, combines it
    /// with the other buffer through `new_to_old` and reads the combined image back.
    pub fn frame(
        &self,
        gpu: &lodkit::gpu::GpuContext,
        buffers: &LodBuffers,
        index: usize,
        view: impl Into<lodkit_scenes::lod_buffer::LodView>,
        item: LodDrawItem,
        new_to_old: Mat4,
    ) -> Vec<u8> {
        let clear = wgpu::Color::BLACK;
        self.renderer
            .render(
                gpu,
                buffers,
                &LodBufferFrame {
                    index,
                    view: view.into(),
                    items: &[item],
                    clear,
                    ..Default::default()
                },
            )
            .unwrap();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let frame = CombineFrame {
            buffers,
            newer: index,
            new_to_old,
            target: &self.target_view,
            regions: CombineRegions::Everywhere,
            coverage: CombineCoverage::Estimated,
        };
        self.combine.record(gpu, &mut encoder, &frame).unwrap();
        gpu.queue.submit([encoder.finish()]);
        read_texture_rgba8(gpu, &self.target).unwrap()
    }
}

#[test]
fn each_lod_is_shown_as_it_is_at_the_frame_displayed() {
    const W: u32 = 64;
    const FRAMES: u32 = 12;
    let gpu = lodkit_test_gpu!();
    let format = SphereLods::FORMAT;
    // The blue (incoming) share of the object is exactly the schedule's, progress p in both.
    let lods = SphereLods::new(gpu, W);
    let proj = lods.proj;
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
    let mut rows = Vec::new();
    for schedule in [Schedule::Paper, Schedule::Complementary] {
        for start in [3u64, 4] {
            let buffers = LodBuffers::new(gpu, W, W, format).unwrap();
            let mut s = TransitionScheduler::with_schedule(schedule);
            let key = s.insert(0);
            let (mut shares, mut coverage) = (Vec::new(), Vec::new());
            for f in 0..start + u64::from(FRAMES) + 2 {
                // One start knows the next frame's progress, the other lets it be predicted.
                let ahead = (start == 3).then_some(1);
                step_transition(&mut s, key, f, start, FRAMES, ahead);
                let d = s.draw(key).unwrap();
                let color = lods.colors[usize::from(d.lod)];
                let item = LodDrawItem::from_draw(&lods.sphere, Mat4::IDENTITY, color, &d);
                let m = if f == 0 {
                    CombinePass::NO_HISTORY
                } else {
                    new_to_old_matrix(&view, &proj, &view, &proj)
                };
                let pixels = lods.frame(gpu, &buffers, s.buffer_index(), proj * view, item, m);
                let (share, covered) = blue_share(&pixels);
                shares.push(share);
                coverage.push(covered);
            }
            let first = coverage[0];
            assert!(first > 1000, "the sphere covers {first} pixels");
            let frames = &shares[start as usize..=(start + u64::from(FRAMES)) as usize];
            for (k, pair) in frames.windows(2).enumerate() {
                assert!(
                    pair[1] > pair[0] + 0.02,
                    "{schedule:?}, start {start}: the incoming share must grow on every frame, \
                     frame {} -> {}: {frames:?}",
                    k,
                    k + 1
                );
            }
            for (k, share) in frames.iter().enumerate() {
                let p = k as f32 / FRAMES as f32;
                assert!(
                    (share - p).abs() < 0.05,
                    "{schedule:?}, start {start}: frame {k} shows {share:.3} of the incoming LOD, \
                     its progress is {p:.3}: {frames:?}"
                );
            }
            assert!(
                coverage.iter().all(|&c| c == first),
                "{schedule:?}, start {start}: the object's coverage changed (see-through or a \
                 hole): {coverage:?}"
            );
            let shown: Vec<String> = frames.iter().map(|s| format!("{s:.3}")).collect();
            rows.push(format!("{schedule:?}, start {start}: {}", shown.join(" ")));
        }
    }
    say(&format!(
        "incoming share per frame of a {FRAMES}-frame transition:\n{}",
        rows.join("\n")
    ));
}
