//! An upper bound of the two-sided Hausdorff distance between two triangle meshes.
//!
//! Two bounds of `sup f` over a piece `Q` of a source triangle, where `f(x) = d(x, S)` is the
//! distance to the target surface:
//!
//! - **Lipschitz**: `f` is 1-Lipschitz, and `Q`'s three corners cover it within `r` (its
//!   circumradius when acute, half its longest side otherwise; both at most `longest / sqrt(3)`,
//!   which is used), so `sup_Q f <= max f(corners) + r`.
//! - **Convex**: for any one triangle `t` of the target, `f(x) <= d(x, t)`, and `d(., t)` is convex
//!   (the distance to a convex set), so over the triangle `Q` its maximum is at a corner:
//!   `sup_Q f <= max d(corner, t)`. The candidates `t` are the triangles nearest to `Q`'s
//!   corners and centroid.
//!
//! [`directed_bound`] evaluates `f` at every vertex of the source (the largest value found, `lb`,
//! is a lower bound of the supremum), then refines each triangle: a piece whose smaller bound is
//! within the tolerance of `lb` is done; any other is cut, along the plane through the edge two
//! neighbouring candidates share (where the nearest triangle changes), or else at its edge
//! midpoints, and `f` is evaluated at the new corners. The result is the largest bound over the
//! accepted pieces: an upper bound whatever the cuts, at most `lb + tolerance` above the largest
//! distance found unless a piece reaches the depth limit (then still an upper bound, only a
//! looser one). Distances are computed in f64 from the f32 positions; the caller rounds up.

use glam::DVec3;
use rstar::{AABB, PointDistance, RTree, RTreeObject};

/// A triangle of the target surface in the R-tree.
struct Tri {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    /// Its vertex indices (neighbours share two).
    ids: [u32; 3],
    /// Unit normal (zero when degenerate).
    normal: DVec3,
    envelope: AABB<[f64; 3]>,
}

