//! The generated LOD chain's figures: per level its triangles, error bound and switch distance,
//! and a picture of every level.

use std::path::Path;

use glam::{Mat3, Vec3};
use serde::Serialize;

use crate::demo::error::{DemoError, save};
use crate::demo::fixtures::chain_scene::{SCENE, world_distances};
use crate::demo::fixtures::lod_chain::{CAMERA, chain, levels};

/// One level of the chain in the report.
#[derive(Clone, Debug, Serialize)]
pub struct ChainLevelRow {
    /// Triangles.
    pub triangles: usize,
    /// Upper bound of the two-sided Hausdorff distance from the original, object units.
    pub error: f32,
    /// meshoptimizer's own error estimate (a quadric estimate, not a bound), object units.
    pub simplifier_error: f32,
    /// Which simplifier made it.
    pub simplifier: String,
    /// View-normalized switch distance for the reference camera.
    pub switch_distance: f32,
    /// The same in object units from the centre (where the scene puts the transition, times
    /// the scene's scale).
    pub object_distance: f32,
}

/// The chain's part of the report.
#[derive(Clone, Debug, Serialize)]
pub struct ChainReport {
    /// The scene that shows the chain's transitions.
    pub scene: String,
    /// The reference camera: vertical field of view (radians), viewport height and pixel error.
    pub camera: [f32; 3],
    /// Bounding-sphere radius of the base mesh, object units.
    pub radius: f32,
    /// Level by level, level 0 the original.
    pub levels: Vec<ChainLevelRow>,
    /// The picture of the levels, relative to the output folder.
    pub picture: String,
}

/// Measures the chain's figures and writes the picture of its levels into `out`.
pub fn report(out: &Path) -> Result<ChainReport, DemoError> {
    let chain = chain();
    let normalized = chain
        .switch_distances(&CAMERA)
        .map_err(|e| DemoError::Internal(e.to_string()))?;
    let levels = chain
        .levels()
        .iter()
        .zip(normalized.iter().zip(world_distances()))
        .map(|(l, (&n, w))| ChainLevelRow {
            triangles: l.triangles(),
            error: l.error(),
            simplifier_error: l.simplifier_error(),
            simplifier: format!("{:?}", l.simplifier()),
            switch_distance: n,
            object_distance: w,
        })
        .collect();
    let picture = "chain/levels.png".to_owned();
    save(&levels_picture(160), &out.join(&picture))?;
    Ok(ChainReport {
        scene: SCENE.to_owned(),
        camera: [CAMERA.fov_y, CAMERA.viewport_height, CAMERA.pixel_error],
        radius: chain.bounding_sphere().radius,
        levels,
        picture,
    })
}

/// Every level side by side, `size` pixels square each, flat-shaded with a depth buffer (an
/// orthographic view from slightly above, the sphere filling the square).
pub fn levels_picture(size: u32) -> image::RgbaImage {
    let n = levels() as u32;
    let mut sheet = image::RgbaImage::from_pixel(size * n, size, image::Rgba([255, 255, 255, 255]));
    let turn = Mat3::from_rotation_x(0.35) * Mat3::from_rotation_y(0.4);
    let light = Vec3::new(-0.4, 0.6, 0.7).normalize();
    let radius = chain().bounding_sphere().radius;
    let centre = Vec3::from(chain().bounding_sphere().center);
    for (k, level) in chain().levels().iter().enumerate() {
        let mut depth = vec![f32::NEG_INFINITY; (size * size) as usize];
        let s = size as f32 * 0.48 / radius;
        let view = |i: u32| turn * (Vec3::from(level.positions()[i as usize]) - centre);
        let screen = |v: Vec3| {
            Vec3::new(
                size as f32 * 0.5 + v.x * s,
                size as f32 * 0.5 - v.y * s,
                v.z,
            )
        };
        for t in level.indices().chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(view);
            let normal = (b - a).cross(c - a);
            // The viewer looks along -z: a triangle whose normal points away is hidden.
            if normal.z <= 0.0 {
                continue;
            }
            let shade = 0.25 + 0.75 * normal.normalize().dot(light).max(0.0);
            let grey = (shade * 235.0) as u8;
            let [a, b, c] = [a, b, c].map(screen);
            raster(size, &mut depth, [a, b, c], |x, y| {
                sheet.put_pixel(k as u32 * size + x, y, image::Rgba([grey, grey, grey, 255]));
            });
        }
    }
    sheet
}

/// Calls `put` for every pixel centre inside the screen triangle `t` that is nearer (larger z)
/// than `depth` holds, updating it.
fn raster(size: u32, depth: &mut [f32], t: [Vec3; 3], mut put: impl FnMut(u32, u32)) {
    let [a, b, c] = t;
    let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if area == 0.0 {
        return;
    }
    let lo = a.min(b).min(c).max(Vec3::ZERO);
    let hi = a.max(b).max(c).min(Vec3::splat(size as f32 - 1.0));
    for y in lo.y.floor() as u32..=hi.y.ceil().max(0.0) as u32 {
        for x in lo.x.floor() as u32..=hi.x.ceil().max(0.0) as u32 {
            if x >= size || y >= size {
                continue;
            }
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let w0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
            let w1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * a.z + w1 * b.z + w2 * c.z;
            let d = &mut depth[(y * size + x) as usize];
            if z > *d {
                *d = z;
                put(x, y);
            }
        }
    }
}
