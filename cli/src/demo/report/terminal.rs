//! The summary the `lodkit demo` command prints on the terminal.

use std::fmt::Write as _;

use crate::demo::measures::DemoReport;
use crate::demo::report::table::{pct, reads, times};

/// The summary table printed on the terminal.
pub fn summary(report: &DemoReport) -> String {
    let mut s = format!(
        "adapter: {}\nclock: {}\n{}x{}, transitions of {} frames, {:.0} s\n",
        report.adapter,
        report.clock.label(),
        report.size.0,
        report.size.1,
        report.frames,
        report.seconds
    );
    for scene in &report.scenes {
        let _ = writeln!(
            s,
            "\n{scene:<24} {:>8} {:>8} {:>8} {:>8} {:>12} {:>8} {:>10} {:>10} {:>10}",
            "pop",
            "pop mov",
            "flicker",
            "flk mov",
            "see-through",
            "sil mov",
            "tris",
            "frags",
            "idle"
        );
        for t in report.transitions.iter().filter(|t| &t.scene == scene) {
            let _ = writeln!(
                s,
                "  {:<22} {:>8.3} {:>8.3} {:>8.2} {:>8.2} {:>12} {:>8} {:>9.3}x {:>10} {:>10}",
                t.technique,
                t.pop_static,
                t.pop_moving,
                t.flicker_static,
                t.flicker_moving,
                pct(t.see_through),
                pct(t.silhouette_error),
                t.triangles_vs_hard,
                times(t.fragments_vs_hard),
                times(t.idle_fragments_vs_hard)
            );
        }
    }
    let _ = writeln!(
        s,
        "\n{:<6} {:>10} {:>10} {:>12} {:>10}",
        "r", "bilinear", "bilateral", "fine-grained", "speed-up"
    );
    for u in &report.upsampling {
        let _ = writeln!(
            s,
            "{:<6} {:>7.2} dB {:>7.2} dB {:>9.2} dB {:>9.2}x",
            u.r, u.psnr[0], u.psnr[1], u.psnr[2], u.speedup[0]
        );
    }
    s.push('\n');
    for p in &report.pass_ratios {
        let _ = writeln!(
            s,
            "{} / {}: {:.3}x ({} vs {} per pixel)",
            p.pass,
            p.baseline,
            p.ratio,
            reads(&p.pass_reads),
            reads(&p.baseline_reads)
        );
    }
    s
}
