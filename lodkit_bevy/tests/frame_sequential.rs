//! Frame-sequential LOD in Bevy: the example's metrics held to hand-made cases, then the
//! example run on the GPU with `--report` and its figures held to the goals against Bevy's own
//! crossfade in the same run; and a combine broken on purpose (no reprojection) must fail them.

#[path = "../examples/common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared with the examples; not every helper is used here"
)]
mod frames;
#[path = "../examples/frame_sequential/measure.rs"]
mod measure;
mod support;

use std::ffi::OsStr;

use frames::Frame;
use lodkit_bevy::frame_sequential::{decode_tag, encode_tag};
use measure::{coverage, pop, see_through};
use serde_json::Value;

const BG: [u8; 3] = [20, 23, 31];
const A: [u8; 3] = [240, 140, 50];
const B: [u8; 3] = [50, 180, 215];

/// A 4x1 frame: pixels 1 and 2 hold `inner`, the others the background.
fn frame(inner: [[u8; 3]; 2]) -> Frame {
    let mut f = Frame::filled(4, 1, BG);
    f.set_rgb(1, 0, inner[0]);
    f.set_rgb(2, 0, inner[1]);
    f
}

#[test]
fn pop_is_the_largest_share_of_the_change_beyond_the_reference() {
    let reference = vec![frame([A, A]); 4];
    // A hard switch: all of the change in one frame.
    let hard = vec![frame([A, A]), frame([A, A]), frame([B, B]), frame([B, B])];
    assert_eq!(pop(&hard, &reference), 1.0);
    // Half a step each: two equal shares.
    let soft = vec![frame([A, A]), frame([A, B]), frame([B, B]), frame([B, B])];
    assert!((pop(&soft, &reference) - 0.5).abs() < 1e-12);
    // Change the reference has too (camera motion) is not the transition's.
    let moving_ref = vec![frame([A, A]), frame([B, A]), frame([B, B]), frame([B, B])];
    assert_eq!(pop(&moving_ref, &moving_ref), 0.0);
}

#[test]
fn see_through_counts_background_where_both_levels_cover() {
    let fine = vec![frame([A, A])];
    let mut coarse = vec![frame([B, B])];
    coarse[0].set_rgb(2, 0, BG); // the coarse level leaves pixel 2 uncovered
    let hole = vec![frame([BG, BG])];
    assert_eq!(see_through(&hole, &fine, &coarse, BG), vec![1]);
    assert_eq!(coverage(&hole, &fine, &coarse, BG), vec![0.0]);
    assert_eq!(see_through(&fine, &fine, &coarse, BG), vec![0]);
}

#[test]
fn tags_round_trip() {
    let (id, tau, tau_next, object) = decode_tag(encode_tag(7, -0.25, 0.5, true).unwrap());
    assert_eq!((id, object), (7, true));
    assert!((tau + 0.25).abs() < 1e-3 && (tau_next - 0.5).abs() < 1e-3);
}

/// Runs the example with `args` in a temporary folder (removed afterwards) and returns its
/// report, once the PNG strips it names are found written.
fn report(args: &[&str]) -> Option<Value> {
    let folder = tempfile::Builder::new()
        .prefix("lodkit-bevy-fs-")
        .tempdir()
        .expect("a temporary folder");
    let dir = folder.path();
    let path = dir.join("report.json");
    let mut all: Vec<&OsStr> = vec![OsStr::new("--out"), dir.as_os_str()];
    all.push(OsStr::new("--report"));
    all.push(path.as_os_str());
    all.extend(args.iter().map(OsStr::new));
    let output = support::run_example("frame_sequential", &all)?;
    assert!(
        output.status.success(),
        "the example failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(&path).expect("the report");
    let r: Value = serde_json::from_str(&text).expect("the report is JSON");
    for key in ["png_strip_frame_sequential", "png_strip_bevy_crossfade"] {
        let png = r[key].as_str().expect("a strip path");
        assert!(std::path::Path::new(png).is_file(), "{png} was not written");
    }
    Some(r)
}

fn num(r: &Value, key: &str) -> f64 {
    r[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing from {r}"))
}

/// The goals against Bevy's crossfade in the same run. Pop and see-through are measured on
/// deterministic renders; fragments are pipeline-statistics counts (exact on lavapipe).
/// Measured (complementary schedule, screen anchor): pop 0.029 / 0.034 against Bevy's
/// 0.043 / 0.035, see-through 0 against 0, fragments 0.779 of Bevy's (0.794 while the combine
/// also covered groups not in transition).
#[test]
fn frame_sequential_beats_bevy_crossfade_in_the_same_run() {
    let Some(r) = report(&[]) else { return };
    for path in ["static", "moving"] {
        let ours = num(&r, &format!("pop_frame_sequential_{path}"));
        let bevy = num(&r, &format!("pop_bevy_crossfade_{path}"));
        assert!(
            ours > 0.0 && ours <= 1.1 * bevy,
            "pop {path}: {ours} vs Bevy's {bevy}"
        );
    }
    assert_eq!(num(&r, "see_through_frame_sequential"), 0.0, "{r}");
    assert_eq!(
        num(&r, "min_coverage_frame_sequential"),
        1.0,
        "a frame lost part of an object: {r}"
    );
    let ratio = num(&r, "fragments_frame_sequential") / num(&r, "fragments_bevy_crossfade");
    assert!(ratio <= 0.8, "fragments {ratio} of Bevy's crossfade");
}

/// The paper's schedule with the pattern on the object: no see-through either.
#[test]
fn paper_schedule_on_the_object_shows_no_background() {
    let Some(r) = report(&["--schedule", "paper", "--anchor", "object"]) else {
        return;
    };
    assert_eq!(num(&r, "see_through_frame_sequential"), 0.0, "{r}");
}

/// Without reprojection the moving camera reads the older frame at the wrong place: the
/// background shows through the objects (66 pixels measured), so the goals above fail.
#[test]
fn a_combine_without_reprojection_shows_the_background() {
    let Some(r) = report(&["--no-reprojection"]) else {
        return;
    };
    let holes = num(&r, "see_through_frame_sequential");
    assert!(holes > 0.0, "no reprojection, yet no see-through: {r}");
    assert!(num(&r, "min_coverage_frame_sequential") < 1.0, "{r}");
}
