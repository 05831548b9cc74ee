//! Geometry-aware upsampling (Yang, Sander & Lawrence 2008, eq. 1): Rust twins of
//! `lodkit::bilateral`.

use glam::{UVec2, UVec4, Vec2, Vec3, Vec4};

use crate::normal_distance::foreshortened_normal;

/// Sum of weights below which [`bilateral_upsample`] falls back to the sample closest in depth.
pub const BILATERAL_MIN_WEIGHT: f32 = 1e-4;

/// A sigma that turns its range term off in the shaders (`BILATERAL_SIGMA_OFF` of
/// `lodkit::bilateral`): every difference over it squares to 0, so the weight is 1. The Rust
/// twins take +inf as well; a shader must not be given an infinity (WGSL, and SPIR-V without
/// float-control modes, promise nothing for one), so hosts write this instead
/// ([`gpu_sigma`]).
pub const BILATERAL_SIGMA_OFF: f32 = 1e30;

/// The sigma to hand a shader for `sigma`: [`BILATERAL_SIGMA_OFF`] for +inf (or anything above
/// it), `sigma` otherwise.
///
/// ```
/// # use lodkit::bilateral::{gpu_sigma, BILATERAL_SIGMA_OFF};
/// assert_eq!(gpu_sigma(f32::INFINITY), BILATERAL_SIGMA_OFF);
/// assert_eq!(gpu_sigma(0.25), 0.25);
/// ```
pub fn gpu_sigma(sigma: f32) -> f32 {
    sigma.min(BILATERAL_SIGMA_OFF)
}

/// The least view depth [`bilateral_relative_sigma`] takes a fraction of: a pixel with no
/// geometry (depth 0) gets a small sigma, which keeps it from mixing with geometry, not a zero
/// one, which would divide by 0.
pub const BILATERAL_MIN_VIEW_DEPTH: f32 = 1e-6;

/// A depth sigma given as a fraction of the pixel's view depth (`relative` 0.05: a sample 5 %
/// nearer or farther weighs e^-1/2), in the depth's units: the same fraction serves a near wall
/// and a distant slanted floor. [`BILATERAL_SIGMA_OFF`] (or +inf) stays off.
///
/// ```
/// # use lodkit::bilateral::{bilateral_relative_sigma, BILATERAL_SIGMA_OFF};
/// assert_eq!(bilateral_relative_sigma(0.05, 20.0), 1.0);
/// assert_eq!(bilateral_relative_sigma(BILATERAL_SIGMA_OFF, 20.0), BILATERAL_SIGMA_OFF);
/// assert_eq!(bilateral_relative_sigma(0.05, 0.0), 0.05 * 1e-6);
/// ```
pub fn bilateral_relative_sigma(relative: f32, view_depth: f32) -> f32 {
    if relative >= BILATERAL_SIGMA_OFF {
        relative
    } else {
        relative * view_depth.max(BILATERAL_MIN_VIEW_DEPTH)
    }
}

/// The range filters' sigmas of eq. 1 as lodkit's hosts take them: `lodkit`'s `UpsamplePass`
/// (`UpsampleSettings::sigmas`) and lodkit_bevy's `FramebufferLodUpsample::Bilateral`, one set of
/// names, units and defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangeSigmas {
    /// On the depth difference, as a fraction of the pixel's view depth
    /// ([`bilateral_relative_sigma`]). > 0; +inf: no depth term.
    pub depth: f32,
    /// On the foreshortened normal distance (`lodkit::normal_distance`). > 0; +inf: no normal
    /// term.
    pub normal: f32,
}

impl RangeSigmas {
    /// No range term: a plain bilinear upsample through the same pass.
    pub const OFF: Self = Self {
        depth: f32::INFINITY,
        normal: f32::INFINITY,
    };
}

impl Default for RangeSigmas {
    /// 0.05 of the view depth, 0.5 of normal distance. On the core's edge scene (its
    /// framebuffer LOD test, 160x120) the upsample gains 4.48 dB over bilinear at r = 2 and
    /// 2.93 dB at r = 4; a sweep of the depth sigma from 0.005 to 0.12 peaks at 0.02 (4.65 dB
    /// at r = 2, 2.92 at r = 4), the normal sigma moves it by under 0.05 dB from 0.3 to 0.7 (no
    /// normal term: 0.6 dB less).
    fn default() -> Self {
        Self {
            depth: 0.05,
            normal: 0.5,
        }
    }
}

