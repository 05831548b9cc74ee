//! lodkit in Bevy 0.20.1: a complementary screen-door crossfade between two discrete LODs,
//! rendered headless and captured frame by frame.
//!
//! ```text
//! cargo run --example crossfade [-- [--check] [OUT.png]]   (default OUT: lodkit-bevy-strip.png)
//! ```
//!
//! What a Bevy application needs from lodkit (the material lives in `lod_material.rs`, the
//! part to copy):
//!
//! 1. `lodkit_bevy::LodkitShadersPlugin`: every lodkit WGSL module becomes a `Shader` asset, so a
//!    material can `#import lodkit::screen_door::screen_door_keep` (Bevy's naga_oil resolves
//!    imports through `Assets<Shader>`; lodkit is used with `default-features = false`).
//! 2. [`LodDitherMaterial`]: a `Material` whose fragment shader (`assets/shaders/lod_dither.wesl`)
//!    discards through lodkit's pattern with a signed alpha per level.
//! 3. [`LodDriver`]: `lodkit::select` decides which level(s) to draw and the transition `t`;
//!    [`apply_selection`] turns `LodSelection::screen_door_alphas()` into visibility and alphas.
//!
//! The headless loop is `../common/headless.rs`. Exit codes: 0 done, 1 nothing rendered or `--check` failed, 2 usage
//! or I/O error.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
mod lod_material;
mod transition;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bevy::camera::{CameraProjection, RenderTarget};
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use lodkit::select::{LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode};
use lodkit_bevy::LodkitShadersPlugin;

use frames::strip;
use headless::{build_app, capture, render_target, save_png};
use lod_material::{
    LevelEntity, LodDitherMaterial, LodDitherParams, LodDitherShaderPlugin, apply_selection,
    show_levels,
};
use transition::TransitionReport;

/// Size of one frame of the strip.
const SIZE: u32 = 160;
/// Frames a transition takes (`TransitionMode::Time` over this many frame times).
const TRANSITION_FRAMES: usize = 12;
/// Duration of a transition; each captured frame advances time by a `TRANSITION_FRAMES`th of it.
const TRANSITION_SECONDS: f32 = 0.5;
/// Frames to wait for a level to appear before declaring the pipeline never ready.
const WARMUP_FRAMES: usize = 30;
/// LOD1 is used from this view-normalized distance on (distance / |P[1][1]|, DigitalRune's
/// measure; Bevy's default 45° field of view).
const LOD1_DISTANCE: f32 = 4.0;
/// Global LOD bias after the quality drop that triggers the switch (1 before).
const LOW_QUALITY_BIAS: f32 = 3.0;
const CAMERA_POSITION: Vec3 = Vec3::new(0.0, 0.0, 4.0);
const BACKGROUND: Color = Color::srgb(0.08, 0.09, 0.12);

/// The lodkit side: one LOD group seen from one camera, selected once per captured frame.
struct LodDriver {
    group: LodGroup,
    settings: LodSettings,
    state: LodState,
    camera: LodCamera,
}

impl LodDriver {
    /// `projection` is Bevy's (glam 0.32); lodkit's API uses glam 0.34, hence the conversion.
    fn new(projection: Mat4) -> Self {
        let projection = glam::Mat4::from_cols_array(&projection.to_cols_array());
        let position = glam::Vec3::from_array(CAMERA_POSITION.to_array());
        Self {
            group: LodGroup::from_distances(&[0.0, LOD1_DISTANCE]).expect("valid LOD distances"),
            settings: LodSettings {
                hysteresis: 1.0,
                transition: TransitionMode::Time {
                    seconds: TRANSITION_SECONDS,
                },
                ..default()
            },
            state: LodState::NEW,
            camera: LodCamera::new(position, projection),
        }
    }

    /// Selects for the object at the origin (scale 1) under `global_bias`, `dt` seconds later.
    fn select(&mut self, global_bias: f32, dt: f32) -> LodSelection {
        let distance = self.camera.lod_distance(glam::Vec3::ZERO, 1.0, global_bias);
        self.group
            .select(distance, &self.settings, dt, &mut self.state)
    }
}

