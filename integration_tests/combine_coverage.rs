//! The combine with the older level's coverage known (`lodkit::combine_coverage` and the pieces
//! of `lodkit::combine` it is built from) on the GPU, WGSL and GLSL, against the Rust twins, on a
//! hand-made pair of LOD buffers whose answers are known: the older level's silhouette covers a
//! pixel the older buffer's read misses, a neighbour is taken only where its sample lies on the
//! pixel's ray, the older color is the bilinear blend of the same object's texels, and an object
//! in front of the older level hides it only by more than `COMBINE_HIDDEN_MARGIN`, and only
//! where it is a t-instance whose older level may still cover the pixel (`combine_may_cover`).
//! Behind a level drawn now whose older silhouette does not cover a pixel, another t-instance's
//! older level shows where its silhouette covers the pixel.

use glam::{Mat4, UVec2, Vec2, Vec3, Vec4};
use lodkit::combine::{
    COMBINE_BLOCK_REACH, COMBINE_COVER_REACH, DepthConvention, LodImage, combine_cover_texel,
    combine_displayed_word, combine_other_texel, combine_ray_offset, combine_read_own,
    combine_snap, combine_texel, combine_uv,
};
use lodkit::combine_coverage::{
    COMBINE_EDGE_REACH, CombineData, CombineDataDescriptor, CombineNewer, CombineObjectData,
    CoverageRoute, combine_edge_uv, combine_far_depth, combine_hider, combine_known_covers,
    combine_may_cover, combine_new_to_old, combine_object, combine_pixel,
};
use lodkit::lod_buffer::{lod_buffer_id, lod_buffer_word};
use lodkit::reproject::{reproject, reproject_base};
use lodkit::silhouette::{SILHOUETTE_ON, silhouette_covers};

use crate::harness::{
    COMBINE_COVERAGE_GLSL, Probe, Word, assert_twin, floats, run_on, twin_runs, words,
};

#[path = "combine_coverage_known.rs"]
mod known;
use known::check_known;

const W: u32 = 16;
const H: u32 = 12;
/// Output words per pixel.
const OUT: usize = 26;
/// The camera moved so that every pixel's center reprojects 0.3 texel right of its own texel's
/// center (NDC x + 0.3 * 2 / 16): a read lands at x + 0.8 texels, 0.2 texel from any edge.
const SHIFT: f32 = 0.0375;

/// The t-instance whose older level's coverage is its silhouette, and its older texels.
const SIL: u32 = 3;
const SIL_X: std::ops::RangeInclusive<u32> = 4..=9;
const SIL_Y: std::ops::RangeInclusive<u32> = 3..=8;
/// The t-instance whose older level is estimated from last frame's picture.
const EST: u32 = 5;
/// A t-instance of the older frame in front of the silhouette t-instance's older level, on
/// texels 5..=7 x 7..=8, whose older coverage is estimated: it may cover those pixels now.
const FRONT: u32 = 7;
/// An object in no transition (no record), in front of the silhouette t-instance's older level
/// on texel (7, 4) of the older frame: drawn this frame too, it is not in front of it now.
const STILL: u32 = 9;
/// A t-instance that did not move (its matrix the identity) on older texels 1..=2 x 9..=10,
/// whose silhouette's left edge passes through the centers of pixel column 1; its level drawn
/// now, not shown at this frame, covers pixel (3, 8), inside the silhouette t-instance's older
/// silhouette and outside its own, and pixel (12, 9), inside none.
const TIE: u32 = 11;

/// The scene: older and newer LOD buffers, the newer words, the screen pattern per pixel.
struct Scene {
    older: LodImage,
    newer: LodImage,
    pattern: Vec<f32>,
    data: CombineData,
}

fn at(x: u32, y: u32) -> usize {
    (y * W + x) as usize
}

