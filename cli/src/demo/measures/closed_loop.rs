//! The resize controllers on the real framebuffer-LOD frame: each frame (prepass, low-resolution
//! shading at the controller's r, upsample) is rendered and timed, the controller gets the
//! measured time and answers the next r, and the scene's shading work doubles mid-run.
//!
//! Each frame's three passes are recorded into one encoder and timed as one run on the
//! [`Clock`] the figure names, as an engine times its frames: GPU timestamps around the
//! recordings where the device has them, the wall clock around the submission and its wait
//! otherwise.

use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::fixtures::clock::{Clock, Timer};
use crate::demo::fixtures::edge_frame::EdgeFrame;
use lodkit::framebuffer_lod::{
    PaperController, ResizeController, ResizeLimits, RlsController, SimulatedFrame, StepController,
    step_response,
};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit_scenes::gbuffer::EdgeScene;

/// Shading work before the step (sky directions per fragment); it doubles at [`STEP_FRAME`].
pub const BASE_WORK: u32 = 64;
/// Frame at which the shading work doubles.
pub const STEP_FRAME: usize = 30;
/// Frames per run.
pub const FRAMES: usize = 75;
/// Settling band: within this fraction of the target.
pub const BAND: f32 = 0.10;
/// Resize factor whose frame time (measured before the runs) is the target.
pub const TARGET_R: f32 = 1.6;
/// Frames in the median that stands for the noise-free frame time (the frame and those before).
pub const SMOOTHING: usize = 5;
/// Frames timed to calibrate the target, K and the noise.
const CALIBRATION: usize = 9;
/// Runs of each controller (interleaved); the table gives their median and range.
pub const REPEATS: usize = 3;

/// One controller's run.
#[derive(Clone, Debug, Serialize)]
pub struct ClosedLoopRun {
    /// Controller.
    pub name: String,
    /// Frames after the step until the frame time (median of [`SMOOTHING`] consecutive
    /// frames) stays within [`BAND`] of the target for the rest of the run (`None`: never).
    pub settling_frames: Option<usize>,
    /// Share of single frames after settling within [`BAND`] of the target (noise included).
    pub frames_within: f32,
    /// Largest drop of that time below the target after the step (fraction of the target).
    pub overshoot: f32,
    /// Standard deviation of the measured time over the last half after the step (fraction).
    pub spread: f32,
    /// Measured frame times (ms).
    pub ms: Vec<f32>,
    /// r of each frame.
    pub r: Vec<f32>,
}

/// The closed-loop measurement.
#[derive(Clone, Debug, Serialize)]
pub struct ClosedLoop {
    /// Image size.
    pub size: (u32, u32),
    /// Target frame time (ms): the measured frame at [`TARGET_R`] before the step.
    pub target_ms: f32,
    /// K calibrated for the paper's controller (ms per unit of 1/r^2).
    pub paper_k: f32,
    /// Relative standard deviation of the calibration frames at [`TARGET_R`]: the noise lodkit's
    /// controller is told to expect.
    pub noise: f32,
    /// Every run of each controller: [`REPEATS`] per controller.
    pub repeats: Vec<Vec<ClosedLoopRun>>,
    /// The clock every frame time was read from.
    pub clock: Clock,
}

impl ClosedLoop {
    /// The first run of each controller (the plots show these).
    pub fn runs(&self) -> impl Iterator<Item = &ClosedLoopRun> {
        self.repeats.iter().filter_map(|runs| runs.first())
    }
}

