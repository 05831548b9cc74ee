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

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::asset::uuid_handle;
use bevy::prelude::*;
use bevy::render::render_resource::AsBindGroup;
use bevy::shader::ShaderRef;
use lodkit::select::{LodGroup, LodSettings, TransitionMode};
use lodkit_bevy::frame_sequential::{
    FrameSequentialDefaultCamera, FrameSequentialGroup, FrameSequentialLevels, FrameSequentialLod,
    FrameSequentialLodPlugin, FrameSequentialMaterialPlugin, FrameSequentialStats, LevelMaterial,
    LodLevel, LodLevels,
};
use serde_json::{Value, json};

use frames::{Frame, strip};
use headless::{
    build_app, finish_readback, harness_camera, render_target, save_png, start_readback, step,
};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 180;
const BACKGROUND: Color = Color::srgb_u8(20, 23, 31);
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

/// How a run draws the balls.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Technique {
    /// Level k of every ball alone, as a plain `Stripes` mesh, with or without MSAA.
    Level(usize, Msaa),
    /// lodkit's frame-sequential combine, `Msaa::Off`.
    FrameSequential,
    /// lodkit's screen-door dither, Bevy's default MSAA.
    Dither,
    /// lodkit switching at once.
    Hard,
}

/// What one run recorded: its frames, the frames with a group in transition, the levels each
/// ball drew.
struct Run {
    frames: Vec<Frame>,
    in_transition: usize,
    drawn: Vec<Vec<u8>>,
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

/// Where the camera stands: about 2.5 ball radii in lodkit's view-normalized distance.
fn camera_pose() -> Transform {
    Transform::from_xyz(0.0, 1.0, 6.0).looking_at(Vec3::ZERO, Vec3::Y)
}

/// Renders the ramp (one LOD bias per frame) with `technique`.
fn run(
    app: &mut App,
    levels: &[Handle<Mesh>; 2],
    materials: &[Handle<Stripes>],
    technique: Technique,
    biases: &[f32],
) -> Result<Run, String> {
    let world = app.world_mut();
    let target = render_target(world, WIDTH, HEIGHT);
    let mut camera = world.spawn(harness_camera(&target, BACKGROUND, camera_pose()));
    let mut lod = FrameSequentialLod::default();
    lod.settings.bias = biases[0];
    match technique {
        Technique::Level(_, msaa) => {
            camera.insert(msaa);
        }
        Technique::FrameSequential => {
            camera.insert((Msaa::Off, lod));
        }
        Technique::Dither => {
            camera.insert(lod);
        }
        Technique::Hard => {
            lod.settings = LodSettings {
                transition: TransitionMode::Hard,
                ..lod.settings
            };
            camera.insert((Msaa::Off, lod));
        }
    }
    let camera = camera.id();
    let mut balls = Vec::new();
    for ((x, distance, ..), material) in BALLS.iter().zip(materials) {
        let transform = Transform::from_xyz(*x, 0.0, 0.0);
        let ball = match technique {
            Technique::Level(k, _) => world.spawn((
                Mesh3d(levels[k].clone()),
                MeshMaterial3d(material.clone()),
                transform,
            )),
            _ => world.spawn((
                LodLevels(
                    levels
                        .iter()
                        .map(|mesh| {
                            LodLevel::new(mesh.clone(), LevelMaterial::custom(material.clone()))
                        })
                        .collect(),
                ),
                FrameSequentialGroup::new(
                    LodGroup::from_distances(&[0.0, *distance]).map_err(|e| e.to_string())?,
                ),
                transform,
            )),
        };
        balls.push(ball.id());
    }
    for _ in 0..3 {
        step(app);
    }
    let readback = start_readback(app.world_mut(), &target);
    let (mut in_transition, mut drawn) = (0, vec![Vec::new(); balls.len()]);
    for &bias in biases {
        if let Some(mut lod) = app.world_mut().get_mut::<FrameSequentialLod>(camera) {
            lod.settings.bias = bias;
        }
        step(app);
        let world = app.world();
        if !matches!(technique, Technique::Level(..)) {
            in_transition +=
                usize::from(world.resource::<FrameSequentialStats>().in_transition > 0);
        }
        for (ball, seen) in balls.iter().zip(&mut drawn) {
            if let Some(levels) = world.get::<FrameSequentialLevels>(*ball)
                && !seen.contains(&levels.drawn)
            {
                seen.push(levels.drawn);
            }
        }
    }
    let entities: Vec<Entity> = std::iter::once(camera).chain(balls).collect();
    let frames = finish_readback(app, readback, &entities, biases.len(), (WIDTH, HEIGHT))?;
    Ok(Run {
        frames,
        in_transition,
        drawn,
    })
}

fn main() -> ExitCode {
    let mut out = PathBuf::from("lodkit-bevy-custom-material");
    let (mut report, mut frames) = (None, 90usize);
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let value = it.next();
        match (arg.as_str(), value) {
            ("--out", Some(v)) => out = PathBuf::from(v),
            ("--report", Some(v)) => report = Some(PathBuf::from(v)),
            ("--frames", Some(v)) if v.parse::<usize>().is_ok_and(|n| n >= 8) => {
                frames = v.parse().unwrap_or(frames);
            }
            _ => {
                eprintln!("error: bad argument `{arg}`\n{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
    match render(&out, report.as_deref(), frames) {
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
    let io = |e: std::io::Error| (2, e.to_string());
    std::fs::create_dir_all(out).map_err(io)?;
    let mut app = app();
    let world = app.world_mut();
    let mut meshes = world.resource_mut::<Assets<Mesh>>();
    let levels = [
        meshes.add(Sphere::new(1.0).mesh().uv(64, 32)),
        meshes.add(Sphere::new(1.0).mesh().uv(12, 6)),
    ];
    let mut stripes = world.resource_mut::<Assets<Stripes>>();
    let materials: Vec<Handle<Stripes>> = BALLS
        .iter()
        .map(|(_, _, warm, cool)| {
            stripes.add(Stripes {
                warm: LinearRgba::from(Color::srgb_from_array(*warm)),
                cool: LinearRgba::from(Color::srgb_from_array(*cool)),
            })
        })
        .collect();
    // The bias ramps from 1 to 2.3: the balls' view-normalized distance from about 2.5 to 5.7,
    // across every switch and its band.
    let biases: Vec<f32> = (0..frames)
        .map(|f| 1.0 + 1.3 * f as f32 / (frames - 1) as f32)
        .collect();
    let mut go =
        |technique| run(&mut app, &levels, &materials, technique, &biases).map_err(|e| (1, e));
    let plain = [
        go(Technique::Level(0, Msaa::Off))?,
        go(Technique::Level(1, Msaa::Off))?,
    ];
    let msaa = [
        go(Technique::Level(0, Msaa::Sample4))?,
        go(Technique::Level(1, Msaa::Sample4))?,
    ];
    if plain[0]
        .frames
        .iter()
        .all(|f| f.object_pixels(background()) == 0)
    {
        return Err((1, "nothing rendered: the reference frames are empty".into()));
    }
    let mut json_report = serde_json::Map::new();
    for (name, technique, references) in [
        ("frame_sequential", Technique::FrameSequential, &plain),
        ("dither", Technique::Dither, &msaa),
        ("hard_switch", Technique::Hard, &plain),
    ] {
        let lodkit = go(technique)?;
        let [fine, coarse] = [&references[0].frames[..], &references[1].frames[..]];
        let figures = measure::Figures::of(
            &lodkit.frames,
            [fine, coarse],
            [fine, coarse],
            [fine, coarse],
            background(),
        )
        .map_err(|e| (1, e.to_string()))?;
        println!(
            "{name:16} {}; {} frames in transition, levels drawn {:?}",
            figures.line(),
            lodkit.in_transition,
            lodkit.drawn
        );
        let picks: Vec<Frame> = (0..8)
            .map(|k| lodkit.frames[k * (frames - 1) / 7].clone())
            .collect();
        save_png(&strip(&picks), &out.join(format!("strip_{name}.png"))).map_err(|e| (2, e))?;
        let mut entry = figures.json();
        entry["frames_in_transition"] = json!(lodkit.in_transition);
        entry["drawn"] = json!(lodkit.drawn);
        json_report.insert(name.into(), entry);
    }
    if let Some(path) = report {
        json_report.insert("frames".into(), json!(frames));
        json_report.insert("size".into(), json!([WIDTH, HEIGHT]));
        let text = serde_json::to_string_pretty(&Value::Object(json_report)).expect("JSON");
        std::fs::write(path, text).map_err(io)?;
    }
    Ok(())
}

/// The background as the frames hold it (sRGB bytes).
fn background() -> [u8; 3] {
    BACKGROUND.to_srgba().to_u8_array_no_alpha()
}
