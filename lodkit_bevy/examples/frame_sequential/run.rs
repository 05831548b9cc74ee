//! The runs: references (one level alone), lodkit's frame-sequential LOD and Bevy's crossfade,
//! each with the still and the moving camera, every frame read back; then the report.

use std::path::Path;

use bevy::camera::RenderTarget;
use bevy::camera::visibility::VisibilityRange;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::diagnostic::{DiagnosticPath, DiagnosticsStore};
use bevy::platform::time::Instant;
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use lodkit::select::{LodSettings, TransitionMode};
use lodkit_bevy::frame_sequential::{
    COMBINE_PASS, FrameSequentialLod, FrameSequentialLodPlugin, FrameSequentialStats,
};

use crate::Args;
use crate::frames::{Frame, strip};
use crate::headless::{build_app, render_target, save_png, step};
use crate::measure::{coverage, pop, see_through};
use crate::scene::{
    FRAMES, Technique, bevy_ranges, camera_at, group_position, groups, in_band, p11, spawn_groups,
};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 192;
const BACKGROUND: Color = Color::srgb(0.08, 0.09, 0.12);
/// Updates to wait for the last readbacks of a run.
const DRAIN_UPDATES: usize = 12;
/// Updates at the first pose before a run is recorded: a material added this frame is ready
/// the next (Bevy prepares it after the images it binds), and the runs start alike.
const WARMUP_UPDATES: usize = 3;
/// The passes whose fragment-shader invocations are the groups' cost (the scene has nothing
/// else): Bevy's prepass and opaque pass, and lodkit's combine.
const PASSES: [&str; 4] = [
    "early prepass",
    "late prepass",
    "main_opaque_pass_3d",
    COMBINE_PASS,
];

/// A failure with its exit code.
pub struct Failure(pub u8, pub String);

fn io(message: String) -> Failure {
    Failure(2, message)
}

/// Frames read back, in order.
#[derive(Resource, Default)]
struct Inbox(Vec<Vec<u8>>);

/// What one run recorded.
struct Run {
    frames: Vec<Frame>,
    /// Per update: fragment-shader invocations of PASSES reported that update (Bevy's render
    /// diagnostics arrive `latency` updates after their frame).
    fragments: Vec<f64>,
    /// Per frame: whether a group was in its transition band.
    in_transition: Vec<bool>,
}

struct Harness {
    app: App,
    camera: Entity,
    target: Handle<Image>,
    /// The last measurement time seen per pass (a pass that did not run adds nothing).
    seen: Vec<Option<Instant>>,
}

