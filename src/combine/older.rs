//! The pieces of frame-sequential LOD's combine with the older level's coverage known: Rust
//! twins of the shader functions of the same names in `lodkit::combine` (put together in
//! `lodkit::combine_coverage::combine_pixel`).
//!
//! The paper reads the older buffer where the camera's reprojection puts the pixel; where a
//! level's silhouette moved by a fraction of a texel, that read lands beside the object and shows
//! the other level or the background every other frame. These read it the way that holds still:
//!
//! - a neighbour texel stands in for the read only where its older sample lies on the pixel's
//!   ray ([`combine_cover_texel`], [`combine_ray_offset`]);
//! - the older color is the bilinear blend of the texels of the same object
//!   ([`combine_own_color`]), snapped to a texel's center within [`COMBINE_SNAP`];
//! - the older level is shown at this frame's threshold ([`combine_displayed_word`]);
//! - the read is refined at the older depth only where that texel holds the pixel's own object
//!   ([`combine_read_own`]); where the older level does not cover the pixel, what lies behind it
//!   ([`combine_other_texel`]).

use glam::{Mat4, UVec2, Vec2, Vec4};

use super::{LodImage, combine_ring_texel, combine_texel};
use crate::lod_buffer::{LOD_BUFFER_SHOWN_NEXT, lod_buffer_id};
use crate::reproject::{in_viewport, reproject_base, reproject_from_base, reproject_refine};

/// [`combine_cover_texel`]'s reach (texels) where the older level is estimated: one texel, the
/// reach of the four samples around a point, less 1/1000 so that a pixel that did not move takes
/// no neighbour (its ray exactly on its own texel's center, a neighbour's a whole texel away).
pub const COMBINE_COVER_REACH: f32 = 0.999;

/// [`combine_cover_texel`]'s reach where the older level is known to cover the pixel: the whole
/// 3x3 block (its corners lie 1.5 texels from its center).
pub const COMBINE_BLOCK_REACH: f32 = 1.5;

/// Where the older read lies within this fraction of a texel of a texel's center (on either
/// axis), [`combine_own_color`] takes that texel alone: a pixel that did not move reads back
/// exactly the color it had, not a hair of a neighbour's by the reprojection's rounding.
pub const COMBINE_SNAP: f32 = 0.01;

/// The older texel a pixel combines with (mirror of WGSL `CombineRead`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CombineRead {
    /// The older texel.
    pub texel: UVec2,
    /// The older color to show.
    pub color: Vec4,
    /// False: no older level at this pixel; it shows the newer buffer.
    pub found: bool,
}

pub(crate) const NOT_FOUND: CombineRead = CombineRead {
    texel: UVec2::ZERO,
    color: Vec4::ZERO,
    found: false,
};

pub(crate) fn size_of(older: &LodImage) -> UVec2 {
    UVec2::new(older.width, older.height)
}

pub(crate) fn index_of(older: &LodImage, t: UVec2) -> usize {
    t.y as usize * older.width as usize + t.x as usize
}

// An image shorter than `width` x `height` (a malformed `LodImage`) reads as empty past its end:
// id 0, depth 0, a zero color, so no piece panics on it.

pub(crate) fn id_at(older: &LodImage, t: UVec2) -> u32 {
    older.ids.get(index_of(older, t)).copied().unwrap_or(0)
}

pub(crate) fn depth_at(older: &LodImage, t: UVec2) -> f32 {
    older.depths.get(index_of(older, t)).copied().unwrap_or(0.0)
}

pub(crate) fn found(older: &LodImage, texel: UVec2) -> CombineRead {
    CombineRead {
        texel,
        color: older
            .colors
            .get(index_of(older, texel))
            .copied()
            .unwrap_or_default(),
        found: true,
    }
}

