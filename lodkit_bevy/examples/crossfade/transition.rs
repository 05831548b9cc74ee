//! The two checks a complementary screen-door crossfade must pass, measured on captured frames.
//! `tests/crossfade.rs` holds them against synthetic frames (a hard pop, a non-complementary
//! dither fail) before the example runs them on what Bevy rendered.

use crate::frames::{Frame, difference, is_background};

/// Largest share of the first-to-last change that one frame-to-frame step may account for.
pub const MAX_STEP_SHARE: f64 = 0.4;

/// What the checks measured over a transition's frames (first frame: the outgoing LOD alone,
/// last frame: the incoming LOD alone).
#[derive(Clone, Debug, PartialEq)]
pub struct TransitionReport {
    /// `difference(frame[i], frame[i + 1])` for every step.
    pub step_changes: Vec<u64>,
    /// `difference(first, last)`: the whole change the transition has to spread out.
    pub total_change: u64,
    /// Largest step change divided by the total change (0 when nothing changed).
    pub largest_step_share: f64,
    /// Pixels covered by the object in both the first and the last frame.
    pub silhouette: usize,
    /// Per frame, how many silhouette pixels show the background (see-through).
    pub see_through: Vec<usize>,
}

impl TransitionReport {
    /// Measures `frames` against `background`; panics on fewer than two frames or mixed sizes.
    pub fn measure(frames: &[Frame], background: [u8; 3]) -> Self {
        assert!(frames.len() >= 2, "a transition needs at least two frames");
        let (first, last) = (&frames[0], &frames[frames.len() - 1]);
        assert!(
            frames
                .iter()
                .all(|f| (f.width, f.height) == (first.width, first.height)),
            "frames differ in size"
        );
        let step_changes: Vec<u64> = frames
            .windows(2)
            .map(|w| difference(&w[0], &w[1]))
            .collect();
        let total_change = difference(first, last);
        let largest = step_changes.iter().copied().max().unwrap_or(0);
        let largest_step_share = if total_change == 0 {
            0.0
        } else {
            largest as f64 / total_change as f64
        };
        // The silhouette: inside both the outgoing and the incoming LOD.
        let inside: Vec<bool> = first
            .coverage(background)
            .into_iter()
            .zip(last.coverage(background))
            .map(|(a, b)| a && b)
            .collect();
        let see_through = frames
            .iter()
            .map(|f| {
                f.pixels()
                    .zip(&inside)
                    .filter(|&(p, &both)| both && is_background(p, background))
                    .count()
            })
            .collect();
        Self {
            step_changes,
            total_change,
            largest_step_share,
            silhouette: inside.iter().filter(|&&i| i).count(),
            see_through,
        }
    }

    /// What is wrong, one sentence per problem; empty when the transition passes.
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.total_change == 0 {
            out.push("the first and last frames are identical: no LOD switch is visible".into());
        } else if self.largest_step_share > MAX_STEP_SHARE {
            let step = self
                .step_changes
                .iter()
                .enumerate()
                .max_by_key(|&(_, change)| *change)
                .map_or(0, |(i, _)| i);
            out.push(format!(
                "popping: step {step} -> {} makes {:.0}% of the whole change (at most {:.0}% allowed)",
                step + 1,
                self.largest_step_share * 100.0,
                MAX_STEP_SHARE * 100.0
            ));
        }
        if self.silhouette == 0 {
            out.push("the object is not visible in both the first and the last frame".into());
        }
        for (frame, &n) in self.see_through.iter().enumerate().filter(|(_, n)| **n > 0) {
            out.push(format!(
                "see-through: frame {frame} shows the background at {n} of the {} pixels \
                 both LODs cover",
                self.silhouette
            ));
        }
        out
    }
}
