//! The report's section on GPU LOD selection against `select_batch`.

use crate::demo::fixtures::clock::RECORDINGS;
use crate::demo::measures::selection::{SelectionReport, WARMUP_FRAMES};
use crate::demo::report::table::Table;

/// The section's text (Markdown and HTML alike).
pub fn text(s: &SelectionReport) -> String {
    format!(
        "GPU LOD selection (`GpuLodSelector`, one dispatch of `passes/select.wgsl`: the level by \
         lodkit's rule with its hysteresis and transitions kept per instance, bounding-sphere \
         culling, per-level instance lists and indirect draw arguments) against `select_batch` on \
         one core, over the same instances and camera path, {} frames each after {} untimed, \
         in this run. The GPU time is read from {} around a run of {} recordings of the \
         frame's selection (the count reset and the dispatches), and beside it from the wall \
         clock around one frame submitted and waited for (where timestamps do not bracket \
         compute work, as lavapipe's do not, the wall figure is the one to read). Per \
         instance the pass reads {} bytes settled ({} at most; {} of them the group table, which \
         stays in cache) and writes {} ({} for an instance in transition), counted from the \
         shader (`lodkit::shaders::cost`, sizes from naga's layouter). At {:.0} GB/s that is \
         {:.2e} to {:.2e} instances per second by memory traffic alone. On a software GPU the \
         dispatch shares the CPU's cores: the figures say nothing about a real GPU \
         (docs/benchmarks.md has an NVIDIA H200's).",
        s.frames,
        WARMUP_FRAMES,
        s.clock.label(),
        RECORDINGS,
        s.bytes_read.0,
        s.bytes_read.1,
        s.group_table_bytes,
        s.bytes_written.0,
        s.bytes_written.1,
        s.bandwidth / 1e9,
        s.bandwidth_bound.0,
        s.bandwidth_bound.1,
    )
}

/// The throughput table.
pub(crate) fn table(s: &SelectionReport) -> Table {
    Table {
        header: &[
            "instances",
            "GPU selection (instances/s, report clock)",
            "GPU selection (instances/s, wall clock)",
            "select_batch, one core (instances/s)",
        ],
        rows: s
            .rows
            .iter()
            .map(|r| {
                vec![
                    r.instances.to_string(),
                    format!("{:.3e}", r.gpu_per_second),
                    format!("{:.3e}", r.wall_per_second),
                    format!("{:.3e}", r.cpu_per_second),
                ]
            })
            .collect(),
    }
}
