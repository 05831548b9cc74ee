//! The combination rule of two LOD buffers (Scherzer & Wimmer 2008, sec. 3.4): Rust twins of
//! `lodkit::combine`.

use glam::Vec4;

/// One texel of a LOD buffer (mirror of WGSL `LodSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSample {
    /// Color.
    pub color: Vec4,
    /// Instance id, 0 for n-instances.
    pub id: u32,
    /// Clip depth (for the newer sample: reprojected into the older buffer's space).
    pub depth: f32,
}

/// Depth convention (`LODKIT_REVERSE_Z` in the shaders).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthConvention {
    /// 0 near, 1 far.
    #[default]
    Standard,
    /// 1 near, 0 far.
    Reversed,
}

/// Whether clip depth `a` is strictly closer than `b`.
pub fn depth_closer(a: f32, b: f32, convention: DepthConvention) -> bool {
    match convention {
        DepthConvention::Standard => a < b,
        DepthConvention::Reversed => a > b,
    }
}

/// The combined color: both ids 0 -> newer; ids differ -> closer (tie: newer); same id -> average.
///
/// ```
/// # use lodkit::combine::*;
/// # use glam::Vec4;
/// let s = |c: f32, id, depth| LodSample { color: Vec4::splat(c), id, depth };
/// assert_eq!(combine_samples(s(1.0, 0, 0.5), s(0.0, 0, 0.1), DepthConvention::Standard), Vec4::splat(1.0));
/// assert_eq!(combine_samples(s(1.0, 0, 0.5), s(0.0, 7, 0.1), DepthConvention::Standard), Vec4::splat(0.0));
/// assert_eq!(combine_samples(s(1.0, 7, 0.5), s(0.0, 7, 0.1), DepthConvention::Standard), Vec4::splat(0.5));
/// ```
pub fn combine_samples(newer: LodSample, older: LodSample, convention: DepthConvention) -> Vec4 {
    if newer.id == 0 && older.id == 0 {
        return newer.color;
    }
    if newer.id == older.id {
        return 0.5 * (newer.color + older.color);
    }
    if depth_closer(older.depth, newer.depth, convention) {
        older.color
    } else {
        newer.color
    }
}
