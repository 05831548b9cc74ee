//! An upper bound of the two-sided Hausdorff distance between two triangle meshes.
//!
//! Three bounds of `sup f` over a piece `Q` of a source triangle, where `f(x) = d(x, T)` is the
//! distance to the target surface `T`:
//!
//! - **Lipschitz**: `f` is 1-Lipschitz, and `Q`'s three corners cover it within `r` (its
//!   circumradius when acute, half its longest side otherwise; both at most `longest / sqrt(3)`,
//!   which is used), so `sup_Q f <= max f(corners) + r`.
//! - **Convex**: for any one triangle `t` of the target, `f(x) <= d(x, t)`, and `d(., t)` is convex
//!   (the distance to a convex set), so over the triangle `Q` its maximum is at a corner:
//!   `sup_Q f <= max d(corner, t)`. The candidates `t` are the triangles the walks found for
//!   `Q`'s corners and centroid (the nearest, or near ones).
//! - **Partition** ([`partition`]): `Q` cut into convex pieces along the outlines of the target
//!   triangles under it, each piece bounded by the convex bound of the triangle over it.
//!
//! [`directed_bound`] bounds `f` at every vertex of the source from above by walking the target's
//! connectivity from the target vertex nearest to it along the source's edges ([`walk`]; the
//! levels of a chain keep a subset of the original's vertices), and at the centroid of every
//! triangle whose corners are all on the target. The largest of these are searched exactly (an
//! R-tree) until the rest are no larger than the largest distance found, `lb`, a lower bound of
//! the supremum (unless a search was capped: then an upper bound of a distance, and the bound is
//! reported as capped). Every source triangle is then bounded by the cheapest of the bounds
//! above that is within the tolerance of `lb`: Lipschitz and convex first (with the upper
//! bounds at the corners, which both allow), then the partition among the walks' triangles of
//! its corners and centroid, then among those and the target triangles connected to them that
//! lie over or under it ([`walk`]'s flood), then among every target triangle near it (the
//! R-tree). The triangles still above the tolerance are looked at again,
//! largest bound first: `f` at the point where the bound is reached often raises `lb` to it;
//! the rest are refined ([`refine`]: cut at the edge midpoints, each piece bounded again). The
//! result is the largest bound over all triangles: an upper bound whatever the walks, cuts and
//! candidates, which only decide how tight it is (at most `lb + tolerance` above the largest
//! distance found unless a piece reaches the depth limit or the budget runs out; then still an
//! upper bound, only a looser one). Distances are computed in f64 from the f32 positions; the caller rounds up.

mod partition;
mod refine;
mod surface;
mod walk;

use glam::DVec3;

pub(crate) use surface::Surface;
use surface::{Corners, Sample, query_box};
use walk::Found;

/// Squared distance from `p` to the segment `a`-`b` (a point when `a == b`).
fn point_segment_distance2(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).length_squared()
}

/// Squared distance from `p` to the closed triangle `a b c`: Ericson's Voronoi-region test
/// ("Real-Time Collision Detection", 5.1.5), corners and edges first, the face last. A
/// degenerate triangle (collinear or coincident corners, or so nearly that its squared cross
/// product is below 1e-10 of the product of its sides' squares, where rounding decides the
/// face's test) is the union of its edges: the two differ by at most its width, below 1e-5 of
/// its sides.
pub(crate) fn point_triangle_distance2(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length_squared();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length_squared();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 > d3 {
        return (ap - ab * (d1 / (d1 - d3))).length_squared();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length_squared();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 > d6 {
        return (ap - ac * (d2 / (d2 - d6))).length_squared();
    }
    let va = d3 * d6 - d5 * d4;
    let (e, f) = (d4 - d3, d5 - d6);
    if va <= 0.0 && e >= 0.0 && f >= 0.0 && e + f > 0.0 {
        return (bp - (c - b) * (e / (e + f))).length_squared();
    }
    let area = va + vb + vc;
    let flat = ab.cross(ac).length_squared() <= 1e-10 * ab.length_squared() * ac.length_squared();
    if !flat && area > 0.0 && va >= 0.0 && vb >= 0.0 && vc >= 0.0 {
        return (ap - ab * (vb / area) - ac * (vc / area)).length_squared();
    }
    // Degenerate, or no region held within rounding: the nearest point is on an edge.
    point_segment_distance2(p, a, b)
        .min(point_segment_distance2(p, b, c))
        .min(point_segment_distance2(p, c, a))
}

/// When a piece of a triangle is refined no further.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tolerance {
    /// Accepted slack relative to the largest distance found.
    pub relative: f64,
    /// Accepted slack in object units (for levels whose error is near zero).
    pub absolute: f64,
}

