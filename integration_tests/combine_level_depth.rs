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
/// Output words per case (the probes': `combine_pixel`'s colour).
const OUT: usize = 4;

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

/// `combine_pixel`'s colour for each case: what the GPU probes compute.
fn twin_words(older: &LodImage, data: &CombineData) -> Vec<u32> {
    cases()
        .iter()
        .enumerate()
        .flat_map(|(k, c)| {
            let n = newer(c, newer_color(k));
            let std = DepthConvention::Standard;
            let color = combine_pixel(&n, c.px, older, &data.texels, std).unwrap();
            words(&color.to_array())
        })
        .collect()
}

/// The hand-made answers: which older texel each case reads (`None`: none, the newer colour
/// shows) and what it shows.
fn expected(older: &LodImage) -> [(Option<UVec2>, Vec4); 5] {
    let at = |x: u32, y: u32| older.colors[(y * W + x) as usize];
    [
        (None, newer_color(0)),
        (Some(UVec2::new(4, 1)), at(4, 1)),
        (Some(UVec2::new(2, 4)), at(2, 4)),
        (None, newer_color(3)),
        (None, newer_color(4)),
    ]
}

/// The colours `got` (OUT words a case) against the hand-made answers.
fn check_shown(got: &[u32], older: &LodImage, who: &str) {
    for (k, (_, shown)) in expected(older).iter().enumerate() {
        let color = Vec4::from_slice(&floats(&got[k * OUT..(k + 1) * OUT]));
        assert!(
            (color - *shown).abs().max_element() <= 1e-6,
            "{who}: case {k} shows {color}, not {shown}"
        );
    }
}

#[test]
fn the_depth_pass_read_gives_the_hand_made_answers() {
    let (older, data) = (older(), data());
    check_shown(&twin_words(&older, &data), &older, "Rust twin");
    // The read itself: the texel each case takes, or none.
    let size = UVec2::new(W, H);
    for (k, (c, (texel, _))) in cases().iter().zip(expected(&older)).enumerate() {
        let id = lodkit::lod_buffer::lod_buffer_id(c.word);
        let uv = combine_uv(c.px, size);
        let old = reproject(uv, c.depth, &combine_new_to_old(&data.texels, id));
        let r = combine_read_level_depth(
            &older,
            &data.texels,
            c.level,
            id,
            uv,
            c.depth,
            old,
            c.motion,
            DepthConvention::Standard,
        );
        assert_eq!(r.found, texel.is_some(), "case {k} found");
        if let Some(t) = texel {
            assert_eq!(r.texel, t, "case {k} texel");
        }
    }
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
    let wgsl = String::from(
        "let px = vec2(inp_u(0u), inp_u(1u));
        let newer = CombineNewer(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u), vec2(inp_f(8u), inp_f(9u)), 0.5, inp_f(10u));
        let c = combine_pixel(newer, px, probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1);
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);"
    );
    let glsl = String::from(
        "uvec2 px = uvec2(inp_u(0u), inp_u(1u));
        lodkit_CombineNewer newer = lodkit_CombineNewer(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u), vec2(inp_f(8u), inp_f(9u)), 0.5, inp_f(10u));
        vec4 c = lodkit_combine_pixel(newer, px);
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);"
    );
    let wgsl_header = "#import lodkit::combine_coverage::{CombineNewer, combine_pixel}";
    // Colors are texels, or bilinear blends of at most four of one object's texels (weights
    // products of 1 - f and f): 1e-5 covers a few ulps of each.
    let kinds = vec![Word::Float(1e-5); OUT];
    // On wgpu's GL backend the GLSL twin reaches the driver through naga's GLSL front end, and
    // llvmpipe's LLVM spends 474 s (measured) compiling that form of the depth-pass read (its
    // scalar-evolution passes over the front end's loop variables); the WGSL form compiles in
    // about a second there. The GLSL twin is held equal on Vulkan's routes; on GL, the WGSL.
    let gl = gpu.adapter.get_info().backend == wgpu::Backend::Gl;
    for (route, language, header, body) in
        twin_runs(gpu, (wgsl_header, &wgsl), (COMBINE_COVERAGE_GLSL, &glsl))
    {
        if gl && !matches!(language, lodkit::shaders::SourceLanguage::Wgsl) {
            continue;
        }
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
        check_shown(&got, &older, &who);
        assert_twin(
            &got,
            &want,
            &kinds,
            &format!("{who} combine_pixel with the depth pass"),
        );
    }
}