/// Gaussian range filter exp(-d^2 / (2 sigma^2)); 1 when sigma is +inf or
/// [`BILATERAL_SIGMA_OFF`].
///
/// ```
/// # use lodkit::bilateral::{bilateral_range, BILATERAL_SIGMA_OFF};
/// assert_eq!(bilateral_range(0.0, 0.5), 1.0);
/// assert_eq!(bilateral_range(3.0, f32::INFINITY), 1.0);
/// assert_eq!(bilateral_range(1e5, BILATERAL_SIGMA_OFF), 1.0);
/// assert!((bilateral_range(1.0, 1.0) - (-0.5f32).exp()).abs() < 1e-7);
/// ```
pub fn bilateral_range(difference: f32, sigma: f32) -> f32 {
    let s = difference / sigma;
    (-0.5 * s * s).exp()
}

/// Tent (bilinear) weights of the 2x2 samples (order: (0,0), (1,0), (0,1), (1,1)) at fraction `f`.
///
/// ```
/// # use lodkit::bilateral::bilateral_tent;
/// # use glam::{Vec2, Vec4};
/// assert_eq!(bilateral_tent(Vec2::new(0.25, 0.5)), Vec4::new(0.375, 0.125, 0.375, 0.125));
/// ```
pub fn bilateral_tent(f: Vec2) -> Vec4 {
    Vec4::new(
        (1.0 - f.x) * (1.0 - f.y),
        f.x * (1.0 - f.y),
        (1.0 - f.x) * f.y,
        f.x * f.y,
    )
}

/// One weight of eq. 1: tent x g(depth difference, sigma_z) x g(normal distance, sigma_n),
/// evaluated as one exponential of the summed exponents (as the shaders do).
///
/// ```
/// # use lodkit::bilateral::{bilateral_range, bilateral_weight};
/// let w = bilateral_weight(0.5, 0.2, 0.1, 0.3, 0.4);
/// assert!((w - 0.5 * bilateral_range(0.2, 0.3) * bilateral_range(0.1, 0.4)).abs() < 1e-7);
/// ```
pub fn bilateral_weight(
    tent: f32,
    depth_diff: f32,
    normal_dist: f32,
    sigma_z: f32,
    sigma_n: f32,
) -> f32 {
    let z = depth_diff / sigma_z;
    let n = normal_dist / sigma_n;
    tent * (-0.5 * (z * z + n * n)).exp()
}

/// Eq. 1 over 2x2 low-res samples for a full-res pixel at fraction `f` with `depth` and
/// `normal`; the sample closest in depth when the weights sum below [`BILATERAL_MIN_WEIGHT`].
///
/// ```
/// # use lodkit::bilateral::bilateral_upsample;
/// # use glam::{UVec2, UVec4, Vec2, Vec3, Vec4};
/// let values = [Vec4::ZERO, Vec4::ONE, Vec4::ZERO, Vec4::ONE];
/// let flat = [Vec3::Z; 4];
/// // A flat region: bilinear.
/// let v = bilateral_upsample(Vec2::new(0.25, 0.5), &values, Vec4::splat(2.0), &flat, 2.0, Vec3::Z, 0.1, 0.5);
/// assert!((v.x - 0.25).abs() < 1e-6);
/// // A depth edge: the far samples (1 and 3) do not bleed into a pixel on the near surface.
/// let v = bilateral_upsample(Vec2::new(0.5, 0.5), &values, Vec4::new(2.0, 9.0, 2.0, 9.0), &flat, 2.0, Vec3::Z, 0.1, 0.5);
/// assert!(v.x < 1e-6);
/// ```
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn bilateral_upsample(
    f: Vec2,
    values: &[Vec4; 4],
    depths: Vec4,
    normals: &[Vec3; 4],
    depth: f32,
    normal: Vec3,
    sigma_z: f32,
    sigma_n: f32,
) -> Vec4 {
    bilateral_upsample_projected(
        f,
        values,
        depths,
        &normals.map(foreshortened_normal),
        depth,
        foreshortened_normal(normal),
        sigma_z,
        sigma_n,
    )
}

/// [`bilateral_upsample`] with the samples' and the pixel's normals given through the
/// foreshortening map (`projected`, `here`: [`foreshortened_normal`] of each), as the packed
/// layout stores them.
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn bilateral_upsample_projected(
    f: Vec2,
    values: &[Vec4; 4],
    depths: Vec4,
    projected: &[Vec2; 4],
    depth: f32,
    here: Vec2,
    sigma_z: f32,
    sigma_n: f32,
) -> Vec4 {
    let tent = bilateral_tent(f);
    let (mut sum, mut total, mut closest) = (Vec4::ZERO, 0.0f32, 0usize);
    for i in 0..4 {
        let n = projected[i].distance(here);
        let w = bilateral_weight(tent[i], depths[i] - depth, n, sigma_z, sigma_n);
        sum += w * values[i];
        total += w;
        if (depths[i] - depth).abs() < (depths[closest] - depth).abs() {
            closest = i;
        }
    }
    if total < BILATERAL_MIN_WEIGHT {
        values[closest]
    } else {
        sum * (1.0 / total)
    }
}