impl Tolerance {
    pub(crate) fn slack(&self, lb: f64) -> f64 {
        (self.relative * lb).max(self.absolute)
    }
}

/// The smallest margin around a source triangle, relative to its longest side, within which
/// target triangles are candidates for its partition.
const MARGIN: f64 = 0.05;

/// Candidate triangles a bound may weigh in partitions, per triangle of the source and the
/// target together. The meshes `lodkit lod` was run on here weigh 1 to 20 per triangle (the
/// sample scene's ball, tree and ring, every level, both directions; Bevy's 28 sample models
/// bound exactly as with 256); long slivers spanning the mesh (a triangle list read as a fan,
/// positions read from the wrong place) weigh much of the target in every partition and every
/// cut of a refinement (1,500 per triangle, 31 s for a level of a 57,598-triangle fan). Past
/// the budget a triangle keeps the Lipschitz and convexity bounds it has (upper bounds still,
/// looser) and nothing is refined further; the surface notes the bound as capped.
const BUDGET_PER_TRIANGLE: u64 = 64;

/// The most target triangles a flood gathers for one source triangle's partition.
const FLOOD_LIMIT: usize = 256;

/// What is left of a bound's budget of candidate triangles ([`BUDGET_PER_TRIANGLE`]).
struct Budget(std::sync::atomic::AtomicU64);

impl Budget {
    fn new(per_triangle: u64, triangles: usize) -> Self {
        Self(std::sync::atomic::AtomicU64::new(
            per_triangle.saturating_mul(triangles as u64),
        ))
    }

    /// Takes `n` candidates from the budget; false (and the budget emptied) when it has fewer.
    fn take(&self, n: u64) -> bool {
        use std::sync::atomic::Ordering::Relaxed;
        match self
            .0
            .fetch_update(Relaxed, Relaxed, |left| left.checked_sub(n))
        {
            Ok(_) => true,
            Err(_) => {
                self.0.store(0, Relaxed);
                false
            }
        }
    }

    /// The candidates of `target` for `s` ([`Surface::candidates`]), taken from the budget;
    /// None when the budget has fewer left (the query stops there, so an exhausted budget costs
    /// no more than it has left).
    fn candidates(&self, target: &Surface, s: &Corners, margin: f64) -> Option<Vec<Corners>> {
        let limit = usize::try_from(self.left()).unwrap_or(usize::MAX);
        let found: Vec<Corners> = target
            .candidates(s, margin)
            .take(limit.saturating_add(1))
            .map(|t| t.corners)
            .collect();
        self.take(found.len() as u64).then_some(found)
    }

    /// The target triangles connected to `seeds` that can cut `s`'s partition
    /// ([`partition::Under`], [`Surface::flood`]), taken from the budget; None past
    /// [`FLOOD_LIMIT`] or the budget.
    fn flood(
        &self,
        target: &Surface,
        seeds: &[u32],
        s: &Corners,
        margin: f64,
    ) -> Option<Vec<Corners>> {
        let found = match partition::Under::new(s, margin) {
            Some(under) => {
                target.flood(seeds, |t| under.holds(&target.corners_of(t)), FLOOD_LIMIT)?
            }
            None => {
                let (lo, hi) = query_box(s, margin);
                target.flood(seeds, |t| target.meets(t, lo, hi), FLOOD_LIMIT)?
            }
        };
        self.take(found.len() as u64)
            .then(|| found.iter().map(|&t| target.corners_of(t)).collect())
    }

