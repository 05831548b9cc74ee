//! The combine's read with the older-level depth pass (`combine_read_level_depth`, the default
//! route), WGSL and GLSL on the GPU against the Rust twin, on a hand-made pair of LOD buffers
//! whose answers are known:
//! - a pixel showing an n-instance in front of the older level the depth pass holds there takes
//!   no older read, though last frame's picture has that level in front (it moved behind);
//! - a pixel showing a t-instance whose depth pass holds another t-instance's older level (the
//!   nearest older level there) reads that one, not its own level's neighbouring texel;
//! - where the pixel's object motion (its newer level's) sends the read off the level, the
//!   level is read where the camera alone puts it;
//! - where no texel of the level lies near (drawn as an n-instance on its transition's first
//!   frame), no older read: the newer color, not what the read holds;
//! - with every t-instance in the depth pass (`COMBINE_ONLY_DEPTH_PASS`), a pixel showing an
//!   n-instance where the pass drew no level reads nothing older (the estimate would show last
//!   frame's level of an object whose transition has just ended, where it lay nearer).

use glam::{UVec2, Vec2, Vec4};
use lodkit::combine::{DepthConvention, LodImage, combine_uv};
use lodkit::combine_coverage::{
    CombineData, CombineNewer, DepthPassFrame, OlderDepth, combine_new_to_old, combine_pixel,
    combine_read_level_depth,
};
use lodkit::lod_buffer::lod_buffer_word;
use lodkit::reproject::reproject;

use crate::harness::{
    COMBINE_COVERAGE_GLSL, Probe, Word, assert_twin, floats, run_on, twin_runs, words,
};

const W: u32 = 10;
const H: u32 = 6;
/// Two t-instances whose older levels the depth pass holds.
const A: u32 = 2;
const B: u32 = 4;
/// A t-instance of the older frame whose transition has ended (no record this frame).
const ENDED: u32 = 6;
/// Output words per case.
const OUT: usize = 11;

/// One pixel of the newer frame and the depth pass.
struct Case {
    px: UVec2,
    word: u32,
    depth: f32,
    motion: Vec2,
    level: f32,
}

fn cases() -> Vec<Case> {
    let hidden = |id| lod_buffer_word(id, 2); // shown next frame only
    vec![
        // An n-instance at 0.5 in front of A's older level (depth pass 0.6); last frame A was
        // at 0.45 there, in front.
        Case {
            px: UVec2::new(1, 1),
            word: lod_buffer_word(0, 3),
            depth: 0.5,
            motion: Vec2::ZERO,
            level: 0.6,
        },
        // A drawn now, not shown; the depth pass holds B's older level (0.55), which the older
        // buffer has at the pixel, A's at the texel beside it.
        Case {
            px: UVec2::new(4, 1),
            word: hidden(A),
            depth: 0.5,
            motion: Vec2::ZERO,
            level: 0.55,
        },
        // A drawn now, not shown, its newer level's motion 3 texels right, onto background;
        // A's older level lies where the camera alone puts the pixel.
        Case {
            px: UVec2::new(2, 4),
            word: hidden(A),
            depth: 0.5,
            motion: Vec2::new(3.0 / W as f32, 0.0),
            level: 0.5,
        },
        // A drawn now, not shown, its older level drawn last frame as an n-instance.
        Case {
            px: UVec2::new(8, 4),
            word: hidden(A),
            depth: 0.5,
            motion: Vec2::ZERO,
            level: 0.5,
        },
        // An n-instance where the depth pass drew nothing; last frame's texel there holds, a
        // little nearer, a t-instance whose transition has ended (no record: now an n-instance).
        Case {
            px: UVec2::new(6, 2),
            word: lod_buffer_word(0, 3),
            depth: 0.7,
            motion: Vec2::ZERO,
            level: 1.0,
        },
    ]
}

