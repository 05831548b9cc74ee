//! Alpha-mask levels (leaves, cards, lattices): `StandardMaterial`s with `AlphaMode::Mask`,
//! used as they are. The combine knows what such a level covers from its alpha test, not from
//! its triangles: the older-level depth pass repeats the material's test (base colour alpha
//! times its texture's, against the cutoff), so a pixel between two leaves shows what is
//! behind, and a pixel on a leaf never shows the background.
//!
//! ```text
//! cargo run --example alpha_mask [-- [--out DIR] [--report FILE] [--frames N]]
//! ```
//!
//! Two LOD groups under a still camera while the LOD bias ramps (every change in the picture
//! is LOD's): a double-sided ball with round holes (a fine and a coarse sphere; a closed mesh,
//! whose triangles' silhouette would claim the holes), and a bunch of leaf cards (three crossed
//! quads, then two; an open mesh). Each is rendered with each level alone, the frame-sequential
//! combine (`Msaa::Off`), the screen-door dither (Bevy's default MSAA) and switching at once,
//! and measured as the custom_material example is: pop and flicker against each level alone,
//! see-through pixel-frames (both levels alone cover the pixel, the frame shows the
//! background) and ghost pixel-frames (neither covers, the frame shows something). Writes
//! `DIR/strip_<run>.png` and, with `--report`, the figures as JSON.
//!
//! Exit codes: 0 done, 1 nothing rendered, 2 usage or I/O error.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
#[path = "../frame_sequential/measure.rs"]
#[allow(dead_code, reason = "shared with the other examples; each uses a part")]
mod measure;
#[path = "../common/ramp.rs"]
mod ramp;

use std::process::ExitCode;

use bevy::asset::RenderAssetUsages;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use lodkit_bevy::frame_sequential::{FrameSequentialDefaultCamera, FrameSequentialLodPlugin};

use headless::build_app;
use ramp::{Object, Stage};

const USAGE: &str = "usage: alpha_mask [--out DIR] [--report FILE] [--frames N]";
/// The masks' texture size (texels a side).
const MASK_SIZE: u32 = 128;

fn main() -> ExitCode {
    let result = ramp::args("lodkit-bevy-alpha-mask", USAGE)
        .map_err(|e| (2, e))
        .and_then(|(out, report, frames)| render(&out, report.as_deref(), frames));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}

/// A mask texture: `inside(u, v)` (texel centres in 0..1) says where alpha is 1, `color` the
/// colour there.
fn mask_image(inside: impl Fn(f32, f32) -> bool, color: impl Fn(f32, f32) -> [u8; 3]) -> Image {
    let n = MASK_SIZE;
    let mut texels = Vec::with_capacity((4 * n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            let (u, v) = ((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            let [r, g, b] = color(u, v);
            texels.extend([r, g, b, if inside(u, v) { 255 } else { 0 }]);
        }
    }
    Image::new(
        Extent3d {
            width: n,
            height: n,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        texels,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    )
}

/// Where `(u, v)` lies in a grid of `cells` x `cells`: the offset from its cell's centre, in
/// cells.
fn cell_offset(u: f32, v: f32, cells: f32) -> (f32, f32) {
    ((u * cells).fract() - 0.5, (v * cells).fract() - 0.5)
}

/// Three (or two) vertical cards through the origin, 2 units wide and tall, turned evenly.
fn cards(count: usize) -> Mesh {
    let mut mesh = Rectangle::new(2.0, 2.0).mesh().build();
    for k in 1..count {
        let angle = std::f32::consts::PI * k as f32 / count as f32;
        let card = Rectangle::new(2.0, 2.0)
            .mesh()
            .build()
            .rotated_by(Quat::from_rotation_y(angle));
        mesh.merge(&card).expect("cards share their attributes");
    }
    mesh
}

fn render(
    out: &std::path::Path,
    report: Option<&std::path::Path>,
    frames: usize,
) -> Result<(), (u8, String)> {
    std::fs::create_dir_all(out).map_err(|e| (2, e.to_string()))?;
    let mut app = build_app(|app| {
        app.add_plugins(FrameSequentialLodPlugin)
            .insert_resource(FrameSequentialDefaultCamera(false));
    });
    let world = app.world_mut();
    world.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let mut images = world.resource_mut::<Assets<Image>>();
    // Round holes, 8 to a turn of the ball.
    let holes = images.add(mask_image(
        |u, v| {
            let (du, dv) = cell_offset(u, v, 8.0);
            du * du + dv * dv > 0.3 * 0.3
        },
        |u, _| [200, (120.0 + 100.0 * u) as u8, 60],
    ));
    // Leaves: an ellipse in each of 4 x 4 cells.
    let leaves = images.add(mask_image(
        |u, v| {
            let (du, dv) = cell_offset(u, v, 4.0);
            (du / 0.42).powi(2) + (dv / 0.3).powi(2) < 1.0
        },
        |u, v| [(40.0 + 60.0 * v) as u8, (120.0 + 80.0 * u) as u8, 50],
    ));
    let mut materials = world.resource_mut::<Assets<StandardMaterial>>();
    let masked = |texture| StandardMaterial {
        base_color_texture: Some(texture),
        alpha_mode: AlphaMode::Mask(0.5),
        cull_mode: None,
        double_sided: true,
        ..default()
    };
    let (ball_material, leaf_material) =
        (materials.add(masked(holes)), materials.add(masked(leaves)));
    let mut meshes = world.resource_mut::<Assets<Mesh>>();
    let objects = [
        Object {
            transform: Transform::from_xyz(-1.5, 0.0, 0.0),
            levels: [
                meshes.add(Sphere::new(1.0).mesh().uv(64, 32)),
                meshes.add(Sphere::new(1.0).mesh().uv(12, 6)),
            ],
            material: ball_material,
            switch: 3.3,
        },
        Object {
            transform: Transform::from_xyz(1.5, 0.0, 0.0),
            levels: [meshes.add(cards(3)), meshes.add(cards(2))],
            material: leaf_material,
            switch: 4.4,
        },
    ];
    let stage = Stage {
        size: (320, 180),
        background: Color::srgb_u8(20, 23, 31),
        camera: Transform::from_xyz(0.0, 1.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y),
    };
    let biases = ramp::biases(frames, 1.0, 2.3);
    let json = ramp::measure_all(&mut app, &stage, &objects, &biases, out)?;
    ramp::write_report(report, json)
}