fn scene() -> Scene {
    let n = (W * H) as usize;
    let noise = lodkit::noise::white_noise(9 * n, 41);
    let colors = |k: usize| -> Vec<Vec4> {
        (0..n)
            .map(|i| {
                Vec4::new(
                    noise[k * n + i],
                    noise[(k + 1) * n + i],
                    noise[(k + 2) * n + i],
                    1.0,
                )
            })
            .collect()
    };
    // Older: the silhouette t-instance on texels 4..=9 x 3..=8 but for FRONT's, STILL's and the
    // background at (9, 3), the estimated one on 11..=13 x 2..=5, background elsewhere.
    let older_id = |x: u32, y: u32| {
        if (x, y) == (9, 3) {
            0
        } else if (5..=7).contains(&x) && (7..=8).contains(&y) {
            FRONT
        } else if (x, y) == (7, 4) {
            STILL
        } else if SIL_X.contains(&x) && SIL_Y.contains(&y) {
            SIL
        } else if (11..=13).contains(&x) && (2..=5).contains(&y) {
            EST
        } else if (1..=2).contains(&x) && (9..=10).contains(&y) {
            TIE
        } else {
            0
        }
    };
    // Newer: the silhouette t-instance on 4..=8 x 3..=8 and (9, 3) (the level drawn this frame is
    // smaller), the estimated one on 10..=14 x 2..=5 (larger).
    let newer_id = |x: u32, y: u32| {
        if (x, y) == (3, 8) || (x, y) == (12, 9) {
            TIE
        } else if (4..=8).contains(&x) && SIL_Y.contains(&y) || (x, y) == (9, 3) {
            SIL
        } else if (10..=14).contains(&x) && (2..=5).contains(&y) {
            EST
        } else {
            0
        }
    };
    let depth = |id: u32| match id {
        FRONT | STILL => 0.9,
        SIL | TIE => 0.95,
        EST => 0.97,
        _ => 1.0,
    };
    let image = |id: &dyn Fn(u32, u32) -> u32, k: usize| {
        let ids: Vec<u32> = (0..n as u32).map(|p| id(p % W, p / W)).collect();
        LodImage {
            width: W,
            height: H,
            colors: colors(k),
            depths: ids.iter().map(|&i| depth(i)).collect(),
            ids,
            flags: vec![3; n],
            motion: Vec::new(),
        }
    };
    let mut older = image(&older_id, 0);
    // FRONT touches the silhouette t-instance's older level at texel (5, 8): 0.0002 in front,
    // within COMBINE_HIDDEN_MARGIN (0.01 of 1 - 0.95: 0.0005).
    older.depths[at(5, 8)] = 0.9498;
    let mut newer = image(&newer_id, 3);
    // TIE's level drawn now is not shown at (3, 8) and (12, 9) this frame (flag: shown next only).
    newer.flags[at(3, 8)] = 2;
    newer.flags[at(12, 9)] = 2;
    // The silhouette t-instance's level drawn now is not shown at (9, 3) either.
    newer.flags[at(9, 3)] = 2;
    let mut pattern: Vec<f32> = noise[6 * n..7 * n].to_vec();
    // Where the silhouette test and the touching texel are checked, the older level is
    // displayed (pattern <= tau 0.5).
    pattern[at(3, 5)] = 0.1;
    pattern[at(5, 8)] = 0.1;
    pattern[at(7, 4)] = 0.1;
    pattern[at(9, 5)] = 0.1;
    pattern[at(1, 9)] = 0.1;
    pattern[at(3, 8)] = 0.1;
    pattern[at(9, 3)] = 0.1;
    // The older level's silhouette under this frame's camera: the rectangle from (3, 3) to
    // (9.5, 9) in pixels (its texels 4..=9 moved 0.3 texel left by the camera, widened on the
    // left), which covers pixel column 3 where the older buffer's read finds background, and
    // whose right edge passes through the centers of column 9 where it finds the level.
    let (x0, y0, x1, y1) = (3.0, 3.0, 9.5, 9.0);
    let square = [
        [x0, y0, x0, y1],
        [x0, y1, x1, y1],
        [x1, y1, x1, y0],
        [x1, y0, x0, y0],
    ];
    let camera = Mat4::from_translation(Vec3::new(SHIFT, 0.0, 0.0));
    // TIE's silhouette: the rectangle from (1.5, 9) to (3, 11), its left edge on the centers of
    // pixel column 1.
    let tie = [
        [1.5, 9.0, 1.5, 11.0],
        [1.5, 11.0, 3.0, 11.0],
        [3.0, 11.0, 3.0, 9.0],
        [3.0, 9.0, 1.5, 9.0],
    ];
    let objects = [
        CombineObjectData {
            id: SIL,
            new_to_old: camera,
            older_tau: Some(0.5),
            route: CoverageRoute::Silhouette(&square),
        },
        CombineObjectData {
            id: EST,
            new_to_old: camera,
            older_tau: None,
            route: CoverageRoute::Estimate,
        },
        CombineObjectData {
            id: FRONT,
            new_to_old: camera,
            older_tau: None,
            route: CoverageRoute::Estimate,
        },
        CombineObjectData {
            id: TIE,
            new_to_old: Mat4::IDENTITY,
            older_tau: Some(0.5),
            route: CoverageRoute::Silhouette(&tie),
        },
    ];
    let data = CombineData::new(&CombineDataDescriptor {
        new_to_old: camera,
        height: H,
        objects: &objects,
        ..Default::default()
    })
    .unwrap();
    Scene {
        older,
        newer,
        pattern,
        data,
    }
}

