//! Framerate control for geometry-aware framebuffer LOD (Yang, Sander & Lawrence 2008, sec. 3):
//! choose the resize factor r each frame so that the frame time meets a target, under the model
//! t ~ K / r^2 + C (eq. 3). Pure math, no wgpu.
//!
//! - [`RlsController`] (lodkit's): estimates K and C online by recursive least squares with
//!   forgetting, ignores NaN/zero/negative samples, smooths noise, and solves eq. 3 for r.
//! - [`PaperController`]: the paper's rule with K fixed by a calibration run:
//!   dt ~ K d(1/r^2) (eq. 4).
//! - [`StepController`]: a window-averaging step heuristic in the style of Unity HDRP's dynamic
//!   resolution.
//! - [`FixedController`]: no control.
//!
//! Every controller keeps r in [1, r_max] and changes it by at most 0.2 per frame (the paper's
//! limits; [`ResizeLimits`]). [`simulate`] runs one against a frame-time model.
//!
//! An engine ships [`RlsController`]. The others, [`simulate`] and [`step_response`] are here
//! for the engine's own tuning before it ships: run its frame-time curve
//! ([`FrameTimeModel`] with the K and C it measured, a workload that steps or drifts) through
//! lodkit's controller and the two baselines an engine would otherwise write (the paper's and a
//! step heuristic like Unity HDRP's), and compare settling, overshoot and spread. lodkit's demo
//! and tests do the same with fixed models.

use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;

/// Bounds every controller honours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResizeLimits {
    /// Largest resize factor (>= 1).
    pub r_max: f32,
    /// Largest change of r between consecutive frames (the paper: 0.2).
    pub max_step: f32,
}

impl Default for ResizeLimits {
    fn default() -> Self {
        Self {
            r_max: 4.0,
            max_step: 0.2,
        }
    }
}

impl ResizeLimits {
    /// `wanted` moved from `r` by at most `max_step`, inside [1, r_max]. NaN wanted keeps `r`.
    ///
    /// ```
    /// # use lodkit::framebuffer_lod::ResizeLimits;
    /// let l = ResizeLimits::default();
    /// assert_eq!(l.apply(2.0, 3.0), 2.2);
    /// assert_eq!(l.apply(1.1, 0.5), 1.0);
    /// assert_eq!(l.apply(2.0, f32::NAN), 2.0);
    /// ```
    pub fn apply(&self, r: f32, wanted: f32) -> f32 {
        let r = clamp_factor(r, self.r_max);
        if wanted.is_nan() {
            return r;
        }
        let step = if self.max_step.is_nan() {
            0.0
        } else {
            self.max_step.max(0.0)
        };
        clamp_factor(wanted.clamp(r - step, r + step), self.r_max)
    }
}

/// A resize factor made usable: NaN is 1, and r is kept in [1, `r_max`] (an `r_max` below 1 or
/// NaN is 1). Every host that takes an r from a user or a controller goes through this one
/// function (lodkit's `LowResBuffer`, lodkit_bevy's controller).
///
/// ```
/// # use lodkit::framebuffer_lod::clamp_factor;
/// assert_eq!(clamp_factor(2.5, 4.0), 2.5);
/// assert_eq!(clamp_factor(0.3, 4.0), 1.0);
/// assert_eq!(clamp_factor(f32::NAN, 4.0), 1.0);
/// assert_eq!(clamp_factor(f32::INFINITY, 16.0), 16.0);
/// ```
pub fn clamp_factor(r: f32, r_max: f32) -> f32 {
    let r_max = if r_max.is_nan() { 1.0 } else { r_max.max(1.0) };
    if r.is_nan() { 1.0 } else { r.clamp(1.0, r_max) }
}

/// The low-resolution size for a full-resolution `full` size at resize factor `r`: ceil(side /
/// r) on each side, at least 1 and at most the side; r through [`clamp_factor`] (no upper
/// bound but the size). The one computation of L's size: lodkit's `LowResBuffer::viewport` and
/// lodkit_bevy's framebuffer LOD call it.
///
/// ```
/// # use lodkit::framebuffer_lod::low_res_size;
/// assert_eq!(low_res_size((1920, 1080), 2.0), (960, 540));
/// assert_eq!(low_res_size((1281, 721), 2.0), (641, 361));
/// assert_eq!(low_res_size((64, 48), f32::NAN), (64, 48));
/// assert_eq!(low_res_size((64, 48), 1e9), (1, 1));
/// ```
pub fn low_res_size((width, height): (u32, u32), r: f32) -> (u32, u32) {
    let r = clamp_factor(r, f32::MAX);
    let side = |s: u32| ((s as f32 / r).ceil() as u32).clamp(1, s.max(1));
    (side(width), side(height))
}

