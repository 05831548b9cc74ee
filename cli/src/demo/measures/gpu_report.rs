//! `lodkit gpu-report`: the figures to take on a real GPU, in one run of a few minutes, on GPU
//! timestamps where the device has them: the pass ratios at 1920x1080 and 3840x2160 (the
//! bilateral upsample, its loads and the packed L against bilinear; the combine against a copy
//! of its textures at 1024^2 and 2048^2), the whole-frame cost sweep of framebuffer LOD at
//! 1920x1080, and GPU selection from 10^4 to 10^7 instances against `select_batch`, returned as a
//! [`GpuReport`] (`report::gpu_report` writes `gpu-report.json` and `gpu-report.md`;
//! `scripts/gpu-report.sh` adds the test binaries' runs).
//! `--quick` measures small sizes for a test on the software GPU.

use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::fixtures::clock::RECORDINGS;
use crate::demo::fixtures::clock::{Clock, Timer};
use crate::demo::measures::combine_timing;
use crate::demo::measures::frame_cost::{self, FrameCost};
use crate::demo::measures::packed_upsample_timing;
use crate::demo::measures::selection::{self, SelectionReport};
use crate::demo::measures::upsample_timing;
use crate::demo::measures::upsample_timing::PassRatio;
use lodkit::gpu::GpuContext;

/// What `lodkit gpu-report` measures.
#[derive(Clone, Debug)]
pub struct GpuReportOptions {
    /// Small sizes and counts (a test on the software GPU), not the real-GPU ones.
    pub quick: bool,
    /// Interleaved pairs per ratio.
    pub pairs: usize,
}

impl Default for GpuReportOptions {
    fn default() -> Self {
        Self {
            quick: false,
            pairs: 9,
        }
    }
}

/// Everything one run measured.
#[derive(Clone, Debug, Serialize)]
pub struct GpuReport {
    /// Adapter name, backend, device type, driver.
    pub adapter: String,
    /// The clock every figure was read from.
    pub clock: Clock,
    /// Recordings per timed run.
    pub recordings: usize,
    /// Whether this was a `--quick` run (small sizes: not figures to quote).
    pub quick: bool,
    /// Pass ratios, at each size.
    pub pass_ratios: Vec<PassRatio>,
    /// Framebuffer LOD's whole-frame cost against shading work.
    pub frame_cost: FrameCost,
    /// GPU selection against `select_batch`.
    pub selection: SelectionReport,
    /// Wall time of the run, seconds.
    pub seconds: f64,
}

/// Runs the measurements on `gpu`.
pub fn measure(gpu: &GpuContext, options: &GpuReportOptions) -> Result<GpuReport, DemoError> {
    let start = std::time::Instant::now();
    let timer = Timer::new(gpu, RECORDINGS)?;
    let pairs = options.pairs.max(1);
    let (sizes, combine_sizes, fb_size, select_sizes): (&[(u32, u32)], &[u32], _, &[usize]) =
        if options.quick {
            (&[(256, 144)], &[128], (256, 144), &[1_000, 10_000])
        } else {
            (
                &[(1920, 1080), (3840, 2160)],
                &[1024, 2048],
                (1920, 1080),
                &[10_000, 100_000, 1_000_000, 10_000_000],
            )
        };
    let mut pass_ratios = Vec::new();
    for &size in sizes {
        pass_ratios.extend(upsample_timing::upsample_vs_bilinear(
            gpu, &timer, size, 2.0, pairs,
        )?);
        pass_ratios.extend(packed_upsample_timing::packed_upsample_vs_bilinear(
            gpu, &timer, size, 2.0, pairs,
        )?);
    }
    for &size in combine_sizes {
        pass_ratios.extend(combine_timing::combine_vs_copy(gpu, &timer, size, pairs)?);
    }
    let frame_cost = frame_cost::measure_frame_cost(gpu, &timer, fb_size, 3, 3)?;
    let selection = selection::measure(gpu, &timer, 3, select_sizes)?;
    Ok(GpuReport {
        adapter: gpu.adapter_summary(),
        clock: timer.clock(),
        recordings: timer.recordings(),
        quick: options.quick,
        pass_ratios,
        frame_cost,
        selection,
        seconds: start.elapsed().as_secs_f64(),
    })
}
