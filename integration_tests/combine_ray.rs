//! The reads along the pixel's ray (`lodkit::combine_coverage::combine_ray_texel`,
//! `combine_read_known`, `combine_behind_texel`) on the GPU, WGSL and GLSL, against the Rust
//! twins, on a hand-made older buffer seen from a camera whose motion moves each depth by another
//! amount (parallax): the texel a read wants lies several texels along the ray's image from where
//! the newer depth reprojects, out of reach of the 3x3 block. A pixel that shows no t-instance
//! reads a level whose silhouette covers it the same way (`combine_read_silhouettes`). The ray
//! search for what lies behind a level passes over levels known by their silhouettes: such a
//! level shows at the pixel only where its silhouette covers it, which `combine_read_silhouettes`
//! reads. What lies behind a level is read under the camera's reprojection alone
//! (`combine_read`), not moved by the level's own matrix or motion.

use glam::{Mat4, UVec2, Vec2, Vec3, Vec4};
use lodkit::combine::{DepthConvention, LodImage, combine_uv};
use lodkit::combine_coverage::{
    CombineData, CombineDataDescriptor, CombineNewer, CombineObjectData, CoverageRoute,
    combine_behind_texel, combine_new_to_old, combine_ray_texel, combine_read, combine_read_known,
    combine_read_silhouettes,
};
use lodkit::gpu::GpuContext;
use lodkit::reproject::{reproject, reproject_base, reproject_from_base};

use crate::harness::{
    COMBINE_COVERAGE_GLSL, Probe, Word, assert_twin, floats, run_on, twin_runs, words,
};

const W: u32 = 16;
const H: u32 = 4;
/// Output words per case.
const OUT: usize = 20;
/// The t-instance whose older level the reads look for, on texels 10..=12 of every row, depth 0.5.
const OWNER: u32 = 3;
/// A t-instance with no texel in the older buffer: what lies behind its level is looked for too.
const OTHER: u32 = 7;
/// The camera's parallax: old NDC x = x + B (z - 0.9), so depth 0.9 stays in place and depth 0.5
/// moves 6 texels right (8 texels per NDC unit), depth 1 1.5 texels left.
const B: f32 = -1.875;
const B_Z0: f32 = 1.6875;

fn new_to_old() -> Mat4 {
    Mat4::from_cols(
        Vec4::new(1.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0, 0.0, 0.0),
        Vec4::new(B, 0.0, 1.0, 0.0),
        Vec4::new(B_Z0, 0.0, 0.0, 1.0),
    )
}

/// Older buffer: OWNER on 10..=12 (depth 0.5); background (id 0) at depth 0.9 on rows 0 and 1,
/// at depth 1 on rows 2 and 3.
fn older() -> LodImage {
    let n = (W * H) as usize;
    let noise = lodkit::noise::white_noise(3 * n, 7);
    let ids: Vec<u32> = (0..n as u32)
        .map(|p| {
            if (10..=12).contains(&(p % W)) {
                OWNER
            } else {
                0
            }
        })
        .collect();
    LodImage {
        width: W,
        height: H,
        colors: (0..n)
            .map(|i| Vec4::new(noise[i], noise[n + i], noise[2 * n + i], 1.0))
            .collect(),
        depths: (0..n)
            .map(|i| match (ids[i], i as u32 / W) {
                (OWNER, _) => 0.5,
                (_, 0 | 1) => 0.9,
                _ => 1.0,
            })
            .collect(),
        ids,
        flags: vec![3; n],
        motion: Vec::new(),
    }
}

/// The outline of the rectangle from (x0, y0) to (x1, y1), pixels: four segments (x0, y0, x1,
/// y1) around it.
fn rectangle(x0: f32, y0: f32, x1: f32, y1: f32) -> [[f32; 4]; 4] {
    [
        [x0, y0, x0, y1],
        [x0, y1, x1, y1],
        [x1, y1, x1, y0],
        [x1, y0, x0, y0],
    ]
}