fn newer_at(s: &Scene, p: usize) -> CombineNewer {
    CombineNewer {
        color: s.newer.colors[p],
        word: s.newer.word(p),
        depth: s.newer.depths[p],
        motion: Vec2::ZERO,
        pattern: s.pattern[p],
        level_depth: combine_far_depth(DepthConvention::Standard),
    }
}

/// The uv each pixel hands `combine_edge_uv`: 5 texels left of its own column, on its row's
/// center, so columns 0..=4 lie 5.5..=1.5 texels outside the view from the left edge texel's
/// center (the probes compute the same: `(x - 5) / 16`, `(y + 0.5) / 12`).
fn edge_probe_uv(px: UVec2) -> Vec2 {
    Vec2::new(
        (px.x as f32 - 5.0) / W as f32,
        (px.y as f32 + 0.5) / H as f32,
    )
}

/// The Rust twins' words for every pixel (the probe's outputs).
fn twin_words(s: &Scene) -> Vec<u32> {
    let size = UVec2::new(W, H);
    let texels = &s.data.texels;
    (0..W * H)
        .flat_map(|p| {
            let px = UVec2::new(p % W, p / W);
            let newer = newer_at(s, p as usize);
            let c = combine_pixel(&newer, px, &s.older, texels, DepthConvention::Standard).unwrap();
            let m = combine_new_to_old(texels, 0);
            let uv = combine_uv(px, size);
            let a = reproject(uv, newer.depth, &m).truncate();
            let read = combine_texel(a, size);
            let r = combine_read_own(
                &s.older,
                SIL,
                uv,
                newer.depth,
                &m,
                Vec2::ZERO,
                COMBINE_BLOCK_REACH,
            );
            let base = reproject_base(uv, &m);
            let cover = combine_cover_texel(
                &s.older,
                EST,
                read,
                base,
                newer.depth,
                &m,
                Vec2::ZERO,
                COMBINE_COVER_REACH,
            );
            let other = combine_other_texel(&s.older, SIL, read, a);
            let table = combine_object(texels, SIL).silhouette;
            let covers = silhouette_covers(texels, table, px.as_vec2() + 0.5);
            let offset = combine_ray_offset(a, read, size);
            let shown = combine_displayed_word(newer.word, true, 0.5, newer.pattern);
            let snap = combine_snap(Vec2::new(newer.pattern, 1.0 - newer.pattern * 0.02));
            let mut w = words(&c.to_array());
            w.extend([r.texel.x, r.texel.y]);
            w.extend(words(&r.color.to_array()));
            w.extend([
                u32::from(r.found),
                cover.x,
                cover.y,
                other.x,
                other.y,
                covers as u32,
            ]);
            w.extend(words(&[offset]));
            w.push(shown);
            w.extend(words(&[snap.x, snap.y]));
            let p = px.as_vec2() + 0.5;
            w.push(
                [SIL, EST, FRONT, 0]
                    .iter()
                    .enumerate()
                    .map(|(k, &id)| u32::from(combine_known_covers(texels, id, p)) << k)
                    .sum(),
            );
            let edge = combine_edge_uv(edge_probe_uv(px), size);
            w.extend(words(&edge.unwrap_or(Vec2::ZERO).to_array()));
            w.push(u32::from(edge.is_some()));
            w.push(
                [SIL, EST, FRONT, STILL, 0]
                    .iter()
                    .enumerate()
                    .map(|(k, &id)| u32::from(combine_may_cover(texels, id, p)) << k)
                    .sum(),
            );
            let point = reproject(uv, newer.depth, &m);
            w.push(combine_hider(
                &s.older,
                SIL,
                a,
                point.z,
                DepthConvention::Standard,
            ));
            w
        })
        .collect()
}

