//! `lodkit gpu-report`'s files: `gpu-report.json` and `gpu-report.md`.

use std::path::Path;

use crate::demo::error::DemoError;
use crate::demo::measures::gpu_report::GpuReport;
use crate::demo::report::{frame_cost, selection};

/// The report as Markdown: the adapter, driver and clock first, then one table per section.
pub fn markdown(report: &GpuReport) -> String {
    let mut s = format!(
        "# lodkit GPU report\n\nAdapter: {}. Clock: {} ({} recordings per timed run). {}Run time \
         {:.0} s.\n\n## Pass time ratios\n\n",
        report.adapter,
        report.clock.label(),
        report.recordings,
        if report.quick {
            "Quick run (small sizes: a test of the command, not figures to quote). "
        } else {
            ""
        },
        report.seconds
    );
    s.push_str(&crate::demo::report::ratio_table(&report.pass_ratios).markdown());
    s.push_str("\n## Framebuffer LOD: where a frame's time goes\n\n");
    s.push_str(&frame_cost::breakdown_table(&report.frame_cost).markdown());
    s.push_str("\n## Framebuffer LOD: speed-up against shading cost\n\n");
    s.push_str(&frame_cost::summary(&report.frame_cost));
    s.push_str("\n\n");
    s.push_str(&frame_cost::sweep_table(&report.frame_cost).markdown());
    s.push_str("\n## GPU LOD selection\n\n");
    s.push_str(&selection::table(&report.selection).markdown());
    s
}

/// Writes `gpu-report.json` and `gpu-report.md` into `out`.
pub fn write(report: &GpuReport, out: &Path) -> Result<(), DemoError> {
    std::fs::create_dir_all(out).map_err(|e| DemoError::io(out, e))?;
    let json =
        serde_json::to_string_pretty(report).map_err(|e| DemoError::Internal(e.to_string()))?;
    let path = out.join("gpu-report.json");
    std::fs::write(&path, json).map_err(|e| DemoError::io(&path, e))?;
    let path = out.join("gpu-report.md");
    std::fs::write(&path, markdown(report)).map_err(|e| DemoError::io(&path, e))
}
