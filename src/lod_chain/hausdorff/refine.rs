//! Refining a source triangle whose first bound is above the tolerance: the smallest of three
//! bounds over each piece, pieces cut at their edge midpoints until the bound is within the
//! tolerance of the largest distance found.

use glam::DVec3;

use super::partition::partition_bound;
use super::{Budget, MARGIN, Sample, Surface, Tolerance, longest_side};

/// Deepest cut of one source triangle.
const MAX_DEPTH: u32 = 12;

/// The bound over the triangle piece with corners `c` (samples of `f`): the smallest of
///
/// - the Lipschitz bound `max f(corners) + longest / sqrt(3)`;
/// - the convexity bound with the nearest triangle to a corner or the centroid;
/// - the partition bound ([`partition_bound`]);
///
/// and the piece is cut in four while that is above `lb` plus the tolerance. Every `f`
/// evaluated raises `lb`.
pub(super) fn refine(
    target: &Surface,
    c: [Sample; 3],
    depth: u32,
    lb: &mut f64,
    tolerance: Tolerance,
    budget: &Budget,
) -> f64 {
    let p = c.map(|s| s.at);
    let longest = longest_side(&p);
    let near = c[0].distance.max(c[1].distance).max(c[2].distance);
    let lipschitz = near + longest / 3f64.sqrt();
    let centre = target.nearest((p[0] + p[1] + p[2]) / 3.0);
    *lb = lb.max(centre.distance);
    let convex = c
        .iter()
        .chain([&centre])
        .filter_map(|s| s.nearest)
        .map(|t| {
            p.iter()
                .map(|&x| target.distance2_to(t, x))
                .fold(0.0, f64::max)
                .sqrt()
        })
        .fold(f64::INFINITY, f64::min);
    let mut bound = lipschitz.min(convex);
    let mut spent = false;
    if bound > *lb + tolerance.slack(*lb) {
        let margin = 2.0 * near.max(centre.distance) + MARGIN * longest;
        match budget.candidates(target, &p, margin) {
            Some(candidates) => {
                if let Some(b) = partition_bound(p, &candidates) {
                    bound = bound.min(b.bound);
                    *lb = lb.max(target.nearest(b.at).distance);
                }
            }
            None => spent = true,
        }
    }
    // Past the budget the piece keeps the bound it has: cutting it would weigh more.
    let within = bound <= *lb + tolerance.slack(*lb);
    if within || depth >= MAX_DEPTH || spent {
        if !within {
            target.note_capped();
        }
        return bound;
    }
    let m = [
        (p[0] + p[1]) * 0.5,
        (p[1] + p[2]) * 0.5,
        (p[2] + p[0]) * 0.5,
    ]
    .map(|x: DVec3| {
        let s = target.nearest(x);
        *lb = lb.max(s.distance);
        s
    });
    [
        [c[0], m[0], m[2]],
        [m[0], c[1], m[1]],
        [m[2], m[1], c[2]],
        [m[0], m[1], m[2]],
    ]
    .into_iter()
    .map(|piece| refine(target, piece, depth + 1, lb, tolerance, budget))
    .fold(0.0, f64::max)
}
