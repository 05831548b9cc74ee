//! Foreshortened distance between screen-space normals (Yang, Sander & Lawrence 2008, sec. 2.2).
//!
//! Rust twins of `lodkit::normal_distance`. Normals are in screen space: (0, 0, 1) points toward
//! the viewer. Each normal is mapped to (nx / nz, ny / nz, 1) before the Euclidean distance.

use glam::{Vec2, Vec3};

/// Smallest z used when dividing by a normal's z (1/64): a projected component never exceeds
/// 64 |n.xy|. Same value as the shader constant `NORMAL_DISTANCE_MIN_Z`.
pub const NORMAL_DISTANCE_MIN_Z: f32 = 1.0 / 64.0;

/// The normal `n` seen through the foreshortening map: (n.x / n.z, n.y / n.z), with n.z clamped
/// below by [`NORMAL_DISTANCE_MIN_Z`] so grazing and back-facing normals stay finite.
///
/// ```
/// # use lodkit::normal_distance::foreshortened_normal;
/// # use glam::{Vec2, Vec3};
/// assert_eq!(foreshortened_normal(Vec3::new(0.6, 0.0, 0.8)), Vec2::new(0.75, 0.0));
/// assert_eq!(foreshortened_normal(Vec3::X), Vec2::new(64.0, 0.0)); // grazing: guarded
/// ```
pub fn foreshortened_normal(n: Vec3) -> Vec2 {
    Vec2::new(n.x, n.y) / n.z.max(NORMAL_DISTANCE_MIN_Z)
}

/// Euclidean distance between (a.x/a.z, a.y/a.z, 1) and (b.x/b.z, b.y/b.z, 1): the range-filter
/// argument of eq. 1. Zero for equal normals; finite for any finite input (see
/// [`foreshortened_normal`] for the guard).
///
/// ```
/// # use lodkit::normal_distance::foreshortened_normal_distance;
/// # use glam::Vec3;
/// let facing = Vec3::Z;
/// let tilted = Vec3::new(0.6, 0.0, 0.8); // 36.9 degrees: tan = 0.75
/// assert!((foreshortened_normal_distance(facing, tilted) - 0.75).abs() < 1e-6);
/// assert_eq!(foreshortened_normal_distance(tilted, tilted), 0.0);
/// ```
pub fn foreshortened_normal_distance(a: Vec3, b: Vec3) -> f32 {
    foreshortened_normal(a).distance(foreshortened_normal(b))
}
