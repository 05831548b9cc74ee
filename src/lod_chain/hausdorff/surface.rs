//! A triangle mesh to measure distances to: its triangles, which triangles meet at each vertex
//! (for the descents and floods of [`super::walk`]), and an R-tree built on first use (for the
//! exact nearest-triangle search and the candidates of a partition).

use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

use glam::DVec3;
use rstar::{AABB, PointDistance, RTree, RTreeObject};

use super::point_triangle_distance2;

/// A triangle's corners, in f64 (exact from the f32 positions).
pub(super) type Corners = [DVec3; 3];

/// A triangle of the surface in the R-tree: its index and corners.
pub(super) struct Tri {
    pub id: u32,
    pub corners: Corners,
    envelope: AABB<[f64; 3]>,
}

impl RTreeObject for Tri {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

impl PointDistance for Tri {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        let [a, b, c] = self.corners;
        point_triangle_distance2(DVec3::from_array(*point), a, b, c)
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

/// A vertex of the surface and one triangle it is a corner of: the nearest vertex's triangle is
/// an upper bound of the distance that costs no more on slivers than elsewhere.
struct Corner {
    at: [f64; 3],
    tri: u32,
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

/// A point where `f`, the distance to the surface, was evaluated, and the triangle that gave it.
#[derive(Clone, Copy)]
pub(super) struct Sample {
    pub at: DVec3,
    pub distance: f64,
    pub nearest: Option<u32>,
}

/// A triangle mesh to measure distances to.
pub(crate) struct Surface<'a> {
    positions: &'a [[f32; 3]],
    triangles: Vec<[u32; 3]>,
    /// The triangles at vertex `v` are `ring[ring_start[v]..ring_start[v + 1]]`.
    ring_start: Vec<u32>,
    ring: Vec<u32>,
    tree: OnceLock<RTree<Tri>>,
    /// Each vertex used, with a triangle it is a corner of (built for the first capped search).
    corners: OnceLock<RTree<Corner>>,
    /// Distances bounded rather than found ([`NEAREST_OVERLAP`]), and bounds whose budget ran
    /// out: the work capped on this surface so far.
    capped: AtomicUsize,
}

impl<'a> Surface<'a> {
    /// The triangles `indices` of `positions` (indices already checked).
    pub(crate) fn new(positions: &'a [[f32; 3]], indices: &[u32]) -> Self {
        let triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let mut ring_start = vec![0u32; positions.len() + 1];
        for &v in indices {
            ring_start[v as usize + 1] += 1;
        }
        for k in 1..ring_start.len() {
            ring_start[k] += ring_start[k - 1];
        }
        let mut fill = ring_start.clone();
        let mut ring = vec![0u32; indices.len()];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                let at = &mut fill[v as usize];
                ring[*at as usize] = t as u32;
                *at += 1;
            }
        }
        Surface {
            positions,
            triangles,
            ring_start,
            ring,
            tree: OnceLock::new(),
            corners: OnceLock::new(),
            capped: AtomicUsize::new(0),
        }
    }

