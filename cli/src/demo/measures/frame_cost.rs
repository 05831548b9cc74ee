//! Where a framebuffer-LOD frame's time goes, at a size where a pass is not dominated by
//! submission overhead (1280x720 by default): each pass of the frame timed on its own at every
//! resize factor, and the whole-frame speed-up as a function of the per-pixel shading cost (a
//! sweep of the synthetic shading work), with the crossover where framebuffer LOD starts to pay.
//!
//! A framebuffer-LOD frame is the full-resolution geometry prepass the upsampling needs (depth
//! and normal, with the cheap albedo term), the low-resolution shading pass at r, and the
//! upsample pass. The fine-grained route shades only the lighting at low resolution; its
//! full-resolution albedo pass writes the geometry, so it is the same pass as the prepass, and its
//! upsample multiplies by that albedo (the composite, inside the pass). Each route also runs from
//! a packed L (`lodkit::gbuffer`'s packed texel: 4 low-resolution loads per pixel instead of 8;
//! in the fine-grained route the upsample is folded into the composite).
//!
//! Every time is read from the [`Clock`] the figure names: GPU timestamps around a run of
//! recordings where the device has them, the wall clock around a submission and its wait
//! otherwise.

use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::fixtures::clock::{Clock, Timer, median};
use crate::demo::fixtures::edge_frame::EdgeFrame;
use lodkit::gpu::GpuContext;
use lodkit_scenes::gbuffer::ShadingTerm;

/// Resize factors of the breakdown.
pub const BREAKDOWN_FACTORS: [f32; 4] = [1.5, 2.0, 3.0, 4.0];
/// Synthetic shading work (sky directions per fragment) of the breakdown.
pub const BREAKDOWN_WORK: u32 = 64;
/// Shading work levels of the sweep.
pub const SWEEP_WORK: [u32; 8] = [0, 8, 16, 32, 64, 128, 256, 512];
/// Resize factors of the sweep.
pub const SWEEP_FACTORS: [f32; 2] = [2.0, 3.0];
/// Passes of a frame, in order.
pub const PASSES: [&str; 3] = ["geometry prepass", "low-res shading", "upsample"];

/// The median time of each pass of one frame configuration.
#[derive(Clone, Debug, Serialize)]
pub struct PassTimes {
    /// `full resolution`, `bilateral` or `fine-grained`, the last two also `..., packed L`.
    pub route: String,
    /// Resize factor (1 for the full-resolution frame).
    pub r: f32,
    /// Median milliseconds of each of [`PASSES`] (the full-resolution frame has only shading).
    pub ms: [f64; 3],
}

/// One shading-work level of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    /// Sky directions summed per fragment.
    pub work: u32,
    /// Median full-resolution frame (ms).
    pub full_ms: f64,
    /// Median framebuffer-LOD frame at each of [`SWEEP_FACTORS`] (ms).
    pub lod_ms: [f64; 2],
    /// The same from a packed L (ms).
    pub packed_ms: [f64; 2],
}

impl SweepRow {
    /// Whole-frame speed-up at `SWEEP_FACTORS[k]`.
    pub fn speedup(&self, k: usize) -> f64 {
        self.full_ms / self.lod_ms[k]
    }

    /// Whole-frame speed-up at `SWEEP_FACTORS[k]` from a packed L.
    pub fn packed_speedup(&self, k: usize) -> f64 {
        self.full_ms / self.packed_ms[k]
    }
}

/// Everything this module measures.
#[derive(Clone, Debug, Serialize)]
pub struct FrameCost {
    /// Image size.
    pub size: (u32, u32),
    /// The clock every time was read from.
    pub clock: Clock,
    /// Recordings per timed run of the breakdown: at most this, fewer for a configuration whose
    /// shortest pass lasts [`MIN_RUN_MS`](crate::demo::fixtures::clock::MIN_RUN_MS) alone on
    /// GPU timestamps.
    pub recordings: usize,
    /// Recordings per timed run of the sweep (1 on GPU timestamps: a whole frame is long
    /// enough to time alone).
    pub sweep_recordings: usize,
    /// Timing rounds per figure of the breakdown (medians).
    pub rounds: usize,
    /// Timing rounds per figure of the sweep (medians), at least 3: a whole frame is long and
    /// steady next to one pass, and the sweep's frames at the heaviest shading work are a large
    /// part of the demo's rendering time.
    pub sweep_rounds: usize,
    /// The breakdown at [`BREAKDOWN_WORK`].
    pub breakdown: Vec<PassTimes>,
    /// The sweep over [`SWEEP_WORK`].
    pub sweep: Vec<SweepRow>,
}

impl FrameCost {
    /// Shading work where the speed-up at `SWEEP_FACTORS[k]` reaches 1 (linear between sweep
    /// points); `Some(0.0)` when it pays without any, `None` when it never does.
    pub fn crossover(&self, k: usize) -> Option<f64> {
        let s = &self.sweep;
        if s.first()?.speedup(k) >= 1.0 {
            return Some(0.0);
        }
        s.windows(2).find_map(|w| {
            let (a, b) = (w[0].speedup(k), w[1].speedup(k));
            (a < 1.0 && b >= 1.0).then(|| {
                let t = (1.0 - a) / (b - a);
                f64::from(w[0].work) + t * f64::from(w[1].work - w[0].work)
            })
        })
    }
}

