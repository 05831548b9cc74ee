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
//!   `sup_Q f <= max d(corner, t)`. The candidates `t` are the triangles nearest to `Q`'s
//!   corners and centroid.
//! - **Partition** ([`partition`]): `Q` cut into convex pieces along the outlines of the target
//!   triangles under it, each piece bounded by the convex bound of the triangle over it.
//!
//! [`directed_bound`] evaluates `f` at every vertex of the source (the largest value found, `lb`,
//! is a lower bound of the supremum), then bounds every source triangle with the cheapest of
//! these that is within the tolerance of `lb`: Lipschitz and convex first, then the partition
//! among the nearest triangles of its corners, then the partition among every target triangle
//! near it. The triangles still above the tolerance are looked at again, largest bound first:
//! `f` at the point where the bound is reached often raises `lb` to it; the rest are refined
//! ([`refine`]: cut at the edge midpoints, each piece bounded again). The result is the largest
//! bound over all triangles: an upper bound whatever the cuts and candidates, which only decide
//! how tight it is (at most `lb + tolerance` above the largest distance found unless a piece
//! reaches the depth limit; then still an upper bound, only a looser one). Distances are
//! computed in f64 from the f32 positions; the caller rounds up.

mod partition;
mod refine;

use glam::DVec3;
use rstar::{AABB, PointDistance, RTree, RTreeObject};

/// A triangle of the target surface in the R-tree.
#[derive(Clone)]
struct Tri {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    envelope: AABB<[f64; 3]>,
}

impl Tri {
    fn distance(&self, p: DVec3) -> f64 {
        self.distance2(p).sqrt()
    }

    fn distance2(&self, p: DVec3) -> f64 {
        point_triangle_distance2(p, self.a, self.b, self.c)
    }
}

impl RTreeObject for Tri {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

impl PointDistance for Tri {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        point_triangle_distance2(DVec3::from_array(*point), self.a, self.b, self.c)
    }

    /// The box's distance first: most triangles a search visits are farther than that already.
    fn distance_2_if_less_or_equal(&self, point: &[f64; 3], max_distance_2: f64) -> Option<f64> {
        if self.envelope.distance_2(point) > max_distance_2 {
            return None;
        }
        let d = self.distance_2(point);
        (d <= max_distance_2).then_some(d)
    }
}

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

/// Squared distance from `p` to the closed triangle `a b c`; a degenerate triangle (collinear or
/// coincident corners) is the union of its edges.
pub(crate) fn point_triangle_distance2(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let n = (b - a).cross(c - a);
    let nn = n.length_squared();
    if nn > 0.0 {
        let inside = (b - a).cross(p - a).dot(n) >= 0.0
            && (c - b).cross(p - b).dot(n) >= 0.0
            && (a - c).cross(p - c).dot(n) >= 0.0;
        if inside {
            let h = (p - a).dot(n);
            return h * h / nn;
        }
    }
    point_segment_distance2(p, a, b)
        .min(point_segment_distance2(p, b, c))
        .min(point_segment_distance2(p, c, a))
}

/// A vertex of the target surface and one triangle it is a corner of: the nearest vertex's
/// triangle is an upper bound of the distance that costs no more on slivers than elsewhere.
struct Corner {
    at: [f64; 3],
    tri: Tri,
}

impl RTreeObject for Corner {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        AABB::from_point(self.at)
    }
}

impl PointDistance for Corner {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        DVec3::from(self.at).distance_squared(DVec3::from(*point))
    }
}

/// The most triangle boxes a point may lie in for the exact nearest-triangle search: past it
/// (long slivers spanning the mesh: a triangle list read as a fan, positions read from the
/// wrong place) the search would weigh much of the mesh for every point, and the distance is
/// bounded instead by the nearest vertex's triangle and the first of those boxes' triangles
/// (an upper bound still; the bound is then reported as capped).
const NEAREST_OVERLAP: usize = 64;

/// A triangle mesh to measure distances to.
pub(crate) struct Surface {
    tree: RTree<Tri>,
    /// Each vertex used, with a triangle it is a corner of.
    corners: RTree<Corner>,
    /// Which vertices the triangles use (`d = 0` there).
    vertices: Vec<bool>,
    /// Distances bounded rather than found ([`NEAREST_OVERLAP`]), and bounds whose budget ran
    /// out ([`BUDGET_PER_TRIANGLE`]): the work capped on this surface so far.
    capped: std::sync::atomic::AtomicUsize,
}