/// Continuous position of a full-res pixel (at `frag_coord`, pixel centers at .5) in L's texel
/// grid (texel centers at integers), for L drawn into `low_viewport` of a `full_size` target.
///
/// ```
/// # use lodkit::bilateral::bilateral_low_position;
/// # use glam::Vec2;
/// // r = 2: full-res pixel 3 (center 3.5) sits between L texels 1 and 2.
/// let p = bilateral_low_position(Vec2::splat(3.5), Vec2::splat(8.0), Vec2::splat(16.0));
/// assert_eq!(p, Vec2::splat(1.25));
/// ```
pub fn bilateral_low_position(frag_coord: Vec2, low_viewport: Vec2, full_size: Vec2) -> Vec2 {
    frag_coord * low_viewport / full_size - 0.5
}

/// Top-left texel of the 2x2 cell around `p`, kept inside the viewport.
pub fn bilateral_cell_origin(p: Vec2, low_viewport: Vec2) -> Vec2 {
    p.floor()
        .clamp(Vec2::ZERO, (low_viewport - 2.0).max(Vec2::ZERO))
}

/// The 2x2 cell of a full-res pixel (Rust twin of the shaders' `BilateralCell`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilateralCell {
    /// Texels 0 and 3 as (x0, y0, x1, y1), clamped to the viewport; texel 1 is (x1, y0),
    /// texel 2 (x0, y1).
    pub corners: UVec4,
    /// The pixel's fraction between them.
    pub fraction: Vec2,
}

/// The cell of the full-res pixel at `frag_coord`: what every lookup fetches.
///
/// ```
/// # use lodkit::bilateral::*;
/// # use glam::{UVec4, Vec2};
/// // r = 2, the last full-res column: the cell is clamped to the 5-texel viewport.
/// let cell = bilateral_cell(Vec2::new(9.5, 0.5), Vec2::new(5.0, 4.0), Vec2::new(10.0, 8.0));
/// assert_eq!(cell.corners, UVec4::new(3, 0, 4, 1));
/// assert_eq!(cell.fraction, Vec2::new(1.0, 0.0));
/// ```
pub fn bilateral_cell(frag_coord: Vec2, low_viewport: Vec2, full_size: Vec2) -> BilateralCell {
    let p = bilateral_low_position(frag_coord, low_viewport, full_size);
    let origin = bilateral_cell_origin(p, low_viewport);
    let last = (low_viewport - 1.0).max(Vec2::ZERO).as_uvec2();
    let first = origin.as_uvec2();
    let (t0, t3) = (first.min(last), (first + 1).min(last));
    BilateralCell {
        corners: UVec4::new(t0.x, t0.y, t3.x, t3.y),
        fraction: (p - origin).clamp(Vec2::ZERO, Vec2::ONE),
    }
}

/// Fraction between the 2x2 L texels of the full-res pixel at `frag_coord`.
pub fn bilateral_cell_fraction(frag_coord: Vec2, low_viewport: Vec2, full_size: Vec2) -> Vec2 {
    bilateral_cell(frag_coord, low_viewport, full_size).fraction
}

/// L texel `i` (0..3) of the 2x2 cell of the full-res pixel at `frag_coord`.
pub fn bilateral_cell_texel(
    frag_coord: Vec2,
    low_viewport: Vec2,
    full_size: Vec2,
    i: u32,
) -> UVec2 {
    let c = bilateral_cell(frag_coord, low_viewport, full_size).corners;
    UVec2::new(
        if i & 1 != 0 { c.z } else { c.x },
        if i & 2 != 0 { c.w } else { c.y },
    )
}

/// Eq. 1 from four fetched L texels: `colors` and `geometry` (gbuffer layout).
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn bilateral_upsample_texels(
    f: Vec2,
    colors: &[Vec4; 4],
    geometry: &[Vec4; 4],
    depth: f32,
    normal: Vec3,
    sigma_z: f32,
    sigma_n: f32,
) -> Vec4 {
    use crate::gbuffer::{gbuffer_depth, gbuffer_normal};
    let depths = Vec4::from_array(geometry.map(gbuffer_depth));
    bilateral_upsample(
        f,
        colors,
        depths,
        &geometry.map(gbuffer_normal),
        depth,
        normal,
        sigma_z,
        sigma_n,
    )
}

