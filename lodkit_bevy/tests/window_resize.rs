//! Framebuffer LOD in a real window that is resized while the app runs (X11 through winit; under
//! an `Xvfb` of its own when no display is set). Every frame after a resize is held to what it
//! must be, so a frame that read a low-resolution target or a prepass texture not written at the
//! size it is read at would differ:
//! - once the camera has the window's new size, the frame rendered at that size from the start
//!   (an image-target camera with the same settings, spawned at that size in the same app);
//! - before that: Bevy's camera learns of a window's new size from winit's resize event, a frame
//!   or more after the app set it, and meanwhile renders at the old size and stretches that to the
//!   window (its upscaling blit, nearest texel). Such a frame must be the previous size's
//!   frame, stretched here by hand.
//!
//! winit wants the main thread, so this test has its own `main` (`harness = false`).

#[path = "../examples/common/frames.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod frames;
#[path = "../examples/common/headless.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod headless;
#[path = "support/shade.rs"]
mod shade;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, ExitCode, Stdio};
use std::sync::{Arc, Mutex};

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::{ExitCondition, PresentMode, WindowResolution};
use frames::Frame;
use lodkit_bevy::prelude::*;
use shade::{Shade, mismatches, pixel, spawn_scene};

/// The window's sizes, in order: it opens at the first and is resized to each next one.
/// r = 1.25 as in the image-target resize test: at a larger size the low-resolution viewport no
/// longer fits in targets allocated at the smaller one.
const SIZES: [UVec2; 3] = [UVec2::new(64, 48), UVec2::new(96, 72), UVec2::new(48, 40)];
const R: f32 = 1.25;
/// The first frames at the start, before anything is compared (pipelines, assets).
const WARMUP: u32 = 6;
/// Frames captured at the window's new size before the next resize: every frame of a size is
/// captured, from its first until the camera has had that size for this many frames (however
/// long winit takes to report the resize: the frame count, not the clock, decides).
const STEADY_FRAMES: usize = 3;
/// The frame of a size at which its reference camera is captured (it was spawned on the size's
/// first frame).
const REFERENCE_AT: u32 = 7;
/// Frames a size may wait for the camera to take it (or for the screenshots to come back at the
/// end) before the test gives up.
const GIVE_UP_AFTER: u32 = 120;
/// Tolerance of a pixel against the reference (8-bit steps per channel), as in the image-target
/// tests.
const TOLERANCE: u8 = 2;

/// Which capture a screenshot is.
#[derive(Clone, Copy, Debug)]
enum Shot {
    /// The window at (index of its size, frame number).
    Window(usize, u32),
    /// The reference camera of a phase.
    Reference(usize),
}

/// What the app captured, read by `main` after the app has exited.
type Captures = Arc<Mutex<Vec<(Shot, Frame)>>>;

/// The run's state: the frame count, the size being shown and since when, the captures and the
/// current reference camera with its target.
#[derive(Resource)]
struct Script {
    frame: u32,
    /// Index into SIZES (SIZES.len(): all shown, waiting for the last screenshots).
    phase: usize,
    /// The frame the current size began at.
    phase_start: u32,
    /// Screenshots asked for so far.
    requested: usize,
    captures: Captures,
    effect: Handle<Shade>,
    reference: Option<(Entity, Handle<Image>)>,
    /// The window camera's target size in each frame, as Bevy computed it for that frame.
    camera_sizes: Arc<Mutex<Vec<(u32, UVec2)>>>,
}

/// The same camera, drawn in `order`: framebuffer LOD at r = `R` with the test effect, no
/// tonemapping or dithering.
fn camera_settings(order: isize, effect: Handle<Shade>) -> impl Bundle {
    (
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(Color::linear_rgb(0.2, 0.3, 0.4)),
            order,
            ..default()
        },
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_xyz(-1.0, 2.5, 7.0).looking_at(Vec3::new(0.0, 0.8, 0.0), Vec3::Y),
        FramebufferLod {
            resolution: FramebufferLodResolution::Fixed(R),
            ..default()
        },
        FramebufferLodEffectHandle(effect),
    )
}

/// The scene and the window's camera.
fn setup(mut commands: Commands, script: Res<Script>) {
    commands.queue(spawn_scene);
    commands.spawn(camera_settings(0, script.effect.clone()));
}

/// Spawns a screenshot whose image goes into the captures, tagged `shot`.
fn capture(commands: &mut Commands, screenshot: Screenshot, shot: Shot, captures: &Captures) {
    let captures = captures.clone();
    commands
        .spawn(screenshot)
        .observe(move |event: On<ScreenshotCaptured>| {
            let image = event.image.clone();
            let (width, height) = (image.width(), image.height());
            let rgba = image
                .try_into_dynamic()
                .expect("a screenshot format the image crate reads")
                .to_rgba8()
                .into_raw();
            captures
                .lock()
                .expect("the captures")
                .push((shot, Frame::new(width, height, rgba)));
        });
}