/// The older frame: background (depth 1) but for the texels the cases name.
fn older() -> LodImage {
    let n = (W * H) as usize;
    let noise = lodkit::noise::white_noise(3 * n, 7);
    let mut image = LodImage {
        width: W,
        height: H,
        colors: (0..n)
            .map(|i| Vec4::new(noise[i], noise[n + i], noise[2 * n + i], 1.0))
            .collect(),
        ids: vec![0; n],
        depths: vec![1.0; n],
        flags: vec![3; n],
        motion: Vec::new(),
    };
    let mut set = |x: u32, y: u32, id: u32, depth: f32| {
        let i = (y * W + x) as usize;
        image.ids[i] = id;
        image.depths[i] = depth;
    };
    set(1, 1, A, 0.45);
    set(4, 1, B, 0.55);
    set(3, 1, A, 0.5);
    set(2, 4, A, 0.5);
    set(6, 2, ENDED, 0.69);
    for y in 3..=5 {
        for x in 7..=9 {
            set(x, y, 0, 0.5);
        }
    }
    image
}

fn data() -> CombineData {
    let objects = [A, B].map(|id| OlderDepth {
        id,
        new_to_old: None,
        older_tau: None,
    });
    CombineData::depth_pass(&DepthPassFrame {
        objects: &objects,
        ..Default::default()
    })
    .unwrap()
}

fn newer(c: &Case, color: Vec4) -> CombineNewer {
    CombineNewer {
        color,
        word: c.word,
        depth: c.depth,
        motion: c.motion,
        pattern: 0.5,
        level_depth: c.level,
    }
}

/// The newer color of case `k`.
fn newer_color(k: usize) -> Vec4 {
    Vec4::new(0.1 * k as f32, 0.9, 0.2, 1.0)
}

fn twin_words(older: &LodImage, data: &CombineData) -> Vec<u32> {
    let size = UVec2::new(W, H);
    cases()
        .iter()
        .enumerate()
        .flat_map(|(k, c)| {
            let n = newer(c, newer_color(k));
            let std = DepthConvention::Standard;
            let color = combine_pixel(&n, c.px, older, &data.texels, std).unwrap();
            let id = lodkit::lod_buffer::lod_buffer_id(c.word);
            let uv = combine_uv(c.px, size);
            let old = reproject(uv, c.depth, &combine_new_to_old(&data.texels, id));
            let r = combine_read_level_depth(
                older,
                &data.texels,
                c.level,
                id,
                uv,
                c.depth,
                old,
                c.motion,
                std,
            );
            let mut w = words(&color.to_array());
            w.extend([r.texel.x, r.texel.y, u32::from(r.found)]);
            w.extend(words(&r.color.to_array()));
            w
        })
        .collect()
}

/// The hand-made answers: which older texel each case reads, and what it shows.
fn check_known(got: &[u32], older: &LodImage, who: &str) {
    let at = |x: u32, y: u32| older.colors[(y * W + x) as usize];
    let expected: [(Option<UVec2>, Vec4); 5] = [
        (None, newer_color(0)),
        (Some(UVec2::new(4, 1)), at(4, 1)),
        (Some(UVec2::new(2, 4)), at(2, 4)),
        (None, newer_color(3)),
        (None, newer_color(4)),
    ];
    for (k, (read, shown)) in expected.iter().enumerate() {
        let w = &got[k * OUT..(k + 1) * OUT];
        let found = w[6] == 1;
        assert_eq!(found, read.is_some(), "{who}: case {k} found");
        if let Some(t) = read {
            assert_eq!(UVec2::new(w[4], w[5]), *t, "{who}: case {k} texel");
        }
        let color = Vec4::from_slice(&floats(&w[..4]));
        assert!(
            (color - *shown).abs().max_element() <= 1e-6,
            "{who}: case {k} shows {color}, not {shown}"
        );
    }
}

#[test]
fn the_depth_pass_read_gives_the_hand_made_answers() {
    let (older, data) = (older(), data());
    check_known(&twin_words(&older, &data), &older, "Rust twin");
}

