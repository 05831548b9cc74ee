//! A glTF scene with LOD levels (`MSFT_lod`, as `lodkit lod` writes them), loaded with Bevy's own
//! glTF loader into an app whose only lodkit code is `FrameSequentialLodPlugin`: its own
//! `StandardMaterial`s, Bevy's default MSAA, and a camera walking away through the scene.
//!
//! ```text
//! cargo run --example gltf_lod [-- [--out DIR] [--report FILE] [--gltf FILE]]
//! ```
//!
//! Without `--gltf` it writes `DIR/assets/scene.gltf` (+ `scene.bin`): two spheres with a coarse
//! level each (`MSFT_lod`, `MSFT_screencoverage` for switch distance [`SWITCH`], view-normalized),
//! the second level of the second sphere with a material of its own, and a cube without
//! `MSFT_lod`; then loads it, walks the camera from near to far and writes `DIR/strip.png` and,
//! with `--report`, JSON: the groups the loader made (`groups`, each with its level count,
//! switch distances and the levels it drew), `plain_meshes` (the nodes without LOD, drawn as
//! before), `intended_switch`, and `min_object_pixels` (the fewest non-background pixels of any
//! frame). With `--gltf FILE` it loads that file (Scene 0) instead.
//!
//! Exit codes: 0 done, 1 the scene did not load or render, 2 usage or I/O error.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/gltf_scene.rs"]
mod gltf_scene;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
mod scene;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use lodkit_bevy::FrameSequentialLodPlugin;
use lodkit_bevy::frame_sequential::{FrameSequentialGroup, FrameSequentialLevels};

use frames::Frame;

/// The view-normalized distance at which the generated file's spheres switch to their coarse
/// level (written as `MSFT_screencoverage`).
const SWITCH: f32 = 3.0;
const WIDTH: u32 = 256;
const HEIGHT: u32 = 144;
const FRAMES: usize = 40;
const BACKGROUND: Color = Color::srgb_u8(20, 23, 31);

const USAGE: &str = "usage: gltf_lod [--out DIR] [--report FILE] [--gltf FILE]";

fn main() -> ExitCode {
    let mut out = PathBuf::from("lodkit-bevy-gltf-lod");
    let mut report = None;
    let mut gltf = None;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().ok_or(format!("{arg} needs a value"));
        let parsed = match arg.as_str() {
            "--out" => value().map(|v| out = v.into()),
            "--report" => value().map(|v| report = Some(PathBuf::from(v))),
            "--gltf" => value().map(|v| gltf = Some(PathBuf::from(v))),
            "-h" | "--help" => {
                println!("{USAGE}");
                return ExitCode::SUCCESS;
            }
            _ => Err(format!("unknown argument {arg}")),
        };
        if let Err(message) = parsed {
            eprintln!("error: {message}\n{USAGE}");
            return ExitCode::from(2);
        }
    }
    match run(&out, report.as_deref(), gltf.as_deref()) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}

