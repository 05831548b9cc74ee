//! Geometry-aware upsampling (Yang, Sander & Lawrence 2008, eq. 1): Rust twins of
//! `lodkit::bilateral`.

use glam::{Vec2, Vec3, Vec4};

use crate::normal_distance::foreshortened_normal;

/// Sum of weights below which [`bilateral_upsample`] falls back to the sample closest in depth.
pub const BILATERAL_MIN_WEIGHT: f32 = 1e-4;

/// Gaussian range filter exp(-d^2 / (2 sigma^2)); 1 when sigma is +inf.
///
/// ```
/// # use lodkit::bilateral::bilateral_range;
/// assert_eq!(bilateral_range(0.0, 0.5), 1.0);
/// assert_eq!(bilateral_range(3.0, f32::INFINITY), 1.0);
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

/// One weight of eq. 1: tent x g(depth difference, sigma_z) x g(normal distance, sigma_n).
pub fn bilateral_weight(
    tent: f32,
    depth_diff: f32,
    normal_dist: f32,
    sigma_z: f32,
    sigma_n: f32,
) -> f32 {
    tent * bilateral_range(depth_diff, sigma_z) * bilateral_range(normal_dist, sigma_n)
}

/// Eq. 1 over 2x2 low-res samples for a full-res pixel at fraction `f` with `depth` and
/// `normal`; the sample closest in depth when the weights sum below [`BILATERAL_MIN_WEIGHT`].
///
/// ```
/// # use lodkit::bilateral::bilateral_upsample;
/// # use glam::{Vec2, Vec3, Vec4};
/// let values = [Vec4::ZERO, Vec4::ONE, Vec4::ZERO, Vec4::ONE];
/// let flat = [Vec3::Z; 4];
/// // A flat region: bilinear.
/// let v = bilateral_upsample(Vec2::new(0.25, 0.5), &values, Vec4::splat(2.0), &flat, 2.0, Vec3::Z, 0.1, 0.5);
/// assert!((v.x - 0.25).abs() < 1e-6);
/// // A depth edge: the far samples (1 and 3) do not bleed into a pixel on the near surface.
/// let v = bilateral_upsample(Vec2::new(0.5, 0.5), &values, Vec4::new(2.0, 9.0, 2.0, 9.0), &flat, 2.0, Vec3::Z, 0.1, 0.5);
/// assert!(v.x < 1e-6);
/// ```
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
    let tent = bilateral_tent(f);
    let here = foreshortened_normal(normal);
    let (mut sum, mut total, mut closest) = (Vec4::ZERO, 0.0f32, 0usize);
    for i in 0..4 {
        let n = foreshortened_normal(normals[i]).distance(here);
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
        sum / total
    }
}