impl Surface {
    /// The triangles `indices` of `positions` (indices already checked).
    pub(crate) fn new(positions: &[[f32; 3]], indices: &[u32]) -> Self {
        let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
        let tris: Vec<Tri> = indices
            .chunks_exact(3)
            .map(|t| {
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                Tri {
                    a,
                    b,
                    c,
                    envelope: AABB::from_corners(lo.to_array(), hi.to_array()),
                }
            })
            .collect();
        let mut vertices = vec![false; positions.len()];
        let mut corners = Vec::new();
        for (t, tri) in indices.chunks_exact(3).zip(&tris) {
            for &i in t {
                if !std::mem::replace(&mut vertices[i as usize], true) {
                    corners.push(Corner {
                        at: p(i).to_array(),
                        tri: tri.clone(),
                    });
                }
            }
        }
        Surface {
            tree: RTree::bulk_load(tris),
            corners: RTree::bulk_load(corners),
            vertices,
            capped: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// How much work was capped on this surface so far (see the field).
    pub(crate) fn capped(&self) -> usize {
        self.capped.load(std::sync::atomic::Ordering::Relaxed)
    }

    pub(super) fn note_capped(&self) {
        self.capped
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// Its number of triangles.
    fn triangles(&self) -> usize {
        self.tree.size()
    }

    /// Whether a triangle of the surface has vertex `v` of the shared positions.
    fn has_vertex(&self, v: u32) -> bool {
        self.vertices.get(v as usize).copied().unwrap_or(false)
    }

    /// The triangles whose bounding boxes meet the box of the triangle `s` moved by up to
    /// `margin` along its normal either way (the target triangles within `margin` of `s`'s
    /// plane that are over or under it), in no order.
    fn candidates(&self, s: &[DVec3; 3], margin: f64) -> impl Iterator<Item = &Tri> {
        let n = (s[1] - s[0]).cross(s[2] - s[0]).normalize_or_zero();
        let grow = if n == DVec3::ZERO {
            DVec3::splat(margin)
        } else {
            n.abs() * margin
        } + DVec3::splat(longest_side(s) * 1e-9);
        let lo = s[0].min(s[1]).min(s[2]) - grow;
        let hi = s[0].max(s[1]).max(s[2]) + grow;
        self.tree
            .locate_in_envelope_intersecting(&AABB::from_corners(lo.to_array(), hi.to_array()))
    }

    /// Distance from `p` to the surface and the nearest triangle (+inf and `None` for an empty
    /// surface).
    /// Where the boxes of more than [`NEAREST_OVERLAP`] triangles hold `p`, an upper bound of
    /// that distance and a triangle at most that far (noted as capped).
    fn nearest(&self, p: DVec3) -> Sample<'_> {
        let point = AABB::from_point(p.to_array());
        let overlap = self
            .tree
            .locate_in_envelope_intersecting(&point)
            .take(NEAREST_OVERLAP + 1)
            .count();
        let found = if overlap <= NEAREST_OVERLAP {
            self.tree.nearest_neighbor(&p.to_array())
        } else {
            self.note_capped();
            let corner = self.corners.nearest_neighbor(&p.to_array()).map(|c| &c.tri);
            corner
                .into_iter()
                .chain(
                    self.tree
                        .locate_in_envelope_intersecting(&point)
                        .take(NEAREST_OVERLAP),
                )
                .min_by(|a, b| a.distance2(p).total_cmp(&b.distance2(p)))
        };
        match found {
            Some(t) => Sample {
                at: p,
                distance: t.distance(p),
                nearest: Some(t),
            },
            None => Sample {
                at: p,
                distance: f64::INFINITY,
                nearest: None,
            },
        }
    }
}

/// A point where `f` was evaluated.
#[derive(Clone, Copy)]
struct Sample<'a> {
    at: DVec3,
    distance: f64,
    nearest: Option<&'a Tri>,
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

/// What is left of a bound's budget of candidate triangles ([`BUDGET_PER_TRIANGLE`]).
struct Budget(std::sync::atomic::AtomicU64);

impl Budget {
    fn new(per_triangle: u64, triangles: usize) -> Self {
        Self(std::sync::atomic::AtomicU64::new(
            per_triangle.saturating_mul(triangles as u64),
        ))
    }

    /// The candidates of `target` for `s` ([`Surface::candidates`]), taken from the budget;
    /// None when the budget has fewer left (the query stops there, so an exhausted budget costs
    /// no more than it has left).
    fn candidates<'a>(
        &self,
        target: &'a Surface,
        s: &[DVec3; 3],
        margin: f64,
    ) -> Option<Vec<&'a Tri>> {
        use std::sync::atomic::Ordering::Relaxed;
        let left = self.0.load(Relaxed);
        let limit = usize::try_from(left).unwrap_or(usize::MAX);
        let found: Vec<&Tri> = target
            .candidates(s, margin)
            .take(limit.saturating_add(1))
            .collect();
        let n = found.len() as u64;
        match self
            .0
            .fetch_update(Relaxed, Relaxed, |left| left.checked_sub(n))
        {
            Ok(_) => Some(found),
            Err(_) => {
                self.0.store(0, Relaxed);
                None
            }
        }
    }