    fn left(&self) -> u64 {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn exhausted(&self) -> bool {
        self.left() == 0
    }
}

/// Upper bound of `sup_{x in source} d(x, target)` (the two surfaces index the same
/// positions).
pub(crate) fn directed_bound(source: &Surface, target: &Surface, tolerance: Tolerance) -> f64 {
    directed_bound_within(source, target, tolerance, BUDGET_PER_TRIANGLE)
}

/// [`directed_bound`] with `per_triangle` candidates of budget per triangle.
pub(crate) fn directed_bound_within(
    source: &Surface,
    target: &Surface,
    tolerance: Tolerance,
    per_triangle: u64,
) -> f64 {
    let budget = Budget::new(per_triangle, source.triangles() + target.triangles());
    // f at every vertex of the source (zero at the target's own vertices), and at the centroid
    // of every triangle whose corners are all on the target (which say nothing of it): walked,
    // upper bounds; the largest of them searched exactly for the lower bound `lb`.
    let mut at_vertex = walk::vertex_samples(source, target);
    let mut centres = walk::centre_samples(source, target);
    let mut lb = walk::exact_lower_bound(source, target, &mut at_vertex, &mut centres);
    // Every triangle's bound: the cheap ones where they are within the tolerance already, the
    // partition among the target triangles connected to the nearest ones under it where not,
    // and among all the target triangles near it where that is not enough.
    let ids: Vec<u32> = (0..source.triangles() as u32).collect();
    let accept = lb + tolerance.slack(lb);
    let first = parallel_map(&ids, |&k| {
        let t = source.triangle(k);
        let corners = t.map(|v| source.point(v));
        let f: [Found; 3] = t.map(|v| at_vertex[v as usize]);
        let centre = centres[k as usize];
        let mut near: Vec<u32> = Vec::with_capacity(4);
        for n in f.iter().chain(&centre).filter_map(|s| s.nearest) {
            if !near.contains(&n) {
                near.push(n);
            }
        }
        let longest = longest_side(&corners);
        let local = f[0]
            .distance
            .max(f[1].distance)
            .max(f[2].distance)
            .max(centre.map_or(0.0, |c| c.distance));
        let lipschitz = f[0].distance.max(f[1].distance).max(f[2].distance) + longest / 3f64.sqrt();
        let convex = near
            .iter()
            .map(|&n| {
                corners
                    .iter()
                    .map(|&x| target.distance2_to(n, x))
                    .fold(0.0, f64::max)
                    .sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        let mut best = (lipschitz.min(convex), None);
        if best.0 <= accept {
            return best;
        }
        let margin = 2.0 * local + MARGIN * longest;
        for stage in 0..3 {
            let candidates = match stage {
                0 if near.len() > 1 => Some(near.iter().map(|&n| target.corners_of(n)).collect()),
                0 => continue,
                1 => budget.flood(target, &near, &corners, margin),
                _ => budget.candidates(target, &corners, margin),
            };
            let Some(candidates) = candidates else {
                if budget.exhausted() {
                    target.note_capped();
                    return best;
                }
                continue;
            };
            if let Some(b) = partition::partition_bound(corners, &candidates)
                && b.bound < best.0
            {
                best = (b.bound, Some(b.at));
                if b.bound <= accept {
                    return best;
                }
            }
        }
        best
    });

    // Branch and bound: only a triangle whose bound is above the tolerance of the largest
    // distance found so far is looked at again, largest first.
    let mut reported = lb;
    let mut open: Vec<usize> = Vec::new();
    for (k, &(bound, _)) in first.iter().enumerate() {
        if bound <= accept {
            reported = reported.max(bound);
        } else {
            open.push(k);
        }
    }
    open.sort_unstable_by(|&a, &b| first[b].0.total_cmp(&first[a].0));
    for k in open {
        let (bound, at) = first[k];
        if budget.exhausted() {
            target.note_capped();
            // No refinement left to pay for: the first bound (an upper bound) stands.
            reported = reported.max(bound);
            continue;
        }
        if bound <= lb + tolerance.slack(lb) {
            // Every triangle after this one is bounded lower still.
            reported = reported.max(bound);
            break;
        }
        if let Some(at) = at {
            // The distance where the bound is reached is often the bound itself.
            lb = lb.max(target.nearest(at).distance);
            if bound <= lb + tolerance.slack(lb) {
                reported = reported.max(bound);
                continue;
            }
        }
        let corners = source
            .triangle(k as u32)
            .map(|v| target.nearest(source.point(v)));
        let refined = refine::refine(target, corners, 0, &mut lb, tolerance, &budget);
        reported = reported.max(refined.min(bound));
    }
    reported.max(lb)
}

/// Length of the longest side of a triangle.
fn longest_side(p: &[DVec3; 3]) -> f64 {
    (p[1] - p[0])
        .length_squared()
        .max((p[2] - p[1]).length_squared())
        .max((p[0] - p[2]).length_squared())
        .sqrt()
}

/// `f` over `items` on every available core, in order.
pub(crate) fn parallel_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    if threads <= 1 || items.len() < 1024 {
        return items.iter().map(f).collect();
    }
    let chunk = items.len().div_ceil(threads);
    let f = &f;
    std::thread::scope(|s| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|c| s.spawn(move || c.iter().map(f).collect::<Vec<R>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a measuring thread panicked"))
            .collect()
    })
}

/// The smallest f32 that is >= `x` (1 + 1e-9), which covers the f64 rounding of the distances
/// (relative errors near 1e-15).
pub(crate) fn round_up_f32(x: f64) -> f32 {
    let x = x * (1.0 + 1e-9);
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_triangle_distance_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        // Above the face, beyond an edge, beyond a corner.
        let d = |p: DVec3| point_triangle_distance2(p, a, b, c).sqrt();
        assert!((d(DVec3::new(0.25, 0.25, 2.0)) - 2.0).abs() < 1e-12);
        assert!((d(DVec3::new(0.5, -1.0, 0.0)) - 1.0).abs() < 1e-12);
        assert!((d(DVec3::new(-3.0, -4.0, 0.0)) - 5.0).abs() < 1e-12);
        // A degenerate (collinear) triangle is its segment.
        let e = point_triangle_distance2(DVec3::new(0.5, 1.0, 0.0), a, b, DVec3::X * 0.5).sqrt();
        assert!((e - 1.0).abs() < 1e-12);
    }

    #[test]
    fn round_up_never_rounds_down() {
        for x in [0.1f64, 1.0 / 3.0, 1e-9, 12345.678901] {
            assert!(f64::from(round_up_f32(x)) >= x);
        }
    }

    /// The R-tree's nearest triangle is the brute-force nearest, and a surface's bound against
    /// itself is zero (every piece is inside the triangle its centroid finds).
    #[test]
    fn nearest_matches_brute_force_and_self_bound_is_zero() {
        let (p, idx) = crate::lod_chain::uv_sphere(16, 32);
        let s = Surface::new(&p, &idx);
        let v = |i: u32| DVec3::from(p[i as usize].map(f64::from));
        for k in 0..200 {
            let k = f64::from(k);
            let q = DVec3::new(
                (k * 0.37).sin() * 1.3,
                (k * 0.71).cos() * 1.1,
                (k * 0.13).sin(),
            );
            let brute = idx
                .chunks_exact(3)
                .map(|t| point_triangle_distance2(q, v(t[0]), v(t[1]), v(t[2])).sqrt())
                .fold(f64::INFINITY, f64::min);
            assert!((brute - s.nearest(q).distance).abs() < 1e-12, "{k}");
        }
        let tolerance = Tolerance {
            relative: 0.05,
            absolute: 1e-5,
        };
        assert!(directed_bound(&s, &s, tolerance) < 1e-12);
    }
}
