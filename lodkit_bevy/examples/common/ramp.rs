//! The LOD-bias ramp the custom_material and alpha_mask examples render: LOD groups under a
//! camera that holds still while the bias ramps (as a quality setting or a frame-time budget
//! would move it), so every change in the picture is LOD's. The ramp is rendered with each level
//! alone (the references), with lodkit's frame-sequential combine (`Msaa::Off`), its screen-door
//! dither (Bevy's default `Msaa::Sample4`, without and with Bevy's depth and motion-vector
//! prepass) and switching at once; each run is measured against the references
//! (`measure::Figures`).

use std::path::Path;

use bevy::prelude::*;
use lodkit::select::{LodGroup, LodSettings, TransitionMode};
use lodkit_bevy::frame_sequential::{
    FrameSequentialGroup, FrameSequentialLevels, FrameSequentialLod, FrameSequentialStats,
    LevelMaterial, LodLevel, LodLevels,
};
use serde_json::{Value, json};

use crate::frames::{Frame, strip};
use crate::headless::{
    finish_readback, harness_camera, render_target, save_png, start_readback, step,
};
use crate::measure;

/// One LOD group of the scene: where it stands, its levels (fine first), their material, the
/// view-normalized distance of its switch.
pub struct Object<M: Material> {
    pub transform: Transform,
    pub levels: [Handle<Mesh>; 2],
    pub material: Handle<M>,
    pub switch: f32,
}

/// How a run draws the objects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Technique {
    /// Level k of every object alone, as a plain mesh, with or without MSAA.
    Level(usize, Msaa),
    /// lodkit's frame-sequential combine, `Msaa::Off`.
    FrameSequential,
    /// lodkit's screen-door dither, Bevy's default MSAA.
    Dither,
    /// The same on a camera with Bevy's depth and motion-vector prepass (motion blur, depth of
    /// field): the levels' prepass must drop the pixels the dither drops.
    DitherPrepass,
    /// lodkit switching at once.
    Hard,
}

/// What one run recorded: its frames, the frames with a group in transition, the levels each
/// object drew.
pub struct Run {
    pub frames: Vec<Frame>,
    pub in_transition: usize,
    pub drawn: Vec<Vec<u8>>,
}

/// The picture: its size, background and camera.
pub struct Stage {
    pub size: (u32, u32),
    pub background: Color,
    pub camera: Transform,
}

impl Stage {
    /// The background as the frames hold it (sRGB bytes).
    pub fn background(&self) -> [u8; 3] {
        self.background.to_srgba().to_u8_array_no_alpha()
    }
}

/// Renders the ramp (one LOD bias per frame) with `technique`.
pub fn run<M: Material>(
    app: &mut App,
    stage: &Stage,
    objects: &[Object<M>],
    technique: Technique,
    biases: &[f32],
) -> Result<Run, String> {
    let world = app.world_mut();
    let (width, height) = stage.size;
    let target = render_target(world, width, height);
    let mut camera = world.spawn(harness_camera(&target, stage.background, stage.camera));
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
        Technique::DitherPrepass => {
            use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass};
            camera.insert((lod, DepthPrepass, MotionVectorPrepass));
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
    let mut spawned = Vec::new();
    for object in objects {
        let entity = match technique {
            Technique::Level(k, _) => world.spawn((
                Mesh3d(object.levels[k].clone()),
                MeshMaterial3d(object.material.clone()),
                object.transform,
            )),
            _ => world.spawn((
                LodLevels(
                    object
                        .levels
                        .iter()
                        .map(|mesh| {
                            LodLevel::new(
                                mesh.clone(),
                                LevelMaterial::custom(object.material.clone()),
                            )
                        })
                        .collect(),
                ),
                FrameSequentialGroup::new(
                    LodGroup::from_distances(&[0.0, object.switch]).map_err(|e| e.to_string())?,
                ),
                object.transform,
            )),
        };
        spawned.push(entity.id());
    }
    for _ in 0..3 {
        step(app);
    }
    let readback = start_readback(app.world_mut(), &target);
    let (mut in_transition, mut drawn) = (0, vec![Vec::new(); spawned.len()]);
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
        for (entity, seen) in spawned.iter().zip(&mut drawn) {
            if let Some(levels) = world.get::<FrameSequentialLevels>(*entity)
                && !seen.contains(&levels.drawn)
            {
                seen.push(levels.drawn);
            }
        }
    }
    let entities: Vec<Entity> = std::iter::once(camera).chain(spawned).collect();
    let frames = finish_readback(app, readback, &entities, biases.len(), stage.size)?;
    Ok(Run {
        frames,
        in_transition,
        drawn,
    })
}