/// The data texture: OWNER's older level known by its silhouette, a rectangle over the whole
/// target (every pixel center lies inside it, none on it).
fn data() -> CombineData {
    let square = rectangle(0.0, 0.0, W as f32, H as f32);
    let objects = [CombineObjectData {
        id: OWNER,
        new_to_old: new_to_old(),
        older_tau: None,
        route: CoverageRoute::Silhouette(&square),
    }];
    CombineData::new(&CombineDataDescriptor {
        new_to_old: new_to_old(),
        height: H,
        objects: &objects,
        ..Default::default()
    })
    .expect("one record")
}

/// The cases: pixel and newer depth.
const CASES: [(u32, u32, f32); 7] = [
    // Background at depth 0.9 shows; OWNER's older texels lie 6 texels along the ray.
    (4, 1, 0.9),
    // The same 8 texels along: past COMBINE_RAY_STEPS.
    (2, 1, 0.9),
    // OWNER's newer level at depth 0.5: its read lands on OWNER's texel 11 at once.
    (5, 1, 0.5),
    // Behind OWNER's level at 0.5: the background at depth 0.9, 6 texels back along the ray.
    (4, 1, 0.5),
    // Behind it the background at depth 1, 7.5 texels back: out of reach.
    (4, 2, 0.5),
    // Depth 0.9 - 2/15 reprojects 2 texels right, onto texel 5's center; at OWNER's depth the ray
    // lies on texel 9's center, 1 texel from OWNER's nearest texel (10).
    (3, 1, 0.9 - 2.0 / 15.0),
    // Depth 0.9 stays in place: the ray meets the background on texel 10's center, which holds
    // OWNER; the nearest background texel (9) lies 1 texel off the ray.
    (10, 1, 0.9),
];

/// The Rust twins' words for each case.
fn twin_words(older: &LodImage, data: &CombineData) -> Vec<u32> {
    let size = UVec2::new(W, H);
    let m = new_to_old();
    CASES
        .iter()
        .flat_map(|&(x, y, depth)| {
            let uv = combine_uv(UVec2::new(x, y), size);
            let base = reproject_base(uv, &m);
            let texels = &data.texels;
            let known = combine_read_known(older, texels, OWNER, uv, depth, &m, Vec2::ZERO);
            let hit = |id, owned| {
                combine_ray_texel(older, texels, id, owned, base, depth, &m, Vec2::ZERO)
                    .map_or([0, 0, 0], |t| [t.x, t.y, 1])
            };
            let at = reproject(uv, depth, &m).truncate();
            let behind =
                |id| combine_behind_texel(older, texels, id, at, base, depth, &m, Vec2::ZERO);
            let (behind, behind_other) = (behind(OWNER), behind(OTHER));
            let mut w = vec![known.texel.x, known.texel.y, u32::from(known.found)];
            w.extend(words(&known.color.to_array()));
            w.extend(hit(OWNER, true));
            w.extend([behind.x, behind.y]);
            let p = UVec2::new(x, y).as_vec2() + 0.5;
            let covered = combine_read_silhouettes(
                older,
                &data.texels,
                uv,
                depth,
                p,
                DepthConvention::Standard,
            );
            w.extend([covered.texel.x, covered.texel.y, u32::from(covered.found)]);
            w.extend([behind_other.x, behind_other.y]);
            w.extend(hit(OTHER, false));
            w
        })
        .collect()
}

/// Every GPU run (WGSL and GLSL, on every route) of a probe of the reads: `wgsl` (header,
/// body) and the GLSL `glsl_body` (with `COMBINE_COVERAGE_GLSL`), the cases' input words with
/// the words in and out per case, over the older buffer `older` (color `probe_rgba0`, depth
/// `probe_rgba1`, id words `probe_urgba0`) and the data texture `data` (`probe_urgba1`): who
/// ran it and its output words.
fn gpu_reads(
    gpu: &GpuContext,
    wgsl: (&str, &str),
    glsl_body: &str,
    (cases, inputs, outputs): (&[u32], usize, usize),
    older: &LodImage,
    data: &CombineData,
) -> Vec<(String, Vec<u32>)> {
    let depths: Vec<Vec4> = older.depths.iter().map(|d| Vec4::splat(*d)).collect();
    let ids: Vec<[u32; 4]> = (0..older.ids.len())
        .map(|p| [older.word(p), 0, 0, 0])
        .collect();
    twin_runs(gpu, wgsl, (COMBINE_COVERAGE_GLSL, glsl_body))
        .into_iter()
        .map(|(route, language, header, body)| {
            let probe = Probe {
                header,
                body,
                inputs,
                outputs,
                texture: None,
                rgba: &[(W, H, &older.colors), (W, H, &depths)],
                urgba: &[(W, H, &ids), (data.width, data.height, &data.texels)],
            };
            let got = run_on(gpu, route, &probe, cases, language, &[]);
            (format!("{route:?} {language:?}"), got)
        })
        .collect()
}

