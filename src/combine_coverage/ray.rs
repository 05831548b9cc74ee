//! Reads along the pixel's ray: where the older level's coverage is known, the older texel is
//! looked for on the image of the pixel's ray in the older buffer, not only in the 3x3 block
//! around the first read. Camera motion moves surfaces at different depths by different amounts
//! (parallax), so the texel that holds a level, or what lies behind it, can lie a few texels
//! along that image from where the newer level's depth reprojects.

use glam::{Mat4, UVec2, Vec2, Vec4};

use crate::combine::older::{NOT_FOUND, depth_at, found, id_at, size_of};
use crate::combine::{
    COMBINE_BLOCK_REACH, CombineRead, LodImage, combine_other_texel, combine_own_color,
    combine_ray_offset, combine_read_own, combine_texel,
};
use crate::reproject::{in_viewport, reproject_base, reproject_from_base, reproject_refine};

use super::combine_by_silhouette;

/// Texels [`combine_ray_texel`] steps along the pixel's ray, each way.
pub const COMBINE_RAY_STEPS: u32 = 6;

/// How far (texels, the larger axis) an older sample may lie from the pixel's ray for
/// [`combine_ray_texel`] to take it: half a texel, and a quarter more for the depth buffer's
/// rounding and a silhouette's edge.
pub const COMBINE_RAY_REACH: f32 = 0.75;

/// The older texel on the pixel's ray (`base` = `reproject_base` under `new_to_old`, moved by
/// `motion`) that holds `id` (`owned`) or any other id (`!owned`) but a t-instance whose record
/// in `data` gives its silhouette as its coverage ([`combine_by_silhouette`]: such a level shows
/// at the pixel only where its silhouette covers it, and
/// [`combine_read_silhouettes`](super::combine_read_silhouettes) reads those), Rust twin of
/// `combine_ray_texel`: stepping a texel at a time along the ray's image in the older buffer from
/// the reprojection of `depth`, both ways, nearest first, up to [`COMBINE_RAY_STEPS`]; the first
/// whose older sample, refined at its own depth, lies within [`COMBINE_RAY_REACH`] of it;
/// `owned`, where none does, the nearest of the texels it visited, if within
/// [`COMBINE_BLOCK_REACH`] (the level covers the pixel, so only its color is looked for: an
/// object that moves by itself, read without its motion, can put its edge texels a little
/// farther off). None where no such texel is. (`data` is read only where `!owned`.)
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_ray_texel(
    older: &LodImage,
    data: &[[u32; 4]],
    id: u32,
    owned: bool,
    base: Vec4,
    depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
) -> Option<UVec2> {
    let size = size_of(older);
    let texels = size.as_vec2();
    let a = reproject_from_base(base, depth, new_to_old).truncate() + motion;
    // A second point of the ray at another finite depth gives the ray's image its direction.
    let other = if depth < 0.5 {
        depth * 0.5 + 0.5
    } else {
        depth * 0.5
    };
    let along = (reproject_from_base(base, other, new_to_old).truncate() + motion - a) * texels;
    let length = along.length();
    let stride = if length > 1.0e-3 {
        along / length.max(1.0e-3)
    } else {
        Vec2::ZERO
    } / texels;
    let mut nearest: Option<(UVec2, f32)> = None;
    for k in 0..=2 * COMBINE_RAY_STEPS {
        let j = k.div_ceil(2) as f32 * if k & 1 == 1 { 1.0 } else { -1.0 };
        let at = a + j * stride;
        if !in_viewport(at) {
            continue;
        }
        let t = combine_texel(at, size);
        let held = id_at(older, t);
        if (held == id) != owned || (!owned && combine_by_silhouette(data, held)) {
            continue;
        }
        let ray = reproject_refine(base, depth, depth_at(older, t), new_to_old).truncate() + motion;
        let offset = combine_ray_offset(ray, t, size);
        if offset < COMBINE_RAY_REACH {
            return Some(t);
        }
        if owned && offset < nearest.map_or(COMBINE_BLOCK_REACH, |(_, o)| o) {
            nearest = Some((t, offset));
        }
    }
    nearest.map(|(t, _)| t)
}

/// The read of `owner`'s older level where its coverage is known to include the pixel, Rust
/// twin of `combine_read_known`: [`combine_read_own`] within the 3x3 block; where that finds no
/// texel of `owner`, the one [`combine_ray_texel`] finds on the pixel's ray (`data` passed on
/// to it); not found where none is (the older buffer does not hold that part of the level, and another object's texel
/// would show through it).
pub fn combine_read_known(
    older: &LodImage,
    data: &[[u32; 4]],
    owner: u32,
    uv: Vec2,
    depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
) -> CombineRead {
    let read = combine_read_own(
        older,
        owner,
        uv,
        depth,
        new_to_old,
        motion,
        COMBINE_BLOCK_REACH,
    );
    if id_at(older, read.texel) == owner {
        return read;
    }
    let base = reproject_base(uv, new_to_old);
    let Some(hit) = combine_ray_texel(older, data, owner, true, base, depth, new_to_old, motion)
    else {
        return NOT_FOUND;
    };
    let at = reproject_refine(base, depth, depth_at(older, hit), new_to_old).truncate() + motion;
    let mut read = found(older, hit);
    read.color = combine_own_color(older, owner, at, read.color);
    read
}

/// The older texel showing what lies behind `id`'s older level at the pixel, where that level
/// is known not to cover it, Rust twin of `combine_behind_texel`: [`combine_ray_texel`]'s texel
/// of another id on the pixel's ray (`base`, `depth`: the newer level's; not a t-instance
/// covering by its silhouette, `data`); where none is, [`combine_other_texel`] around `at`
/// (which may be such a level's texel).
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_behind_texel(
    older: &LodImage,
    data: &[[u32; 4]],
    id: u32,
    at: Vec2,
    base: Vec4,
    depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
) -> UVec2 {
    combine_ray_texel(older, data, id, false, base, depth, new_to_old, motion)
        .unwrap_or_else(|| combine_other_texel(older, id, combine_texel(at, size_of(older)), at))
}
