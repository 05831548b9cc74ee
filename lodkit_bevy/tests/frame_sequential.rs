//! Frame-sequential LOD in Bevy: the example's metrics held to hand-made cases, then the
//! example run on the GPU with `--report` and its figures held against Bevy's own crossfade in
//! the same run, in an app without a prepass and in one with Bevy's depth and motion-vector
//! prepass; and a combine broken on purpose (no reprojection) must fail them.

#[path = "../examples/common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared with the examples; not every helper is used here"
)]
mod frames;
#[path = "../examples/frame_sequential/measure.rs"]
#[allow(dead_code, reason = "shared with the other examples; each uses a part")]
mod measure;
mod support;

use std::ffi::OsStr;

use frames::Frame;
use lodkit_bevy::frame_sequential::{decode_tag, encode_tag};
use measure::{coverage, flicker, ghosts, pop, see_through, still_flicker};
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
fn flicker_sees_a_pixel_that_blinks_and_pop_does_not() {
    let reference = vec![frame([A, A]); 6];
    // Pixel 1 blinks between the levels every frame; pixel 2 switches once.
    let blinking: Vec<Frame> = (0..6)
        .map(|i| frame([if i % 2 == 1 { B } else { A }, if i < 3 { A } else { B }]))
        .collect();
    let f = flicker(&blinking, &reference).unwrap();
    // Pixel 1: five steps of |B - A| and a net change of one; pixel 2: one step, net one.
    assert_eq!(f.ratio(), 3.0);
    assert_eq!(f.reversals, 4);
    // Its change spreads over the frames: pop calls it smooth (the largest share is 2/6).
    assert!((pop(&blinking, &reference) - 2.0 / 6.0).abs() < 1e-12);
    // A switch that goes once, in one direction, does not flicker.
    let once: Vec<Frame> = (0..6)
        .map(|i| frame([if i < 2 { A } else { B }, if i < 4 { A } else { B }]))
        .collect();
    let f = flicker(&once, &reference).unwrap();
    assert_eq!((f.ratio(), f.reversals), (1.0, 0));
}

