//! One run: a camera of its own with only what its technique needs, the scene's groups, the
//! still or moving camera path, every frame read back and the fragment-shader invocations of
//! each pass counted.

use bevy::camera::RenderTarget;
use bevy::camera::visibility::VisibilityRange;
use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass};
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::diagnostic::{DiagnosticPath, DiagnosticsStore};
use bevy::platform::time::Instant;
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use lodkit::select::{LodSettings, TransitionMode};
use lodkit_bevy::frame_sequential::{
    COMBINE_PASS, FrameSequentialLod, FrameSequentialLodPlugin, FrameSequentialStats,
    OLDER_DEPTH_PASS,
};

use crate::Args;
use crate::frames::Frame;
use crate::headless::{FrameInbox, build_app, render_target, start_readback, step};
use crate::scene::{
    FRAMES, Technique, bevy_ranges, camera_at, group_position, groups, in_band, p11, spawn_groups,
};

pub const WIDTH: u32 = 320;
pub const HEIGHT: u32 = crate::scene::HEIGHT;
pub const BACKGROUND: Color = Color::srgb(0.08, 0.09, 0.12);
/// Updates to wait for the last readbacks of a run.
const DRAIN_UPDATES: usize = 12;
/// Updates at the first pose before a run is recorded: a material added this frame is ready
/// the next (Bevy prepares it after the images it binds), the camera's view resources are
/// made, and the runs start alike.
const WARMUP_UPDATES: usize = 3;
/// The passes whose fragment-shader invocations are the groups' cost (the scene has nothing
/// else), with the part of the report each adds to: Bevy's prepass, its opaque pass, lodkit's
/// older-level depth pass (depth only: no fragment stage) and lodkit's combine.
pub const PASSES: [(&str, Pass); 5] = [
    ("early prepass", Pass::Prepass),
    ("late prepass", Pass::Prepass),
    ("main_opaque_pass_3d", Pass::Opaque),
    (OLDER_DEPTH_PASS, Pass::OlderDepth),
    (COMBINE_PASS, Pass::Combine),
];

/// How many parts the fragments are reported in.
pub const PARTS: usize = 4;

/// Where fragments go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// Bevy's depth (and motion-vector) prepass.
    Prepass,
    /// Bevy's opaque main pass.
    Opaque,
    /// lodkit's older-level depth pass.
    OlderDepth,
    /// lodkit's combine.
    Combine,
}

impl Pass {
    pub const ALL: [Pass; PARTS] = [Pass::Prepass, Pass::Opaque, Pass::OlderDepth, Pass::Combine];

    pub fn name(self) -> &'static str {
        match self {
            Pass::Prepass => "prepass",
            Pass::Opaque => "opaque",
            Pass::OlderDepth => "older_depth",
            Pass::Combine => "combine",
        }
    }
}

/// A failure with its exit code.
pub struct Failure(pub u8, pub String);

/// What one run recorded.
pub struct Run {
    pub frames: Vec<Frame>,
    /// Per update: fragment-shader invocations of each [`Pass`] (in `Pass::ALL` order) reported
    /// that update (Bevy's render diagnostics arrive `latency` updates after their frame).
    pub fragments: Vec<[f64; PARTS]>,
    /// Per update: GPU milliseconds of each [`Pass`] reported that update (Bevy's render
    /// diagnostics `elapsed_gpu`, from timestamp queries; empty where the device has none).
    pub gpu_ms: Vec<[f64; PARTS]>,
    /// Per frame: whether a group was in its transition band.
    pub in_transition: Vec<bool>,
    /// Per frame: the CPU time (microseconds) the plugin spent on silhouettes, and the
    /// triangles they tested (`FrameSequentialStats`; 0 for other techniques).
    pub silhouettes: Vec<(f64, u64)>,
}

impl Run {
    /// Fragments of each pass over the frames in transition, with the diagnostics `latency`.
    pub fn transition_fragments(&self, latency: usize) -> [f64; PARTS] {
        transition_sum(&self.in_transition, &self.fragments, latency)
    }

    /// GPU milliseconds of each pass over the frames in transition (`latency` as above).
    pub fn transition_gpu_ms(&self, latency: usize) -> [f64; PARTS] {
        transition_sum(&self.in_transition, &self.gpu_ms, latency)
    }
}

/// The sum of per-update `values` over the frames in transition, read `latency` updates later.
fn transition_sum(in_transition: &[bool], values: &[[f64; PARTS]], latency: usize) -> [f64; PARTS] {
    let mut sum = [0.0; PARTS];
    for (f, _) in in_transition.iter().enumerate().filter(|(_, t)| **t) {
        if let Some(counts) = values.get(f + latency) {
            for (s, c) in sum.iter_mut().zip(counts) {
                *s += c;
            }
        }
    }
    sum
}

impl Run {}

pub struct Harness {
    app: App,
    target: Handle<Image>,
    /// The last measurement time seen per pass and diagnostic (fragments, GPU time): a pass
    /// that did not run adds nothing.
    seen: Vec<[Option<Instant>; 2]>,
}

