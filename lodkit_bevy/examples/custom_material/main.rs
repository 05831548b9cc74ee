//! A material of the app's own as the levels' material: `Stripes`, an ordinary Bevy `Material`
//! with its own WESL fragment shader (`stripes.wesl`), whose one call to
//! `lodkit_bevy::frame_sequential_level::lod_level_color` makes it take part in frame-sequential
//! LOD. The app adds `FrameSequentialMaterialPlugin::<Stripes>` and names its `Stripes` handles
//! in the levels with `LevelMaterial::custom`; nothing is converted by hand.
//!
//! ```text
//! cargo run --example custom_material [-- [--out DIR] [--report FILE] [--frames N]]
//! ```
//!
//! Three balls, each a LOD group of a fine and a coarse sphere in `Stripes`, switch at three
//! distances while the LOD bias ramps from 1 to 2.3 under a camera that holds still (as a
//! quality setting or a frame-time budget would move it), so every change in the picture is
//! LOD's. The ramp is rendered with each level alone (the same material drawn as itself: the
//! references), with lodkit's frame-sequential combine
//! (`Msaa::Off`), with lodkit's screen-door dither (Bevy's default `Msaa::Sample4`), and
//! switching at once (`TransitionMode::Hard`). Writes `DIR/strip_<run>.png` (8 frames of the
//! walk) and, with `--report`, JSON per run: pop and flicker against each level alone,
//! see-through pixel-frames (both levels alone cover the pixel, the frame shows the background)
//! and ghost pixel-frames (neither covers, the frame shows something), frames with a group in
//! transition, and the levels each group drew.
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

use bevy::asset::uuid_handle;
use bevy::prelude::*;
use bevy::render::render_resource::AsBindGroup;
use bevy::shader::ShaderRef;
use lodkit_bevy::frame_sequential::{
    FrameSequentialDefaultCamera, FrameSequentialLodPlugin, FrameSequentialMaterialPlugin,
};

use headless::build_app;
use ramp::{Object, Stage};

const STRIPES: Handle<Shader> = uuid_handle!("6c1f9a2e-3b7d-4e58-a0c4-9d2b7e5f1a36");
/// The balls: x, switch distance (view-normalized), the two colours.
const BALLS: [(f32, f32, [f32; 3], [f32; 3]); 3] = [
    (-2.4, 3.0, [0.9, 0.45, 0.15], [0.15, 0.3, 0.7]),
    (0.0, 3.8, [0.85, 0.8, 0.2], [0.55, 0.15, 0.45]),
    (2.4, 4.6, [0.3, 0.75, 0.35], [0.8, 0.8, 0.8]),
];
const USAGE: &str = "usage: custom_material [--out DIR] [--report FILE] [--frames N]";

/// The app's own material: two colours in bands, shaded by `stripes.wesl`.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
pub struct Stripes {
    #[uniform(0)]
    warm: LinearRgba,
    #[uniform(1)]
    cool: LinearRgba,
}

impl Material for Stripes {
    fn fragment_shader() -> ShaderRef {
        STRIPES.into()
    }
}

/// The example's app: the plugins a Bevy app with its own material adds.
fn app() -> App {
    let mut app = build_app(|app| {
        app.add_plugins((
            MaterialPlugin::<Stripes>::default(),
            FrameSequentialLodPlugin,
            FrameSequentialMaterialPlugin::<Stripes>::default(),
        ))
        // Each run names its camera's settings.
        .insert_resource(FrameSequentialDefaultCamera(false));
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(
                &STRIPES,
                Shader::from_wesl(include_str!("stripes.wesl"), "stripes.wesl"),
            )
            .expect("UUID handles never fail to insert");
    });
    app.world_mut().spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    app
}

fn main() -> ExitCode {
    let result = ramp::args("lodkit-bevy-custom-material", USAGE)
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

fn render(
    out: &std::path::Path,
    report: Option<&std::path::Path>,
    frames: usize,
) -> Result<(), (u8, String)> {
    std::fs::create_dir_all(out).map_err(|e| (2, e.to_string()))?;
    let mut app = app();
    let world = app.world_mut();
    let mut meshes = world.resource_mut::<Assets<Mesh>>();
    let levels = [
        meshes.add(Sphere::new(1.0).mesh().uv(64, 32)),
        meshes.add(Sphere::new(1.0).mesh().uv(12, 6)),
    ];
    let mut stripes = world.resource_mut::<Assets<Stripes>>();
    let objects: Vec<Object<Stripes>> = BALLS
        .iter()
        .map(|(x, switch, warm, cool)| Object {
            transform: Transform::from_xyz(*x, 0.0, 0.0),
            levels: levels.clone(),
            material: stripes.add(Stripes {
                warm: LinearRgba::from(Color::srgb_from_array(*warm)),
                cool: LinearRgba::from(Color::srgb_from_array(*cool)),
            }),
            switch: *switch,
        })
        .collect();
    // Where the camera stands: about 2.5 ball radii in lodkit's view-normalized distance; the
    // bias ramps from 1 to 2.3: the balls' view-normalized distance from about 2.5 to 5.7,
    // across every switch and its band.
    let stage = Stage {
        size: (320, 180),
        background: Color::srgb_u8(20, 23, 31),
        camera: Transform::from_xyz(0.0, 1.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y),
    };
    let biases = ramp::biases(frames, 1.0, 2.3);
    let json = ramp::measure_all(&mut app, &stage, &objects, &biases, out)?;
    ramp::write_report(report, json)
}