#[test]
fn combine_coverage_pieces_give_the_hand_made_answers() {
    let s = scene();
    check_known(&twin_words(&s), &s, "Rust twins");
    assert_eq!(combine_snap(Vec2::new(0.995, 0.3)), Vec2::new(1.0, 0.3));
    // The scene's words are what it says.
    assert_eq!(lod_buffer_id(s.newer.word(at(14, 3))), EST);
    assert_eq!(s.newer.word(at(3, 5)), lod_buffer_word(0, 3));
}

/// A camera that moved sideways brings a strip of the picture into view: where a pixel's
/// reprojection lands within COMBINE_EDGE_REACH texels outside last frame's picture, its older
/// level is read at the picture's edge, not left to the level drawn now (a full switch between
/// the two levels there on every other frame).
#[test]
fn combine_pixel_reads_the_older_edge_for_a_strip_coming_into_view() {
    const T: u32 = 2;
    let (w, h) = (8u32, 2u32);
    let n = (w * h) as usize;
    // Every pixel's center reprojects 2 texels left of itself (NDC x - 2 * 2 / 8).
    let camera = Mat4::from_translation(Vec3::new(-0.5, 0.0, 0.0));
    let image = |red: f32| LodImage {
        width: w,
        height: h,
        colors: (0..n)
            .map(|i| Vec4::new(red, i as f32 / 16.0, 0.5, 1.0))
            .collect(),
        depths: vec![0.5; n],
        ids: vec![T; n],
        flags: vec![3; n],
        motion: Vec::new(),
    };
    let (older, newer) = (image(0.25), image(0.75));
    let objects = [CombineObjectData {
        id: T,
        new_to_old: camera,
        older_tau: None,
        route: CoverageRoute::Estimate,
    }];
    let data = CombineData::new(&CombineDataDescriptor {
        new_to_old: camera,
        height: h,
        objects: &objects,
        ..Default::default()
    })
    .unwrap();
    for p in 0..n {
        let px = UVec2::new(p as u32 % w, p as u32 / w);
        let pixel = CombineNewer {
            color: newer.colors[p],
            word: newer.word(p),
            depth: 0.5,
            motion: Vec2::ZERO,
            pattern: 0.0,
            level_depth: combine_far_depth(DepthConvention::Standard),
        };
        let got =
            combine_pixel(&pixel, px, &older, &data.texels, DepthConvention::Standard).unwrap();
        // Both levels shown, one id: their average. Columns 0 and 1 reproject 1.5 and 0.5
        // texels left of the picture and read its left column, as column 2 does.
        let texel = (px.y * w + px.x.saturating_sub(2)) as usize;
        let want = 0.5 * (newer.colors[p] + older.colors[texel]);
        assert!(
            (got - want).abs().max_element() <= 1e-6,
            "pixel {px}: {got}, not the average {want} of its newer color and older texel {texel}"
        );
    }
}