/// Renders the references, then the combine, the dither (without and with a prepass) and the
/// hard switch; prints a line per run, writes `out/strip_<run>.png` (8 frames) and returns the
/// report (JSON per run). Errors: (exit code, message).
pub fn measure_all<M: Material>(
    app: &mut App,
    stage: &Stage,
    objects: &[Object<M>],
    biases: &[f32],
    out: &Path,
) -> Result<serde_json::Map<String, Value>, (u8, String)> {
    let frames = biases.len();
    let mut go = |technique| run(app, stage, objects, technique, biases).map_err(|e| (1, e));
    let plain = [
        go(Technique::Level(0, Msaa::Off))?,
        go(Technique::Level(1, Msaa::Off))?,
    ];
    let msaa = [
        go(Technique::Level(0, Msaa::Sample4))?,
        go(Technique::Level(1, Msaa::Sample4))?,
    ];
    let background = stage.background();
    if plain[0]
        .frames
        .iter()
        .all(|f| f.object_pixels(background) == 0)
    {
        return Err((1, "nothing rendered: the reference frames are empty".into()));
    }
    let mut report = serde_json::Map::new();
    for (name, technique, references) in [
        ("frame_sequential", Technique::FrameSequential, &plain),
        ("dither", Technique::Dither, &msaa),
        ("dither_prepass", Technique::DitherPrepass, &msaa),
        ("hard_switch", Technique::Hard, &plain),
    ] {
        let lodkit = go(technique)?;
        let [fine, coarse] = [&references[0].frames[..], &references[1].frames[..]];
        let figures = measure::Figures::of(
            &lodkit.frames,
            [fine, coarse],
            [fine, coarse],
            [fine, coarse],
            background,
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
        report.insert(name.into(), entry);
    }
    report.insert("frames".into(), json!(frames));
    report.insert("size".into(), json!([stage.size.0, stage.size.1]));
    Ok(report)
}

/// Parses `--out DIR --report FILE --frames N` (N at least 8); `usage` on anything else.
pub fn args(
    default_out: &str,
    usage: &str,
) -> Result<(std::path::PathBuf, Option<std::path::PathBuf>, usize), String> {
    let mut out = std::path::PathBuf::from(default_out);
    let (mut report, mut frames) = (None, 90usize);
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let value = it.next();
        match (arg.as_str(), value) {
            ("--out", Some(v)) => out = v.into(),
            ("--report", Some(v)) => report = Some(v.into()),
            ("--frames", Some(v)) if v.parse::<usize>().is_ok_and(|n| n >= 8) => {
                frames = v.parse().unwrap_or(frames);
            }
            _ => return Err(format!("bad argument `{arg}`\n{usage}")),
        }
    }
    Ok((out, report, frames))
}

/// The ramp of LOD biases: `frames` values from `from` to `to`.
pub fn biases(frames: usize, from: f32, to: f32) -> Vec<f32> {
    (0..frames)
        .map(|f| from + (to - from) * f as f32 / (frames - 1) as f32)
        .collect()
}

/// Writes the report (pretty JSON) where `--report` said.
pub fn write_report(
    path: Option<&Path>,
    report: serde_json::Map<String, Value>,
) -> Result<(), (u8, String)> {
    if let Some(path) = path {
        let text = serde_json::to_string_pretty(&Value::Object(report)).expect("JSON");
        std::fs::write(path, text).map_err(|e| (2, e.to_string()))?;
    }
    Ok(())
}
