//! Back-projection between the two LOD buffers (Scherzer & Wimmer 2008, eq. 2): Rust twins of
//! `lodkit::reproject` and the matrix the combine pass needs.

use glam::{Mat4, Vec2, Vec3, Vec4};

/// P_old V_old V_new^-1 P_new^-1: maps the newer buffer's NDC (with its stored depth) to the older
/// buffer's clip space. Works for standard, reversed and infinite projections (glam's inverse of
/// an infinite perspective is finite).
///
/// ```
/// # use lodkit::reproject::{new_to_old_matrix, reproject};
/// # use glam::{Mat4, Vec2, Vec3};
/// let p = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0);
/// let v = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
/// let m = new_to_old_matrix(&v, &p, &v, &p); // camera did not move
/// let r = reproject(Vec2::new(0.3, 0.7), 0.9, &m);
/// assert!((r - Vec3::new(0.3, 0.7, 0.9)).abs().max_element() < 1e-5);
/// ```
pub fn new_to_old_matrix(
    view_new: &Mat4,
    proj_new: &Mat4,
    view_old: &Mat4,
    proj_old: &Mat4,
) -> Mat4 {
    *proj_old * *view_old * view_new.inverse() * proj_new.inverse()
}

/// Position in the older buffer of the newer buffer's pixel at texture-space `uv` with clip
/// `depth`: (old uv, old depth); uv (-1, -1) when the point is behind the older camera.
pub fn reproject(uv: Vec2, depth: f32, new_to_old: &Mat4) -> Vec3 {
    reproject_from_base(reproject_base(uv, new_to_old), depth, new_to_old)
}

/// new_to_old x (ndc.x, ndc.y, 0, 1): the depth-independent part of [`reproject`], affine in uv.
pub fn reproject_base(uv: Vec2, new_to_old: &Mat4) -> Vec4 {
    *new_to_old * Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0)
}

/// Finishes [`reproject`] from `base` = [`reproject_base`]`(uv, new_to_old)`.
pub fn reproject_from_base(base: Vec4, depth: f32, new_to_old: &Mat4) -> Vec3 {
    let old = base + depth * new_to_old.z_axis;
    if old.w <= 0.0 {
        return Vec3::new(-1.0, -1.0, depth);
    }
    let p = old.truncate() / old.w;
    Vec3::new(p.x * 0.5 + 0.5, 0.5 - p.y * 0.5, p.z)
}

/// Reprojects the point on the ray of `base`'s pixel whose old clip depth is `old_depth` (read
/// from the older buffer at the first estimate, the reprojection of `depth`): the older surface
/// with its own parallax where the newer pixel shows another surface. Where no point of the ray
/// has that old depth, the reprojection of `depth`.
///
/// ```
/// # use lodkit::reproject::*;
/// # use glam::{Vec2, Vec3};
/// let p = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0);
/// let eye = |x| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
/// let m = new_to_old_matrix(&eye(0.2), &p, &eye(0.0), &p);
/// let base = reproject_base(Vec2::new(0.4, 0.5), &m);
/// // A surface at old depth 0.98 along this pixel's ray: refining from a far first guess finds it.
/// let want = reproject_from_base(base, 0.98, &m);
/// let got = reproject_refine(base, 0.999, want.z, &m);
/// assert!((got - want).abs().max_element() < 1e-4);
/// ```
pub fn reproject_refine(base: Vec4, depth: f32, old_depth: f32, new_to_old: &Mat4) -> Vec3 {
    // Solved for z = num / den; whether it is solved is read from num and den, not from the
    // quotient, as the shaders must (a GPU need not make a division by zero infinite or NaN).
    let c = new_to_old.z_axis;
    let num = old_depth * base.w - base.z;
    let den = c.z - old_depth * c.w;
    let solved = den.abs() >= f32::MIN_POSITIVE && num.abs() <= 3.0e38 * den.abs().min(1.0);
    reproject_from_base(base, if solved { num / den } else { depth }, new_to_old)
}

/// Whether `uv` lies inside the older buffer ([0, 1] on both axes).
pub fn in_viewport(uv: Vec2) -> bool {
    uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all()
}