#[test]
fn combine_coverage_twins_match() {
    let gpu = lodkit_test_gpu!();
    let s = scene();
    let want = twin_words(&s);
    let inputs: Vec<u32> = (0..W * H)
        .flat_map(|p| {
            let i = p as usize;
            let mut w = vec![p % W, p / W];
            w.extend(words(&s.newer.colors[i].to_array()));
            w.push(s.newer.word(i));
            w.extend(words(&[s.newer.depths[i], s.pattern[i]]));
            w
        })
        .collect();
    let colors = s.older.colors.clone();
    let depths: Vec<Vec4> = s.older.depths.iter().map(|d| Vec4::splat(*d)).collect();
    let ids: Vec<[u32; 4]> = (0..(W * H) as usize)
        .map(|p| [s.older.word(p), 0, 0, 0])
        .collect();
    let wgsl = format!(
        "let px = vec2(inp_u(0u), inp_u(1u));
        let size = vec2({W}u, {H}u);
        let newer = CombineNewer(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u), vec2(0.0), inp_f(8u), combine_far_depth());
        let c = combine_pixel(newer, px, probe_rgba0, probe_urgba0, probe_rgba1, probe_urgba1);
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);
        let m = combine_new_to_old(probe_urgba1, 0u);
        let uv = combine_uv(px, size);
        let a = reproject(uv, newer.depth, m).xy;
        let read = combine_texel(a, size);
        let r = combine_read_own(probe_rgba0, probe_urgba0, probe_rgba1, {SIL}u, uv, newer.depth, m, vec2(0.0), COMBINE_BLOCK_REACH);
        out_u(4u, r.texel.x); out_u(5u, r.texel.y);
        out_f(6u, r.color.x); out_f(7u, r.color.y); out_f(8u, r.color.z); out_f(9u, r.color.w);
        out_u(10u, u32(r.found));
        let cover = combine_cover_texel(probe_urgba0, probe_rgba1, {EST}u, read, reproject_base(uv, m), newer.depth, m, vec2(0.0), COMBINE_COVER_REACH);
        out_u(11u, cover.x); out_u(12u, cover.y);
        let other = combine_other_texel(probe_urgba0, {SIL}u, read, a);
        out_u(13u, other.x); out_u(14u, other.y);
        let table = combine_object(probe_urgba1, {SIL}u).silhouette;
        out_u(15u, bitcast<u32>(silhouette_covers(probe_urgba1, table, vec2<f32>(px) + 0.5)));
        out_f(16u, combine_ray_offset(a, read, size));
        out_u(17u, combine_displayed_word(newer.word, true, 0.5, newer.pattern));
        let snap = combine_snap(vec2(newer.pattern, 1.0 - newer.pattern * 0.02));
        out_f(18u, snap.x); out_f(19u, snap.y);
        let p = vec2<f32>(px) + 0.5;
        out_u(20u, select(0u, 1u, combine_known_covers(probe_urgba1, {SIL}u, p)) | select(0u, 2u, combine_known_covers(probe_urgba1, {EST}u, p)) | select(0u, 4u, combine_known_covers(probe_urgba1, {FRONT}u, p)) | select(0u, 8u, combine_known_covers(probe_urgba1, 0u, p)));
        let edge = combine_edge_uv(vec2((f32(px.x) - 5.0) / {W}.0, (f32(px.y) + 0.5) / {H}.0), size);
        let edge_uv = select(vec2(0.0), edge.xy, edge.z == 1.0);
        out_f(21u, edge_uv.x); out_f(22u, edge_uv.y); out_u(23u, select(0u, 1u, edge.z == 1.0));
        out_u(24u, select(0u, 1u, combine_may_cover(probe_urgba1, {SIL}u, p)) | select(0u, 2u, combine_may_cover(probe_urgba1, {EST}u, p)) | select(0u, 4u, combine_may_cover(probe_urgba1, {FRONT}u, p)) | select(0u, 8u, combine_may_cover(probe_urgba1, {STILL}u, p)) | select(0u, 16u, combine_may_cover(probe_urgba1, 0u, p)));
        out_u(25u, combine_hider(probe_urgba0, probe_rgba1, {SIL}u, a, reproject(uv, newer.depth, m).z));"
    );
    let glsl = format!(
        "uvec2 px = uvec2(inp_u(0u), inp_u(1u));
        uvec2 size = uvec2({W}u, {H}u);
        lodkit_CombineNewer newer = lodkit_CombineNewer(vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), inp_u(6u), inp_f(7u), vec2(0.0), inp_f(8u), lodkit_combine_far_depth());
        vec4 c = lodkit_combine_pixel(newer, px);
        out_f(0u, c.x); out_f(1u, c.y); out_f(2u, c.z); out_f(3u, c.w);
        mat4 m = lodkit_combine_new_to_old(0u);
        vec2 uv = lodkit_combine_uv(px, size);
        vec2 a = lodkit_reproject(uv, newer.depth, m).xy;
        uvec2 read = lodkit_combine_texel(a, size);
        lodkit_CombineRead r = lodkit_combine_read_own({SIL}u, uv, newer.depth, m, vec2(0.0), LODKIT_COMBINE_BLOCK_REACH);
        out_u(4u, r.texel.x); out_u(5u, r.texel.y);
        out_f(6u, r.color.x); out_f(7u, r.color.y); out_f(8u, r.color.z); out_f(9u, r.color.w);
        out_u(10u, uint(r.found));
        uvec2 cover = lodkit_combine_cover_texel({EST}u, read, lodkit_reproject_base(uv, m), newer.depth, m, vec2(0.0), LODKIT_COMBINE_COVER_REACH);
        out_u(11u, cover.x); out_u(12u, cover.y);
        uvec2 other = lodkit_combine_other_texel({SIL}u, read, a);
        out_u(13u, other.x); out_u(14u, other.y);
        uvec4 table = lodkit_combine_object({SIL}u).silhouette;
        out_u(15u, uint(lodkit_silhouette_covers(table, vec2(px) + 0.5)));
        out_f(16u, lodkit_combine_ray_offset(a, read, size));
        out_u(17u, lodkit_combine_displayed_word(newer.word, true, 0.5, newer.pattern));
        vec2 snap = lodkit_combine_snap(vec2(newer.pattern, 1.0 - newer.pattern * 0.02));
        out_f(18u, snap.x); out_f(19u, snap.y);
        vec2 p = vec2(px) + 0.5;
        out_u(20u, (lodkit_combine_known_covers({SIL}u, p) ? 1u : 0u) | (lodkit_combine_known_covers({EST}u, p) ? 2u : 0u) | (lodkit_combine_known_covers({FRONT}u, p) ? 4u : 0u) | (lodkit_combine_known_covers(0u, p) ? 8u : 0u));
        vec3 edge = lodkit_combine_edge_uv(vec2((float(px.x) - 5.0) / {W}.0, (float(px.y) + 0.5) / {H}.0), size);
        vec2 edge_uv = edge.z == 1.0 ? edge.xy : vec2(0.0);
        out_f(21u, edge_uv.x); out_f(22u, edge_uv.y); out_u(23u, edge.z == 1.0 ? 1u : 0u);
        out_u(24u, (lodkit_combine_may_cover({SIL}u, p) ? 1u : 0u) | (lodkit_combine_may_cover({EST}u, p) ? 2u : 0u) | (lodkit_combine_may_cover({FRONT}u, p) ? 4u : 0u) | (lodkit_combine_may_cover({STILL}u, p) ? 8u : 0u) | (lodkit_combine_may_cover(0u, p) ? 16u : 0u));
        out_u(25u, lodkit_combine_hider({SIL}u, a, lodkit_reproject(uv, newer.depth, m).z));"
    );
    // The GLSL twins read the textures through the hooks the includer defines
    // (COMBINE_COVERAGE_GLSL).
    let glsl_header = COMBINE_COVERAGE_GLSL;
    let wgsl_header = "#import lodkit::combine::{combine_uv, combine_texel, combine_read_own, combine_cover_texel, combine_other_texel, combine_ray_offset, combine_displayed_word, combine_snap, COMBINE_BLOCK_REACH, COMBINE_COVER_REACH}
