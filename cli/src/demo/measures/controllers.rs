//! The framerate controllers simulated under a workload step: lodkit's, the paper's, a step
//! heuristic and a fixed r, on the frame-time model of eq. 3 with noise.

use serde::Serialize;

use lodkit::framebuffer_lod::{
    FixedController, FrameTimeModel, PaperController, ResizeController, ResizeLimits,
    RlsController, StepController, simulate, step_response,
};

/// One controller under a workload step.
#[derive(Clone, Debug, Serialize)]
pub struct ControllerRow {
    /// Controller.
    pub name: String,
    /// Median frames to settle within 5 % of the target after the step (None: never).
    pub settling_frames: Option<f32>,
    /// Median overshoot (fraction of the target).
    pub overshoot: f32,
    /// Median spread after settling (fraction of the target).
    pub spread: f32,
    /// Frame times of seed 1 over the whole run (ms), for the plot.
    pub curve: Vec<f32>,
}

/// Noise seeds the controller medians are taken over.
pub const CONTROLLER_SEEDS: u64 = 50;

/// Frame-time target of the controller simulation (ms).
pub const TARGET_MS: f32 = 16.7;
/// Frames in the controller simulation; the workload doubles over frames 60..160.
pub const CONTROLLER_FRAMES: usize = 220;

fn controllers() -> Vec<(&'static str, Box<dyn ResizeController>)> {
    let limits = ResizeLimits::default();
    vec![
        ("fixed r = 1.6", Box::new(FixedController { r: 1.6 })),
        (
            "paper (calibrated K)",
            Box::new(PaperController::new(TARGET_MS, 40.0, limits)),
        ),
        (
            "lodkit (online K, C)",
            Box::new(RlsController::new(TARGET_MS, limits)),
        ),
        (
            "step heuristic",
            Box::new(StepController::new(TARGET_MS, limits)),
        ),
    ]
}

/// Simulates the controllers (t = K workload / r^2 + C + 3 % noise, K = 40 ms, C = 3 ms) with
/// the workload doubling at frame 60 and back at 160; medians over `seeds` noise seeds.
pub fn measure_controllers(seeds: u64) -> Vec<ControllerRow> {
    let model = FrameTimeModel {
        k: 40.0,
        c: 3.0,
        noise: 0.03,
    };
    let workload = |f: usize| if (60..160).contains(&f) { 2.0 } else { 1.0 };
    let median32 = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f32::NAN)
    };
    let names: Vec<&str> = controllers().iter().map(|c| c.0).collect();
    names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let (mut settle, mut over, mut spread) = (Vec::new(), Vec::new(), Vec::new());
            for seed in 0..seeds.max(1) {
                let mut c = controllers().swap_remove(i).1;
                let frames = simulate(c.as_mut(), &model, workload, 160, seed);
                let s = step_response(&frames, 60, TARGET_MS, 0.05);
                settle.push(s.settling_frames.map_or(f32::INFINITY, |s| s as f32));
                over.push(s.overshoot);
                spread.push(s.spread);
            }
            let mut c = controllers().swap_remove(i).1;
            let curve = simulate(c.as_mut(), &model, workload, CONTROLLER_FRAMES, 1)
                .iter()
                .map(|f| f.measured)
                .collect();
            let s = median32(&mut settle);
            ControllerRow {
                name: (*name).to_owned(),
                settling_frames: s.is_finite().then_some(s),
                overshoot: median32(&mut over),
                spread: median32(&mut spread),
                curve,
            }
        })
        .collect()
}