/// A resize controller: told each frame's time, answers the r for the next frame.
pub trait ResizeController {
    /// The resize factor currently in use.
    fn r(&self) -> f32;
    /// Takes the time (seconds or any unit, as long as it matches the target) of the frame just
    /// rendered at [`r`](Self::r) and returns the r for the next frame.
    fn update(&mut self, frame_time: f32) -> f32;
}

fn valid(t: f32) -> bool {
    t.is_finite() && t > 0.0
}

/// Keeps r where it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedController {
    /// The resize factor.
    pub r: f32,
}

impl ResizeController for FixedController {
    fn r(&self) -> f32 {
        self.r
    }
    fn update(&mut self, _frame_time: f32) -> f32 {
        self.r
    }
}

/// The paper's controller: K fixed from a calibration run, dt ~ K d(1/r^2) solved for the r that
/// brings the frame time to the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperController {
    /// Target frame time.
    pub target: f32,
    /// Calibrated K (frame time per unit of 1/r^2).
    pub k: f32,
    /// Limits.
    pub limits: ResizeLimits,
    r: f32,
}

impl PaperController {
    /// Starts at r = 1.
    pub fn new(target: f32, k: f32, limits: ResizeLimits) -> Self {
        Self {
            target,
            k,
            limits,
            r: 1.0,
        }
    }
}

impl ResizeController for PaperController {
    fn r(&self) -> f32 {
        self.r
    }
    fn update(&mut self, frame_time: f32) -> f32 {
        if valid(frame_time) && self.k > 0.0 {
            let x = 1.0 / (self.r * self.r) + (self.target - frame_time) / self.k;
            let wanted = if x > 0.0 {
                1.0 / x.sqrt()
            } else {
                f32::INFINITY
            };
            self.r = self.limits.apply(self.r, wanted);
        }
        self.r
    }
}

/// lodkit's controller: a two-state Kalman filter (recursive least squares with per-parameter
/// forgetting) over (1/r^2, t) pairs estimates K and C of eq. 3 online, then solves eq. 3 for the
/// target. K, the pixel cost, is allowed to drift fast (workload changes), C, the fixed overhead,
/// slowly; so it needs no calibration run and follows a workload step within a few frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RlsController {
    /// Target frame time.
    pub target: f32,
    /// Limits.
    pub limits: ResizeLimits,
    /// Relative drift of K expected per frame (default 0.005); an innovation beyond 3 sigma is
    /// taken as a workload change and lets K jump.
    pub k_drift: f32,
    /// Drift of C allowed per frame, as a fraction of the target (default 0.01).
    pub c_drift: f32,
    /// Expected relative noise of a frame time (default 0.03).
    pub noise: f32,
    r: f32,
    theta: [f64; 2],
    p: [[f64; 2]; 2],
}

impl RlsController {
    /// Starts at r = 1 with a prior of K = `target`, C = 0 (the first frames steer as if the frame
    /// were entirely pixel bound).
    pub fn new(target: f32, limits: ResizeLimits) -> Self {
        let t = f64::from(target);
        Self {
            target,
            limits,
            k_drift: 0.005,
            c_drift: 0.01,
            noise: 0.03,
            r: 1.0,
            theta: [t, 0.0],
            p: [[t * t, 0.0], [0.0, 0.25 * t * t]],
        }
    }

    /// The same controller starting at `r` (clamped to [1, r_max]) instead of 1: for a
    /// controller replaced mid-run (a new target or limits) that should not jump back to r = 1.
    ///
    /// ```
    /// # use lodkit::framebuffer_lod::{ResizeController, ResizeLimits, RlsController};
    /// let c = RlsController::new(0.016, ResizeLimits::default()).starting_at(2.5);
    /// assert_eq!(c.r(), 2.5);
    /// assert_eq!(RlsController::new(0.016, ResizeLimits::default()).starting_at(9.0).r(), 4.0);
    /// ```
    pub fn starting_at(mut self, r: f32) -> Self {
        self.r = self.limits.apply(r, r);
        self
    }

    /// Current estimates (K, C).
    pub fn estimates(&self) -> (f32, f32) {
        (self.theta[0] as f32, self.theta[1] as f32)
    }