impl Harness {
    fn new() -> Self {
        let mut app = build_app(|app| {
            app.add_plugins((FrameSequentialLodPlugin, RenderDiagnosticsPlugin))
                .init_resource::<Inbox>();
        });
        let world = app.world_mut();
        let target = render_target(world, WIDTH, HEIGHT);
        let camera = world
            .spawn((
                Camera3d::default(),
                Camera {
                    clear_color: ClearColorConfig::Custom(BACKGROUND),
                    ..default()
                },
                RenderTarget::from(target.clone()),
                Msaa::Off,
                Tonemapping::None,
                DebandDither::Disabled,
                camera_at(false, 0).0,
            ))
            .id();
        world.spawn((
            DirectionalLight {
                shadow_maps_enabled: false,
                illuminance: 6000.0,
                ..default()
            },
            Transform::from_xyz(-2.0, 4.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        Self {
            app,
            camera,
            target,
            seen: vec![None; PASSES.len()],
        }
    }

    /// Fragment invocations the passes reported since the last call.
    fn fragments(&mut self) -> f64 {
        let store = self.app.world().resource::<DiagnosticsStore>();
        let mut sum = 0.0;
        for (pass, seen) in PASSES.iter().zip(&mut self.seen) {
            let path = DiagnosticPath::new(format!("render/{pass}/fragment_shader_invocations"));
            let Some(m) = store.get(&path).and_then(|d| d.measurement()) else {
                continue;
            };
            if *seen != Some(m.time) {
                *seen = Some(m.time);
                sum += m.value;
            }
        }
        sum
    }

    fn step(&mut self) -> f64 {
        step(&mut self.app);
        self.fragments()
    }

    /// Runs `technique` along the still or moving camera path.
    fn run(&mut self, technique: Technique, moving: bool, args: &Args) -> Result<Run, Failure> {
        let world = self.app.world_mut();
        let roots = spawn_groups(world, technique);
        let mut camera = world.entity_mut(self.camera);
        if technique == Technique::FrameSequential {
            camera.insert(FrameSequentialLod {
                schedule: args.schedule,
                anchor: args.anchor,
                settings: LodSettings {
                    hysteresis: crate::scene::BAND / p11(),
                    transition: TransitionMode::Distance,
                    ..default()
                },
                reprojection: args.reprojection,
            });
        } else {
            camera.remove::<FrameSequentialLod>();
        }
        let (pose, bias) = camera_at(moving, 0);
        *world.get_mut::<Transform>(self.camera).expect("camera") = pose;
        if let Some(mut lod) = world.get_mut::<FrameSequentialLod>(self.camera) {
            lod.settings.bias = bias;
        }
        for _ in 0..WARMUP_UPDATES {
            self.step();
        }
        let world = self.app.world_mut();
        world.resource_mut::<Inbox>().0.clear();
        let readback = world
            .spawn(Readback::texture(self.target.clone()))
            .observe(|done: On<ReadbackComplete>, mut inbox: ResMut<Inbox>| {
                inbox.0.push(done.data.clone());
            })
            .id();
        let specs = groups();
        let mut run = Run {
            frames: Vec::new(),
            fragments: Vec::new(),
            in_transition: Vec::new(),
        };
        for frame in 0..FRAMES {
            let (pose, bias) = camera_at(moving, frame);
            let world = self.app.world_mut();
            *world.get_mut::<Transform>(self.camera).expect("camera") = pose;
            if let Some(mut lod) = world.get_mut::<FrameSequentialLod>(self.camera) {
                lod.settings.bias = bias;
            }
            let mut banded = false;
            for (spec, (root, levels)) in specs.iter().zip(&roots) {
                let position = group_position(spec, frame);
                world
                    .get_mut::<Transform>(*root)
                    .expect("group")
                    .translation = position;
                banded |= in_band(spec, position.distance(pose.translation), bias);
                for (level, range) in levels.iter().zip(bevy_ranges(spec, bias)) {
                    *world.get_mut::<VisibilityRange>(*level).expect("level") = range;
                }
            }
            run.in_transition.push(banded);
            let fragments = self.step();
            run.fragments.push(fragments);
        }
        for _ in 0..DRAIN_UPDATES {
            if self.app.world().resource::<Inbox>().0.len() >= FRAMES {
                break;
            }
            let fragments = self.step();
            run.fragments.push(fragments);
        }
        let world = self.app.world_mut();
        world.despawn(readback);
        for (root, _) in roots {
            world.despawn(root);
        }
        let data = std::mem::take(&mut world.resource_mut::<Inbox>().0);
        if data.len() < FRAMES {
            return Err(Failure(
                1,
                format!("{} of {FRAMES} frames came back", data.len()),
            ));
        }
        run.frames = data
            .into_iter()
            .take(FRAMES)
            .map(|rgba| Frame::new(WIDTH, HEIGHT, rgba))
            .collect();
        // Let the last frames' readbacks and diagnostics come in before the next run.
        for _ in 0..4 {
            self.step();
        }
        Ok(run)
    }

    /// Updates between a frame and its render diagnostics: the first update reporting
    /// fragments after the scene appears.
    fn diagnostics_latency(&mut self) -> Result<usize, Failure> {
        for _ in 0..6 {
            self.step();
        }
        let roots = spawn_groups(self.app.world_mut(), Technique::Reference(0));
        let mut latency = None;
        for k in 0..10 {
            if self.step() > 0.0 && latency.is_none() {
                latency = Some(k);
            }
        }
        for (root, _) in roots {
            self.app.world_mut().despawn(root);
        }
        for _ in 0..6 {
            self.step();
        }
        latency.ok_or_else(|| {
            Failure(
                1,
                "no fragment counts from Bevy's render diagnostics (pipeline statistics)".into(),
            )
        })
    }
}

/// Fragments of the frames in transition, with the diagnostics `latency`.
fn transition_fragments(run: &Run, latency: usize) -> f64 {
    run.in_transition
        .iter()
        .enumerate()
        .filter(|(_, t)| **t)
        .map(|(f, _)| run.fragments.get(f + latency).copied().unwrap_or(0.0))
        .sum()
}

/// 7 frames evenly over the frames in transition.
fn strip_of(run: &Run) -> Frame {
    let frames: Vec<usize> = (0..FRAMES).filter(|&f| run.in_transition[f]).collect();
    let (first, last) = (frames[0], frames[frames.len() - 1]);
    let picks: Vec<Frame> = (0..7)
        .map(|k| run.frames[first + (last - first) * k / 6].clone())
        .collect();
    strip(&picks)
}

pub fn run(args: &Args) -> Result<(), Failure> {
    std::fs::create_dir_all(&args.out).map_err(|e| io(format!("{}: {e}", args.out.display())))?;
    let mut h = Harness::new();
    let latency = h.diagnostics_latency()?;
    println!("render diagnostics arrive {latency} update(s) after their frame");
    let background = Frame::filled(1, 1, srgb8(BACKGROUND)).rgb(0, 0);
    let mut report = serde_json::Map::new();
    let mut see = [0usize; 2];
    let mut cover = [1.0f64; 2];
    let mut fragments = [0.0f64; 2];
    for moving in [false, true] {
        let path = if moving { "moving" } else { "static" };
        let fine = h.run(Technique::Reference(0), moving, args)?;
        let coarse = h.run(Technique::Reference(1), moving, args)?;
        if fine.frames[0].object_pixels(background) == 0 {
            return Err(Failure(
                1,
                "nothing rendered: the reference frame is empty".into(),
            ));
        }
        for (i, (technique, name)) in [
            (Technique::FrameSequential, "frame_sequential"),
            (Technique::BevyCrossfade, "bevy_crossfade"),
        ]
        .into_iter()
        .enumerate()
        {
            let run = h.run(technique, moving, args)?;
            let p = pop(&run.frames, &fine.frames);
            let holes = see_through(&run.frames, &fine.frames, &coarse.frames, background);
            let shown = coverage(&run.frames, &fine.frames, &coarse.frames, background);
            let window: Vec<usize> = (0..FRAMES).filter(|&f| run.in_transition[f]).collect();
            see[i] += window.iter().map(|&f| holes[f]).sum::<usize>();
            cover[i] = window.iter().map(|&f| shown[f]).fold(cover[i], f64::min);
            fragments[i] += transition_fragments(&run, latency);
            println!(
                "{name:16} {path:6}: pop {p:.3}, see-through {} px, fragments {:.0}",
                window.iter().map(|&f| holes[f]).sum::<usize>(),
                transition_fragments(&run, latency)
            );
            report.insert(format!("pop_{name}_{path}"), p.into());
            if moving {
                let file = args.out.join(format!("strip_{name}.png"));
                save_png(&strip_of(&run), &file).map_err(io)?;
                report.insert(
                    format!("png_strip_{name}"),
                    file.display().to_string().into(),
                );
            }
        }
    }
    for (i, name) in ["frame_sequential", "bevy_crossfade"].iter().enumerate() {
        report.insert(format!("see_through_{name}"), see[i].into());
        report.insert(format!("min_coverage_{name}"), cover[i].into());
        report.insert(format!("fragments_{name}"), fragments[i].into());
    }
    report.insert(
        "fragments_ratio".into(),
        (fragments[0] / fragments[1].max(1.0)).into(),
    );
    report.insert("frames_per_run".into(), FRAMES.into());
    report.insert("size".into(), vec![WIDTH, HEIGHT].into());
    report.insert("diagnostics_latency".into(), latency.into());
    report.insert(
        "schedule".into(),
        format!("{:?}", args.schedule).to_lowercase().into(),
    );
    report.insert(
        "anchor".into(),
        format!("{:?}", args.anchor).to_lowercase().into(),
    );
    report.insert("reprojection".into(), args.reprojection.into());
    let stats = h.app.world().resource::<FrameSequentialStats>().clone();
    report.insert("frames_scheduled".into(), stats.frames.into());
    report.insert("frames_kept".into(), stats.frames_kept.into());
    let json = serde_json::to_string_pretty(&report).expect("a JSON map serializes");
    println!("{json}");
    if let Some(path) = &args.report {
        write(path, &json)?;
    }
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<(), Failure> {
    std::fs::write(path, text).map_err(|e| io(format!("{}: {e}", path.display())))
}

/// `color` as 8-bit sRGB, as the render target stores it.
fn srgb8(color: Color) -> [u8; 3] {
    let c = color.to_srgba();
    [c.red, c.green, c.blue].map(|v| (v * 255.0).round() as u8)
}
