//! The low-resolution buffer of framebuffer LOD (Rust twins of `lodkit::gbuffer`): color at
//! location 0 and an `Rgba16Float` geometry texel (view depth, screen-space normal) at location 1.

use glam::{Vec3, Vec4};

/// Bytes per low-res pixel with an RGBA8 color: 4 + 8.
pub const BYTES_PER_PIXEL: u32 = 12;

/// Format of the geometry target.
#[cfg(feature = "wgpu")]
pub const GEOMETRY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The geometry texel: (view depth, normal).
///
/// ```
/// # use lodkit::gbuffer::*;
/// # use glam::Vec3;
/// let g = gbuffer_pack_geometry(4.5, Vec3::Z);
/// assert_eq!((gbuffer_depth(g), gbuffer_normal(g)), (4.5, Vec3::Z));
/// ```
pub fn gbuffer_pack_geometry(view_depth: f32, normal: Vec3) -> Vec4 {
    Vec4::new(view_depth, normal.x, normal.y, normal.z)
}

/// What `gbuffer_output` writes: the color and the geometry texel.
pub fn gbuffer_output(color: Vec4, view_depth: f32, normal: Vec3) -> (Vec4, Vec4) {
    (color, gbuffer_pack_geometry(view_depth, normal))
}

/// View depth of a geometry texel.
pub fn gbuffer_depth(geometry: Vec4) -> f32 {
    geometry.x
}

/// Normal of a geometry texel.
pub fn gbuffer_normal(geometry: Vec4) -> Vec3 {
    Vec3::new(geometry.y, geometry.z, geometry.w)
}
