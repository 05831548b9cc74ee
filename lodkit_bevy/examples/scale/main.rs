//! Frame-sequential LOD at scale against Bevy's own `VisibilityRange` crossfade: N groups of two
//! sphere levels on a grid, the same meshes, materials, switch distance and camera path for both,
//! each technique in an app of its own, one after the other in one run.
//!
//! ```text
//! cargo run --release --example scale [-- [--groups 100,1000,10000,100000] [--frames 48]
//!     [--size 160x90] [--report FILE]]
//! ```
//!
//! The camera flies low over the grid, so a band of groups (those whose distance is within the
//! hysteresis band of the switch distance) is in transition every frame. Both apps have what
//! their technique needs and nothing else: `Msaa::Off` (the frame-sequential combine needs it; the
//! crossfade is indifferent, and the same setting keeps the pictures alike), no prepass, no
//! tonemapping. Per technique and N it prints, and with `--report` writes as JSON, the median and
//! 90th-percentile frame time (wall clock of one `App::update` and the GPU finishing it, after
//! warm-up: labelled `wall_ms`), the GPU time of the render passes Bevy's render diagnostics time
//! with timestamps (`gpu_ms`, median), the groups in transition (median), and lodkit's CPU time
//! spent on silhouettes.
//!
//! `--auto-lod N` instead times N entities given `AutoLod` (one 65,536-triangle sphere mesh, so
//! one chain built in the background): every frame from the one that adds the component until
//! all are groups, and the frames around; it prints the median and the slowest frame in between
//! against the medians before and after, and every frame time.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;

use std::ops::Range;
use std::path::PathBuf;
use std::process::ExitCode;

use bevy::camera::RenderTarget;
use bevy::camera::visibility::VisibilityRange;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::diagnostic::DiagnosticsStore;
use bevy::platform::time::Instant;
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use lodkit::metrics::median;
use lodkit::select::{LodGroup, LodSettings, TransitionMode};
use lodkit_bevy::frame_sequential::{
    FrameSequentialGroup, FrameSequentialLod, FrameSequentialLodPlugin, FrameSequentialStats,
    LodLevel, LodLevels,
};

/// Grid spacing (world units).
const SPACING: f32 = 3.0;
/// The switch distance (world units; lodkit selects on it over |P11|).
const SWITCH: f32 = 30.0;
/// The width of the transition band (world units).
const BAND: f32 = 6.0;
/// Updates before timing: pipelines compiled, buffers grown.
const WARMUP: usize = 8;

const USAGE: &str =
    "usage: scale [--groups N[,N...]] [--frames F] [--size WxH] [--report FILE] [--auto-lod N]";

#[derive(Clone, Copy, PartialEq)]
enum Technique {
    FrameSequential,
    BevyCrossfade,
}

impl Technique {
    fn name(self) -> &'static str {
        match self {
            Self::FrameSequential => "frame_sequential",
            Self::BevyCrossfade => "bevy_crossfade",
        }
    }
}

struct Args {
    groups: Vec<usize>,
    frames: usize,
    size: UVec2,
    report: Option<PathBuf>,
    auto_lod: Option<usize>,
}

fn parse() -> Result<Args, String> {
    let mut args = Args {
        groups: vec![100, 1_000, 10_000, 100_000],
        frames: 48,
        size: UVec2::new(160, 90),
        report: None,
        auto_lod: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--groups" => {
                args.groups = value()?
                    .split(',')
                    .map(|n| n.trim().parse().map_err(|e| format!("--groups {n}: {e}")))
                    .collect::<Result<_, _>>()?;
                if args.groups.contains(&0) {
                    return Err("--groups must be at least 1".into());
                }
            }
            "--frames" => {
                args.frames = value()?.parse().map_err(|e| format!("--frames: {e}"))?;
                if args.frames < 2 {
                    return Err("--frames must be at least 2".into());
                }
            }
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or(format!("--size {v}: WxH"))?;
                let parse = |s: &str| s.parse::<u32>().ok().filter(|&n| n > 0);
                args.size = match (parse(w), parse(h)) {
                    (Some(w), Some(h)) => UVec2::new(w, h),
                    _ => return Err(format!("--size {v}: WxH, both at least 1")),
                };
            }
            "--report" => args.report = Some(value()?.into()),
            "--auto-lod" => {
                let n = value()?;
                args.auto_lod = Some(n.parse().map_err(|e| format!("--auto-lod {n}: {e}"))?);
            }
            "-h" | "--help" => return Err(String::new()),
            _ => return Err(format!("unknown argument {arg}")),
        }
    }
    Ok(args)
}

