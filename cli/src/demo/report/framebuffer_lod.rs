//! The report's sections on framebuffer LOD at full HD-like sizes: the per-pass breakdown, the
//! shading-cost sweep and the controllers on the real frame (HTML, Markdown and plots).

use std::path::Path;

use crate::demo::error::DemoError;
use crate::demo::measures::DemoReport;
use crate::demo::report::{closed_loop, frame_cost};

use crate::demo::report::table::img as figure;

const BREAKDOWN_TEXT: &str = "Each pass of a frame timed on its own (per recording, on the clock below, median of the rounds): the full-resolution geometry prepass the upsampling needs (depth and normal, with the cheap albedo term), the low-resolution shading pass, and the upsample pass. The fine-grained route shades only the lighting at low resolution; its full-resolution albedo pass writes the geometry, so it is the prepass. Speed-up: the full-resolution frame's time over the sum of the passes.";

const SWEEP_TEXT: &str = "Whole frames (the three passes recorded one after the other, per recording, on the same clock; on GPU timestamps each frame is timed alone, as an engine times its frames) against the synthetic shading work per fragment: the full-resolution frame shades every pixel, the framebuffer-LOD frame runs the prepass, the low-resolution shading and the upsample.";

/// The plots of these sections.
pub fn write_plots(report: &DemoReport, out: &Path) -> Result<(), DemoError> {
    frame_cost::write_plots(&report.frame_cost, out)?;
    closed_loop::write_plots(&report.closed_loop, out)
}

/// The HTML sections.
pub fn html(report: &DemoReport) -> String {
    let (cost, closed) = (&report.frame_cost, &report.closed_loop);
    let (w, h) = cost.size;
    let mut s = format!(
        "<h2>Framebuffer LOD at {w}x{h}: where the time goes</h2>\n<p>{BREAKDOWN_TEXT} Clock: \
         {}.</p>\n",
        cost.clock.label()
    );
    s.push_str(&frame_cost::breakdown_table(cost).html());
    s.push_str(&figure(
        "plots/frame-breakdown.png",
        "time of each pass, per resize factor and route",
    ));
    s.push_str(&format!(
        "<p>{SWEEP_TEXT} Medians of {} rounds. {}</p>\n",
        cost.sweep_rounds,
        frame_cost::summary(cost)
    ));
    s.push_str(&frame_cost::sweep_table(cost).html());
    s.push_str(&figure(
        "plots/speedup-vs-shading.png",
        "whole-frame speed-up against shading work; 1 is the crossover",
    ));
    s.push_str(&format!(
        "<h2>Controllers on the real frame</h2>\n<p>{}</p>\n",
        closed_loop::summary(closed)
    ));
    s.push_str(&closed_loop::table(closed).html());
    s.push_str(&figure(
        "plots/closed-loop-ms.png",
        "measured frame time per frame; the line is the target",
    ));
    s.push_str(&figure(
        "plots/closed-loop-r.png",
        "resize factor per frame",
    ));
    s
}

/// The sections of `benchmarks.md`.
pub fn benchmarks_markdown(report: &DemoReport) -> String {
    let cost = &report.frame_cost;
    let (w, h) = cost.size;
    let mut s = format!(
        "\n## Framebuffer LOD at {w}x{h}: where the time goes\n\n{BREAKDOWN_TEXT} Clock: {}. Shading work {}.\n\n",
        cost.clock.label(),
        crate::demo::measures::frame_cost::BREAKDOWN_WORK
    );
    s.push_str(&frame_cost::breakdown_table(cost).markdown());
    s.push_str("\n![Time of each pass per resize factor and route](img/frame-breakdown.png)\n");
    s.push_str(&format!(
        "\n## Framebuffer LOD at {w}x{h}: speed-up against shading cost\n\n{SWEEP_TEXT} Medians \
         of {} rounds. {}\n\n",
        cost.sweep_rounds,
        frame_cost::summary(cost)
    ));
    s.push_str(&frame_cost::sweep_table(cost).markdown());
    s.push_str("\n![Whole-frame speed-up against shading work](img/speedup-vs-shading.png)\n");
    s
}

/// The section of `quality.md`.
pub fn quality_markdown(report: &DemoReport) -> String {
    let closed = &report.closed_loop;
    let mut s = format!(
        "\n## Framerate control on the real frame\n\n{}\n\n",
        closed_loop::summary(closed)
    );
    s.push_str(&closed_loop::table(closed).markdown());
    s.push_str("\n![Measured frame time per frame](img/closed-loop-ms.png)\n");
    s
}
