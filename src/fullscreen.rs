//! The fullscreen triangle (Rust twins of `lodkit::fullscreen`).

use glam::{Vec2, Vec4};

/// Texture-space uv of vertex `vertex_index` (0, 1 or 2): (0,0), (2,0), (0,2).
///
/// ```
/// # use lodkit::fullscreen::fullscreen_uv;
/// assert_eq!(fullscreen_uv(1), glam::Vec2::new(2.0, 0.0));
/// ```
pub fn fullscreen_uv(vertex_index: u32) -> Vec2 {
    Vec2::new(((vertex_index << 1) & 2) as f32, (vertex_index & 2) as f32)
}

/// Clip-space position of vertex `vertex_index` (z = 0, w = 1); y up, so uv (0,0) is the
/// top-left corner of the viewport.
///
/// ```
/// # use lodkit::fullscreen::fullscreen_position;
/// assert_eq!(fullscreen_position(0), glam::Vec4::new(-1.0, 1.0, 0.0, 1.0));
/// ```
pub fn fullscreen_position(vertex_index: u32) -> Vec4 {
    let uv = fullscreen_uv(vertex_index);
    Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0)
}

/// Position and uv of one fullscreen-triangle vertex (mirror of WGSL `FullscreenVertex`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FullscreenVertex {
    /// Clip-space position.
    pub position: Vec4,
    /// Texture-space uv.
    pub uv: Vec2,
}

/// Position and uv of vertex `vertex_index`.
///
/// ```
/// # use lodkit::fullscreen::fullscreen_vertex;
/// let v = fullscreen_vertex(2);
/// assert_eq!((v.position.y, v.uv.y), (-3.0, 2.0));
/// ```
pub fn fullscreen_vertex(vertex_index: u32) -> FullscreenVertex {
    FullscreenVertex {
        position: fullscreen_position(vertex_index),
        uv: fullscreen_uv(vertex_index),
    }
}
