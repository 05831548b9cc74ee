//! Alpha-tested LODs (billboard impostors, foliage cards): Rust twins of `lodkit::alpha_mask`,
//! and the mask a host binds. The mask is looked up at the fragment's object-space position
//! through a rect, `uv = p.xy * rect.xy + rect.zw` (texture space, row 0 at the top); a texel
//! >= 0.5 is covered; `rect.x == 0` means no mask.

use glam::{UVec2, Vec2, Vec3, Vec4};

/// A square coverage mask, row-major from the top row, one float per texel (>= 0.5 covered).
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaMask {
    /// Width and height in texels.
    pub size: u32,
    /// `size * size` texels.
    pub texels: Vec<f32>,
}

impl AlphaMask {
    /// A 1x1 mask that covers everything: what a renderer binds when no draw has a mask.
    pub fn opaque() -> Self {
        Self {
            size: 1,
            texels: vec![1.0],
        }
    }
}

/// The rect that maps the object-space rectangle `min..max` (x right, y up) onto the whole
/// mask, its top edge (y = max.y) on row 0. Zero (no mask) for an empty rectangle.
///
/// ```
/// # use lodkit::alpha_mask::{alpha_mask_rect, alpha_mask_uv};
/// # use glam::{Vec2, Vec3};
/// let rect = alpha_mask_rect(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 2.0));
/// assert_eq!(alpha_mask_uv(Vec3::new(-1.0, 2.0, 0.3), rect), Vec2::ZERO);
/// assert_eq!(alpha_mask_uv(Vec3::new(0.0, 1.0, 0.0), rect), Vec2::splat(0.5));
/// ```
pub fn alpha_mask_rect(min: Vec2, max: Vec2) -> Vec4 {
    let size = max - min;
    if !(size.x > 0.0 && size.y > 0.0) {
        return Vec4::ZERO;
    }
    Vec4::new(1.0 / size.x, -1.0 / size.y, -min.x / size.x, max.y / size.y)
}

/// Mask uv (texture space) of object-space position `p`: `p.xy * rect.xy + rect.zw`.
pub fn alpha_mask_uv(p: Vec3, rect: Vec4) -> Vec2 {
    p.truncate() * Vec2::new(rect.x, rect.y) + Vec2::new(rect.z, rect.w)
}

/// Whether `uv` lies within the mask, [0, 1) on both axes.
pub fn alpha_mask_inside(uv: Vec2) -> bool {
    uv.cmpge(Vec2::ZERO).all() && uv.cmplt(Vec2::ONE).all()
}

/// The texel of a `size` mask at `uv` (clamped to the mask).
pub fn alpha_mask_texel(uv: Vec2, size: UVec2) -> UVec2 {
    let inside = uv.clamp(Vec2::ZERO, Vec2::ONE);
    (inside * size.as_vec2())
        .as_uvec2()
        .min(size.saturating_sub(UVec2::ONE))
}

/// Whether the fragment at object-space `p` survives the alpha test of `mask` mapped by `rect`:
/// always when `rect.x == 0` (no mask); else when `p` maps inside the mask onto a texel >= 0.5.
/// A mask without texels covers nothing.
///
/// ```
/// # use lodkit::alpha_mask::*;
/// # use glam::{Vec2, Vec3, Vec4};
/// let mask = AlphaMask { size: 2, texels: vec![1.0, 0.0, 0.0, 0.0] }; // top-left covered
/// let rect = alpha_mask_rect(Vec2::splat(-1.0), Vec2::splat(1.0));
/// assert!(alpha_mask_keep(&mask, Vec3::new(-0.5, 0.5, 0.0), rect));
/// assert!(!alpha_mask_keep(&mask, Vec3::new(0.5, 0.5, 0.0), rect));
/// assert!(!alpha_mask_keep(&mask, Vec3::new(1.5, 0.5, 0.0), rect)); // outside
/// assert!(alpha_mask_keep(&mask, Vec3::new(0.5, 0.5, 0.0), Vec4::ZERO)); // no mask
/// ```
pub fn alpha_mask_keep(mask: &AlphaMask, p: Vec3, rect: Vec4) -> bool {
    if rect.x == 0.0 {
        return true;
    }
    let uv = alpha_mask_uv(p, rect);
    if !alpha_mask_inside(uv) {
        return false;
    }
    let t = alpha_mask_texel(uv, UVec2::splat(mask.size));
    let i = (t.y * mask.size + t.x) as usize;
    mask.texels.get(i).is_some_and(|&v| v >= 0.5)
}