/// The scene: the render target, a camera and a light, and the two levels at the origin.
fn spawn_scene(world: &mut World) -> (Handle<Image>, Vec<LevelEntity>) {
    let target = render_target(world, SIZE, SIZE);

    // Exact colors for the checks: no MSAA (edge pixels would mix), no tonemapping, no debanding noise.
    world.spawn((
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(BACKGROUND),
            ..default()
        },
        RenderTarget::from(target.clone()),
        Projection::Perspective(PerspectiveProjection::default()),
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_translation(CAMERA_POSITION).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    world.spawn((
        DirectionalLight {
            shadow_maps_enabled: false,
            ..default()
        },
        Transform::from_xyz(-2.0, 3.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));

    // LOD0: a smooth warm sphere; LOD1: a coarse cool one. Different colors make the handover visible.
    let lods = [
        (
            Sphere::new(1.0).mesh().uv(48, 24),
            Color::srgb(0.95, 0.55, 0.20),
        ),
        (
            Sphere::new(1.0).mesh().uv(8, 5),
            Color::srgb(0.20, 0.70, 0.85),
        ),
    ];
    let levels = lods
        .into_iter()
        .map(|(mesh, color)| {
            let mesh = world.resource_mut::<Assets<Mesh>>().add(mesh);
            let params = LodDitherParams {
                color: color.to_linear().to_vec4(),
                alpha: 1.0,
            };
            let material = world
                .resource_mut::<Assets<LodDitherMaterial>>()
                .add(LodDitherMaterial { params });
            let entity = world
                .spawn((
                    Mesh3d(mesh),
                    MeshMaterial3d(material.clone()),
                    Transform::IDENTITY,
                    Visibility::Hidden,
                ))
                .id();
            LevelEntity { entity, material }
        })
        .collect();
    (target, levels)
}

/// Whether anything but the background shows up within `frames` frames.
fn drawn_within(app: &mut App, target: &Handle<Image>, frames: usize) -> Result<bool, String> {
    for _ in 0..frames {
        let frame = capture(app, target)?;
        if frame.object_pixels(frame.corner()) > 0 {
            return Ok(true);
        }
    }
    Ok(false)
}

/// A failure with its exit code.
struct Failure(u8, String);

fn run(out: &Path, check: bool) -> Result<(), Failure> {
    let io = |message: String| Failure(2, message);
    let mut app = build_app(|app| {
        app.add_plugins((
            LodkitShadersPlugin,
            LodDitherShaderPlugin,
            MaterialPlugin::<LodDitherMaterial>::default(),
        ));
    });
    let (target, levels) = spawn_scene(app.world_mut());

    // Warm-up: show each level alone until it appears. Bevy gives no error when a shader import
    // is missing (the pipeline just never becomes ready), so "nothing drawn" is the signal.
    for level in (0..levels.len()).rev() {
        show_levels(app.world_mut(), &levels, |i| (i == level).then_some(1.0));
        if !drawn_within(&mut app, &target, WARMUP_FRAMES).map_err(io)? {
            let why = "its pipeline never became ready (a missing `#import` fails silently)";
            return Err(Failure(
                1,
                format!("LOD{level} not drawn in {WARMUP_FRAMES} frames: {why}"),
            ));
        }
    }

    // The transition: settled on LOD0 at bias 1; then the LOD bias rises (a quality preset drops,
    // as a framerate controller would do), LOD1 becomes the desired level, and a time-driven
    // transition of TRANSITION_SECONDS runs, one captured frame per frame time.
    let projection = PerspectiveProjection::default().get_clip_from_view();
    let mut driver = LodDriver::new(projection);
    let dt = TRANSITION_SECONDS / TRANSITION_FRAMES as f32;
    let mut frames = Vec::new();
    let mut selection = driver.select(1.0, dt);
    loop {
        apply_selection(app.world_mut(), &levels, &selection);
        frames.push(capture(&mut app, &target).map_err(io)?);
        let (current, next) = selection.screen_door_alphas();
        println!(
            "frame {:2}: LOD{} {}  t = {:.3}  alphas {current:+.3} / {}",
            frames.len() - 1,
            selection.current,
            selection
                .next
                .map_or("settled ".into(), |n| format!("-> LOD{n}")),
            selection.transition,
            next.map_or("-".into(), |a| format!("{a:+.3}")),
        );
        if selection.next.is_none() && selection.current == 1 {
            break;
        }
        if frames.len() > 4 * TRANSITION_FRAMES {
            return Err(Failure(1, "the transition to LOD1 never finished".into()));
        }
        selection = driver.select(LOW_QUALITY_BIAS, dt);
    }

    save_png(&strip(&frames), out).map_err(io)?;
    println!(
        "wrote {} ({} frames of {SIZE}x{SIZE})",
        out.display(),
        frames.len()
    );

    let report = TransitionReport::measure(&frames, frames[0].corner());
    println!(
        "largest step: {:.1}% of the change; silhouette {} px; see-through px per frame {:?}",
        report.largest_step_share * 100.0,
        report.silhouette,
        report.see_through
    );
    let failures = report.failures();
    if failures.is_empty() {
        println!("check: gradual change, no see-through inside the silhouette");
        return Ok(());
    }
    let message = format!("check failed:\n  {}", failures.join("\n  "));
    if check {
        return Err(Failure(1, message));
    }
    eprintln!("warning: {message}");
    Ok(())
}

fn main() -> ExitCode {
    let mut check = false;
    let mut out = None;
    for arg in std::env::args().skip(1) {
        match arg.as_str() {
            "--check" => check = true,
            "-h" | "--help" => {
                println!("usage: crossfade [--check] [OUT.png]");
                return ExitCode::SUCCESS;
            }
            _ if arg.starts_with('-') || out.is_some() => {
                eprintln!(
                    "error: unexpected argument `{arg}`\nusage: crossfade [--check] [OUT.png]"
                );
                return ExitCode::from(2);
            }
            _ => out = Some(PathBuf::from(&arg)),
        }
    }
    let out = out.unwrap_or_else(|| PathBuf::from("lodkit-bevy-strip.png"));
    match run(&out, check) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}