    fn left(&self) -> u64 {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn exhausted(&self) -> bool {
        self.left() == 0
    }
}

/// Upper bound of `sup_{x in source} d(x, target)` over the triangles `indices` of `positions`
/// (which the target indexes too).
pub(crate) fn directed_bound(
    positions: &[[f32; 3]],
    indices: &[u32],
    target: &Surface,
    tolerance: Tolerance,
) -> f64 {
    directed_bound_within(positions, indices, target, tolerance, BUDGET_PER_TRIANGLE)
}

/// [`directed_bound`] with `per_triangle` candidates of budget per triangle.
pub(crate) fn directed_bound_within(
    positions: &[[f32; 3]],
    indices: &[u32],
    target: &Surface,
    tolerance: Tolerance,
    per_triangle: u64,
) -> f64 {
    let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
    let budget = Budget::new(per_triangle, indices.len() / 3 + target.triangles());
    // f at every vertex the source uses (with the nearest triangle): zero at the target's own
    // vertices.
    let mut used: Vec<u32> = indices.to_vec();
    used.sort_unstable();
    used.dedup();
    let samples = parallel_map(&used, |&v| {
        if target.has_vertex(v) {
            (0.0, None)
        } else {
            let s = target.nearest(p(v));
            (s.distance, s.nearest)
        }
    });
    let mut at_vertex = vec![(0.0, None); positions.len()];
    for (&v, &s) in used.iter().zip(&samples) {
        at_vertex[v as usize] = s;
    }
    let triangles: Vec<[u32; 3]> = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    // f at the centroid of every triangle whose corners are all on the target (no nearest
    // triangle to start from): with the vertices, a lower bound close to the supremum before
    // any triangle is bounded.
    let centres = parallel_map(&triangles, |t| {
        t.iter()
            .all(|&v| at_vertex[v as usize].1.is_none())
            .then(|| target.nearest((p(t[0]) + p(t[1]) + p(t[2])) / 3.0))
    });
    let mut lb = samples
        .iter()
        .map(|s| s.0)
        .chain(centres.iter().flatten().map(|s| s.distance))
        .fold(0.0, f64::max);
    // Every triangle's bound: the cheap ones where they are within the tolerance already, the
    // partition among the nearest triangles of its corners (or centroid) where not, and among
    // all the target triangles near it where that is not enough.
    let work: Vec<([u32; 3], Option<Sample>)> = triangles.iter().copied().zip(centres).collect();
    let accept = lb + tolerance.slack(lb);
    let first = parallel_map(&work, |(t, centre)| {
        let corners = t.map(p);
        let f = t.map(|v| at_vertex[v as usize].0);
        let mut near: Vec<&Tri> = Vec::with_capacity(3);
        for n in t
            .iter()
            .filter_map(|&v| at_vertex[v as usize].1)
            .chain(centre.and_then(|c| c.nearest))
        {
            if !near.iter().any(|&m| std::ptr::eq(m, n)) {
                near.push(n);
            }
        }
        let longest = longest_side(&corners);
        let lipschitz = f[0].max(f[1]).max(f[2]) + longest / 3f64.sqrt();
        let convex = near
            .iter()
            .map(|n| corners.iter().map(|&x| n.distance(x)).fold(0.0, f64::max))
            .fold(f64::INFINITY, f64::min);
        let mut best = (lipschitz.min(convex), None);
        if best.0 <= accept {
            return best;
        }
        if near.len() > 1
            && let Some(b) = partition::partition_bound(corners, &near)
            && b.bound < best.0
        {
            best = (b.bound, Some(b.at));
            if b.bound <= accept {
                return best;
            }
        }
        let local = f[0]
            .max(f[1])
            .max(f[2])
            .max(centre.map_or(0.0, |c| c.distance));
        let Some(candidates) = budget.candidates(target, &corners, 2.0 * local + MARGIN * longest)
        else {
            target.note_capped();
            return best;
        };
        match partition::partition_bound(corners, &candidates) {
            Some(b) if b.bound < best.0 => (b.bound, Some(b.at)),
            _ => best,
        }
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
        let corners = triangles[k].map(|v| target.nearest(p(v)));
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
        assert!(directed_bound(&p, &idx, &s, tolerance) < 1e-12);
    }
}
