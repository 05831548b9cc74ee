//! The transition metrics, on captured frames (no Bevy here, so the tests hold them to
//! hand-made cases): pop and flicker as lodkit's demo measures them (`lodkit::metrics`),
//! see-through, ghosts and coverage against the two single-level reference runs.

use lodkit::metrics::{self, Flicker, MetricsError};

use crate::frames::{Frame, is_background};

/// Pop (`lodkit::metrics::pop`): the largest single-frame share of a run's change beyond the
/// reference run's (1 = all in one frame, as a hard switch; 1/N spread evenly over N frames); 0
/// when nothing changed.
pub fn pop(run: &[Frame], reference: &[Frame]) -> f64 {
    let changes: Vec<f64> = (1..run.len().min(reference.len()))
        .map(|i| {
            metrics::transition_change(
                &run[i - 1].rgba,
                &run[i].rgba,
                &reference[i - 1].rgba,
                &reference[i].rgba,
            )
        })
        .collect();
    metrics::pop(&changes)
}

/// Flicker (`lodkit::metrics::Flicker`): the run's frame-to-frame change beyond the reference
/// run's over its net change from the first frame to the last, and the per-pixel direction
/// reversals.
pub fn flicker(run: &[Frame], reference: &[Frame]) -> Result<Flicker, MetricsError> {
    let bytes = |frames: &[Frame]| frames.iter().map(|f| f.rgba.clone()).collect::<Vec<_>>();
    metrics::flicker(&bytes(run), &bytes(reference))
}

/// [`flicker`] over the still pixels only: those where neither reference run (`fine`, `coarse`)
/// changes from its first frame to its last (objects that do not move, under a camera that does
/// not). Each such pixel has two fixed colors to move between, so a run that switches it once, or
/// once through a blend of the two, scores 1 exactly; any back-and-forth of even one level scores
/// above 1. Elsewhere the run is taken as the fine reference (no change counted).
pub fn still_flicker(
    run: &[Frame],
    fine: &[Frame],
    coarse: &[Frame],
) -> Result<Flicker, MetricsError> {
    let (Some(first), Some(coarse_first)) = (fine.first(), coarse.first()) else {
        return metrics::flicker(&[] as &[Vec<u8>], &[] as &[Vec<u8>]);
    };
    let same = |a: &Frame, b: &Frame, i: usize| a.rgba[i..i + 3] == b.rgba[i..i + 3];
    let still: Vec<bool> = (0..first.rgba.len())
        .step_by(4)
        .map(|i| {
            fine.iter()
                .all(|f| f.rgba.len() == first.rgba.len() && same(f, first, i))
                && coarse
                    .iter()
                    .all(|c| c.rgba.len() == first.rgba.len() && same(c, coarse_first, i))
        })
        .collect();
    let masked: Vec<Vec<u8>> = run
        .iter()
        .zip(fine)
        .map(|(r, f)| {
            let mut out = f.rgba.clone();
            for (i, _) in still.iter().enumerate().filter(|(_, s)| **s) {
                if let Some(px) = r.rgba.get(4 * i..4 * i + 4) {
                    out[4 * i..4 * i + 4].copy_from_slice(px);
                }
            }
            out
        })
        .collect();
    let reference: Vec<&[u8]> = fine.iter().map(|f| f.rgba.as_slice()).collect();
    metrics::flicker(&masked, &reference)
}

/// Per pixel of `frame`: whether it covers it (shows something other than `background`).
fn mask(frame: &Frame, background: [u8; 3]) -> Vec<bool> {
    frame
        .pixels()
        .map(|p| !is_background(p, background))
        .collect()
}

/// A measure of three coverage masks (fine, coarse, shown): `lodkit::metrics::see_through` or
/// `ghosts`.
type MaskMeasure = fn(&[bool], &[bool], &[bool]) -> Result<usize, MetricsError>;

/// Per frame of `frames`: `measure(fine, coarse, shown)` of the three coverage masks
/// (`lodkit::metrics::see_through` or `ghosts`).
fn per_frame(
    frames: &[Frame],
    fine: &[Frame],
    coarse: &[Frame],
    background: [u8; 3],
    measure: MaskMeasure,
) -> Vec<usize> {
    frames
        .iter()
        .zip(fine.iter().zip(coarse))
        .map(|(f, (a, b))| {
            let [shown, a, b] = [f, a, b].map(|x| mask(x, background));
            // The three frames come from one app at one size; a mismatch would be a bug here.
            measure(&a, &b, &shown).expect("frames of one size")
        })
        .collect()
}