/// An image on the CPU: `width` and row-major texels (`Vec4` for float textures, `UVec4` for
/// the packed layout).
#[derive(Clone, Copy, Debug)]
pub struct Image<'a, T = Vec4> {
    /// Width in texels.
    pub width: u32,
    /// Texels, row-major.
    pub texels: &'a [T],
}

impl<T: Copy> Image<'_, T> {
    fn at(&self, t: UVec2) -> T {
        self.texels[(t.y * self.width + t.x) as usize]
    }

    /// The texels (order 0..3) of `cell`.
    fn cell(&self, cell: &BilateralCell) -> [T; 4] {
        let c = cell.corners;
        [(c.x, c.y), (c.z, c.y), (c.x, c.w), (c.z, c.w)].map(|(x, y)| self.at(UVec2::new(x, y)))
    }
}

/// The whole lookup on the CPU, as `bilateral_upsample_at` does on the GPU: the 2x2 L texels of
/// the full-res pixel at `frag_coord` from `low_color` and `low_geometry`, then eq. 1.
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn bilateral_upsample_at(
    low_color: Image,
    low_geometry: Image,
    low_viewport: Vec2,
    full_size: Vec2,
    frag_coord: Vec2,
    depth: f32,
    normal: Vec3,
    sigma_z: f32,
    sigma_n: f32,
) -> Vec4 {
    let cell = bilateral_cell(frag_coord, low_viewport, full_size);
    let (colors, geometry) = (low_color.cell(&cell), low_geometry.cell(&cell));
    bilateral_upsample_texels(
        cell.fraction,
        &colors,
        &geometry,
        depth,
        normal,
        sigma_z,
        sigma_n,
    )
}

/// Eq. 1 from four packed L texels ([`crate::gbuffer::gbuffer_pack_texel`]) for a full-res
/// pixel at fraction `f` with `depth` and screen `normal`.
pub fn bilateral_upsample_packed(
    f: Vec2,
    texels: &[UVec4; 4],
    depth: f32,
    normal: Vec3,
    sigma_z: f32,
    sigma_n: f32,
) -> Vec4 {
    use crate::gbuffer::{
        gbuffer_texel_color, gbuffer_texel_depth, gbuffer_texel_projected_normal,
    };
    bilateral_upsample_projected(
        f,
        &texels.map(gbuffer_texel_color),
        Vec4::from_array(texels.map(gbuffer_texel_depth)),
        &texels.map(gbuffer_texel_projected_normal),
        depth,
        foreshortened_normal(normal),
        sigma_z,
        sigma_n,
    )
}

/// The whole lookup from a packed L on the CPU, as `bilateral_upsample_packed_at` does on the
/// GPU (four texel loads): the fold-in upsample of a composite pass.
///
/// ```
/// # use lodkit::bilateral::{Image, bilateral_upsample_packed_at};
/// # use lodkit::gbuffer::gbuffer_pack_texel;
/// # use glam::{Vec2, Vec3, Vec4};
/// // A 2x1 L, near on the left and far on the right, for a 4x2 target (r = 2).
/// let texels = [
///     gbuffer_pack_texel(Vec4::new(1.0, 0.0, 0.0, 1.0), 2.0, Vec3::Z),
///     gbuffer_pack_texel(Vec4::new(0.0, 0.0, 1.0, 1.0), 9.0, Vec3::Z),
/// ];
/// let low = Image { width: 2, texels: &texels };
/// let (viewport, full) = (Vec2::new(2.0, 1.0), Vec2::new(4.0, 2.0));
/// // Pixel 2 sits between the texels; on the far surface it takes only the far one.
/// let c = bilateral_upsample_packed_at(low, viewport, full, Vec2::new(2.5, 0.5), 9.0, Vec3::Z, 0.1, 0.5);
/// assert_eq!(c, Vec4::new(0.0, 0.0, 1.0, 1.0));
/// ```
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn bilateral_upsample_packed_at(
    low: Image<UVec4>,
    low_viewport: Vec2,
    full_size: Vec2,
    frag_coord: Vec2,
    depth: f32,
    normal: Vec3,
    sigma_z: f32,
    sigma_n: f32,
) -> Vec4 {
    let cell = bilateral_cell(frag_coord, low_viewport, full_size);
    bilateral_upsample_packed(
        cell.fraction,
        &low.cell(&cell),
        depth,
        normal,
        sigma_z,
        sigma_n,
    )
}