impl Harness {
    pub fn new() -> Self {
        let mut app = build_app(|app| {
            app.add_plugins((FrameSequentialLodPlugin, RenderDiagnosticsPlugin));
        });
        let world = app.world_mut();
        let target = render_target(world, WIDTH, HEIGHT);
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
            target,
            seen: vec![[None; 2]; PASSES.len()],
        }
    }

    pub fn app(&self) -> &App {
        &self.app
    }

    /// Fragment invocations and GPU milliseconds per [`Pass`] reported since the last call.
    fn diagnostics(&mut self) -> [[f64; PARTS]; 2] {
        let store = self.app.world().resource::<DiagnosticsStore>();
        let mut sum = [[0.0; PARTS]; 2];
        for ((pass, part), seen) in PASSES.iter().zip(&mut self.seen) {
            let k = Pass::ALL.iter().position(|p| p == part).unwrap_or(0);
            for (d, name) in ["fragment_shader_invocations", "elapsed_gpu"]
                .iter()
                .enumerate()
            {
                let path = DiagnosticPath::new(format!("render/{pass}/{name}"));
                let Some(m) = store.get(&path).and_then(|d| d.measurement()) else {
                    continue;
                };
                if seen[d] != Some(m.time) {
                    seen[d] = Some(m.time);
                    sum[d][k] += m.value;
                }
            }
        }
        sum
    }

    /// One update; the fragments and GPU time reported in it.
    fn step_timed(&mut self) -> [[f64; PARTS]; 2] {
        step(&mut self.app);
        self.diagnostics()
    }

    fn step(&mut self) -> [f64; PARTS] {
        self.step_timed()[0]
    }

    /// The camera of a run: what every run has (target, clear color, no MSAA, no tonemapping
    /// or dither, so frames compare exactly), Bevy's depth and motion-vector prepass in the app
    /// that runs one anyway, and lodkit's component for frame-sequential LOD.
    fn spawn_camera(&mut self, technique: Technique, prepass: bool, args: &Args) -> Entity {
        let world = self.app.world_mut();
        let mut camera = world.spawn((
            Camera3d::default(),
            Camera {
                clear_color: ClearColorConfig::Custom(BACKGROUND),
                ..default()
            },
            RenderTarget::from(self.target.clone()),
            if args.msaa { Msaa::Sample4 } else { Msaa::Off },
            Tonemapping::None,
            DebandDither::Disabled,
            camera_at(false, 0).0,
        ));
        if prepass {
            camera.insert((DepthPrepass, MotionVectorPrepass));
        }
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
                coverage: args.coverage,
                combine_region: args.combine_region,
            });
        }
        camera.id()
    }

    /// Runs `technique` along the still or moving camera path, on a camera with Bevy's prepass
    /// or without.
    pub fn run(
        &mut self,
        technique: Technique,
        prepass: bool,
        moving: bool,
        args: &Args,
    ) -> Result<Run, Failure> {
        let camera = self.spawn_camera(technique, prepass, args);
        let world = self.app.world_mut();
        let roots = spawn_groups(world, technique);
        let place = |world: &mut World, frame: usize| {
            let (pose, bias) = camera_at(moving, frame);
            *world.get_mut::<Transform>(camera).expect("camera") = pose;
            if let Some(mut lod) = world.get_mut::<FrameSequentialLod>(camera) {
                lod.settings.bias = bias;
            }
            (pose, bias)
        };
        place(world, 0);
        for _ in 0..WARMUP_UPDATES {
            self.step();
        }
        let readback = start_readback(self.app.world_mut(), &self.target);
        let specs = groups();
        let mut run = Run {
            frames: Vec::new(),
            fragments: Vec::new(),
            gpu_ms: Vec::new(),
            in_transition: Vec::new(),
            silhouettes: Vec::new(),
        };
        for frame in 0..FRAMES {
            let world = self.app.world_mut();
            let (pose, bias) = place(world, frame);
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
            let [fragments, gpu_ms] = self.step_timed();
            run.fragments.push(fragments);
            run.gpu_ms.push(gpu_ms);
            let stats = self.app.world().resource::<FrameSequentialStats>();
            run.silhouettes.push((
                stats.silhouette_time.as_secs_f64() * 1e6,
                stats.silhouette_triangles,
            ));
        }
        for _ in 0..DRAIN_UPDATES {
            if self.app.world().resource::<FrameInbox>().0.len() >= FRAMES {
                break;
            }
            let [fragments, gpu_ms] = self.step_timed();
            run.fragments.push(fragments);
            run.gpu_ms.push(gpu_ms);
        }
        let world = self.app.world_mut();
        world.despawn(readback);
        world.despawn(camera);
        for (root, _) in roots {
            world.despawn(root);
        }
        let data = std::mem::take(&mut world.resource_mut::<FrameInbox>().0);
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
    pub fn diagnostics_latency(&mut self, args: &Args) -> Result<usize, Failure> {
        let camera = self.spawn_camera(Technique::Reference(0), false, args);
        for _ in 0..6 {
            self.step();
        }
        let roots = spawn_groups(self.app.world_mut(), Technique::Reference(0));
        let mut latency = None;
        for k in 0..10 {
            if self.step().iter().sum::<f64>() > 0.0 && latency.is_none() {
                latency = Some(k);
            }
        }
        let world = self.app.world_mut();
        world.despawn(camera);
        for (root, _) in roots {
            world.despawn(root);
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
