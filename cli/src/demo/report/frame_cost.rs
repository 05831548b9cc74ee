//! The report's sections on where a framebuffer-LOD frame's time goes: the breakdown and sweep
//! tables, the crossover sentence and their plots.

use std::path::Path;

use crate::demo::error::DemoError;
use crate::demo::measures::frame_cost::{BREAKDOWN_WORK, FrameCost, PASSES, SWEEP_FACTORS};
use crate::demo::report::plots::{BarChart, Chart, Series, line_chart, stacked_bars};
use crate::demo::report::table::Table;

/// The breakdown as a table.
pub(crate) fn breakdown_table(cost: &FrameCost) -> Table {
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
pub(crate) fn sweep_table(cost: &FrameCost) -> Table {
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
