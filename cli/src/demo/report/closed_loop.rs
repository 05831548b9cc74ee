//! The report's section on the controllers on the real frame: the table of runs, the sentence on
//! their setting and the plots of frame time and r.

use std::path::Path;

use crate::demo::error::DemoError;
use crate::demo::measures::closed_loop::{
    BASE_WORK, ClosedLoop, ClosedLoopRun, REPEATS, SMOOTHING, STEP_FRAME, TARGET_R,
};
use crate::demo::report::plots::{Chart, Series, line_chart};
use crate::demo::report::table::Table;

/// The median of `values` and their range, formatted by `f` (`"6 (5-9)"`).
fn median_range(mut values: Vec<f32>, f: &dyn Fn(f32) -> String) -> String {
    values.sort_by(f32::total_cmp);
    match (values.first(), values.get(values.len() / 2), values.last()) {
        (Some(lo), Some(mid), Some(hi)) if lo == hi => f(*mid),
        (Some(lo), Some(mid), Some(hi)) => format!("{} ({}-{})", f(*mid), f(*lo), f(*hi)),
        _ => "-".to_owned(),
    }
}

/// The runs as a table: per controller the median over its [`REPEATS`] runs and, in brackets,
/// their range.
pub(crate) fn table(closed: &ClosedLoop) -> Table {
    let settle = |s: f32| {
        if s.is_finite() {
            format!("{s:.0}")
        } else {
            "never".to_owned()
        }
    };
    let percent = |p: f32| format!("{:.0} %", p * 100.0);
    let percent1 = |p: f32| format!("{:.1} %", p * 100.0);
    let r = |r: f32| format!("{r:.2}");
    Table {
        header: &[
            "controller",
            "settling frames (within 10 %)",
            "single frames within 10 % after settling",
            "overshoot",
            "spread",
            "r at the end",
        ],
        rows: closed
            .repeats
            .iter()
            .map(|runs| {
                let of = |v: &dyn Fn(&ClosedLoopRun) -> f32| runs.iter().map(v).collect();
                let settled =
                    |run: &ClosedLoopRun| run.settling_frames.map_or(f32::INFINITY, |s| s as f32);
                let end = |run: &ClosedLoopRun| run.r.last().copied().unwrap_or(f32::NAN);
                vec![
                    runs.first().map_or(String::new(), |run| run.name.clone()),
                    median_range(of(&settled), &settle),
                    median_range(of(&|run| run.frames_within), &percent),
                    median_range(of(&|run| run.overshoot), &percent1),
                    median_range(of(&|run| run.spread), &percent1),
                    median_range(of(&end), &r),
                ]
            })
            .collect(),
    }
}

/// One sentence on the setting of the runs.
pub fn summary(closed: &ClosedLoop) -> String {
    let (w, h) = closed.size;
    format!(
        "The edge scene at {w}x{h}, rendered frame by frame (prepass, low-resolution shading at \
         the controller's r, upsample), each frame timed as one run of its recordings on the \
         clock: {}. Target {:.1} ms (the frame at r = {TARGET_R} measured before the runs); the shading \
         work doubles from {BASE_WORK} to {} sky directions at frame {STEP_FRAME}; the paper's K \
         calibrated from frames at r = 1 and r = 2: {:.1} ms; lodkit's controller is told the \
         noise measured in the calibration frames ({:.1} %). Settling: frames after the step until \
         the median of the last {SMOOTHING} frame times stays within 10 % of the target in every \
         frame to the end of the run; single frames scatter around it by the noise. Each \
         controller ran {REPEATS} times, interleaved: the table gives the median and, in \
         brackets, the range.",
        closed.clock.label(),
        closed.target_ms,
        2 * BASE_WORK,
        closed.paper_k,
        closed.noise * 100.0
    )
}

/// Writes `plots/closed-loop-ms.png` and `plots/closed-loop-r.png` under `out`.
pub fn write_plots(closed: &ClosedLoop, out: &Path) -> Result<(), DemoError> {
    let series = |of: &dyn Fn(&ClosedLoopRun) -> &Vec<f32>| -> Vec<Series> {
        closed
            .runs()
            .map(|run| Series {
                name: run.name.clone(),
                points: of(run)
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| (i as f32, v))
                    .collect(),
            })
            .collect()
    };
    let (w, h) = closed.size;
    line_chart(
        &out.join("plots/closed-loop-ms.png"),
        &Chart {
            title: format!(
                "Measured frame time, shading work doubling at frame {STEP_FRAME} ({w}x{h})"
            ),
            x_label: "frame".to_owned(),
            y_label: "ms".to_owned(),
            series: series(&|run| &run.ms),
            markers: false,
            reference: Some(closed.target_ms),
            y_from_zero: true,
        },
    )?;
    line_chart(
        &out.join("plots/closed-loop-r.png"),
        &Chart {
            title: "Resize factor chosen by each controller".to_owned(),
            x_label: "frame".to_owned(),
            y_label: "r".to_owned(),
            series: series(&|run| &run.r),
            markers: false,
            reference: None,
            y_from_zero: false,
        },
    )
}
