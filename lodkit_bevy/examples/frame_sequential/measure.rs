//! The transition metrics, on captured frames (no Bevy here, so the tests hold them to
//! hand-made cases): pop as lodkit's demo measures it, see-through and coverage against the
//! two single-level reference runs.

use crate::frames::{Frame, is_background};

/// Mean absolute RGB change, in 0..1, of `(a1 - r1) - (a0 - r0)`: how much the picture changed
/// from one frame to the next beyond what the reference run (no transition) changed.
pub fn transition_change(a0: &Frame, a1: &Frame, r0: &Frame, r1: &Frame) -> f64 {
    let mut sum = 0u64;
    let mut n = 0u64;
    for (((p0, p1), q0), q1) in a0
        .pixels()
        .zip(a1.pixels())
        .zip(r0.pixels())
        .zip(r1.pixels())
    {
        for c in 0..3 {
            let d = (i32::from(p1[c]) - i32::from(q1[c])) - (i32::from(p0[c]) - i32::from(q0[c]));
            sum += u64::from(d.unsigned_abs());
            n += 1;
        }
    }
    sum as f64 / n.max(1) as f64 / 255.0
}

/// Pop: the largest single-frame share of a run's transition change (1 = all in one frame, as
/// a hard switch; 1/N spread evenly over N frames); 0 when nothing changed.
pub fn pop(run: &[Frame], reference: &[Frame]) -> f64 {
    let changes: Vec<f64> = (1..run.len().min(reference.len()))
        .map(|i| transition_change(&run[i - 1], &run[i], &reference[i - 1], &reference[i]))
        .collect();
    let total: f64 = changes.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    changes.iter().copied().fold(0.0, f64::max) / total
}

/// Per frame of `frames`: pixels both references (the finest and the coarsest level alone)
/// cover, where the frame shows the `background`: the object's silhouette seen through.
pub fn see_through(
    frames: &[Frame],
    fine: &[Frame],
    coarse: &[Frame],
    background: [u8; 3],
) -> Vec<usize> {
    frames
        .iter()
        .zip(fine.iter().zip(coarse))
        .map(|(f, (a, b))| {
            f.pixels()
                .zip(a.pixels().zip(b.pixels()))
                .filter(|&(p, (pa, pb))| {
                    !is_background(pa, background)
                        && !is_background(pb, background)
                        && is_background(p, background)
                })
                .count()
        })
        .collect()
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
    fine.iter()
        .zip(coarse)
        .zip(holes)
        .map(|((a, b), hole)| {
            let both = a
                .pixels()
                .zip(b.pixels())
                .filter(|&(pa, pb)| {
                    !is_background(pa, background) && !is_background(pb, background)
                })
                .count();
            if both == 0 {
                1.0
            } else {
                1.0 - hole as f64 / both as f64
            }
        })
        .collect()
}