/// Drives the run: shows each size in turn (resizing the window on the size's first frame and
/// spawning its reference camera there), captures every window frame, and exits once every
/// capture is back.
fn script(
    mut commands: Commands,
    mut script: ResMut<Script>,
    mut windows: Query<&mut Window>,
    mut images: ResMut<Assets<Image>>,
    mut exit: MessageWriter<AppExit>,
) {
    let frame = script.frame;
    script.frame += 1;
    if frame < WARMUP {
        return;
    }
    let received = script.captures.lock().expect("the captures").len();
    if script.phase == SIZES.len() {
        if received >= script.requested || frame - script.phase_start > GIVE_UP_AFTER {
            exit.write(AppExit::Success);
        }
        return;
    }
    let in_phase = frame - script.phase_start;
    // The frames of this size so far (their sizes are recorded after camera_system ran) at
    // which the camera had it.
    let steady = script
        .camera_sizes
        .lock()
        .expect("the camera sizes")
        .iter()
        .filter(|&&(f, s)| f >= script.phase_start && s == SIZES[script.phase])
        .count();
    let next = frame == WARMUP
        || (steady >= STEADY_FRAMES && in_phase > REFERENCE_AT)
        || in_phase > GIVE_UP_AFTER;
    if next {
        if frame > WARMUP {
            script.phase += 1;
        }
        script.phase_start = frame;
        if script.phase == SIZES.len() {
            return;
        }
        let size = SIZES[script.phase];
        if script.phase > 0 {
            let mut window = windows.single_mut().expect("the primary window");
            window.resolution.set_physical_resolution(size.x, size.y);
        }
        if let Some((old, _)) = script.reference.take() {
            commands.entity(old).despawn();
        }
        let target = images.add(headless::render_target_image(size.x, size.y));
        let reference = commands
            .spawn((
                camera_settings(1, script.effect.clone()),
                RenderTarget::from(target.clone()),
            ))
            .id();
        script.reference = Some((reference, target));
    }
    let (phase, in_phase) = (script.phase, frame - script.phase_start);
    let captures = script.captures.clone();
    capture(
        &mut commands,
        Screenshot::primary_window(),
        Shot::Window(phase, frame),
        &captures,
    );
    script.requested += 1;
    if in_phase == REFERENCE_AT {
        let (_, target) = script
            .reference
            .clone()
            .expect("this size's reference camera");
        capture(
            &mut commands,
            Screenshot::image(target),
            Shot::Reference(phase),
            &captures,
        );
        script.requested += 1;
    }
}

/// Records the window camera's target size in this frame (after `camera_system`).
fn record_camera_size(script: Res<Script>, cameras: Query<&Camera>) {
    let Some(frame) = script.frame.checked_sub(1) else {
        return;
    };
    for camera in cameras.iter().filter(|c| c.order == 0) {
        if let Some(size) = camera.physical_target_size() {
            script
                .camera_sizes
                .lock()
                .expect("the camera sizes")
                .push((frame, size));
        }
    }
}

/// An X display for the window: `$DISPLAY` when set, else an `Xvfb` started here (which the
/// returned child keeps alive).
fn display() -> Result<Option<Child>, String> {
    if std::env::var_os("DISPLAY").is_some() {
        return Ok(None);
    }
    let mut xvfb = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "320x240x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("no DISPLAY and no Xvfb to start ({e}): install xvfb"))?;
    let mut line = String::new();
    BufReader::new(xvfb.stdout.take().expect("Xvfb's stdout"))
        .read_line(&mut line)
        .map_err(|e| format!("Xvfb's display number: {e}"))?;
    let number = line.trim();
    if number.is_empty() {
        return Err("Xvfb exited without a display".into());
    }
    // SAFETY: no other thread runs yet; winit reads DISPLAY when the app starts below.
    unsafe {
        std::env::set_var("DISPLAY", format!(":{number}"));
        std::env::remove_var("WAYLAND_DISPLAY");
    }
    Ok(Some(xvfb))
}

/// `frame` stretched to `size` the way Bevy's upscaling blit does it (a full-screen triangle
/// sampled with a nearest-texel sampler at each output pixel's centre).
fn stretched(frame: &Frame, size: UVec2) -> Frame {
    let nearest = |i: u32, n: u32, m: u32| ((i as f32 + 0.5) / n as f32 * m as f32) as u32;
    let mut rgba = Vec::with_capacity((size.x * size.y * 4) as usize);
    for y in 0..size.y {
        for x in 0..size.x {
            let [r, g, b] = pixel(
                frame,
                nearest(x, size.x, frame.width),
                nearest(y, size.y, frame.height),
            );
            rgba.extend([r, g, b, 255]);
        }
    }
    Frame::new(size.x, size.y, rgba)
}