    /// The shared vertex positions.
    pub(crate) fn positions(&self) -> &'a [[f32; 3]] {
        self.positions
    }

    /// Vertex `v`'s position in f64.
    pub(super) fn point(&self, v: u32) -> DVec3 {
        DVec3::from(self.positions[v as usize].map(f64::from))
    }

    /// Its number of triangles.
    pub(super) fn triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Triangle `t`'s vertices.
    pub(super) fn triangle(&self, t: u32) -> [u32; 3] {
        self.triangles[t as usize]
    }

    /// Triangle `t`'s corners.
    pub(super) fn corners_of(&self, t: u32) -> Corners {
        self.triangle(t).map(|v| self.point(v))
    }

    /// Squared distance from `p` to triangle `t`.
    pub(super) fn distance2_to(&self, t: u32, p: DVec3) -> f64 {
        let [a, b, c] = self.corners_of(t);
        point_triangle_distance2(p, a, b, c)
    }

    /// The triangles vertex `v` is a corner of (none for a vertex the surface does not use).
    pub(super) fn incident(&self, v: u32) -> &[u32] {
        match (
            self.ring_start.get(v as usize),
            self.ring_start.get(v as usize + 1),
        ) {
            (Some(&a), Some(&b)) => &self.ring[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Whether a triangle of the surface has vertex `v` of the shared positions.
    pub(super) fn has_vertex(&self, v: u32) -> bool {
        !self.incident(v).is_empty()
    }

    /// The R-tree of the triangles, built on first use.
    fn tree(&self) -> &RTree<Tri> {
        self.tree.get_or_init(|| {
            let tris = (0..self.triangles.len() as u32)
                .map(|id| {
                    let corners = self.corners_of(id);
                    let [a, b, c] = corners;
                    let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                    Tri {
                        id,
                        corners,
                        envelope: AABB::from_corners(lo.to_array(), hi.to_array()),
                    }
                })
                .collect();
            RTree::bulk_load(tris)
        })
    }

    /// Builds the R-tree now (on another thread while the caller does other work).
    pub(crate) fn index(&self) {
        self.tree();
    }

    /// How much work was capped on this surface so far (see the field).
    pub(crate) fn capped(&self) -> usize {
        self.capped.load(Relaxed)
    }

    pub(super) fn note_capped(&self) {
        self.capped.fetch_add(1, Relaxed);
    }

    /// The triangles whose bounding boxes meet the box of the triangle `s` moved by up to
    /// `margin` along its normal either way (the target triangles within `margin` of `s`'s
    /// plane that are over or under it), in no order.
    pub(super) fn candidates(&self, s: &Corners, margin: f64) -> impl Iterator<Item = &Tri> {
        let (lo, hi) = query_box(s, margin);
        self.tree()
            .locate_in_envelope_intersecting(&AABB::from_corners(lo.to_array(), hi.to_array()))
    }

    /// Whether triangle `t`'s box meets the box `lo..hi`.
    pub(super) fn meets(&self, t: u32, lo: DVec3, hi: DVec3) -> bool {
        let [a, b, c] = self.corners_of(t);
        let (tlo, thi) = (a.min(b).min(c), a.max(b).max(c));
        tlo.cmple(hi).all() && thi.cmpge(lo).all()
    }

    /// Distance from `p` to the surface and the nearest triangle (+inf and `None` for an empty
    /// surface).
    /// Where the boxes of more than [`NEAREST_OVERLAP`] triangles hold `p`, an upper bound of
    /// that distance and a triangle at most that far (noted as capped).
    pub(super) fn nearest(&self, p: DVec3) -> Sample {
        let tree = self.tree();
        let point = AABB::from_point(p.to_array());
        let overlap = tree
            .locate_in_envelope_intersecting(&point)
            .take(NEAREST_OVERLAP + 1)
            .count();
        let found = if overlap <= NEAREST_OVERLAP {
            tree.nearest_neighbor(&p.to_array()).map(|t| t.id)
        } else {
            self.note_capped();
            let corners = self.corners.get_or_init(|| {
                let mut seen = vec![false; self.positions.len()];
                let mut corners = Vec::new();
                for (t, tri) in self.triangles.iter().enumerate() {
                    for &i in tri {
                        if !std::mem::replace(&mut seen[i as usize], true) {
                            corners.push(Corner {
                                at: self.point(i).to_array(),
                                tri: t as u32,
                            });
                        }
                    }
                }
                RTree::bulk_load(corners)
            });
            let corner = corners.nearest_neighbor(&p.to_array()).map(|c| c.tri);
            corner
                .into_iter()
                .chain(
                    tree.locate_in_envelope_intersecting(&point)
                        .take(NEAREST_OVERLAP)
                        .map(|t| t.id),
                )
                .min_by(|&a, &b| self.distance2_to(a, p).total_cmp(&self.distance2_to(b, p)))
        };
        match found {
            Some(t) => Sample {
                at: p,
                distance: self.distance2_to(t, p).sqrt(),
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

/// The box of the triangle `s` moved by up to `margin` along its normal either way.
pub(super) fn query_box(s: &Corners, margin: f64) -> (DVec3, DVec3) {
    let n = (s[1] - s[0]).cross(s[2] - s[0]).normalize_or_zero();
    let grow = if n == DVec3::ZERO {
        DVec3::splat(margin)
    } else {
        n.abs() * margin
    } + DVec3::splat(super::longest_side(s) * 1e-9);
    (
        s[0].min(s[1]).min(s[2]) - grow,
        s[0].max(s[1]).max(s[2]) + grow,
    )
}
