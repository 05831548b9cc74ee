//! Finding nearby triangles by walking the target's connectivity instead of searching a tree.
//!
//! A level of a chain and the original share their vertices (a level keeps a subset of the
//! original's), so the target triangle nearest to a source vertex is usually a few steps from
//! the target vertex nearest to it along the source's edges. [`vertex_samples`] finds that
//! vertex for every source vertex (one breadth-first pass over the source) and walks from the
//! triangles there to the one nearest the vertex (steepest descent over the triangles sharing
//! a vertex with the current one). A walk can stop at a triangle that is not the nearest (a
//! fold of the target): its distance is then larger than the true one, an upper bound of it,
//! which is all the triangles' bounds need. The largest distance found, which decides how
//! tight the bound is, comes from searches of the whole target ([`exact_lower_bound`]; exact
//! unless a search was capped, and then the level says so). [`Surface::flood`] gathers the
//! target triangles a source triangle's partition may weigh, breadth first over shared
//! vertices from its nearest ones.

use std::cell::RefCell;

use glam::DVec3;

use super::parallel_map;
use super::surface::Surface;

/// Most steps of one walk.
const MAX_STEPS: u32 = 64;

/// Vertices shared by more triangles than this are not walked or flooded through (a fan's
/// hub): each step would weigh all of them.
const MAX_RING: usize = 64;

/// No vertex.
const NONE: u32 = u32::MAX;

/// Triangles a flood may look at per triangle it may keep (a well-shaped mesh's flood looks at
/// 3 to 6).
const FLOOD_LOOKS: usize = 8;

/// `f`, the distance to the target, at a point of the source: an upper bound of it with the
/// triangle that gives it, exact when it comes from a search of the whole target.
#[derive(Clone, Copy)]
pub(super) struct Found {
    pub distance: f64,
    pub nearest: Option<u32>,
    pub exact: bool,
}

impl Found {
    const ON_TARGET: Found = Found {
        distance: 0.0,
        nearest: None,
        exact: true,
    };
}

/// Per-thread marks of the triangles and vertices a flood has seen, by generation (no clearing
/// per flood).
struct Marks {
    generation: u32,
    triangles: Vec<u32>,
    vertices: Vec<u32>,
}

impl Marks {
    /// Starts a flood over a surface of `triangles` triangles and `vertices` vertices.
    fn start(&mut self, triangles: usize, vertices: usize) {
        if self.triangles.len() < triangles {
            self.triangles.resize(triangles, 0);
        }
        if self.vertices.len() < vertices {
            self.vertices.resize(vertices, 0);
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.triangles.fill(0);
            self.vertices.fill(0);
            self.generation = 1;
        }
    }

    /// Marks triangle `t`; false when this flood has marked it already.
    fn triangle(&mut self, t: u32) -> bool {
        let seen = &mut self.triangles[t as usize];
        (*seen != self.generation) && {
            *seen = self.generation;
            true
        }
    }

    /// Marks vertex `v`; false when this flood has marked it already.
    fn vertex(&mut self, v: u32) -> bool {
        let seen = &mut self.vertices[v as usize];
        (*seen != self.generation) && {
            *seen = self.generation;
            true
        }
    }
}

thread_local! {
    static MARKS: RefCell<Marks> = const {
        RefCell::new(Marks {
            generation: 0,
            triangles: Vec::new(),
            vertices: Vec::new(),
        })
    };
}

impl Surface<'_> {
    /// From the triangles at vertex `v`, a walk to the triangle nearest to `p`: its squared
    /// distance and index (`None` when no triangle has `v`).
    pub(super) fn walk_from(&self, p: DVec3, v: u32) -> Option<(f64, u32)> {
        let start = self
            .incident(v)
            .iter()
            .take(MAX_RING)
            .map(|&t| (self.distance2_to(t, p), t))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        Some(self.walk(p, start))
    }

    /// Steepest descent from `best` (squared distance, triangle) over the triangles sharing a
    /// vertex with the current one, while one of them is nearer to `p`.
    pub(super) fn walk(&self, p: DVec3, mut best: (f64, u32)) -> (f64, u32) {
        for _ in 0..MAX_STEPS {
            let here = best.1;
            if best.0 == 0.0 {
                break;
            }
            for v in self.triangle(here) {
                let ring = self.incident(v);
                if ring.len() > MAX_RING {
                    continue;
                }
                for &t in ring {
                    if t != here {
                        let d = self.distance2_to(t, p);
                        if d < best.0 {
                            best = (d, t);
                        }
                    }
                }
            }
            if best.1 == here {
                break;
            }
        }
        best
    }

    /// The triangles connected to `seeds` through shared vertices that `keep` keeps, and the
    /// seeds (kept or not); `None` when there are more than `limit`, or when it has looked at
    /// more than [`FLOOD_LOOKS`] times `limit` triangles. Each vertex's triangles are looked at
    /// once.
    pub(super) fn flood(
        &self,
        seeds: &[u32],
        keep: impl Fn(u32) -> bool,
        limit: usize,
    ) -> Option<Vec<u32>> {
        MARKS.with(|marks| {
            let mut marks = marks.borrow_mut();
            marks.start(self.triangles(), self.positions().len());
            let mut found = Vec::new();
            let mut vertices = Vec::new();
            let reached = |t: u32, marks: &mut Marks, vertices: &mut Vec<u32>| {
                for v in self.triangle(t) {
                    if marks.vertex(v) {
                        vertices.push(v);
                    }
                }
            };
            for &t in seeds {
                if marks.triangle(t) {
                    found.push(t);
                    reached(t, &mut marks, &mut vertices);
                }
            }
            let mut looks = 0;
            while let Some(v) = vertices.pop() {
                let ring = self.incident(v);
                if ring.len() > MAX_RING {
                    continue;
                }
                looks += ring.len();
                if looks > FLOOD_LOOKS * limit {
                    return None;
                }
                for &t in ring {
                    if marks.triangle(t) && keep(t) {
                        if found.len() >= limit {
                            return None;
                        }
                        found.push(t);
                        reached(t, &mut marks, &mut vertices);
                    }
                }
            }
            Some(found)
        })
    }
}

