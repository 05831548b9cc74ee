//! Where the combine runs: the convex hull of a group's two silhouettes (`CombineRegion::Hulls`)
//! drawn as rows of pixels or, where a level has none, the group's screen rectangles: its box, cut
//! down to its bounding sphere's rectangle, this frame and where the older frame had it.

use bevy::camera::primitives::MeshAabb;
use bevy::mesh::VertexAttributeValues;
use bevy::prelude::*;
use lodkit::combine::{ScreenRect, merge_rects, screen_rect};
use lodkit::silhouette::{Segment, silhouette_hull};

use super::LodLevels;

/// Pixels the combine rectangles grow by on each side (rasterization and reprojection reach).
const RECT_DILATE: u32 = 1;

/// Pixels a combine hull grows by on each side. The combine changes a pixel only where one of
/// the levels covers its center or the older level's silhouette passes within
/// `SILHOUETTE_TIE` (1/1000 pixel) of it, and the CPU projects the silhouettes with other
/// rounding than the GPU the levels (millionths of the target's size; the rasterizer snaps
/// vertices to at least 1/16 pixel in Vulkan): one pixel holds all of it with room to spare.
pub(super) const HULL_DILATE: f32 = 1.0;

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

/// Rows of pixels a combine hull is drawn in: each row of the hull is one scissored rectangle,
/// its rows at multiples of 4. A software rasterizer (llvmpipe, lavapipe) shades, and counts, a
/// primitive's pixels by aligned 4x4 blocks, so the hull drawn as a fan of triangles shades the
/// blocks along every inner edge once per triangle (measured in the example: 1.10 M combine
/// invocations over such a fan against 0.74 M over the rectangles); the rows shade each block
/// once, and on a GPU their edges fall between its 2x2 quads.
const HULL_ROW: u32 = 4;

/// The combine region of a group whose older level's silhouette is `older` and whose level drawn
/// this frame has the silhouette `newer` (both found with this frame's camera and transform, on
/// a target of `size` pixels): the convex hull of both, grown by [`HULL_DILATE`], as rows of
/// [`HULL_ROW`] pixels (each as wide as the hull between its top and bottom edges), on screen.
/// None where the level drawn has no outline (nothing faces the camera) or the hull is empty:
/// the group then keeps its rectangles.
pub(super) fn group_hull(
    older: &[Segment],
    newer: &[Segment],
    size: UVec2,
) -> Option<Vec<ScreenRect>> {
    if newer.is_empty() {
        return None;
    }
    let hull = silhouette_hull(&[older, newer], HULL_DILATE);
    if hull.is_empty() {
        return None;
    }
    Some(hull_rows(&hull, size))
}

/// The rows of a convex polygon (pixels, top left origin) on a target of `size` pixels: per band
/// of [`HULL_ROW`] rows, the columns from the polygon's least x to its greatest within the band
/// (every pixel whose center the polygon holds is in one).
fn hull_rows(hull: &[glam::Vec2], size: UVec2) -> Vec<ScreenRect> {
    let (top, bottom) = hull
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
    let (w, h) = (size.x as f32, size.y as f32);
    let first = (top.max(0.0).floor() as u32) / HULL_ROW * HULL_ROW;
    let last = bottom.min(h).ceil().max(0.0) as u32;
    let mut rows = Vec::new();
    for y in (first..last).step_by(HULL_ROW as usize) {
        let (a, b) = (y as f32, (y + HULL_ROW) as f32);
        let (mut left, mut right) = (f32::INFINITY, f32::NEG_INFINITY);
        let mut take = |x: f32| {
            left = left.min(x);
            right = right.max(x);
        };
        for (k, &p) in hull.iter().enumerate() {
            let q = hull[(k + 1) % hull.len()];
            if (a..=b).contains(&p.y) {
                take(p.x);
            }
            // Where the edge from p to q crosses the band's top or bottom line.
            for line in [a, b] {
                if (p.y - line) * (q.y - line) < 0.0 {
                    take(p.x + (q.x - p.x) * (line - p.y) / (q.y - p.y));
                }
            }
        }
        let (x0, x1) = (left.floor().max(0.0), right.ceil().min(w));
        if x0 < x1 {
            rows.push(ScreenRect {
                x: x0 as u32,
                y,
                width: (x1 - x0) as u32,
                height: HULL_ROW.min(size.y - y),
            });
        }
    }
    rows
}

/// The rectangles of `rows` (rows of hulls, overlapping where groups do) merged: overlapping
/// rows of a band into their union (one row: their columns overlap), then rows of equal columns
/// one under the other into one rectangle. None overlap, and they hold the same pixels.
pub(super) fn merge_rows(rows: &[ScreenRect]) -> Vec<ScreenRect> {
    let mut rows = merge_rects(rows);
    rows.sort_by_key(|r| (r.x, r.width, r.y));
    let mut out: Vec<ScreenRect> = Vec::with_capacity(rows.len());
    for r in rows {
        match out.last_mut() {
            Some(o) if o.x == r.x && o.width == r.width && o.y + o.height == r.y => {
                o.height += r.height;
            }
            _ => out.push(r),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel center a polygon holds lies in its rows, and the rows of a disc hold fewer
    /// pixels than its square: checked pixel by pixel against the point-in-polygon test.
    #[test]
    fn hull_rows_hold_every_pixel_center_of_the_hull() {
        let size = UVec2::new(64, 48);
        let disc: Vec<glam::Vec2> = (0..40)
            .map(|k| {
                let t = k as f32 / 40.0 * std::f32::consts::TAU;
                glam::Vec2::new(30.3 + 13.7 * t.cos(), 21.6 - 17.2 * t.sin())
            })
            .collect();
        let hull = lodkit::silhouette::convex_hull(&disc, 0.0);
        let rows = merge_rows(&hull_rows(&hull, size));
        let side = |p: glam::Vec2, k: usize| {
            let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
            (b - a).perp_dot(p - a)
        };
        let inside = |p: glam::Vec2| {
            (0..hull.len()).all(|k| side(p, k) >= 0.0) || (0..hull.len()).all(|k| side(p, k) <= 0.0)
        };
        let mut held = 0;
        for y in 0..size.y {
            for x in 0..size.x {
                let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let covered = rows
                    .iter()
                    .filter(|r| {
                        (r.x..r.x + r.width).contains(&x) && (r.y..r.y + r.height).contains(&y)
                    })
                    .count();
                assert!(covered <= 1, "pixel ({x}, {y}) in {covered} rows");
                if inside(p) {
                    held += 1;
                    assert_eq!(covered, 1, "pixel ({x}, {y}) of the hull in no row");
                }
            }
        }
        let area: u64 = rows.iter().map(ScreenRect::area).sum();
        // 2 x 13.7 by 2 x 17.2 pixels: its square holds about 942.
        assert!(
            held > 700 && area < 900,
            "{held} pixels of the hull, rows of {area}"
        );
    }
}