impl Tri {
    fn distance(&self, p: DVec3) -> f64 {
        point_triangle_distance2(p, self.a, self.b, self.c).sqrt()
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

/// A triangle mesh to measure distances to.
pub(crate) struct Surface {
    tree: RTree<Tri>,
}

impl Surface {
    /// The triangles `indices` of `positions` (indices already checked).
    pub(crate) fn new(positions: &[[f32; 3]], indices: &[u32]) -> Self {
        let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
        let tris = indices
            .chunks_exact(3)
            .map(|t| {
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                Tri {
                    a,
                    b,
                    c,
                    ids: [t[0], t[1], t[2]],
                    normal: (b - a).cross(c - a).normalize_or_zero(),
                    envelope: AABB::from_corners(lo.to_array(), hi.to_array()),
                }
            })
            .collect();
        Surface {
            tree: RTree::bulk_load(tris),
        }
    }

    /// Distance from `p` to the surface and the nearest triangle (+inf and `None` for an empty
    /// surface).
    fn nearest(&self, p: DVec3) -> Sample<'_> {
        match self.tree.nearest_neighbor(&p.to_array()) {
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
    fn slack(&self, lb: f64) -> f64 {
        (self.relative * lb).max(self.absolute)
    }
}

/// Deepest cut of one source triangle.
const MAX_DEPTH: u32 = 12;

/// Upper bound of `sup_{x in source} d(x, target)` over the triangles `indices` of `positions`.
pub(crate) fn directed_bound(
    positions: &[[f32; 3]],
    indices: &[u32],
    target: &Surface,
    tolerance: Tolerance,
) -> f64 {
    let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
    // f at every vertex the source uses.
    let mut used: Vec<u32> = indices.to_vec();
    used.sort_unstable();
    used.dedup();
    let samples = parallel_map(&used, |&v| target.nearest(p(v)));
    let mut at_vertex = vec![None; positions.len()];
    for (&v, s) in used.iter().zip(&samples) {
        at_vertex[v as usize] = Some(*s);
    }
    let triangles: Vec<[u32; 3]> = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    // f at every centroid too: with the vertices, a lower bound close to the supremum before
    // any piece is refined (refining against a small early `lb` would split pieces far finer
    // than the tolerance of the final result needs).
    let centres = parallel_map(&triangles, |t| {
        target.nearest((p(t[0]) + p(t[1]) + p(t[2])) / 3.0)
    });
    let lb = samples
        .iter()
        .chain(&centres)
        .map(|s| s.distance)
        .fold(0.0, f64::max);
    let work: Vec<([u32; 3], Sample)> = triangles.into_iter().zip(centres).collect();
    let bounds = parallel_map(&work, |(t, centre)| {
        let mut lb = lb;
        let corners = t.map(|v| at_vertex[v as usize].expect("every used vertex was sampled"));
        refine(target, corners, Some(*centre), 0, &mut lb, tolerance)
    });
    bounds.into_iter().fold(lb, f64::max)
}

/// The bound over the triangle piece with corners `c`.
fn refine<'a>(
    target: &'a Surface,
    c: [Sample<'a>; 3],
    centre: Option<Sample<'a>>,
    depth: u32,
    lb: &mut f64,
    tolerance: Tolerance,
) -> f64 {
    let p = c.map(|s| s.at);
    let longest = (p[1] - p[0])
        .length_squared()
        .max((p[2] - p[1]).length_squared())
        .max((p[0] - p[2]).length_squared())
        .sqrt();
    let lipschitz = c[0].distance.max(c[1].distance).max(c[2].distance) + longest / 3f64.sqrt();
    // The centroid's nearest triangle is often the one whose prism holds the whole piece.
    let centre = centre.unwrap_or_else(|| target.nearest((p[0] + p[1] + p[2]) / 3.0));
    *lb = lb.max(centre.distance);
    let convex = c
        .iter()
        .chain([&centre])
        .filter_map(|s| s.nearest)
        .map(|t| p.iter().map(|&x| t.distance(x)).fold(0.0, f64::max))
        .fold(f64::INFINITY, f64::min);
    let bound = lipschitz.min(convex);
    if bound <= *lb + tolerance.slack(*lb) || depth >= MAX_DEPTH {
        return bound;
    }
    // Plane cuts do not shorten the longest side: every other cut is at the midpoints.
    let plane = if depth.is_multiple_of(2) {
        cut_between_neighbours(&c)
    } else {
        None
    };
    let pieces = plane.unwrap_or_else(|| midpoint_pieces(&p));
    pieces
        .into_iter()
        .map(|piece| {
            let corners = piece.map(|x| corner(target, &c, x, lb));
            refine(target, corners, None, depth + 1, lb, tolerance)
        })
        .fold(0.0, f64::max)
}

/// The sample at `x`: a parent corner's when `x` is one, else a new evaluation (raising `lb`).
fn corner<'a>(target: &'a Surface, parent: &[Sample<'a>; 3], x: DVec3, lb: &mut f64) -> Sample<'a> {
    if let Some(s) = parent.iter().find(|s| s.at == x) {
        return *s;
    }
    let s = target.nearest(x);
    *lb = lb.max(s.distance);
    s
}

/// The four pieces of a triangle cut at its edge midpoints.
fn midpoint_pieces(p: &[DVec3; 3]) -> Vec<[DVec3; 3]> {
    let m = [
        (p[0] + p[1]) * 0.5,
        (p[1] + p[2]) * 0.5,
        (p[2] + p[0]) * 0.5,
    ];
    vec![
        [p[0], m[0], m[2]],
        [m[0], p[1], m[1]],
        [m[2], m[1], p[2]],
        [m[0], m[1], m[2]],
    ]
}

/// Where two corners' nearest target triangles share an edge, the triangle cut by the plane
/// through that edge halfway between their normals (the nearest triangle changes about there);
/// `None` when no two share an edge or the plane misses the triangle.
fn cut_between_neighbours(c: &[Sample; 3]) -> Option<Vec<[DVec3; 3]>> {
    let tris: Vec<&Tri> = c.iter().filter_map(|s| s.nearest).collect();
    for (i, a) in tris.iter().enumerate() {
        for b in &tris[i + 1..] {
            let shared: Vec<u32> = a.ids.into_iter().filter(|v| b.ids.contains(v)).collect();
            if shared.len() != 2 {
                continue;
            }
            let at_id = |id: u32| {
                let k = a.ids.iter().position(|&v| v == id).expect("shared");
                [a.a, a.b, a.c][k]
            };
            let (e0, e1) = (at_id(shared[0]), at_id(shared[1]));
            let mean = if a.normal.dot(b.normal) >= 0.0 {
                a.normal + b.normal
            } else {
                a.normal - b.normal
            };
            let n = (e1 - e0).cross(mean);
            if n.length_squared() == 0.0 {
                continue;
            }
            let p = c.map(|s| s.at);
            let side = p.map(|x| (x - e0).dot(n));
            if let Some(pieces) = split_by_plane(&p, &side) {
                return Some(pieces);
            }
        }
    }
    None
}

/// The triangle `p` cut where the signed distances `side` change sign: a triangle and a quad
/// (as two triangles); `None` unless the plane separates its corners.
fn split_by_plane(p: &[DVec3; 3], side: &[f64; 3]) -> Option<Vec<[DVec3; 3]>> {
    // The corner alone on its side.
    let lone = (0..3).find(|&i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        (side[i] > 0.0 && side[j] < 0.0 && side[k] < 0.0)
            || (side[i] < 0.0 && side[j] > 0.0 && side[k] > 0.0)
    })?;
    let (j, k) = ((lone + 1) % 3, (lone + 2) % 3);
    let at = |a: usize, b: usize| {
        let t = side[a] / (side[a] - side[b]);
        p[a] + (p[b] - p[a]) * t
    };
    let (x, y) = (at(lone, j), at(lone, k));
    Some(vec![[p[lone], x, y], [x, p[j], p[k]], [x, p[k], y]])
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