/// Holds the words of one language (or of the Rust twins) to the answers worked out by hand from
/// the texels above (not by the code under test).
fn check_known(out: &[u32], older: &LodImage, who: &str) {
    let case = |k: usize| &out[k * OUT..(k + 1) * OUT];
    let color = |w: &[u32]| Vec4::from_slice(&floats(&w[3..7]));
    let texel = |x: u32, y: u32| older.colors[(y * W + x) as usize];
    let close = |a: Vec4, b: Vec4| (a - b).abs().max_element() <= 1e-5;
    // (4, 1): the ray at depth 0.5 reprojects onto texel 10's center: that texel alone.
    assert_eq!(case(0)[0..3], [10, 1, 1], "{who}: known read at (4, 1)");
    assert!(
        close(color(case(0)), texel(10, 1)),
        "{who}: color at (4, 1)"
    );
    assert_eq!(case(0)[7..10], [10, 1, 1], "{who}: ray texel at (4, 1)");
    // (2, 1): not found; no texel of OWNER within reach.
    assert_eq!(
        case(1)[2],
        0,
        "{who}: known read at (2, 1) must not be found"
    );
    assert_eq!(
        case(1)[9],
        0,
        "{who}: ray texel at (2, 1) must not be found"
    );
    // (5, 1): the read lands on texel 11 at once.
    assert_eq!(case(2)[0..3], [11, 1, 1], "{who}: known read at (5, 1)");
    assert!(
        close(color(case(2)), texel(11, 1)),
        "{who}: color at (5, 1)"
    );
    // (4, 1) behind depth 0.5: the background texel (4, 1), where the ray meets depth 0.9; the
    // 3x3 block's nearest other texel, (9, 1), shows background 5 texels off the ray.
    assert_eq!(case(3)[10..12], [4, 1], "{who}: behind texel at (4, 1)");
    // (4, 2): out of reach, the 3x3 block's nearest texel not holding OWNER.
    assert_eq!(case(4)[10..12], [9, 2], "{who}: behind texel at (4, 2)");
    // Behind OTHER's level at (4, 1), depth 0.5: the ray's first texels, 10..=12, hold OWNER,
    // whose older level is known by its silhouette: skipped. The background texel (4, 1) is what
    // lies behind, as for OWNER.
    assert_eq!(
        case(3)[15..17],
        [4, 1],
        "{who}: behind OTHER's level at (4, 1) (not OWNER's texel 10, a level known by its silhouette)"
    );
    // A pixel showing the background (depth 0.9) inside OWNER's older silhouette reads that
    // level along the ray: at (4, 1) texel 10; at (2, 1) none within reach, so not found
    // (combine_read goes on to the estimate, not to the background texel the read lands on).
    assert_eq!(
        case(0)[12..15],
        [10, 1, 1],
        "{who}: silhouette read at (4, 1)"
    );
    assert_eq!(
        case(1)[14],
        0,
        "{who}: silhouette read at (2, 1) must not be found"
    );
    // (3, 1): no texel of OWNER within COMBINE_RAY_REACH (0.75) of the ray; texel 10 lies 1
    // texel off it, within COMBINE_BLOCK_REACH (1.5), the nearest (texel 11: 2). OWNER covers
    // the pixel, so its color is read there: texel 10's own, as the bilinear weights at texel
    // 9's center fall on texel 9 alone, which does not hold OWNER.
    assert_eq!(case(5)[7..10], [10, 1, 1], "{who}: ray texel at (3, 1)");
    assert_eq!(case(5)[0..3], [10, 1, 1], "{who}: known read at (3, 1)");
    assert!(
        close(color(case(5)), texel(10, 1)),
        "{who}: color at (3, 1)"
    );
    assert_eq!(
        case(5)[12..15],
        [10, 1, 1],
        "{who}: silhouette read at (3, 1)"
    );
    // (10, 1) at depth 0.9, behind OTHER's level: the ray's texels 10..=12 hold OWNER, known by
    // its silhouette (skipped); the background texel nearest the ray, 9, lies 1 texel off it,
    // past COMBINE_RAY_REACH (0.75). Looking for what lies behind a level, the search takes no
    // texel off the ray (the nearest-texel fallback within COMBINE_BLOCK_REACH is for a level's
    // own texels): not found, where texel 9 would be found if it did.
    assert_eq!(
        case(6)[17..20],
        [0, 0, 0],
        "{who}: ray texel behind OTHER's level at (10, 1) must not be found"
    );
    // With the ray's texel not found, the 3x3 block's texel nearest the read not holding OWNER.
    assert_eq!(case(6)[10..12], [9, 1], "{who}: behind texel at (10, 1)");
}