/// Measures the breakdown and the sweep on the edge scene at `size`: the breakdown's figures
/// medians of `rounds`, the sweep's of `sweep_rounds` (each at least 3).
pub fn measure_frame_cost(
    gpu: &GpuContext,
    timer: &Timer,
    size: (u32, u32),
    rounds: usize,
    sweep_rounds: usize,
) -> Result<FrameCost, DemoError> {
    let (rounds, sweep_rounds) = (rounds.max(3), sweep_rounds.max(3));
    let (frame, mut scene) = EdgeFrame::new(gpu, timer, size)?;
    // Pass by pass, rounds interleaved over the configurations; round 0 warms up.
    scene.set_shading_work(BREAKDOWN_WORK);
    let full = ("full resolution", 1.0, ShadingTerm::Full, 0);
    let (bilateral, fine) = (ShadingTerm::Full, ShadingTerm::Lighting);
    let configs: Vec<(&str, f32, ShadingTerm, usize)> = std::iter::once(full)
        .chain(BREAKDOWN_FACTORS.map(|r| ("bilateral", r, bilateral, 0)))
        .chain(BREAKDOWN_FACTORS.map(|r| ("fine-grained", r, fine, 0)))
        .chain(BREAKDOWN_FACTORS.map(|r| ("bilateral, packed L", r, bilateral, 1)))
        .chain(BREAKDOWN_FACTORS.map(|r| ("fine-grained, packed L", r, fine, 1)))
        .collect();
    let mut samples = vec![[Vec::new(), Vec::new(), Vec::new()]; configs.len()];
    // Recordings per run of each configuration, from its warm-up round: as many as its
    // shortest pass needs (`Timer::recordings_for`).
    let mut recordings = vec![timer.recordings(); configs.len()];
    for round in 0..=rounds {
        for (c, &(route, r, term, p)) in configs.iter().enumerate() {
            let times = timer.with_recordings(recordings[c], || {
                if route == full.0 {
                    Ok([0.0, frame.shade(&scene, 1.0, term, 0)?, 0.0])
                } else {
                    frame.passes(&scene, r, term, p)
                }
            })?;
            if round == 0 {
                let shortest = times
                    .iter()
                    .copied()
                    .filter(|&t| t > 0.0)
                    .fold(f64::INFINITY, f64::min);
                recordings[c] = timer.recordings_for(shortest);
            }
            for (k, t) in times.into_iter().enumerate().filter(|_| round > 0) {
                samples[c][k].push(t);
            }
        }
    }
    let breakdown = configs
        .iter()
        .zip(&samples)
        .map(|(&(route, r, _, _), s)| PassTimes {
            route: route.to_owned(),
            r,
            ms: [median(&s[0]), median(&s[1]), median(&s[2])],
        })
        .collect();
    // Whole frames against the shading work. A whole frame at this size is long next to a
    // timestamp's resolution, so on GPU timestamps each is timed as one recording, as an engine
    // times its frames (and as the closed loop does); on the wall clock a run of recordings
    // still spreads the submission's fixed cost. On lavapipe at 1280x720 this took the sweep
    // from 3/4 of the demo's time to 1/8 of it.
    let one = Timer::new(gpu, 1)?;
    let sweep_timer = match timer.clock() {
        Clock::GpuTimestamps => &one,
        Clock::WallClock => timer,
    };
    let (frame, mut scene) = EdgeFrame::new(gpu, sweep_timer, size)?;
    let mut sweep = Vec::new();
    for work in SWEEP_WORK {
        scene.set_shading_work(work);
        let lod_frame = |r: f32, p: usize| frame.whole(&scene, r, p);
        lod_frame(SWEEP_FACTORS[0], 0)?;
        lod_frame(SWEEP_FACTORS[0], 1)?;
        let mut full_ms = Vec::new();
        let mut lod = [[Vec::new(), Vec::new()], [Vec::new(), Vec::new()]];
        for _ in 0..sweep_rounds {
            full_ms.push(frame.shade(&scene, 1.0, ShadingTerm::Full, 0)?);
            for (k, &r) in SWEEP_FACTORS.iter().enumerate() {
                for (p, times) in lod.iter_mut().enumerate() {
                    times[k].push(lod_frame(r, p)?);
                }
            }
        }
        sweep.push(SweepRow {
            work,
            full_ms: median(&full_ms),
            lod_ms: [median(&lod[0][0]), median(&lod[0][1])],
            packed_ms: [median(&lod[1][0]), median(&lod[1][1])],
        });
    }
    Ok(FrameCost {
        size,
        clock: timer.clock(),
        recordings: timer.recordings(),
        sweep_recordings: sweep_timer.recordings(),
        rounds,
        sweep_rounds,
        breakdown,
        sweep,
    })
}