/// Clip position of a combine region's vertex at `pixel` (pixels, top-left origin) on a target
/// of `size` pixels: a host draws the region (e.g. a silhouette hull) as triangles in pixels.
///
/// ```
/// # use lodkit::combine::combine_region_position;
/// # use glam::{Vec2, Vec4};
/// let size = Vec2::new(64.0, 32.0);
/// assert_eq!(combine_region_position(Vec2::ZERO, size), Vec4::new(-1.0, 1.0, 0.0, 1.0));
/// assert_eq!(combine_region_position(size, size), Vec4::new(1.0, -1.0, 0.0, 1.0));
/// ```
pub fn combine_region_position(pixel: Vec2, size: Vec2) -> Vec4 {
    Vec4::new(
        pixel.x / size.x * 2.0 - 1.0,
        1.0 - pixel.y / size.y * 2.0,
        0.0,
        1.0,
    )
}

/// An older id `word` with its display flag for this frame taken from the screen pattern value
/// `pattern` at the pixel it is displayed at, where its level is `anchored` to the screen: shown
/// next where `visibility_shown(pattern, older_tau)`. The newer level's flag is the pattern at the
/// same pixel, so the two stay complementary however the pixel moved. Other words as they are.
///
/// ```
/// # use lodkit::combine::combine_displayed_word;
/// let word = 7; // id 7, no flags
/// assert_eq!(combine_displayed_word(word, true, 0.5, 0.25), 7 | 2 << 30); // shown next
/// assert_eq!(combine_displayed_word(word | 2 << 30, true, 0.5, 0.75), 7);
/// assert_eq!(combine_displayed_word(word, false, 0.5, 0.25), 7); // not anchored: as it is
/// ```
pub fn combine_displayed_word(word: u32, anchored: bool, older_tau: f32, pattern: f32) -> u32 {
    if lod_buffer_id(word) == 0 || !anchored {
        return word;
    }
    let next = LOD_BUFFER_SHOWN_NEXT << 30;
    if crate::visibility::visibility_shown(pattern, older_tau) {
        word | next
    } else {
        word & !next
    }
}

/// How far (texels, the larger axis) the point `at` (texture-space uv) lies from the center of
/// `texel` on a `size` texture: a texel's older sample is a point of the surface a pixel sees
/// when the pixel's ray, at that texel's older depth, passes within a texel of its center.
///
/// ```
/// # use lodkit::combine::combine_ray_offset;
/// # use glam::{UVec2, Vec2};
/// let size = UVec2::new(4, 4);
/// assert_eq!(combine_ray_offset(Vec2::new(0.375, 0.625), UVec2::new(1, 2), size), 0.0);
/// assert_eq!(combine_ray_offset(Vec2::new(0.5, 0.625), UVec2::new(1, 2), size), 0.5);
/// ```
pub fn combine_ray_offset(at: Vec2, texel: UVec2, size: UVec2) -> f32 {
    let offset = (at * size.as_vec2() - (texel.as_vec2() + 0.5)).abs();
    offset.x.max(offset.y)
}

/// For a pixel whose older read `read` holds another object than `id`: the texel of the 3x3
/// block around it that holds `id` and whose older sample lies nearest the pixel's ray
/// ([`combine_ray_offset`] of the ray's point at that texel's older depth, reprojected from
/// `base` = `reproject_base(uv, new_to_old)` and moved by `motion`), if nearer than `reach`
/// texels; else `read`. A neighbour whose sample lies farther is not shown here: where the
/// older level does not cover the pixel, it shows what the read holds.
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_cover_texel(
    older: &LodImage,
    id: u32,
    read: UVec2,
    base: Vec4,
    depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
    reach: f32,
) -> UVec2 {
    let size = size_of(older);
    let mut best = read;
    let mut best_offset = reach;
    for k in 1..9 {
        let t = combine_ring_texel(read, size, k);
        if id_at(older, t) == id {
            let ray = reproject_refine(base, depth, depth_at(older, t), new_to_old).truncate();
            let offset = combine_ray_offset(ray + motion, t, size);
            if offset < best_offset {
                best = t;
                best_offset = offset;
            }
        }
    }
    best
}

/// The bilinear weights' fractions `fraction` with a value within [`COMBINE_SNAP`] of 0 or 1
/// taken as that.
///
/// ```
/// # use lodkit::combine::combine_snap;
/// # use glam::Vec2;
/// assert_eq!(combine_snap(Vec2::new(0.005, 0.3)), Vec2::new(0.0, 0.3));
/// assert_eq!(combine_snap(Vec2::new(0.995, 0.5)), Vec2::new(1.0, 0.5));
/// ```
pub fn combine_snap(fraction: Vec2) -> Vec2 {
    let near = Vec2::new(fraction.x.round_ties_even(), fraction.y.round_ties_even());
    Vec2::select(
        (fraction - near).abs().cmplt(Vec2::splat(COMBINE_SNAP)),
        near,
        fraction,
    )
}