#[test]
fn ray_reads_give_the_hand_made_answers() {
    let older = older();
    check_known(&twin_words(&older, &data()), &older, "Rust twins");
    // The scene is what it says: depth 0.5 at pixel 4 reprojects onto texel 10's center.
    let uv = combine_uv(UVec2::new(4, 1), UVec2::new(W, H));
    let at = reproject(uv, 0.5, &new_to_old()).truncate() * Vec2::new(W as f32, H as f32);
    assert!((at - Vec2::new(10.5, 1.5)).length() < 1e-4, "{at}");
}

#[test]
fn ray_read_twins_match() {
    let gpu = lodkit_test_gpu!();
    let older = older();
    let data = data();
    let want = twin_words(&older, &data);
    let inputs: Vec<u32> = CASES
        .iter()
        .flat_map(|&(x, y, depth)| [x, y, depth.to_bits()])
        .collect();
    let matrix = format!("vec4({B:?}, 0.0, 1.0, 0.0), vec4({B_Z0:?}, 0.0, 0.0, 1.0)");
    let wgsl = format!(
        "let px = vec2(inp_u(0u), inp_u(1u));
        let depth = inp_f(2u);
        let m = mat4x4<f32>(vec4(1.0, 0.0, 0.0, 0.0), vec4(0.0, 1.0, 0.0, 0.0), {matrix});
        let uv = combine_uv(px, vec2({W}u, {H}u));
        let base = reproject_base(uv, m);
        let known = combine_read_known(probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1, {OWNER}u, uv, depth, m, vec2(0.0));
        out_u(0u, known.texel.x); out_u(1u, known.texel.y); out_u(2u, u32(known.found));
        out_f(3u, known.color.x); out_f(4u, known.color.y); out_f(5u, known.color.z); out_f(6u, known.color.w);
        let hit = combine_ray_texel(probe_urgba0, probe_rgba1, probe_urgba1, {OWNER}u, true, base, depth, m, vec2(0.0));
        out_u(7u, hit.x); out_u(8u, hit.y); out_u(9u, hit.z);
        let behind = combine_behind_texel(probe_urgba0, probe_rgba1, probe_urgba1, {OWNER}u, reproject(uv, depth, m).xy, base, depth, m, vec2(0.0));
        out_u(10u, behind.x); out_u(11u, behind.y);
        let other = combine_behind_texel(probe_urgba0, probe_rgba1, probe_urgba1, {OTHER}u, reproject(uv, depth, m).xy, base, depth, m, vec2(0.0));
        out_u(15u, other.x); out_u(16u, other.y);
        let other_hit = combine_ray_texel(probe_urgba0, probe_rgba1, probe_urgba1, {OTHER}u, false, base, depth, m, vec2(0.0));
        out_u(17u, other_hit.x); out_u(18u, other_hit.y); out_u(19u, other_hit.z);
        let covered = combine_read_silhouettes(probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1, uv, depth, vec2<f32>(px) + 0.5);
        out_u(12u, covered.texel.x); out_u(13u, covered.texel.y); out_u(14u, u32(covered.found));"
    );
    let glsl = format!(
        "uvec2 px = uvec2(inp_u(0u), inp_u(1u));
        float depth = inp_f(2u);
        mat4 m = mat4(vec4(1.0, 0.0, 0.0, 0.0), vec4(0.0, 1.0, 0.0, 0.0), {matrix});
        vec2 uv = lodkit_combine_uv(px, uvec2({W}u, {H}u));
        vec4 base = lodkit_reproject_base(uv, m);
        lodkit_CombineRead known = lodkit_combine_read_known({OWNER}u, uv, depth, m, vec2(0.0));
        out_u(0u, known.texel.x); out_u(1u, known.texel.y); out_u(2u, uint(known.found));
        out_f(3u, known.color.x); out_f(4u, known.color.y); out_f(5u, known.color.z); out_f(6u, known.color.w);
        uvec3 hit = lodkit_combine_ray_texel({OWNER}u, true, base, depth, m, vec2(0.0));
        out_u(7u, hit.x); out_u(8u, hit.y); out_u(9u, hit.z);
        uvec2 behind = lodkit_combine_behind_texel({OWNER}u, lodkit_reproject(uv, depth, m).xy, base, depth, m, vec2(0.0));
        out_u(10u, behind.x); out_u(11u, behind.y);
        uvec2 other = lodkit_combine_behind_texel({OTHER}u, lodkit_reproject(uv, depth, m).xy, base, depth, m, vec2(0.0));
        out_u(15u, other.x); out_u(16u, other.y);
        uvec3 other_hit = lodkit_combine_ray_texel({OTHER}u, false, base, depth, m, vec2(0.0));
        out_u(17u, other_hit.x); out_u(18u, other_hit.y); out_u(19u, other_hit.z);
        lodkit_CombineRead covered = lodkit_combine_read_silhouettes(uv, depth, vec2(px) + 0.5);
        out_u(12u, covered.texel.x); out_u(13u, covered.texel.y); out_u(14u, uint(covered.found));"
    );
    let wgsl_header = "#import lodkit::combine::combine_uv
#import lodkit::combine_coverage::{combine_read_known, combine_ray_texel, combine_behind_texel, combine_read_silhouettes}
#import lodkit::reproject::{reproject, reproject_base}";
    // Texels and flags exact; the colors are single texels (a weight of exactly 1): 1e-5.
    let mut kinds = vec![Word::Exact; 3];
    kinds.extend([Word::Float(1e-5); 4]);
    kinds.extend([Word::Exact; 13]);
    let runs = gpu_reads(
        gpu,
        (wgsl_header, &wgsl),
        &glsl,
        (&inputs, 3, OUT),
        &older,
        &data,
    );
    for (who, got) in runs {
        check_known(&got, &older, &who);
        assert_twin(&got, &want, &kinds, &format!("{who} combine ray reads"));
    }
}