/// Per frame of `frames`: pixels both references (the finest and the coarsest level alone)
/// cover, where the frame shows the `background`: the object's silhouette seen through
/// (`lodkit::metrics::see_through`).
pub fn see_through(
    frames: &[Frame],
    fine: &[Frame],
    coarse: &[Frame],
    background: [u8; 3],
) -> Vec<usize> {
    per_frame(frames, fine, coarse, background, metrics::see_through)
}

/// Per frame of `frames`: pixels neither reference covers, where the frame shows something other
/// than the `background`: an object drawn where no level of it is (e.g. a moving object's last
/// position left behind), the mirror of [`see_through`] (`lodkit::metrics::ghosts`).
pub fn ghosts(
    frames: &[Frame],
    fine: &[Frame],
    coarse: &[Frame],
    background: [u8; 3],
) -> Vec<usize> {
    per_frame(frames, fine, coarse, background, metrics::ghosts)
}

/// Per frame: the share of the pixels both references cover that the frame covers (1: the
/// object is all there; a vanishing frame shows as a low value).
pub fn coverage(
    frames: &[Frame],
    fine: &[Frame],
    coarse: &[Frame],
    background: [u8; 3],
) -> Vec<f64> {
    let holes = see_through(frames, fine, coarse, background);
    let both = fine.iter().zip(coarse).map(|(a, b)| {
        let [a, b] = [a, b].map(|x| mask(x, background));
        a.iter().zip(&b).filter(|&(a, b)| *a && *b).count()
    });
    both.zip(holes)
        .map(|(both, hole)| {
            if both == 0 {
                1.0
            } else {
                1.0 - hole as f64 / both as f64
            }
        })
        .collect()
}

/// A technique's figures over a run: pop and flicker against the finest and the coarsest
/// single-level run, see-through pixel-frames where both of `covers` cover, ghost pixel-frames
/// where neither of `misses` covers, and the lowest [`coverage`].
pub struct Figures {
    pub pop: f64,
    pub flicker_vs_fine: Flicker,
    pub flicker_vs_coarse: Flicker,
    pub see_through: usize,
    pub ghosts: usize,
    pub min_coverage: f64,
}

impl Figures {
    /// The figures of `run` (see [`Figures`]).
    pub fn of(
        run: &[Frame],
        [fine, coarse]: [&[Frame]; 2],
        covers: [&[Frame]; 2],
        misses: [&[Frame]; 2],
        background: [u8; 3],
    ) -> Result<Self, MetricsError> {
        Ok(Self {
            pop: pop(run, fine),
            flicker_vs_fine: flicker(run, fine)?,
            flicker_vs_coarse: flicker(run, coarse)?,
            see_through: see_through(run, covers[0], covers[1], background)
                .iter()
                .sum(),
            ghosts: ghosts(run, misses[0], misses[1], background).iter().sum(),
            min_coverage: coverage(run, covers[0], covers[1], background)
                .into_iter()
                .fold(1.0, f64::min),
        })
    }

    /// The figures as a report's JSON object.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "pop": self.pop,
            "flicker_vs_fine": self.flicker_vs_fine.ratio(),
            "reversals_vs_fine": self.flicker_vs_fine.reversals,
            "flicker_vs_coarse": self.flicker_vs_coarse.ratio(),
            "reversals_vs_coarse": self.flicker_vs_coarse.reversals,
            "see_through": self.see_through,
            "ghosts": self.ghosts,
            "min_coverage": self.min_coverage,
        })
    }

    /// One line for the console.
    pub fn line(&self) -> String {
        format!(
            "pop {:.4}, flicker {:.3} vs fine ({} reversals), {:.3} vs coarse, see-through {} \
             px, ghosts {} px",
            self.pop,
            self.flicker_vs_fine.ratio(),
            self.flicker_vs_fine.reversals,
            self.flicker_vs_coarse.ratio(),
            self.see_through,
            self.ghosts
        )
    }
}