#[test]
fn combine_level_depth_twins_match() {
    let gpu = lodkit_test_gpu!();
    let (older, data) = (older(), data());
    let want = twin_words(&older, &data);
    let inputs: Vec<u32> = cases()
        .iter()
        .enumerate()
        .flat_map(|(k, c)| {
            let mut w = vec![c.px.x, c.px.y];
            w.extend(words(&newer_color(k).to_array()));
            w.push(c.word);
            w.extend(words(&[c.depth, c.motion.x, c.motion.y, c.level]));
            w
        })
        .collect();
    let depths: Vec<Vec4> = older.depths.iter().map(|d| Vec4::splat(*d)).collect();
    let ids: Vec<[u32; 4]> = (0..(W * H) as usize)
        .map(|p| [older.word(p), 0, 0, 0])
        .collect();
    let wgsl = format!(
        "let px = vec2(inp_u(0u), inp_u(1u));
        let newer = CombineNewer(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u), vec2(inp_f(8u), inp_f(9u)), 0.5, inp_f(10u));
        let c = combine_pixel(newer, px, probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1);
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);
        let g = lod_buffer_id(newer.word);
        let uv = combine_uv(px, vec2({W}u, {H}u));
        let old = reproject(uv, newer.depth, combine_new_to_old(probe_urgba1, g));
        let r = combine_read_level_depth(probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1, newer.level_depth, g, uv, newer.depth, old, newer.motion);
        out_u(4u, r.texel.x); out_u(5u, r.texel.y); out_u(6u, u32(r.found));
        out_f(7u, r.color.x); out_f(8u, r.color.y); out_f(9u, r.color.z); out_f(10u, r.color.w);"
    );
    let glsl = format!(
        "uvec2 px = uvec2(inp_u(0u), inp_u(1u));
        lodkit_CombineNewer newer = lodkit_CombineNewer(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u), vec2(inp_f(8u), inp_f(9u)), 0.5, inp_f(10u));
        vec4 c = lodkit_combine_pixel(newer, px);
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);
        uint g = lodkit_lod_buffer_id(newer.word);
        vec2 uv = lodkit_combine_uv(px, uvec2({W}u, {H}u));
        vec3 old = lodkit_reproject(uv, newer.depth, lodkit_combine_new_to_old(g));
        lodkit_CombineRead r = lodkit_combine_read_level_depth(newer.level_depth, g, uv, newer.depth, old, newer.motion);
        out_u(4u, r.texel.x); out_u(5u, r.texel.y); out_u(6u, uint(r.found));
        out_f(7u, r.color.x); out_f(8u, r.color.y); out_f(9u, r.color.z); out_f(10u, r.color.w);"
    );
    let wgsl_header = "#import lodkit::combine::combine_uv
#import lodkit::combine_coverage::{CombineNewer, combine_pixel, combine_new_to_old, combine_read_level_depth}
#import lodkit::lod_buffer::lod_buffer_id
#import lodkit::reproject::reproject";
    // Texels and flags exact; colors are texels, or bilinear blends of at most four of one
    // object's texels (weights products of 1 - f and f): 1e-5 covers a few ulps of each.
    let mut kinds = vec![Word::Float(1e-5); 4];
    kinds.extend([Word::Exact; 3]);
    kinds.extend([Word::Float(1e-5); 4]);
    for (route, language, header, body) in
        twin_runs(gpu, (wgsl_header, &wgsl), (COMBINE_COVERAGE_GLSL, &glsl))
    {
        let probe = Probe {
            header,
            body,
            inputs: 11,
            outputs: OUT,
            texture: None,
            rgba: &[(W, H, &older.colors), (W, H, &depths)],
            urgba: &[(W, H, &ids), (data.width, data.height, &data.texels)],
        };
        let got = run_on(gpu, route, &probe, &inputs, language, &[]);
        let who = format!("{route:?} {language:?}");
        check_known(&got, &older, &who);
        assert_twin(
            &got,
            &want,
            &kinds,
            &format!("{who} combine_read_level_depth"),
        );
    }
}