/// OTHER's level at pixel (2, 0), depth 0.9, drawn now and hidden there, with its older level
/// known by a silhouette that does not cover the pixel: the frame's data with OTHER's record
/// moved 2 texels right of the camera's matrix (`object_motion` false), or, with object motion,
/// the pixel's motion 2 texels right.
fn behind_data(object_motion: bool) -> CombineData {
    let everywhere = rectangle(0.0, 0.0, W as f32, H as f32);
    // A square around pixel (14, 3)'s center, far from pixel (2, 0).
    let away = rectangle(14.0, 3.0, 15.0, 4.0);
    // 2 texels: 0.25 NDC at 8 texels per NDC unit.
    let moved = Mat4::from_translation(Vec3::new(0.25, 0.0, 0.0)) * new_to_old();
    let objects = [
        CombineObjectData {
            id: OWNER,
            new_to_old: new_to_old(),
            older_tau: None,
            route: CoverageRoute::Silhouette(&everywhere),
        },
        CombineObjectData {
            id: OTHER,
            new_to_old: moved,
            older_tau: None,
            route: CoverageRoute::Silhouette(&away),
        },
    ];
    CombineData::new(&CombineDataDescriptor {
        new_to_old: new_to_old(),
        object_motion,
        height: H,
        objects: &objects,
        ..Default::default()
    })
    .expect("two records")
}