fn run(out: &Path, report: Option<&Path>, gltf: Option<&Path>) -> Result<(), (u8, String)> {
    let io = |e: std::io::Error| (2, e.to_string());
    let (assets, file) = match gltf {
        Some(path) => {
            let path = std::fs::canonicalize(path).map_err(io)?;
            let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
            (dir, name.unwrap_or_default())
        }
        None => {
            let dir = std::fs::canonicalize(out).or_else(|_| {
                std::fs::create_dir_all(out)?;
                std::fs::canonicalize(out)
            });
            let dir = dir.map_err(io)?.join("assets");
            scene::write(&dir, SWITCH).map_err(io)?;
            (dir, "scene.gltf".to_owned())
        }
    };
    std::fs::create_dir_all(out).map_err(io)?;
    let mut app = headless::build_app_with_assets(Some(&assets), |app| {
        app.add_plugins(FrameSequentialLodPlugin);
    });
    let world = app.world_mut();
    let target = headless::render_target(world, WIDTH, HEIGHT);
    // An app's camera: Bevy's default MSAA is left as it is.
    let camera = world
        .spawn(headless::harness_camera(
            &target,
            BACKGROUND,
            Transform::default(),
        ))
        .id();
    world.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    // Until the scene is spawned and its groups made.
    if !gltf_scene::load_scene(&mut app, &file) {
        return Err((1, format!("{file} did not load")));
    }
    let Some(sphere) = gltf_scene::scene_sphere(app.world_mut()) else {
        return Err((1, format!("{file} has no mesh")));
    };
    let far = farthest_switch(app.world_mut(), sphere);
    let mut frames = Vec::new();
    // The levels each group drew, by entity.
    let mut drawn: HashMap<Entity, Vec<u8>> = HashMap::new();
    for frame in 0..FRAMES {
        *app.world_mut()
            .get_mut::<Transform>(camera)
            .expect("camera") = camera_at(sphere, far, frame);
        frames.push(headless::capture(&mut app, &target).map_err(|e| (1, e))?);
        let world = app.world_mut();
        for (group, levels) in world
            .query::<(Entity, &FrameSequentialLevels)>()
            .iter(world)
        {
            let seen = drawn.entry(group).or_default();
            if !seen.contains(&levels.drawn) {
                seen.push(levels.drawn);
            }
        }
    }
    let strip: Vec<Frame> = frames.iter().step_by(FRAMES / 8).cloned().collect();
    headless::save_png(&frames::strip(&strip), &out.join("strip.png")).map_err(|e| (2, e))?;
    let world = app.world_mut();
    let groups: Vec<serde_json::Value> = world
        .query::<(Entity, &FrameSequentialGroup)>()
        .iter(world)
        .map(|(entity, group)| {
            let drawn = drawn.get(&entity).cloned().unwrap_or_default();
            let distances: Vec<f32> = group.group.levels().iter().map(|l| l.distance).collect();
            serde_json::json!({
                "levels": distances.len(),
                "distances": distances,
                "max_distance": group.group.max_distance(),
                "drawn": drawn,
            })
        })
        .collect();
    let plain_meshes = world
        .query_filtered::<(), With<MeshMaterial3d<StandardMaterial>>>()
        .iter(world)
        .count();
    let background = frames::Frame::filled(1, 1, [20, 23, 31]).rgb(0, 0);
    let min_object_pixels = frames.iter().map(|f| f.object_pixels(background)).min();
    println!(
        "{} groups from {file}; {plain_meshes} meshes without LOD; the fewest object pixels in a frame: {}",
        groups.len(),
        min_object_pixels.unwrap_or(0)
    );
    if let Some(path) = report {
        let json = serde_json::json!({
            "groups": groups,
            "plain_meshes": plain_meshes,
            "intended_switch": SWITCH,
            "min_object_pixels": min_object_pixels,
            "frames": FRAMES,
        });
        std::fs::write(path, serde_json::to_string_pretty(&json).expect("JSON")).map_err(io)?;
    }
    Ok(())
}

/// The world distance from the scene's centre past which every group shows its last level: the
/// largest switch distance (view-normalized, so times |P11| of Bevy's default π/4 field of view
/// and the group's scale) plus the group's distance from the centre; at least 30 scene radii.
fn farthest_switch(world: &mut World, (centre, radius): (Vec3, f32)) -> f32 {
    let p11 = 1.0 / std::f32::consts::FRAC_PI_8.tan();
    world
        .query::<(&FrameSequentialGroup, &GlobalTransform)>()
        .iter(world)
        .filter_map(|(group, transform)| {
            let last = group.group.levels().last()?.distance;
            let scale = transform
                .to_scale_rotation_translation()
                .0
                .abs()
                .max_element();
            Some(last * p11 * scale + transform.translation().distance(centre))
        })
        .fold(30.0 * radius, f32::max)
}

/// The camera at `frame`: walking back from 2 scene radii from the scene's centre to 1.25 times
/// `far`, a little above it, at the same pace in log distance (each level gets its share of the
/// walk, for a small asset or a large one).
fn camera_at((centre, radius): (Vec3, f32), far: f32, frame: usize) -> Transform {
    let t = frame as f32 / (FRAMES - 1) as f32;
    let (near, far) = (2.0 * radius, 1.25 * far);
    let distance = near * (far / near).powf(t);
    let eye = centre + distance * Vec3::new(0.0, 0.25, 1.0).normalize();
    Transform::from_translation(eye).looking_at(centre, Vec3::Y)
}