    fn learn(&mut self, x: f64, t: f64) {
        let target = f64::from(self.target);
        let qk = (f64::from(self.k_drift) * self.theta[0].abs().max(0.1 * target)).powi(2);
        let qc = (f64::from(self.c_drift) * target).powi(2);
        let r = (f64::from(self.noise) * t).powi(2).max(1e-12);
        self.p[0][0] += qk;
        self.p[1][1] += qc;
        let phi = [x, 1.0];
        let error = t - (self.theta[0] * phi[0] + self.theta[1] * phi[1]);
        let predicted_var = r + self.p[0][0] * x * x + 2.0 * self.p[0][1] * x + self.p[1][1];
        if error * error > 9.0 * predicted_var {
            // A change, not noise (the innovation is beyond 3 sigma): let K move at once.
            self.p[0][0] += (0.5 * self.theta[0].abs().max(0.1 * target)).powi(2);
        }
        let p = self.p;
        let p_phi = [
            p[0][0] * phi[0] + p[0][1] * phi[1],
            p[1][0] * phi[0] + p[1][1] * phi[1],
        ];
        let denom = r + phi[0] * p_phi[0] + phi[1] * p_phi[1];
        let gain = [p_phi[0] / denom, p_phi[1] / denom];
        self.theta = [
            self.theta[0] + gain[0] * error,
            (self.theta[1] + gain[1] * error).max(0.0),
        ];
        for i in 0..2 {
            for j in 0..2 {
                self.p[i][j] = p[i][j] - gain[i] * p_phi[j];
            }
        }
    }
}

impl ResizeController for RlsController {
    fn r(&self) -> f32 {
        self.r
    }

    fn update(&mut self, frame_time: f32) -> f32 {
        self.observe(self.r, frame_time)
    }
}

impl RlsController {
    /// Like [`ResizeController::update`], for a frame time measured at `rendered_r`, which need
    /// not be the current r: GPU timestamps arrive a frame or more late, and by then r has moved.
    /// Crediting each time to the r it was rendered at keeps K and C right under that delay.
    /// A NaN or non-positive `rendered_r` or time is ignored (r is kept).
    ///
    /// ```
    /// # use lodkit::framebuffer_lod::{ResizeController, ResizeLimits, RlsController};
    /// // 26 ms at r = 1 and 14 ms at r = 2, credited to the r they were rendered at:
    /// // t = 16 / r^2 + 10 (ms).
    /// let mut c = RlsController::new(0.020, ResizeLimits::default());
    /// for _ in 0..30 {
    ///     c.observe(1.0, 0.026);
    ///     c.observe(2.0, 0.014);
    /// }
    /// let (k, overhead) = c.estimates();
    /// assert!((k - 0.016).abs() < 0.002 && (overhead - 0.010).abs() < 0.002, "{k} {overhead}");
    /// ```
    pub fn observe(&mut self, rendered_r: f32, frame_time: f32) -> f32 {
        if !valid(frame_time) || !valid(rendered_r) {
            return self.r;
        }
        self.learn(
            1.0 / f64::from(rendered_r * rendered_r),
            f64::from(frame_time),
        );
        let (k, c) = (self.theta[0], self.theta[1]);
        let wanted = if k > 1e-9 {
            let x_new = (f64::from(self.target) - c) / k;
            if x_new > 0.0 {
                (1.0 / x_new.sqrt()) as f32
            } else {
                f32::INFINITY
            }
        } else {
            // No usable K: move one step in the direction of the error.
            self.r + self.limits.max_step * (frame_time - self.target).signum()
        };
        self.r = self.limits.apply(self.r, wanted);
        self.r
    }
}

/// A step heuristic in the style of Unity HDRP's dynamic resolution: average the frame time over
/// a window; after `down_after` windows over budget raise r by `step`, after `up_after` windows
/// under budget (by the `headroom` fraction) lower it.
#[derive(Clone, Debug, PartialEq)]
pub struct StepController {
    /// Target frame time.
    pub target: f32,
    /// Limits (`step` is clamped to `max_step`).
    pub limits: ResizeLimits,
    /// Frames per averaging window (default 4).
    pub window: usize,
    /// Consecutive over-budget windows before r goes up (default 2).
    pub down_after: usize,
    /// Consecutive under-budget windows before r goes down (default 4).
    pub up_after: usize,
    /// Fraction under the target a window must be to count as under budget (default 0.1).
    pub headroom: f32,
    /// Change of r per decision (default 0.2).
    pub step: f32,
    r: f32,
    samples: Vec<f32>,
    over: usize,
    under: usize,
}

