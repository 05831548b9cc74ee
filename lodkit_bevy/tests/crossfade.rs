//! The transition checks: first held against synthetic frames built with lodkit's Rust twin of
//! the shader's `screen_door_keep` (so we know they pass a good crossfade and catch a pop or a
//! see-through one), then run on what Bevy renders (`--check`).

#[path = "../examples/common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared with the examples; not every helper is used here"
)]
mod frames;
mod support;
#[path = "../examples/crossfade/transition.rs"]
mod transition;

use glam::Vec2;
use lodkit::screen_door::screen_door_keep;

use frames::{Frame, strip};
use transition::TransitionReport;

const SIZE: u32 = 32;
const BACKGROUND: [u8; 3] = [20, 23, 31];
const OUTGOING: [u8; 3] = [240, 140, 50];
const INCOMING: [u8; 3] = [50, 180, 215];
const STEPS: usize = 12;

/// A disc of radius 12 in the middle of the frame: where both LODs cover the screen.
fn in_disc(x: u32, y: u32) -> bool {
    let (dx, dy) = (x as f32 + 0.5 - 16.0, y as f32 + 0.5 - 16.0);
    dx * dx + dy * dy < 144.0
}

/// Frames of a transition over `STEPS` steps; `draw(pixel, t)` says which level (if any) covers
/// a disc pixel at progress `t`.
fn transition(draw: impl Fn(Vec2, f32) -> Option<[u8; 3]>) -> Vec<Frame> {
    (0..=STEPS)
        .map(|k| {
            let t = k as f32 / STEPS as f32;
            let mut frame = Frame::filled(SIZE, SIZE, BACKGROUND);
            for y in 0..SIZE {
                for x in 0..SIZE {
                    let pixel = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    if let Some(color) = draw(pixel, t).filter(|_| in_disc(x, y)) {
                        frame.set_rgb(x, y, color);
                    }
                }
            }
            frame
        })
        .collect()
}

#[test]
fn complementary_dither_passes() {
    // Outgoing level with alpha -(1 - t) (inverted pattern), incoming with +t: what the example's
    // shader does with `LodSelection::screen_door_alphas()`.
    let frames = transition(|p, t| {
        if screen_door_keep(p, t) {
            Some(INCOMING)
        } else if screen_door_keep(p, -(1.0 - t)) {
            Some(OUTGOING)
        } else {
            None
        }
    });
    let report = TransitionReport::measure(&frames, BACKGROUND);
    assert!(report.failures().is_empty(), "{:?}", report.failures());
    assert!(report.largest_step_share < 0.2, "{report:?}");
    assert!(report.see_through.iter().all(|&n| n == 0));
}

#[test]
fn hard_pop_fails() {
    let frames = transition(|_, t| Some(if t < 0.5 { OUTGOING } else { INCOMING }));
    let report = TransitionReport::measure(&frames, BACKGROUND);
    assert_eq!(report.largest_step_share, 1.0);
    assert!(
        report.failures().iter().any(|f| f.starts_with("popping")),
        "{report:?}"
    );
}

#[test]
fn same_pattern_for_both_levels_shows_see_through() {
    // Both levels with positive alphas (1 - t and t) use the same pixels of the pattern: at t = 0.5
    // the lower half of the thresholds is drawn twice and the upper half not at all.
    let frames = transition(|p, t| {
        if screen_door_keep(p, t) {
            Some(INCOMING)
        } else if screen_door_keep(p, 1.0 - t) {
            Some(OUTGOING)
        } else {
            None
        }
    });
    let report = TransitionReport::measure(&frames, BACKGROUND);
    assert!(report.see_through[STEPS / 2] > 0, "{report:?}");
    assert!(
        report
            .failures()
            .iter()
            .any(|f| f.starts_with("see-through"))
    );
}

#[test]
fn strip_places_frames_side_by_side() {
    let a = Frame::filled(2, 2, OUTGOING);
    let b = Frame::filled(2, 2, INCOMING);
    let s = strip(&[a, b]);
    assert_eq!((s.width, s.height), (4, 2));
    assert_eq!([s.rgb(1, 1), s.rgb(2, 1)], [OUTGOING, INCOMING]);
}

/// The example itself on the GPU (Vulkan or GL; lavapipe is enough). Without an adapter it is
/// skipped loudly, and fails when `LODKIT_REQUIRE_GPU=1` (as in lodkit's CI).
#[test]
fn bevy_renders_a_complementary_crossfade() {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("lodkit-bevy-strip.png");
    let Some(output) = support::run_example("crossfade", &["--check".as_ref(), out.as_os_str()])
    else {
        return;
    };
    assert!(
        output.status.success(),
        "example failed:\n{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(out.exists(), "no strip at {}", out.display());
}