/// Runs lodkit's controller, the paper's and the step heuristic on the edge scene at `size`.
pub fn measure_closed_loop(gpu: &GpuContext, size: (u32, u32)) -> Result<ClosedLoop, DemoError> {
    // One frame per timed run, as an engine times its frames: GPU timestamps where the device
    // has them.
    let timer = Timer::new(gpu, 1)?;
    let (frame, mut scene) = EdgeFrame::new(gpu, &timer, size)?;
    let frame = |scene: &EdgeScene, r: f32| frame.whole(scene, r, 0).map(|ms| ms as f32);
    let times = |scene: &EdgeScene, r: f32| -> Result<Vec<f32>, GpuError> {
        let mut t = (0..CALIBRATION)
            .map(|_| frame(scene, r))
            .collect::<Result<Vec<_>, _>>()?;
        t.sort_by(f32::total_cmp);
        Ok(t)
    };
    scene.set_shading_work(BASE_WORK);
    frame(&scene, 1.0)?;
    let at_target = times(&scene, TARGET_R)?;
    let target_ms = at_target[CALIBRATION / 2];
    let mean = at_target.iter().sum::<f32>() / CALIBRATION as f32;
    let variance = at_target.iter().map(|t| (t - mean).powi(2)).sum::<f32>() / CALIBRATION as f32;
    let noise = (variance.sqrt() / mean).clamp(0.01, 0.2);
    // The paper calibrates K once: t(1) - t(2) = K (1 - 1/4).
    let (t1, t2) = (times(&scene, 1.0)?, times(&scene, 2.0)?);
    let paper_k = ((t1[CALIBRATION / 2] - t2[CALIBRATION / 2]) / 0.75).max(1e-3);
    let limits = ResizeLimits::default();
    let lodkit = move || {
        let mut c = RlsController::new(target_ms, limits);
        c.noise = noise;
        Box::new(c) as Box<dyn ResizeController>
    };
    let paper = move || {
        Box::new(PaperController::new(target_ms, paper_k, limits)) as Box<dyn ResizeController>
    };
    let step =
        move || Box::new(StepController::new(target_ms, limits)) as Box<dyn ResizeController>;
    let controllers: [(&str, MakeController); 3] = [
        ("lodkit (online K, C)", &lodkit),
        ("paper (calibrated K)", &paper),
        ("step heuristic", &step),
    ];
    // Repetitions interleaved, so a slow patch of the machine does not hit one controller only.
    let mut repeats: Vec<Vec<ClosedLoopRun>> = vec![Vec::new(); controllers.len()];
    for _ in 0..REPEATS {
        for (k, (name, controller)) in controllers.iter().enumerate() {
            let mut run = run_controller(&mut scene, &frame, controller(), target_ms)?;
            run.name = (*name).to_owned();
            repeats[k].push(run);
        }
    }
    Ok(ClosedLoop {
        size,
        target_ms,
        paper_k,
        noise,
        repeats,
        clock: timer.clock(),
    })
}

/// Makes a fresh controller for one run.
type MakeController<'a> = &'a dyn Fn() -> Box<dyn ResizeController>;

/// One closed-loop run of `controller` (its name left empty): the shading work doubles at
/// [`STEP_FRAME`].
fn run_controller(
    scene: &mut EdgeScene,
    frame: &dyn Fn(&EdgeScene, f32) -> Result<f32, GpuError>,
    mut controller: Box<dyn ResizeController>,
    target_ms: f32,
) -> Result<ClosedLoopRun, DemoError> {
    let (mut ms, mut rs) = (Vec::new(), Vec::new());
    for f in 0..FRAMES {
        let work = if f < STEP_FRAME {
            BASE_WORK
        } else {
            2 * BASE_WORK
        };
        scene.set_shading_work(work);
        let r = controller.r();
        let t = frame(scene, r)?;
        controller.update(t);
        ms.push(t);
        rs.push(r);
    }
    // The noise-free time of the simulation becomes the median of the last SMOOTHING frames
    // (what a frame-time monitor sees), not reaching back across the step.
    let frames: Vec<SimulatedFrame> = (0..FRAMES)
        .map(|i| {
            let first = if i < STEP_FRAME { 0 } else { STEP_FRAME };
            let window = (i + 1).saturating_sub(SMOOTHING).max(first)..i + 1;
            let mut w = ms[window].to_vec();
            w.sort_by(f32::total_cmp);
            SimulatedFrame {
                r: rs[i],
                measured: ms[i],
                expected: w[w.len() / 2],
            }
        })
        .collect();
    let response = step_response(&frames, STEP_FRAME, target_ms, BAND);
    let settled = STEP_FRAME + response.settling_frames.unwrap_or(FRAMES);
    let tail = ms.get(settled..).unwrap_or_default();
    let within = tail
        .iter()
        .filter(|t| (*t - target_ms).abs() <= BAND * target_ms)
        .count();
    Ok(ClosedLoopRun {
        name: String::new(),
        settling_frames: response.settling_frames,
        frames_within: within as f32 / tail.len().max(1) as f32,
        overshoot: response.overshoot,
        spread: response.spread,
        ms,
        r: rs,
    })
}
