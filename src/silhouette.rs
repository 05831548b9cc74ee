//! The silhouette of a mesh as a camera sees it, for coverage without rasterizing the mesh
//! (frame-sequential LOD's exact coverage of the level not drawn this frame; Scherzer & Wimmer
//! 2008, sec. 4, estimate it from the older frame). A closed mesh covers a point of the screen
//! exactly where one of its front faces does; the boundary of that region is made of the edges
//! between a face turned to the camera and one turned away. [`Surface::silhouette`] finds those
//! edges, projected to pixels and oriented the same way round their front face, and the winding
//! number of the segments around a pixel center ([`winding`], the shader module
//! `lodkit::silhouette` per segment) is not 0 exactly where the mesh covers it.
//!
//! ```
//! # use lodkit::silhouette::{Surface, winding};
//! # use glam::{Mat4, Vec2, Vec3};
//! // A tetrahedron seen from the front, on a 64x64 target.
//! let positions = [[0.0, 1.0, 0.0], [-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [0.0, -1.0, -1.0]];
//! let indices = [0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2];
//! let surface = Surface::new(&positions, Some(&indices)).unwrap();
//! let eye = Vec3::new(0.0, 0.0, 4.0);
//! let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
//! let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0);
//! let segments = surface.silhouette(proj * view, eye, (64, 64), true).unwrap();
//! assert_ne!(winding(&segments, Vec2::new(32.5, 32.5)), 0); // the middle is covered
//! assert_eq!(winding(&segments, Vec2::new(0.5, 0.5)), 0); // a corner is not
//! ```

use std::collections::HashMap;

use glam::{Mat4, Vec2, Vec3};
use thiserror::Error;

mod coverage;
mod mask;
pub use coverage::{
    SILHOUETTE_ON, SILHOUETTE_TIE, bin_silhouette, convex_hull, hull_triangles, polygon_area,
    silhouette_covers, silhouette_hull, silhouette_texel,
};
pub use mask::{MaskOutline, MaskOutlineError};

/// One silhouette segment in pixels (x right, y down, pixel centers at `i + 0.5`): from
/// `(x0, y0)` to `(x1, y1)`, its front face on the same side for every segment of a mesh.
pub type Segment = [f32; 4];

/// Why a mesh has no silhouette (coverage must then come from rasterizing it).
#[derive(Clone, Copy, Debug, Error, PartialEq)]
pub enum SilhouetteError {
    /// An index past the end of the positions.
    #[error("index {index} of triangle {triangle} is past the {vertices} positions")]
    IndexOutOfRange {
        /// The triangle (its first index is at `3 * triangle`).
        triangle: usize,
        /// The index.
        index: u32,
        /// How many positions there are.
        vertices: usize,
    },
    /// An edge with no face on its other side: coverage is then not bounded by the silhouette.
    #[error(
        "the mesh is not closed: the edge from {from:?} to {to:?} has no face on its other side"
    )]
    NotClosed {
        /// Where the edge starts.
        from: [f32; 3],
        /// Where it ends.
        to: [f32; 3],
    },
    /// An edge two faces run along in the same direction (faces wound inconsistently, or more
    /// than two faces at an edge).
    #[error("two faces run along the edge from {from:?} to {to:?} the same way")]
    NotManifold {
        /// Where the edge starts.
        from: [f32; 3],
        /// Where it ends.
        to: [f32; 3],
    },
    /// A silhouette vertex at or behind the camera plane: its projection is undefined.
    #[error("a silhouette vertex lies at or behind the camera plane")]
    BehindCamera,
}

/// A mesh's surface as its silhouettes need it: positions welded (one vertex per position),
/// triangles, and for each directed edge the edge running the other way on the face next to it.
/// Built once per mesh; [`Surface::silhouette`] then costs one facing test per triangle.
#[derive(Clone, Debug)]
pub struct Surface {
    points: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Per directed edge `3 * triangle + k` (from corner k to corner k + 1): its twin's index.
    twins: Vec<u32>,
}

