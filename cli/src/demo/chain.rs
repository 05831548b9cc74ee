//! The demo's generated LOD group: one bumpy sphere whose levels `lodkit::lod_chain` builds
//! (meshoptimizer's simplifier, each level's two-sided Hausdorff bound, switch distances from a
//! pixel error), shown as the scene `chain`, in which each transition of the chain (level k to
//! level k + 1) is one object standing at that transition's switch distance from the camera;
//! and the chain's section of the report: a picture of every level, its triangles, error bound
//! and switch distance.

use std::fmt::Write as _;
use std::path::Path;

use glam::{Mat3, Vec3};
use serde::Serialize;

pub use super::chain_levels::{CAMERA, chain, level_mesh, levels};
use super::scene::{DemoCamera, DemoObject, DemoScene, Shape};
use super::table::{Table, img};
use super::{DemoError, save};

/// The scene's name.
pub const SCENE: &str = "chain";

/// World scale of the sphere (its radius is about this).
const SCALE: f32 = 0.5;

/// Where the camera stands.
const EYE: [f32; 3] = [0.0, 0.8, 3.0];

/// Switch distance of each level in object units from the sphere's centre (view-normalized
/// distance times `|P[1][1]|` of the reference camera).
fn world_distances() -> Vec<f32> {
    let p11 = CAMERA.p11() as f32;
    chain()
        .switch_distances(&CAMERA)
        .expect("the reference camera is valid")
        .iter()
        .map(|d| d * p11)
        .collect()
}

impl DemoScene {
    /// The built-in scenes: `simple`, `trees`, `field` and `chain`.
    pub fn built_in() -> Vec<DemoScene> {
        vec![Self::simple(), Self::trees(), Self::field(), scene()]
    }
}

/// The scene `chain`: transition k (level k to level k + 1) is an object at the switch distance
/// of level k + 1 (scaled by [`SCALE`]) from the camera, the transitions fanned out left to
/// right, over a floor.
pub fn scene() -> DemoScene {
    let distances = world_distances();
    let transitions = levels() - 1;
    let eye = Vec3::from(EYE);
    let mut objects: Vec<DemoObject> = (0..transitions)
        .map(|k| {
            let across = if transitions > 1 {
                k as f32 / (transitions - 1) as f32 - 0.5
            } else {
                0.0
            };
            let direction = Vec3::new(0.9 * across, -0.15, -1.0).normalize();
            let centre = eye + direction * distances[k + 1] * SCALE;
            let shade = |level: usize| {
                let t = level as f32 / (levels() - 1) as f32;
                [0.9 - 0.7 * t, 0.3 + 0.3 * t, 0.15 + 0.8 * t]
            };
            DemoObject {
                fine: Shape::Chain { level: k as u32 },
                coarse: Shape::Chain {
                    level: k as u32 + 1,
                },
                fine_color: shade(k),
                coarse_color: shade(k + 1),
                position: centre.to_array(),
                scale: [SCALE; 3],
                transition: true,
                sway: 0.0,
            }
        })
        .collect();
    let floor = objects
        .iter()
        .map(|o| o.position[1])
        .fold(f32::INFINITY, f32::min)
        - SCALE * 1.2;
    objects.push(DemoObject {
        fine: Shape::Cube,
        coarse: Shape::Cube,
        fine_color: [0.55, 0.55, 0.5],
        coarse_color: [0.55, 0.55, 0.5],
        position: [0.0, floor, -6.0],
        scale: [12.0, 0.05, 12.0],
        transition: false,
        sway: 0.0,
    });
    DemoScene {
        name: SCENE.to_owned(),
        camera: DemoCamera {
            eye: EYE,
            target: [0.0, 0.2, -1.0],
            moving_eye: [0.4, 0.9, 2.5],
            fov_y: CAMERA.fov_y,
        },
        objects,
    }
}

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

/// The chain's section of `index.html`: the table of levels and their picture.
pub fn html(report: &ChainReport) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<p>Levels generated by <code>lodkit::lod_chain</code> from one bumpy sphere (radius \
         {:.3}); each object of the scene is one transition of the chain, standing at the switch \
         distance of its coarser level (times the scene's scale {SCALE}) for a camera of \
         {:.2} rad vertical field of view, {} pixels high, {} pixel of error.</p>",
        report.radius, report.camera[0], report.camera[1], report.camera[2]
    );
    h.push_str(&table(report).html());
    h.push_str(&img(
        &report.picture,
        "the chain's levels, left to right, flat-shaded (CPU rasterizer)",
    ));
    h
}

fn table(report: &ChainReport) -> Table {
    Table {
        header: &[
            "level",
            "triangles",
            "simplifier",
            "error bound (object units)",
            "meshoptimizer's estimate",
            "switch distance (view-normalized)",
            "switch distance (object units)",
        ],
        rows: report
            .levels
            .iter()
            .enumerate()
            .map(|(i, l)| {
                vec![
                    i.to_string(),
                    l.triangles.to_string(),
                    l.simplifier.clone(),
                    format!("{:.5}", l.error),
                    format!("{:.5}", l.simplifier_error),
                    format!("{:.3}", l.switch_distance),
                    format!("{:.3}", l.object_distance),
                ]
            })
            .collect(),
    }
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