/// For every vertex, the target vertex nearest to it in steps along the source's edges (the
/// vertex itself when the target has it), [`NONE`] when none is connected to it.
fn roots(source: &Surface, target: &Surface) -> Vec<u32> {
    let n = source.positions().len();
    let mut root = vec![NONE; n];
    let mut queue = Vec::new();
    for v in 0..n as u32 {
        if source.has_vertex(v) && target.has_vertex(v) {
            root[v as usize] = v;
            queue.push(v);
        }
    }
    let mut next = 0;
    while let Some(&v) = queue.get(next) {
        next += 1;
        for &t in source.incident(v) {
            for u in source.triangle(t) {
                if root[u as usize] == NONE {
                    root[u as usize] = root[v as usize];
                    queue.push(u);
                }
            }
        }
    }
    root
}

/// `f` at every vertex of the source (indexed by vertex; 0 where the target has the vertex or
/// the source does not use it): walked from the vertex's root ([`roots`]), searched where no
/// target vertex is connected to it.
pub(super) fn vertex_samples(source: &Surface, target: &Surface) -> Vec<Found> {
    let root = roots(source, target);
    let used: Vec<u32> = (0..source.positions().len() as u32)
        .filter(|&v| source.has_vertex(v))
        .collect();
    let found = parallel_map(&used, |&v| {
        let r = root[v as usize];
        if r == v {
            Found {
                nearest: target.incident(v).first().copied(),
                ..Found::ON_TARGET
            }
        } else if let Some((d2, t)) = (r != NONE)
            .then(|| target.walk_from(source.point(v), r))
            .flatten()
        {
            Found {
                distance: d2.sqrt(),
                nearest: Some(t),
                exact: false,
            }
        } else {
            let s = target.nearest(source.point(v));
            Found {
                distance: s.distance,
                nearest: s.nearest,
                exact: true,
            }
        }
    });
    let mut at_vertex = vec![Found::ON_TARGET; source.positions().len()];
    for (&v, f) in used.iter().zip(found) {
        at_vertex[v as usize] = f;
    }
    at_vertex
}

/// `f` at the centroid of every source triangle whose corners are all on the target (where the
/// corners say nothing of the triangle's distance), walked from its first corner.
pub(super) fn centre_samples(source: &Surface, target: &Surface) -> Vec<Option<Found>> {
    let ids: Vec<u32> = (0..source.triangles() as u32).collect();
    parallel_map(&ids, |&t| {
        let tri = source.triangle(t);
        if !tri.iter().all(|&v| target.has_vertex(v)) {
            return None;
        }
        let c = (source.point(tri[0]) + source.point(tri[1]) + source.point(tri[2])) / 3.0;
        target.walk_from(c, tri[0]).map(|(d2, t)| Found {
            distance: d2.sqrt(),
            nearest: Some(t),
            exact: false,
        })
    })
}

/// Walked samples checked by an exact search at a time.
const BATCH: usize = 256;

/// The largest searched distance among the samples: the walked ones are searched, largest
/// first, until every one left is at most the largest distance found (a walk's distance is
/// never below the exact one); each searched sample keeps the nearer of its walk and its search
/// (a capped search, [`Surface::nearest`], can find a farther triangle than the walk did; both
/// are upper bounds, and `lb` is then one too, which only loosens the bound).
pub(super) fn exact_lower_bound(
    source: &Surface,
    target: &Surface,
    vertices: &mut [Found],
    centres: &mut [Option<Found>],
) -> f64 {
    let centroid = |t: u32| {
        let tri = source.triangle(t);
        (source.point(tri[0]) + source.point(tri[1]) + source.point(tri[2])) / 3.0
    };
    // (distance, vertex or !triangle) of every walked sample.
    let mut walked: Vec<(f64, u32, bool)> = Vec::new();
    let mut lb = 0.0f64;
    for (v, f) in vertices.iter().enumerate() {
        if f.exact {
            lb = lb.max(f.distance);
        } else {
            walked.push((f.distance, v as u32, false));
        }
    }
    for (t, f) in centres.iter().enumerate() {
        if let Some(f) = f {
            walked.push((f.distance, t as u32, true));
        }
    }
    walked.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    let mut next = 0;
    while next < walked.len() && walked[next].0 > lb {
        let end = (next + BATCH).min(walked.len());
        let batch = &walked[next..end];
        let exact = parallel_map(batch, |&(_, k, centre)| {
            let at = if centre { centroid(k) } else { source.point(k) };
            target.nearest(at)
        });
        for (&(walked_distance, k, centre), s) in batch.iter().zip(exact) {
            // A capped search may find a farther triangle than the walk did: both are upper
            // bounds, the nearer is kept.
            let f = if s.distance <= walked_distance {
                Found {
                    distance: s.distance,
                    nearest: s.nearest,
                    exact: true,
                }
            } else {
                let mut f = if centre {
                    centres[k as usize].unwrap_or(Found::ON_TARGET)
                } else {
                    vertices[k as usize]
                };
                f.exact = true;
                f
            };
            lb = lb.max(f.distance);
            if centre {
                centres[k as usize] = Some(f);
            } else {
                vertices[k as usize] = f;
            }
        }
        next = end;
    }
    lb
}