/// What lies behind a level is read under the camera's reprojection alone: the level's own
/// matrix and motion move the level, not what is behind it. Pixel (2, 0) shows OTHER's level at
/// depth 0.9, hidden now, whose older silhouette does not cover it; OWNER's older silhouette does,
/// but OWNER's texels lie 8 texels along the ray, past COMBINE_RAY_STEPS (case (2, 1) above). The
/// camera keeps depth 0.9 in place, so the background texel (2, 0) lies on the ray; under OTHER's
/// matrix, or moved by the pixel's motion, the read would land 2 texels right, on texel (4, 0),
/// which holds the background at depth 0.9 too and would be taken.
#[test]
fn what_lies_behind_a_level_is_read_without_its_motion() {
    let gpu = lodkit_test_gpu!();
    let older = older();
    let word = lodkit::lod_buffer::lod_buffer_word(OTHER, 2);
    let motion = Vec2::new(2.0 / W as f32, 0.0);
    let wgsl = format!(
        "let px = vec2(inp_u(0u), inp_u(1u));
        let newer = CombineNewer(vec4(0.0), inp_u(3u), inp_f(2u), vec2(inp_f(4u), inp_f(5u)), 0.5, 1.0);
        let m = combine_new_to_old(probe_urgba1, {OTHER}u);
        let base = reproject_base(combine_uv(px, vec2({W}u, {H}u)), m);
        let old = reproject_from_base(base, newer.depth, m);
        let read = combine_read(probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1, newer, px, base, old, m);
        out_u(0u, read.texel.x); out_u(1u, read.texel.y); out_u(2u, u32(read.found));"
    );
    let glsl = format!(
        "uvec2 px = uvec2(inp_u(0u), inp_u(1u));
        lodkit_CombineNewer newer = lodkit_CombineNewer(vec4(0.0), inp_u(3u), inp_f(2u), vec2(inp_f(4u), inp_f(5u)), 0.5, 1.0);
        mat4 m = lodkit_combine_new_to_old({OTHER}u);
        vec4 base = lodkit_reproject_base(lodkit_combine_uv(px, uvec2({W}u, {H}u)), m);
        vec3 old = lodkit_reproject_from_base(base, newer.depth, m);
        lodkit_CombineRead read = lodkit_combine_read(newer, px, base, old, m);
        out_u(0u, read.texel.x); out_u(1u, read.texel.y); out_u(2u, uint(read.found));"
    );
    let wgsl_header = "#import lodkit::combine::combine_uv
#import lodkit::combine_coverage::{CombineNewer, combine_read, combine_new_to_old}
#import lodkit::reproject::{reproject_base, reproject_from_base}";
    for object_motion in [false, true] {
        let data = behind_data(object_motion);
        let pixel_motion = if object_motion { motion } else { Vec2::ZERO };
        let newer = CombineNewer {
            color: Vec4::ZERO,
            word,
            depth: 0.9,
            motion: pixel_motion,
            pattern: 0.5,
            level_depth: 1.0,
        };
        let texels = &data.texels;
        let m = combine_new_to_old(texels, OTHER);
        let pixel = UVec2::new(2, 0);
        let base = reproject_base(combine_uv(pixel, UVec2::new(W, H)), &m);
        let old = reproject_from_base(base, 0.9, &m);
        let read = combine_read(
            &older,
            texels,
            &newer,
            pixel,
            base,
            old,
            &m,
            DepthConvention::Standard,
        );
        let what = if object_motion {
            "the pixel's motion"
        } else {
            "OTHER's matrix"
        };
        let want = [2, 0, 1];
        assert_eq!(
            [read.texel.x, read.texel.y, u32::from(read.found)],
            want,
            "Rust twins: behind OTHER's level at (2, 0), {what}"
        );
        let inputs = [
            2,
            0,
            0.9f32.to_bits(),
            word,
            pixel_motion.x.to_bits(),
            pixel_motion.y.to_bits(),
        ];
        let runs = gpu_reads(
            gpu,
            (wgsl_header, &wgsl),
            &glsl,
            (&inputs, 6, 3),
            &older,
            &data,
        );
        for (who, got) in runs {
            assert_eq!(got, want, "{who}: behind OTHER's level at (2, 0), {what}");
        }
    }
}