impl StepController {
    /// HDRP-like defaults, starting at r = 1.
    pub fn new(target: f32, limits: ResizeLimits) -> Self {
        Self {
            target,
            limits,
            window: 4,
            down_after: 2,
            up_after: 4,
            headroom: 0.1,
            step: 0.2,
            r: 1.0,
            samples: Vec::new(),
            over: 0,
            under: 0,
        }
    }
}

impl ResizeController for StepController {
    fn r(&self) -> f32 {
        self.r
    }

    fn update(&mut self, frame_time: f32) -> f32 {
        if !valid(frame_time) {
            return self.r;
        }
        self.samples.push(frame_time);
        if self.samples.len() < self.window.max(1) {
            return self.r;
        }
        let mean = self.samples.iter().sum::<f32>() / self.samples.len() as f32;
        self.samples.clear();
        let step = self.step.min(self.limits.max_step);
        if mean > self.target {
            self.over += 1;
            self.under = 0;
            if self.over >= self.down_after {
                self.r = self.limits.apply(self.r, self.r + step);
                self.over = 0;
            }
        } else if mean < self.target * (1.0 - self.headroom) {
            self.under += 1;
            self.over = 0;
            if self.under >= self.up_after {
                self.r = self.limits.apply(self.r, self.r - step);
                self.under = 0;
            }
        } else {
            self.over = 0;
            self.under = 0;
        }
        self.r
    }
}

/// The frame-time model of eq. 3 with noise: t = K x workload(frame) / r^2 + C, times
/// (1 + noise x a standard normal sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTimeModel {
    /// Pixel cost at r = 1.
    pub k: f32,
    /// Fixed cost.
    pub c: f32,
    /// Relative standard deviation of the noise.
    pub noise: f32,
}

impl FrameTimeModel {
    /// The noise-free frame time at `r` under workload multiplier `workload`.
    pub fn expected(&self, r: f32, workload: f32) -> f32 {
        self.k * workload / (r * r) + self.c
    }
}

/// One simulated frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimulatedFrame {
    /// r the frame was rendered at.
    pub r: f32,
    /// The time the controller saw (with noise).
    pub measured: f32,
    /// The noise-free time.
    pub expected: f32,
}

/// Runs `controller` for `frames` frames against `model`, with the workload multiplier given per
/// frame by `workload`; deterministic for `seed`.
pub fn simulate(
    controller: &mut dyn ResizeController,
    model: &FrameTimeModel,
    workload: impl Fn(usize) -> f32,
    frames: usize,
    seed: u64,
) -> Vec<SimulatedFrame> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let mut uniform = || ((rng.next_u32() >> 8) as f32 + 0.5) / (1u32 << 24) as f32;
    (0..frames)
        .map(|f| {
            let r = controller.r();
            let expected = model.expected(r, workload(f));
            // Box-Muller.
            let gauss = (-2.0 * uniform().ln()).sqrt() * (std::f32::consts::TAU * uniform()).cos();
            let measured = expected * (1.0 + model.noise * gauss).max(0.05);
            controller.update(measured);
            SimulatedFrame {
                r,
                measured,
                expected,
            }
        })
        .collect()
}

/// How a controller responded to a workload step at frame `step_frame`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepResponse {
    /// Frames after the step until the noise-free frame time stays within `band` of the target
    /// for the rest of the run (`None`: never).
    pub settling_frames: Option<usize>,
    /// Largest drop of the noise-free time below the target after the step, as a fraction of the
    /// target (r overshooting).
    pub overshoot: f32,
    /// Standard deviation of the measured time over the second half of the frames after the
    /// step, as a fraction of the target.
    pub spread: f32,
}

/// Measures the response in `frames` to a step at `step_frame`, with settling band `band` (0.05).
pub fn step_response(
    frames: &[SimulatedFrame],
    step_frame: usize,
    target: f32,
    band: f32,
) -> StepResponse {
    let after = &frames[step_frame.min(frames.len())..];
    let within = |f: &SimulatedFrame| (f.expected - target).abs() <= band * target;
    let settled_at = (0..after.len()).find(|&i| after[i..].iter().all(within));
    let overshoot = after
        .iter()
        .map(|f| (target - f.expected) / target)
        .fold(0.0f32, f32::max);
    let tail = &after[after.len() / 2..];
    let spread = if tail.len() > 1 {
        let mean = tail.iter().map(|f| f.measured).sum::<f32>() / tail.len() as f32;
        (tail
            .iter()
            .map(|f| (f.measured - mean).powi(2))
            .sum::<f32>()
            / tail.len() as f32)
            .sqrt()
            / target
    } else {
        0.0
    };
    StepResponse {
        settling_frames: settled_at,
        overshoot,
        spread,
    }
}