/// The older color of object `id` at texture-space `at`: the bilinear blend of the 2x2 older
/// texels around `at` that hold `id` (weights renormalized over them, fractions snapped by
/// [`combine_snap`]); `fallback` where none does. A texel's color is its center's, and the
/// nearest one is up to half a texel off the point the pixel shows.
pub fn combine_own_color(older: &LodImage, id: u32, at: Vec2, fallback: Vec4) -> Vec4 {
    let size = size_of(older);
    let f = at * size.as_vec2() - 0.5;
    let i0 = f.floor();
    let fr = combine_snap(f - i0);
    let mut sum = Vec4::ZERO;
    let mut weight = 0.0;
    for k in 0..4u32 {
        let t = (i0 + Vec2::new((k & 1) as f32, (k >> 1) as f32)).as_ivec2();
        if t.cmplt(glam::IVec2::ZERO).any() || t.cmpge(size.as_ivec2()).any() {
            continue;
        }
        let wx = if k & 1 == 1 { fr.x } else { 1.0 - fr.x };
        let wy = if k >> 1 == 1 { fr.y } else { 1.0 - fr.y };
        let w = wx * wy;
        let texel = t.as_uvec2();
        if w > 0.0 && id_at(older, texel) == id {
            sum += w * older.colors[index_of(older, texel)];
            weight += w;
        }
    }
    if weight <= 0.0 {
        fallback
    } else {
        sum / weight
    }
}

/// The texel of the 3x3 block around `read` that does not hold `id`, nearest to `at`
/// (texture-space uv); `read` if every one holds it: what lies behind `id`'s older level where
/// that level no longer covers the pixel.
pub fn combine_other_texel(older: &LodImage, id: u32, read: UVec2, at: Vec2) -> UVec2 {
    let size = size_of(older);
    let mut best = read;
    let mut best_distance = 1.0e9;
    for k in 0..9 {
        let t = combine_ring_texel(read, size, k);
        if id_at(older, t) != id {
            let d = at * size.as_vec2() - (t.as_vec2() + 0.5);
            if d.dot(d) < best_distance {
                best = t;
                best_distance = d.dot(d);
            }
        }
    }
    best
}

/// The older read of t-instance `owner` at a pixel its older level covers (or, estimated, may
/// cover): the pixel's newer `depth` reprojected with `new_to_old` and moved by `motion`, refined
/// at the older depth found there only where that texel holds `owner` (another object's depth,
/// or the clear depth, would move the read by that surface's parallax, off the level); where
/// the read holds something else, [`combine_cover_texel`] within `reach`, read at its sample;
/// the color [`combine_own_color`].
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_read_own(
    older: &LodImage,
    owner: u32,
    uv: Vec2,
    depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
    reach: f32,
) -> CombineRead {
    let size = size_of(older);
    let base = reproject_base(uv, new_to_old);
    let first = reproject_from_base(base, depth, new_to_old).truncate() + motion;
    let mut read_at = first;
    let first_texel = combine_texel(first, size);
    if id_at(older, first_texel) == owner {
        let refined =
            reproject_refine(base, depth, depth_at(older, first_texel), new_to_old).truncate();
        let refined = refined + motion;
        read_at = if in_viewport(refined) { refined } else { first };
    }
    let mut texel = combine_texel(read_at, size);
    if id_at(older, texel) != owner {
        texel = combine_cover_texel(older, owner, texel, base, depth, new_to_old, motion, reach);
        if id_at(older, texel) == owner {
            let ray = reproject_refine(base, depth, depth_at(older, texel), new_to_old);
            read_at = ray.truncate() + motion;
        }
    }
    let mut read = found(older, texel);
    if id_at(older, texel) == owner {
        read.color = combine_own_color(older, owner, read_at, read.color);
    }
    read
}