#import lodkit::combine_coverage::{CombineNewer, combine_pixel, combine_new_to_old, combine_object, combine_far_depth, combine_known_covers, combine_may_cover, combine_hider, combine_edge_uv}
#import lodkit::reproject::{reproject, reproject_base}
#import lodkit::silhouette::silhouette_covers";
    // Texels, flags and ids exact; colors are sums of at most four weighted texels (weights
    // products of 1 - f and f): 1e-5 covers a few ulps of each.
    let mut kinds = vec![Word::Float(1e-5); 4];
    kinds.extend([Word::Exact; 2]);
    kinds.extend([Word::Float(1e-5); 4]);
    kinds.extend([Word::Exact; 6]);
    kinds.push(Word::Float(1e-5));
    kinds.push(Word::Exact);
    // The snap passes its input through or rounds it; the input 1 - 0.02 p may be computed with
    // a fused multiply-add on the GPU (an ulp apart, ~1.2e-7 near 1): 1e-6.
    kinds.extend([Word::Float(1e-6); 2]);
    kinds.push(Word::Exact);
    // The edge uv: a quotient (WGSL's division: 2.5 ulp) or the edge texel's center.
    kinds.extend([Word::Float(1e-6); 2]);
    kinds.extend([Word::Exact; 3]);
    for (route, language, header, body) in
        twin_runs(gpu, (wgsl_header, &wgsl), (glsl_header, &glsl))
    {
        let probe = Probe {
            header,
            body,
            inputs: 9,
            outputs: OUT,
            texture: None,
            rgba: &[(W, H, &colors), (W, H, &depths)],
            urgba: &[(W, H, &ids), (s.data.width, s.data.height, &s.data.texels)],
        };
        let got = run_on(gpu, route, &probe, &inputs, language, &[]);
        let who = format!("{route:?} {language:?}");
        // The hand-made answers first: a change to a piece fails there, not only as a twin
        // mismatch.
        check_known(&got, &s, &who);
        assert_twin(&got, &want, &kinds, &format!("{who} combine_coverage"));
    }
}
