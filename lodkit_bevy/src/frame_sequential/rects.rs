//! The screen rectangles the combine runs over: each group's box, cut down to its bounding
//! sphere's rectangle, this frame and where the older frame had it.

use bevy::camera::primitives::MeshAabb;
use bevy::mesh::VertexAttributeValues;
use bevy::prelude::*;
use lodkit::combine::{ScreenRect, screen_rect};

use super::LodLevels;

/// Pixels the combine rectangles grow by on each side (rasterization and reprojection reach).
const RECT_DILATE: u32 = 1;

/// A group's bounds: the box, and the sphere around the box's center holding every vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct Bounds {
    pub lo: Vec3,
    pub hi: Vec3,
    pub radius: f32,
}

/// Bevy 0.20's glam and lodkit's differ in version: matrices cross as arrays.
pub(super) fn to_lodkit(m: Mat4) -> glam::Mat4 {
    glam::Mat4::from_cols_array(&m.to_cols_array())
}

/// The union of the level meshes' bounds, once every mesh is loaded.
pub(super) fn level_bounds(levels: &LodLevels, meshes: &Assets<Mesh>) -> Option<Bounds> {
    let mut boxed: Option<(Vec3, Vec3)> = None;
    for level in &levels.0 {
        let aabb = meshes.get(&level.mesh)?.get_aabb()?;
        let (lo, hi) = (Vec3::from(aabb.min()), Vec3::from(aabb.max()));
        boxed = Some(boxed.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
    }
    let (lo, hi) = boxed?;
    let center = (lo + hi) / 2.0;
    let mut radius = 0.0f32;
    for level in &levels.0 {
        let Some(VertexAttributeValues::Float32x3(positions)) = meshes
            .get(&level.mesh)
            .and_then(|m| m.attribute(Mesh::ATTRIBUTE_POSITION))
        else {
            radius = (hi - lo).length() / 2.0;
            break;
        };
        for p in positions {
            radius = radius.max(Vec3::from(*p).distance(center));
        }
    }
    Some(Bounds { lo, hi, radius })
}

/// The screen rectangle of a sphere (world `center`, `radius`) under a symmetric perspective
/// projection: the tangent planes through the eye in x and y. None where it does not apply
/// (an orthographic projection, the eye within the sphere's depth).
fn sphere_rect(
    center: Vec3,
    radius: f32,
    view_from_world: Mat4,
    clip_from_view: Mat4,
    size: UVec2,
    dilate: u32,
) -> Option<ScreenRect> {
    if clip_from_view.w_axis.w != 0.0 {
        return None;
    }
    let c = view_from_world.transform_point3(center);
    let z = -c.z;
    let denom = z * z - radius * radius;
    if z <= radius || denom <= 0.0 {
        return None;
    }
    let slopes = |a: f32| {
        let t = (a * a + denom).sqrt();
        ((a * z - radius * t) / denom, (a * z + radius * t) / denom)
    };
    let (x0, x1) = slopes(c.x);
    let (y0, y1) = slopes(c.y);
    let (w, h) = (size.x as f32, size.y as f32);
    let px = |s: f32| (clip_from_view.x_axis.x * s * 0.5 + 0.5) * w;
    let py = |s: f32| (0.5 - clip_from_view.y_axis.y * s * 0.5) * h;
    let d = dilate as f32;
    let left = (px(x0) - d).floor().clamp(0.0, w);
    let right = (px(x1) + d).ceil().clamp(0.0, w);
    let top = (py(y1) - d).floor().clamp(0.0, h);
    let bottom = (py(y0) + d).ceil().clamp(0.0, h);
    Some(ScreenRect {
        x: left as u32,
        y: top as u32,
        width: (right - left).max(0.0) as u32,
        height: (bottom - top).max(0.0) as u32,
    })
}

/// The combine rectangle of a group drawn with `model` by a camera: its box's rectangle
/// (lodkit::combine::screen_rect) cut down to its bounding sphere's. None: off screen.
pub(super) fn group_rect(
    bounds: Bounds,
    model: Mat4,
    view_from_world: Mat4,
    clip_from_view: Mat4,
    size: UVec2,
) -> Option<ScreenRect> {
    let v = |v: Vec3| glam::Vec3::from_array(v.to_array());
    let boxed = screen_rect(
        (v(bounds.lo), v(bounds.hi)),
        to_lodkit(model),
        &[to_lodkit(clip_from_view * view_from_world)],
        (size.x, size.y),
        RECT_DILATE,
    )?;
    let scale = model.to_scale_rotation_translation().0.abs().max_element();
    let center = model.transform_point3((bounds.lo + bounds.hi) / 2.0);
    match sphere_rect(
        center,
        bounds.radius * scale,
        view_from_world,
        clip_from_view,
        size,
        RECT_DILATE,
    ) {
        Some(sphere) => boxed.intersection(&sphere),
        None => Some(boxed),
    }
}