fn main() -> ExitCode {
    let args = match parse() {
        Ok(args) => args,
        Err(message) if message.is_empty() => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    if let Some(n) = args.auto_lod {
        auto_lod_frames(n, &args);
        return ExitCode::SUCCESS;
    }
    let mut rows = Vec::new();
    println!("groups  technique          median ms  p90 ms  GPU ms  in transition  silhouettes ms");
    for &n in &args.groups {
        for technique in [Technique::FrameSequential, Technique::BevyCrossfade] {
            let row = run(technique, n, &args);
            println!(
                "{n:>6}  {:<17} {:>9.2} {:>7.2} {:>7.2} {:>14} {:>15.3}",
                technique.name(),
                row.median,
                row.p90,
                row.gpu,
                row.in_transition,
                row.silhouette_ms
            );
            rows.push(serde_json::json!({
                "groups": n,
                "technique": technique.name(),
                "wall_ms_median": row.median,
                "wall_ms_p90": row.p90,
                "gpu_ms_median": row.gpu,
                "in_transition_median": row.in_transition,
                "silhouette_ms_median": row.silhouette_ms,
                "gpu_ms_median_per_pass": row.passes.iter().map(|(p, ms)| (p.clone(), serde_json::Value::from(*ms))).collect::<serde_json::Map<_, _>>(),
            }));
            let passes: Vec<String> = row
                .passes
                .iter()
                .filter(|(_, ms)| *ms >= 0.05)
                .map(|(pass, ms)| format!("{pass} {ms:.2}"))
                .collect();
            println!("        GPU ms per pass: {}", passes.join(", "));
        }
    }
    if let Some(path) = &args.report {
        let json = serde_json::json!({
            "frames": args.frames,
            "size": [args.size.x, args.size.y],
            "rows": rows,
        });
        if let Err(e) = std::fs::write(path, serde_json::to_string_pretty(&json).expect("JSON")) {
            eprintln!("error: {}: {e}", path.display());
            return ExitCode::from(2);
        }
    }
    ExitCode::SUCCESS
}

struct Row {
    median: f64,
    p90: f64,
    gpu: f64,
    in_transition: usize,
    silhouette_ms: f64,
    /// Median GPU milliseconds of each render pass Bevy's diagnostics time.
    passes: Vec<(String, f64)>,
}

/// The grid's side for `n` groups, and each group's position (centred on x, in front along -z).
fn position(n: usize, i: usize) -> Vec3 {
    let side = (n as f64).sqrt().ceil() as usize;
    let (x, z) = (i % side, i / side);
    Vec3::new(
        (x as f32 - side as f32 / 2.0) * SPACING,
        0.0,
        -(z as f32) * SPACING,
    )
}

/// The camera at `frame` of `frames`: low over the grid, flying along it.
fn camera_at(frame: usize, frames: usize) -> Transform {
    let z = 10.0 - 2.0 * SPACING * frame as f32 / frames as f32;
    Transform::from_xyz(0.0, 4.0, z).looking_at(Vec3::new(0.0, 0.0, z - 40.0), Vec3::Y)
}

/// |P11| of Bevy's default perspective (vertical field of view π/4).
fn p11() -> f32 {
    1.0 / std::f32::consts::FRAC_PI_8.tan()
}

fn run(technique: Technique, n: usize, args: &Args) -> Row {
    let mut app = headless::build_app(|app| {
        app.add_plugins(RenderDiagnosticsPlugin);
        if technique == Technique::FrameSequential {
            app.add_plugins(FrameSequentialLodPlugin);
        }
    });
    let world = app.world_mut();
    let target = headless::render_target(world, args.size.x, args.size.y);
    let mut camera = world.spawn((
        Camera3d::default(),
        RenderTarget::from(target),
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        camera_at(0, args.frames),
    ));
    if technique == Technique::FrameSequential {
        camera.insert(FrameSequentialLod {
            settings: LodSettings {
                hysteresis: BAND / p11(),
                transition: TransitionMode::Distance,
                ..default()
            },
            ..default()
        });
    }
    let camera = camera.id();
    world.spawn((
        DirectionalLight {
            shadow_maps_enabled: false,
            ..default()
        },
        Transform::from_xyz(-2.0, 4.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let meshes = {
        let mut assets = world.resource_mut::<Assets<Mesh>>();
        [
            assets.add(Sphere::new(1.0).mesh().uv(24, 12)),
            assets.add(Sphere::new(1.0).mesh().uv(8, 4)),
        ]
    };
    let materials = {
        let mut assets = world.resource_mut::<Assets<StandardMaterial>>();
        [
            assets.add(Color::srgb(0.9, 0.55, 0.2)),
            assets.add(Color::srgb(0.2, 0.7, 0.85)),
        ]
    };
    let band: Range<f32> = SWITCH - BAND / 2.0..SWITCH + BAND / 2.0;
    for i in 0..n {
        let transform = Transform::from_translation(position(n, i));
        match technique {
            Technique::FrameSequential => {
                let levels = (0..2)
                    .map(|k| LodLevel::new(meshes[k].clone(), materials[k].clone()))
                    .collect();
                let group =
                    LodGroup::from_distances(&[0.0, SWITCH / p11()]).expect("increasing distances");
                world.spawn((
                    LodLevels(levels),
                    FrameSequentialGroup::new(group),
                    transform,
                ));
            }
            Technique::BevyCrossfade => {
                let ranges = [
                    VisibilityRange {
                        start_margin: 0.0..0.0,
                        end_margin: band.clone(),
                        use_aabb: false,
                    },
                    VisibilityRange {
                        start_margin: band.clone(),
                        end_margin: f32::MAX..f32::MAX,
                        use_aabb: false,
                    },
                ];
                let root = world.spawn((transform, Visibility::default())).id();
                for (k, range) in ranges.into_iter().enumerate() {
                    world.spawn((
                        Mesh3d(meshes[k].clone()),
                        MeshMaterial3d(materials[k].clone()),
                        range,
                        Transform::IDENTITY,
                        ChildOf(root),
                    ));
                }
            }
        }
    }
    for _ in 0..WARMUP {
        headless::step(&mut app);
    }
    let mut wall = Vec::new();
    let mut gpu = Vec::new();
    let mut in_transition = Vec::new();
    let mut silhouettes = Vec::new();
    let mut seen = std::collections::HashMap::new();
    let mut passes: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
    for frame in 0..args.frames {
        *app.world_mut()
            .get_mut::<Transform>(camera)
            .expect("camera") = camera_at(frame, args.frames);
        let start = Instant::now();
        headless::step(&mut app);
        wall.push(start.elapsed().as_secs_f64() * 1e3);
        // The GPU time of every render pass reported since the last frame.
        let store = app.world().resource::<DiagnosticsStore>();
        let mut ms = 0.0;
        for d in store.iter() {
            let path = d.path().as_str();
            let Some(pass) = path
                .strip_prefix("render/")
                .and_then(|p| p.strip_suffix("/elapsed_gpu"))
            else {
                continue;
            };
            if let Some(m) = d.measurement()
                && seen.insert(d.path().clone(), m.time) != Some(m.time)
            {
                ms += m.value;
                passes.entry(pass.to_owned()).or_default().push(m.value);
            }
        }
        gpu.push(ms);
        let camera_position = camera_at(frame, args.frames).translation;
        in_transition.push(match technique {
            Technique::FrameSequential => {
                app.world().resource::<FrameSequentialStats>().in_transition
            }
            Technique::BevyCrossfade => (0..n)
                .filter(|&i| band.contains(&position(n, i).distance(camera_position)))
                .count(),
        });
        silhouettes.push(
            app.world()
                .get_resource::<FrameSequentialStats>()
                .map_or(0.0, |s| s.silhouette_time.as_secs_f64() * 1e3),
        );
    }
    Row {
        median: median(&wall),
        p90: percentile(&mut wall, 0.9),
        gpu: median(&gpu),
        in_transition: {
            in_transition.sort_unstable();
            in_transition[in_transition.len() / 2]
        },
        silhouette_ms: median(&silhouettes),
        passes: passes
            .into_iter()
            .map(|(pass, mut ms)| {
                // A pass that ran in only some frames counts 0 in the others.
                ms.resize(args.frames, 0.0);
                (pass, median(&ms))
            })
            .collect(),
    }
}

/// The `q` quantile of `values` (nearest rank; the medians are `lodkit::metrics::median`'s).
fn percentile(values: &mut [f64], q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    values[rank - 1]
}

/// Frames while `n` entities sharing one mesh get `AutoLod`: the median frame before and after,
/// and the slowest frame in between.
fn auto_lod_frames(n: usize, args: &Args) {
    use lodkit_bevy::auto_lod::{AutoLod, AutoLodStatus};
    let mut app = headless::build_app(|app| {
        app.add_plugins(FrameSequentialLodPlugin);
    });
    let world = app.world_mut();
    let target = headless::render_target(world, args.size.x, args.size.y);
    world.spawn((
        Camera3d::default(),
        RenderTarget::from(target),
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        FrameSequentialLod::default(),
        camera_at(0, args.frames),
    ));
    world.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(-2.0, 4.0, 3.0),
    ));
    let mesh = world
        .resource_mut::<Assets<Mesh>>()
        .add(Sphere::new(1.0).mesh().uv(256, 129));
    let material = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(Color::srgb(0.9, 0.55, 0.2));
    let entities: Vec<Entity> = (0..n)
        .map(|i| {
            world
                .spawn((
                    Mesh3d(mesh.clone()),
                    MeshMaterial3d(material.clone()),
                    Transform::from_translation(position(n, i)),
                ))
                .id()
        })
        .collect();
    // One group drawn from the start: the level material's pipelines are compiled before the
    // timed frames (the headless app compiles them synchronously, a one-off cost that is not
    // AutoLod's).
    let level = || LodLevel::new(mesh.clone(), material.clone());
    world.spawn((
        LodLevels(vec![level(), level()]),
        FrameSequentialGroup::new(LodGroup::from_distances(&[0.0, 1e6]).expect("increasing")),
        Transform::from_xyz(0.0, 0.0, -3.0),
    ));
    for _ in 0..WARMUP {
        headless::step(&mut app);
    }
    const AROUND: usize = 10;
    let mut times = Vec::new();
    let mut all_ready = None;
    for frame in 0..2_000 {
        if frame == AROUND {
            for &e in &entities {
                app.world_mut().entity_mut(e).insert(AutoLod::default());
            }
        }
        let start = Instant::now();
        headless::step(&mut app);
        times.push(start.elapsed().as_secs_f64() * 1e3);
        let world = app.world_mut();
        let ready = world
            .query::<&AutoLodStatus>()
            .iter(world)
            .filter(|s| matches!(s, AutoLodStatus::Ready(_)))
            .count();
        if ready == n && all_ready.is_none() {
            all_ready = Some(frame);
        }
        if all_ready.is_some_and(|f| frame >= f + AROUND) {
            break;
        }
    }
    let before = median(&times[..AROUND]);
    let after = median(&times[times.len() - AROUND..]);
    let between = &times[AROUND..times.len() - AROUND + 1];
    let worst = between.iter().copied().fold(0.0, f64::max);
    println!(
        "{n} entities, AutoLod added at frame {AROUND}, all groups at frame {}: median frame \
         {before:.2} ms before, {after:.2} ms after; in between ({} frames) median {:.2} ms, \
         slowest {worst:.2} ms",
        all_ready.map_or("never".into(), |f| f.to_string()),
        between.len(),
        median(between),
    );
    let list: Vec<String> = times.iter().map(|t| format!("{t:.1}")).collect();
    println!("frame times (ms): {}", list.join(" "));
}