/// The comparisons: each window frame against what it must be at its camera's size.
fn verdict(captures: &[(Shot, Frame)], camera_sizes: &[(u32, UVec2)]) -> Result<(), String> {
    let mut failures = Vec::new();
    // The previous size's steady frame, which a lagging frame is stretched from.
    let mut previous: Option<&Frame> = None;
    for (phase, size) in SIZES.iter().enumerate() {
        let reference = captures
            .iter()
            .find(|(s, _)| matches!(s, Shot::Reference(p) if *p == phase))
            .map(|(_, f)| f)
            .ok_or(format!("no reference frame came back at {size}"))?;
        let mut shots: Vec<(u32, &Frame)> = captures
            .iter()
            .filter_map(|(s, f)| match s {
                Shot::Window(p, number) if *p == phase => Some((*number, f)),
                _ => None,
            })
            .collect();
        shots.sort_by_key(|&(number, _)| number);
        let first = shots
            .first()
            .map(|&(number, _)| number)
            .ok_or(format!("no window screenshot came back at {size}"))?;
        let (mut lag, mut steady) = (0, None);
        for &(number, frame) in &shots {
            let k = number - first;
            let camera = camera_sizes
                .iter()
                .find(|(f, _)| *f == number)
                .map(|(_, s)| *s)
                .ok_or(format!("frame {k} at {size}: the camera had no size"))?;
            if (frame.width, frame.height) != (size.x, size.y) {
                failures.push(format!(
                    "frame {k} after the resize to {size} is {}x{}",
                    frame.width, frame.height
                ));
                continue;
            }
            let (expected, what) = if camera == *size {
                steady.get_or_insert(frame);
                (
                    reference.clone(),
                    "the camera rendered at that size from the start",
                )
            } else if let (Some(previous), None) = (previous, steady) {
                lag += 1;
                (
                    stretched(previous, *size),
                    "the previous size's frame, stretched",
                )
            } else {
                failures.push(format!(
                    "frame {k} at {size}: the camera is at {camera}, not at the window's size"
                ));
                continue;
            };
            let (bad, at) = mismatches(
                frame,
                [0, 0, size.x, size.y],
                |x, y| pixel(&expected, x, y),
                TOLERANCE,
            );
            println!(
                "window at {size}, frame {k} (camera at {camera}): {bad} pixels differ from {what}"
            );
            if bad > 0 {
                failures.push(format!(
                    "frame {k} at {size}: {bad} pixels differ from {what}: {at:?}"
                ));
            }
        }
        println!("the camera took the window's size {size} after {lag} frame(s)");
        previous = Some(steady.ok_or(format!(
            "the camera never took the window's size {size} in {} frames",
            shots.len()
        ))?);
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

fn run() -> Result<(), String> {
    let _xvfb = match display() {
        Ok(xvfb) => xvfb.map(KillOnDrop),
        Err(e) if !strict() => {
            println!("SKIPPED: {e}");
            return Ok(());
        }
        Err(e) => return Err(e),
    };
    let captures = Captures::default();
    let camera_sizes = Arc::<Mutex<Vec<(u32, UVec2)>>>::default();
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: Some(Window {
                    title: "lodkit window resize test".into(),
                    resolution: WindowResolution::new(SIZES[0].x, SIZES[0].y)
                        .with_scale_factor_override(1.0),
                    present_mode: PresentMode::AutoNoVsync,
                    ..default()
                }),
                exit_condition: ExitCondition::OnPrimaryClosed,
                ..default()
            })
            .set(RenderPlugin {
                synchronous_pipeline_compilation: true,
                ..default()
            }),
    )
    .add_plugins(FramebufferLodEffectPlugin::<Shade>::default())
    .add_systems(Startup, setup)
    .add_systems(Update, script)
    .add_systems(Last, record_camera_size);
    app.world_mut()
        .resource_mut::<Assets<Shader>>()
        .insert(
            &shade::SHADE,
            Shader::from_wesl(shade::SHADE_SOURCE, "shade.wesl"),
        )
        .expect("a UUID handle");
    let effect = app.world_mut().resource_mut::<Assets<Shade>>().add(Shade {
        tint: Vec4::new(1.0, 0.5, 0.1, 0.7),
    });
    app.insert_resource(Script {
        frame: 0,
        phase: 0,
        phase_start: WARMUP,
        requested: 0,
        captures: captures.clone(),
        effect,
        reference: None,
        camera_sizes: camera_sizes.clone(),
    });
    // Without a GPU adapter Bevy's renderer panics while the app starts: a skip unless the
    // GPU is required.
    let exit = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| app.run())) {
        Ok(exit) => exit,
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("a panic");
            if message.contains("Unable to find a GPU") && !strict() {
                println!("SKIPPED: no GPU adapter (install mesa-vulkan-drivers for lavapipe)");
                return Ok(());
            }
            return Err(format!("the app panicked: {message}"));
        }
    };
    if exit != AppExit::Success {
        return Err(format!("the app exited with {exit:?}"));
    }
    let captures = std::mem::take(&mut *captures.lock().expect("the captures"));
    let camera_sizes = std::mem::take(&mut *camera_sizes.lock().expect("the camera sizes"));
    verdict(&captures, &camera_sizes)
}

/// Whether a missing display or GPU fails the test (lodkit's CI) instead of skipping it.
fn strict() -> bool {
    std::env::var("LODKIT_REQUIRE_GPU").is_ok_and(|v| v == "1")
}

/// Kills the Xvfb this test started when the test ends.
struct KillOnDrop(Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => {
            println!("test window_resize ... ok");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("test window_resize ... FAILED\n{e}");
            ExitCode::FAILURE
        }
    }
}