impl Surface {
    /// The surface of the triangle list `positions` / `indices` (None: consecutive triples of
    /// positions; a trailing partial triangle is ignored). Positions within a millionth of the
    /// mesh's extent of each other are one vertex, so the seams of texture coordinates or
    /// normals, whose copies of a vertex are often computed apart (a sphere's `sin(2 pi)`), do
    /// not open the mesh; degenerate triangles are left out.
    pub fn new(positions: &[[f32; 3]], indices: Option<&[u32]>) -> Result<Self, SilhouetteError> {
        let (welded, points) = weld(positions);
        let all: Vec<u32>;
        let indices = match indices {
            Some(indices) => indices,
            None => {
                all = (0..positions.len() as u32).collect();
                &all
            }
        };
        let mut triangles = Vec::new();
        for (t, triangle) in indices.chunks_exact(3).enumerate() {
            let mut v = [0u32; 3];
            for (slot, &i) in v.iter_mut().zip(triangle) {
                *slot = *welded
                    .get(i as usize)
                    .ok_or(SilhouetteError::IndexOutOfRange {
                        triangle: t,
                        index: i,
                        vertices: positions.len(),
                    })?;
            }
            if v[0] != v[1] && v[1] != v[2] && v[2] != v[0] {
                triangles.push(v);
            }
        }
        let at = |i: u32| points[i as usize].to_array();
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for (t, v) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                if edges.insert((a, b), (3 * t + k) as u32).is_some() {
                    return Err(SilhouetteError::NotManifold {
                        from: at(a),
                        to: at(b),
                    });
                }
            }
        }
        let mut twins = Vec::with_capacity(3 * triangles.len());
        for v in &triangles {
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                twins.push(*edges.get(&(b, a)).ok_or(SilhouetteError::NotClosed {
                    from: at(a),
                    to: at(b),
                })?);
            }
        }
        Ok(Self {
            points,
            triangles,
            twins,
        })
    }

    /// Its triangles (degenerate ones left out).
    pub fn triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The silhouette under `clip_from_local` (a camera's clip_from_world times the mesh's
    /// world_from_local; NDC x and y in [-1, 1], y up) seen from `eye` (the camera's position in
    /// the mesh's space), on a target of `size` pixels. `front_ccw`: whether front faces wind
    /// counterclockwise in the mesh's space (false under a mirroring transform). Empty from
    /// inside the mesh (every face turned away: nothing covered).
    pub fn silhouette(
        &self,
        clip_from_local: Mat4,
        eye: Vec3,
        size: (u32, u32),
        front_ccw: bool,
    ) -> Result<Vec<Segment>, SilhouetteError> {
        self.outline(&self.points, clip_from_local, eye, size, front_ccw)
    }

    /// [`silhouette`](Self::silhouette) of the mesh with each vertex moved by `displace`
    /// (object space in, object space out): a vertex animation the host can evaluate, such as
    /// wind sway, keeps its exact coverage. Facing is tested on the moved triangles.
    pub fn silhouette_displaced(
        &self,
        clip_from_local: Mat4,
        eye: Vec3,
        size: (u32, u32),
        front_ccw: bool,
        displace: impl Fn(Vec3) -> Vec3,
    ) -> Result<Vec<Segment>, SilhouetteError> {
        let moved: Vec<Vec3> = self.points.iter().map(|&p| displace(p)).collect();
        self.outline(&moved, clip_from_local, eye, size, front_ccw)
    }

    /// The silhouette with the welded vertices at `points`.
    fn outline(
        &self,
        points: &[Vec3],
        clip_from_local: Mat4,
        eye: Vec3,
        size: (u32, u32),
        front_ccw: bool,
    ) -> Result<Vec<Segment>, SilhouetteError> {
        let front: Vec<bool> = self
            .triangles
            .iter()
            .map(|v| {
                let [a, b, c] = v.map(|i| points[i as usize]);
                ((b - a).cross(c - a).dot(eye - a) > 0.0) == front_ccw
            })
            .collect();
        let project = |id: u32| to_pixels(clip_from_local, points[id as usize], size);
        let mut segments = Vec::new();
        for (e, &twin) in self.twins.iter().enumerate() {
            if front[e / 3] && !front[twin as usize / 3] {
                let v = self.triangles[e / 3];
                let (Some(a), Some(b)) = (project(v[e % 3]), project(v[(e + 1) % 3])) else {
                    return Err(SilhouetteError::BehindCamera);
                };
                segments.push([a.x, a.y, b.x, b.y]);
            }
        }
        Ok(segments)
    }
}

/// Pixel position (x right, y down) of local point `p` under `clip_from_local` on a target of
/// `size` pixels; `None` at or behind the camera plane (w <= 1e-6), where it has none.
fn to_pixels(clip_from_local: Mat4, p: Vec3, size: (u32, u32)) -> Option<Vec2> {
    let clip = clip_from_local * p.extend(1.0);
    (clip.w > 1e-6).then(|| {
        let ndc = clip.truncate().truncate() / clip.w;
        let half = Vec2::new(size.0 as f32, size.1 as f32) / 2.0;
        Vec2::new((ndc.x + 1.0) * half.x, (1.0 - ndc.y) * half.y)
    })
}

/// One id per position (and the positions by id), positions within a millionth of the mesh's
/// extent of each other (on every axis) taken as one.
fn weld(positions: &[[f32; 3]]) -> (Vec<u32>, Vec<Vec3>) {
    let points: Vec<Vec3> = positions.iter().map(|&p| Vec3::from_array(p)).collect();
    let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
        (lo.min(p), hi.max(p))
    });
    let hair = ((hi - lo).max_element() * 1e-6).max(f32::MIN_POSITIVE);
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].x.total_cmp(&points[b].x));
    let mut id = vec![u32::MAX; points.len()];
    let mut welded = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        if id[i] != u32::MAX {
            continue;
        }
        id[i] = welded.len() as u32;
        for &j in order[k + 1..]
            .iter()
            .take_while(|&&j| points[j].x - points[i].x <= hair)
        {
            if id[j] == u32::MAX && (points[j] - points[i]).abs().max_element() <= hair {
                id[j] = id[i];
            }
        }
        welded.push(points[i]);
    }
    (id, welded)
}

/// The winding number contribution of the segment from `a` to `b` around `p` (Rust twin of the
/// shader function of the same name): +1 where it crosses p's horizontal line upwards with p on
/// its left, -1 downwards with p on its right, else 0.
pub fn silhouette_crossing(p: Vec2, a: Vec2, b: Vec2) -> i32 {
    let side = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    if a.y <= p.y {
        i32::from(b.y > p.y && side > 0.0)
    } else {
        -i32::from(b.y <= p.y && side < 0.0)
    }
}

/// Distance from `p` to the segment from `a` to `b` (Rust twin of the shader function of the
/// same name).
pub fn silhouette_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let along = ((p - a).dot(ab) / ab.dot(ab).max(1.0e-12)).clamp(0.0, 1.0);
    (p - (a + along * ab)).length()
}

/// The winding number of `segments` around `point` (pixels): not 0 where the mesh they outline
/// covers the point.
pub fn winding(segments: &[Segment], point: Vec2) -> i32 {
    segments
        .iter()
        .map(|s| silhouette_crossing(point, Vec2::new(s[0], s[1]), Vec2::new(s[2], s[3])))
        .sum()
}

#[cfg(test)]
#[path = "silhouette_tests.rs"]
mod tests;
