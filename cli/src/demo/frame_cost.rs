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

use std::path::Path;

use serde::Serialize;

use super::DemoError;
use super::clock::{Clock, Timer, median};
use super::edge_frame::EdgeFrame;
use super::plots::{BarChart, Chart, Series, line_chart, stacked_bars};
use super::table::Table;
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
    /// Recordings per timed run.
    pub recordings: usize,
    /// Timing rounds per figure (medians).
    pub rounds: usize,
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

/// Measures the breakdown and the sweep on the edge scene at `size`, medians of `rounds`.
pub fn measure_frame_cost(
    gpu: &GpuContext,
    timer: &Timer,
    size: (u32, u32),
    rounds: usize,
) -> Result<FrameCost, DemoError> {
    let rounds = rounds.max(3);
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
    for round in 0..=rounds {
        for (c, &(route, r, term, p)) in configs.iter().enumerate() {
            let times = if route == full.0 {
                [0.0, frame.shade(&scene, 1.0, term, 0)?, 0.0]
            } else {
                frame.passes(&scene, r, term, p)?
            };
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
    // Whole frames against the shading work, each waited for once.
    let mut sweep = Vec::new();
    for work in SWEEP_WORK {
        scene.set_shading_work(work);
        let lod_frame = |r: f32, p: usize| frame.whole(&scene, r, p);
        lod_frame(SWEEP_FACTORS[0], 0)?;
        lod_frame(SWEEP_FACTORS[0], 1)?;
        let mut full_ms = Vec::new();
        let mut lod = [[Vec::new(), Vec::new()], [Vec::new(), Vec::new()]];
        for _ in 0..rounds {
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
        rounds,
        breakdown,
        sweep,
    })
}

/// The breakdown as a table.
pub(super) fn breakdown_table(cost: &FrameCost) -> Table {
    Table {
        header: &[
            "route",
            "r",
            "geometry prepass ms",
            "low-res shading ms",
            "upsample ms",
            "sum ms",
            "speed-up",
        ],
        rows: cost
            .breakdown
            .iter()
            .map(|p| {
                let sum: f64 = p.ms.iter().sum();
                let full: f64 = cost.breakdown[0].ms.iter().sum();
                let mut row = vec![p.route.clone(), p.r.to_string()];
                row.extend(p.ms.iter().map(|t| format!("{t:.2}")));
                row.push(format!("{sum:.2}"));
                row.push(format!("{:.2}x", full / sum));
                row
            })
            .collect(),
    }
}

/// The sweep as a table.
pub(super) fn sweep_table(cost: &FrameCost) -> Table {
    Table {
        header: &[
            "shading work",
            "full-resolution frame ms",
            "r = 2 frame ms",
            "r = 2 speed-up",
            "r = 3 frame ms",
            "r = 3 speed-up",
            "r = 2 speed-up, packed L",
            "r = 3 speed-up, packed L",
        ],
        rows: cost
            .sweep
            .iter()
            .map(|s| {
                vec![
                    s.work.to_string(),
                    format!("{:.1}", s.full_ms),
                    format!("{:.1}", s.lod_ms[0]),
                    format!("{:.2}x", s.speedup(0)),
                    format!("{:.1}", s.lod_ms[1]),
                    format!("{:.2}x", s.speedup(1)),
                    format!("{:.2}x", s.packed_speedup(0)),
                    format!("{:.2}x", s.packed_speedup(1)),
                ]
            })
            .collect(),
    }
}

/// The crossover and the pixel-bound figures, one sentence.
pub fn summary(cost: &FrameCost) -> String {
    let cross = |k: usize| {
        cost.crossover(k)
            .map_or("never within the sweep".to_owned(), |w| {
                format!("from a shading work of {w:.0}")
            })
    };
    let last = cost.sweep.last();
    let (work, full, s2, s3) = last.map_or((0, 0.0, 0.0, 0.0), |s| {
        (s.work, s.full_ms, s.speedup(0), s.speedup(1))
    });
    let at = |w: u32| cost.sweep.iter().find(|s| s.work == w);
    let packed = at(BREAKDOWN_WORK).map_or(String::new(), |s| {
        format!(
            " At shading work {}, from a packed L: {:.2}x at r = 2 and {:.2}x at r = 3 (unpacked \
             {:.2}x and {:.2}x).",
            s.work,
            s.packed_speedup(0),
            s.packed_speedup(1),
            s.speedup(0),
            s.speedup(1)
        )
    });
    let (w, h) = cost.size;
    let mpix = f64::from(w) * f64::from(h) / 1e6;
    format!(
        "Framebuffer LOD pays (speed-up above 1) at r = 2 {}, at r = 3 {}. At the most \
         pixel-bound point of the sweep (shading work {work}: the full-resolution frame takes \
         {full:.0} ms, {:.0} ms per megapixel of shading) the whole-frame speed-up is {s2:.2}x \
         at r = 2 and {s3:.2}x at r = 3.{packed}",
        cross(0),
        cross(1),
        full / mpix
    )
}

/// Writes `plots/frame-breakdown.png` and `plots/speedup-vs-shading.png` under `out`.
pub fn write_plots(cost: &FrameCost, out: &Path) -> Result<(), DemoError> {
    let bars = cost
        .breakdown
        .iter()
        .map(|p| {
            let label = match p.route.as_str() {
                "full resolution" => "full res".to_owned(),
                "fine-grained" => format!("fine {}", p.r),
                "bilateral, packed L" => format!("packed {}", p.r),
                "fine-grained, packed L" => format!("fine packed {}", p.r),
                _ => format!("r = {}", p.r),
            };
            (label, p.ms.map(|t| t as f32).to_vec())
        })
        .collect();
    let (w, h) = cost.size;
    stacked_bars(
        &out.join("plots/frame-breakdown.png"),
        &BarChart {
            title: format!("Where a frame's time goes ({w}x{h}, shading work {BREAKDOWN_WORK})"),
            y_label: "ms per pass (median)".to_owned(),
            parts: PASSES.iter().map(|p| p.to_string()).collect(),
            bars,
        },
    )?;
    let series = [false, true]
        .into_iter()
        .flat_map(|packed| {
            SWEEP_FACTORS
                .iter()
                .enumerate()
                .map(move |(k, r)| (packed, k, r))
        })
        .map(|(packed, k, r)| Series {
            name: format!("r = {r}{}", if packed { ", packed L" } else { "" }),
            points: cost
                .sweep
                .iter()
                .map(|s| {
                    let x = if packed {
                        s.packed_speedup(k)
                    } else {
                        s.speedup(k)
                    };
                    (s.work as f32, x as f32)
                })
                .collect(),
        })
        .collect();
    line_chart(
        &out.join("plots/speedup-vs-shading.png"),
        &Chart {
            title: format!("Whole-frame speed-up against shading cost ({w}x{h})"),
            x_label: "synthetic shading work (sky directions per fragment)".to_owned(),
            y_label: "full-resolution frame / framebuffer-LOD frame".to_owned(),
            series,
            markers: true,
            reference: Some(1.0),
            y_from_zero: true,
        },
    )
}