#[test]
fn still_flicker_sees_a_still_pixel_that_wavers_by_one_level() {
    let fine = vec![frame([A, A]); 5];
    // Pixel 2 is not still: the coarse reference changes there (it moves); pixel 1 is.
    let coarse: Vec<Frame> = (0..5)
        .map(|i| frame([B, if i < 2 { B } else { A }]))
        .collect();
    let mid = [145, 160, 132];
    // Pixel 1 switches once through a blend of the two levels; pixel 2 blinks.
    let once: Vec<Frame> = [A, A, mid, B, B]
        .iter()
        .enumerate()
        .map(|(i, &p)| frame([p, if i % 2 == 1 { B } else { A }]))
        .collect();
    let f = still_flicker(&once, &fine, &coarse).unwrap();
    assert_eq!((f.ratio(), f.reversals), (1.0, 0));
    // The same switch with the coarse color one level off every other frame.
    let b1 = [B[0] + 1, B[1], B[2]];
    let wavering: Vec<Frame> = [A, A, B, b1, B].iter().map(|&p| frame([p, A])).collect();
    let f = still_flicker(&wavering, &fine, &coarse).unwrap();
    // Net |B - A| = 190 + 40 + 165 = 395 levels; change 395 + 1 + 1.
    assert_eq!(f.ratio(), 397.0 / 395.0);
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
fn ghosts_count_an_object_where_neither_level_is() {
    let mut fine = vec![frame([A, A])];
    fine[0].set_rgb(2, 0, BG); // only pixel 1 is covered, by both levels
    let coarse = vec![frame([B, BG])];
    // Pixel 2 shows the object though neither level covers it; pixel 3 is background.
    let trail = vec![frame([A, A])];
    assert_eq!(ghosts(&trail, &fine, &coarse, BG), vec![1]);
    assert_eq!(ghosts(&fine, &fine, &coarse, BG), vec![0]);
    // A pixel one level covers is no ghost, whichever level it shows.
    let mut coarse_wider = coarse.clone();
    coarse_wider[0].set_rgb(2, 0, B);
    assert_eq!(ghosts(&trail, &fine, &coarse_wider, BG), vec![0]);
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
    if let Some(frames) = r.get("frames_dir").and_then(Value::as_str) {
        // --frames: every frame of every run, the references included.
        for run in ["reference_fine", "frame_sequential", "bevy_crossfade"] {
            for path in ["static", "moving"] {
                let n =
                    std::fs::read_dir(std::path::Path::new(frames).join(format!("{run}_{path}")))
                        .map_or(0, |d| d.count());
                assert_eq!(
                    n as f64,
                    num(&r, "frames_per_run"),
                    "{run}_{path} in {frames}"
                );
            }
        }
    }
    Some(r)
}

fn num(r: &Value, key: &str) -> f64 {
    r[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing from {r}"))
}

/// Frame-sequential LOD's flicker in `app` (`""` or `"_with_prepass"`) at most `limits` (still,
/// moving camera), and with `below_bevy` at most Bevy's crossfade's in the same run as well.
fn assert_flicker(r: &Value, app: &str, limits: [f64; 2], below_bevy: bool) {
    for (path, limit) in ["static", "moving"].into_iter().zip(limits) {
        let f = num(r, &format!("flicker_frame_sequential{app}_{path}"));
        let theirs = num(r, &format!("flicker_bevy_crossfade{app}_{path}"));
        assert!(
            f <= limit && (!below_bevy || f <= theirs),
            "flicker frame_sequential{app} {path}: {f} (limit {limit}, Bevy's {theirs})"
        );
    }
}

/// The figures against Bevy's crossfade in the same run, each technique on a camera of its own
/// with only what it needs, with the plugin's defaults (the paper's schedule, the pattern on the
/// screen, coverage from the older levels' silhouettes). Pop and see-through are measured on
/// deterministic renders, fragments are pipeline-statistics counts (exact on lavapipe), flicker
/// is the change over the net change (`lodkit::metrics::Flicker`).
///
/// Measured (lavapipe, 320x192), the same in both apps unless said:
/// - fragments 0.709x Bevy's crossfade without a prepass (3.53 M against 4.98 M), 0.771x with
///   Bevy's depth and motion-vector prepass (11.80 M against 15.31 M): goal 0.8x in both (over
///   the screen rectangles instead of the hulls, 0.735x and 0.779x);
/// - pop 0.031 / 0.028 (static / moving) against Bevy's 0.043 / 0.035: goal 1.1x Bevy's;
/// - flicker 1.896 / 5.065 against Bevy's 1.973 / 5.517: goal at most Bevy's, held to 1.94 /
///   5.25 as well (the older color at its nearest texel measures 1.92 / 5.32; the complementary
///   schedule 1.98 / 5.60);
/// - over the still pixels of the still camera (nothing moves there in either reference) the
///   flicker is exactly 1, as Bevy's: each changes once, in one direction (where a pixel center
///   lies on a silhouette, its coverage is taken from last frame's picture; without that,
///   1.0055: one pixel went back and forth);
/// - see-through 0, every frame covering the silhouettes both levels cover; ghosts 1
///   pixel-frame (Bevy's 0); the older-level depth pass draws nothing (both levels of every
///   group have a silhouette).
#[test]
fn frame_sequential_against_bevy_crossfade_in_the_same_run() {
    let folder = tempfile::Builder::new()
        .prefix("lodkit-bevy-fs-frames-")
        .tempdir()
        .expect("a temporary folder");
    let frames = folder.path().to_str().expect("a UTF-8 temporary path");
    let Some(r) = report(&["--frames", frames]) else {
        return;
    };
    for app in ["", "_with_prepass"] {
        let fs = format!("frame_sequential{app}");
        let bevy = format!("bevy_crossfade{app}");
        for path in ["static", "moving"] {
            let (ours, theirs) = (
                num(&r, &format!("pop_{fs}_{path}")),
                num(&r, &format!("pop_{bevy}_{path}")),
            );
            assert!(
                ours > 0.0 && ours <= 1.1 * theirs,
                "pop {fs} {path}: {ours} vs Bevy's {theirs}"
            );
        }
        assert_flicker(&r, app, [1.94, 5.25], true);
        for run in [&fs, &bevy] {
            let still = num(&r, &format!("flicker_{run}_still_pixels"));
            assert_eq!(still, 1.0, "still pixels of {run} flicker: {still}");
        }
        assert_eq!(
            num(&r, &format!("min_coverage_{fs}")),
            1.0,
            "a frame lost part of an object: {r}"
        );
        assert_eq!(num(&r, &format!("see_through_{fs}")), 0.0, "{r}");
        let trail = num(&r, &format!("ghosts_{fs}"));
        assert!(trail <= 5.0, "ghosts {fs}: {trail} (limit 5)");
        assert_eq!(num(&r, &format!("ghosts_{bevy}")), 0.0, "{r}");
        let ratio = num(&r, &format!("fragments_{fs}")) / num(&r, &format!("fragments_{bevy}"));
        assert!(ratio <= 0.8, "fragments {fs}: {ratio} of Bevy's crossfade");
        // Where the fragments go: the prepass only where the camera runs one, the combine only
        // for frame-sequential LOD, no older-level depth pass where silhouettes tell.
        let prepass = num(&r, &format!("fragments_{fs}_prepass"));
        assert_eq!(prepass > 0.0, !app.is_empty(), "{fs}: prepass {prepass}");
        assert!(num(&r, &format!("fragments_{fs}_combine")) > 0.0);
        assert_eq!(num(&r, &format!("fragments_{bevy}_combine")), 0.0);
        assert_eq!(num(&r, &format!("fragments_{fs}_older_depth")), 0.0);
    }
}

/// Coverage estimated from last frame's picture (`OlderCoverage::Estimated`): no pass added
/// and no see-through, but the silhouettes are known only to within a texel. Measured: flicker
/// 2.073 / 6.171 in both apps (held to 2.10 / 6.25; the nearest older texel instead of the
/// bilinear blend measures 2.08 / 6.31), ghosts 497 and 515 pixel-frames (held to 520 / 540).
#[test]
fn estimated_coverage_shows_no_background() {
    let Some(r) = report(&["--coverage", "estimated"]) else {
        return;
    };
    for app in ["", "_with_prepass"] {
        let fs = format!("frame_sequential{app}");
        assert_flicker(&r, app, [2.10, 6.25], false);
        assert_eq!(num(&r, &format!("see_through_{fs}")), 0.0, "{r}");
        assert_eq!(num(&r, &format!("min_coverage_{fs}")), 1.0, "{r}");
        let limit = if app.is_empty() { 520.0 } else { 540.0 };
        let trail = num(&r, &format!("ghosts_{fs}"));
        assert!(trail <= limit, "ghosts {fs}: {trail} (limit {limit})");
        let ratio = num(&r, &format!("fragments_{fs}"))
            / num(&r, &format!("fragments_bevy_crossfade{app}"));
        assert!(ratio <= 0.8, "fragments {fs}: {ratio} of Bevy's crossfade");
        assert_eq!(num(&r, &format!("fragments_{fs}_older_depth")), 0.0);
    }
}

/// The paper's schedule with the pattern on the object: no see-through, with the prepass or
/// without it (measured 0 and 0).
#[test]
fn paper_schedule_on_the_object_shows_no_background() {
    let Some(r) = report(&["--schedule", "paper", "--anchor", "object"]) else {
        return;
    };
    for app in ["", "_with_prepass"] {
        assert_eq!(
            num(&r, &format!("see_through_frame_sequential{app}")),
            0.0,
            "{r}"
        );
    }
}

/// Coverage from the older-level depth pass (`OlderCoverage::DepthPass`, for levels with no
/// silhouette): no ghost, no background, less flicker than Bevy's crossfade, in both apps.
/// Measured: ghosts 0 and 0; flicker 1.910 / 5.104 without the prepass, 1.923 / 5.137 with it
/// (held to 1.95 / 5.22; the nearest older texel measures 1.92 / 5.27). The pass's samples,
/// which lavapipe counts as fragment invocations, are in the total: 2.08 M, so frame-sequential
/// LOD then costs 1.15x Bevy's crossfade without a prepass and 0.91x with one; shaded (prepass,
/// opaque and combine) it is unchanged.
#[test]
fn depth_pass_coverage_leaves_no_ghost_and_no_hole() {
    let Some(r) = report(&["--coverage", "depth-pass"]) else {
        return;
    };
    for app in ["", "_with_prepass"] {
        let fs = format!("frame_sequential{app}");
        assert_flicker(&r, app, [1.95, 5.22], true);
        let still = num(&r, &format!("flicker_{fs}_still_pixels"));
        assert_eq!(still, 1.0, "still pixels of {fs} flicker: {still}");
        assert_eq!(num(&r, &format!("ghosts_{fs}")), 0.0, "{r}");
        assert_eq!(num(&r, &format!("see_through_{fs}")), 0.0, "{r}");
        assert_eq!(num(&r, &format!("min_coverage_{fs}")), 1.0, "{r}");
        assert!(num(&r, &format!("fragments_{fs}_older_depth")) > 0.0, "{r}");
        let shaded = ["prepass", "opaque", "combine"]
            .iter()
            .map(|part| num(&r, &format!("fragments_{fs}_{part}")))
            .sum::<f64>();
        let ratio = shaded / num(&r, &format!("fragments_bevy_crossfade{app}"));
        assert!(
            ratio <= 0.8,
            "shaded fragments {fs}: {ratio} of Bevy's crossfade"
        );
    }
}

/// Without reprojection the moving camera reads the older frame at the wrong place, and the
/// figures above fail. Where a read finds none of the older level it shows the level drawn now
/// (`combine_read_known`), not the background, so the pixels flip between the levels instead of
/// showing holes: measured 1.989 / 5.555 against the limits 1.94 / 5.25 (and Bevy's 1.973 /
/// 5.516), 22,119 / 23,712 reversals, see-through 0. Before the reads along the ray it showed
/// the background through the objects.
#[test]
fn a_combine_without_reprojection_fails_the_flicker_limits() {
    let Some(r) = report(&["--no-reprojection", "--without-prepass-only"]) else {
        return;
    };
    for (path, limit) in ["static", "moving"].into_iter().zip([1.94, 5.25]) {
        let f = num(&r, &format!("flicker_frame_sequential_{path}"));
        assert!(
            f > limit,
            "no reprojection, yet flicker {path} {f} within {limit}: {r}"
        );
    }
}

/// Bevy's default camera has MSAA (`Msaa::Sample4`), where the combine cannot run: the plugin
/// draws both levels through lodkit's complementary screen-door dither instead, so the change
/// is spread over the transition (no pop) and no background shows through, in an app without a
/// prepass and in one with Bevy's depth and motion-vector prepass (whose prepass drops the same
/// pixels of each level as the main pass). Measured (lavapipe, every camera `Msaa::Sample4`):
/// pop 0.0434 / 0.0339 against Bevy's crossfade's 0.0435 / 0.0348 (still / moving camera) in
/// both apps, see-through 0, ghosts 0, no combine. Without the fallback (the switch at once it
/// replaced) the whole change lands in one frame; without the prepass's discard (a throwaway
/// edit) the app with a prepass showed the background in 210,457 pixel-frames, pop 0.290.
#[test]
fn msaa_blends_with_the_dither_without_a_pop_or_a_hole() {
    let Some(r) = report(&["--msaa"]) else {
        return;
    };
    assert_eq!(r["msaa"], true);
    for app in ["", "_with_prepass"] {
        let fs = format!("frame_sequential{app}");
        for path in ["static", "moving"] {
            let (ours, theirs) = (
                num(&r, &format!("pop_{fs}_{path}")),
                num(&r, &format!("pop_bevy_crossfade{app}_{path}")),
            );
            assert!(
                ours > 0.0 && ours <= 1.1 * theirs,
                "pop {fs} {path} with MSAA: {ours} vs Bevy's {theirs}"
            );
        }
        assert_eq!(num(&r, &format!("see_through_{fs}")), 0.0, "{r}");
        assert_eq!(num(&r, &format!("min_coverage_{fs}")), 1.0, "{r}");
        assert_eq!(num(&r, &format!("ghosts_{fs}")), 0.0, "{r}");
        assert_eq!(num(&r, &format!("fragments_{fs}_combine")), 0.0, "{r}");
    }
}

/// The frame-sequential runs' frames in `dir` (`--frames`), per folder: its name and its PNG
/// files' bytes, in name order.
fn run_frames(dir: &std::path::Path) -> Vec<(String, Vec<Vec<u8>>)> {
    let mut out = Vec::new();
    for run in ["frame_sequential", "frame_sequential_with_prepass"] {
        for path in ["static", "moving"] {
            let folder = dir.join(format!("{run}_{path}"));
            let mut files: Vec<_> = std::fs::read_dir(&folder)
                .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
                .map(|e| e.expect("a folder entry").path())
                .collect();
            files.sort();
            let bytes = files
                .iter()
                .map(|f| std::fs::read(f).expect("a frame"))
                .collect();
            out.push((format!("{run}_{path}"), bytes));
        }
    }
    out
}

/// The combine over the convex hulls of both levels' silhouettes (the default) draws exactly
/// the picture it draws over the groups' screen rectangles: every frame of every
/// frame-sequential run (both apps, still and moving camera) is the same 8-bit readback, its PNG
/// the same bytes (lossless, one encoder), and every figure derived from the frames is equal;
/// the combine shades fewer pixels. Measured (lavapipe, 320x192): see docs/engines.md.
#[test]
fn combine_over_hulls_draws_what_it_draws_over_rectangles() {
    let folders = [(); 2].map(|_| {
        tempfile::Builder::new()
            .prefix("lodkit-bevy-fs-region-")
            .tempdir()
            .expect("a temporary folder")
    });
    let [hull_dir, rect_dir] = folders
        .each_ref()
        .map(|f| f.path().to_str().expect("UTF-8"));
    let Some(hulls) = report(&["--frames", hull_dir]) else {
        return;
    };
    let Some(rects) = report(&["--frames", rect_dir, "--combine-region", "rectangles"]) else {
        return;
    };
    assert_eq!(hulls["combine_region"], "hulls");
    assert_eq!(rects["combine_region"], "rectangles");
    let (a, b) = (run_frames(folders[0].path()), run_frames(folders[1].path()));
    for ((run, ours), (_, theirs)) in a.iter().zip(&b) {
        assert_eq!(ours.len(), theirs.len(), "{run}: frame counts");
        let differ: Vec<usize> = (0..ours.len()).filter(|&k| ours[k] != theirs[k]).collect();
        assert!(
            differ.is_empty(),
            "{run}: frames {differ:?} differ between the hulls and the rectangles"
        );
    }
    for app in ["", "_with_prepass"] {
        let fs = format!("frame_sequential{app}");
        let mut keys = vec![
            format!("see_through_{fs}"),
            format!("ghosts_{fs}"),
            format!("min_coverage_{fs}"),
            format!("fragments_{fs}_opaque"),
        ];
        for path in ["static", "moving"] {
            keys.push(format!("pop_{fs}_{path}"));
            keys.push(format!("flicker_{fs}_{path}"));
        }
        for key in keys {
            assert_eq!(num(&hulls, &key), num(&rects, &key), "{key}");
        }
        let (over_hulls, over_rects) = (
            num(&hulls, &format!("fragments_{fs}_combine")),
            num(&rects, &format!("fragments_{fs}_combine")),
        );
        println!("{fs}: combine fragments {over_hulls} over hulls, {over_rects} over rectangles");
        assert!(
            over_hulls > 0.0 && over_hulls < over_rects,
            "{fs}: combine fragments {over_hulls} over hulls, {over_rects} over rectangles"
        );
    }
}
