//! LOD chains generated from one mesh (feature `lod_chain`): meshoptimizer's attribute-aware
//! simplifier makes each level (its sloppy mode takes over when the regular one stalls), every
//! level comes with an **upper bound** of its two-sided Hausdorff distance from the original
//! (object space, measured, not meshoptimizer's quadric estimate), and [`LodChain::lod_group`]
//! turns those bounds into switch distances that keep the level on screen within a pixel error.
//!
//! ```
//! use lodkit::lod_chain::{LodChain, LodChainDescriptor, MeshData, PixelErrorCamera};
//! # let (positions, indices) = lodkit::lod_chain::uv_sphere(24, 48);
//! let chain = LodChain::build(
//!     &MeshData { positions: &positions, indices: &indices, ..Default::default() },
//!     &LodChainDescriptor { levels: 4, ..Default::default() },
//! )?;
//! for level in chain.levels() {
//!     println!("{} triangles, within {} of the original", level.triangles(), level.error());
//! }
//! let group = chain.lod_group(&PixelErrorCamera { pixel_error: 1.0, ..Default::default() })?;
//! assert_eq!(group.levels().len(), chain.levels().len());
//! # Ok::<(), lodkit::lod_chain::LodChainError>(())
//! ```
//!
//! See `docs/lod-chain.md` for the guide and `docs/selection.md` for the switch-distance
//! derivation.

mod build;
mod hausdorff;
mod switch;
#[cfg(test)]
mod tests;

pub use switch::{
    PixelErrorCamera, hide_distance, pixel_error_group, projected_error, suggested_hysteresis,
    switch_distances,
};

use crate::select::{LodError, LodGroup};

/// The mesh a chain is built from: an indexed triangle list and optional per-vertex attributes.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshData<'a> {
    /// Vertex positions (object space).
    pub positions: &'a [[f32; 3]],
    /// Triangle list, three indices a triangle.
    pub indices: &'a [u32],
    /// Per-vertex normals (weighed by [`LodChainDescriptor::normal_weight`]), if any.
    pub normals: Option<&'a [[f32; 3]]>,
    /// Per-vertex texture coordinates (weighed by [`LodChainDescriptor::uv_weight`]), if any.
    pub uvs: Option<&'a [[f32; 2]]>,
}

/// What [`LodChain::build`] does with a mesh it cannot simplify at all.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SmallMesh {
    /// [`LodChainError::TooSmall`].
    #[default]
    Error,
    /// A chain of one level, the mesh itself.
    SingleLevel,
}

/// How a chain is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodChainDescriptor {
    /// Levels wanted, LOD0 (the mesh itself) included (default 5; 1..=255). The chain stops
    /// earlier when a level cannot be made smaller.
    pub levels: usize,
    /// Triangle share of level i+1 relative to level i (default 0.5: level i aims at
    /// `triangles x ratio^i`); in (0, 1).
    pub ratio: f32,
    /// The reference camera and pixel error the chain is meant for; [`LodChain::lod_group`]
    /// takes its own, this one is what [`LodChain::default_group`] uses.
    pub camera: PixelErrorCamera,
    /// Weight of normal differences against position error in the regular simplifier (default
    /// 0.5, as meshoptimizer's gltfpack uses).
    pub normal_weight: f32,
    /// Weight of UV differences (default 0.5).
    pub uv_weight: f32,
    /// Keep the vertices on the mesh's open border where they are (meshoptimizer's
    /// `LockBorder`; default false): neighbouring chunks stay stitched.
    pub lock_border: bool,
    /// Keep every vertex on an attribute seam (a position shared by several vertices: UV
    /// seams, hard edges) where it is (default false; the regular simplifier already keeps
    /// seams from tearing).
    pub lock_seams: bool,
    /// Use meshoptimizer's sloppy simplifier for a level the regular one cannot bring within
    /// 25 % of its target, and for every level after (default true).
    pub sloppy_fallback: bool,
    /// Largest meshoptimizer error (relative to the mesh's extent) a level may reach (default
    /// 1: no limit, the triangle target decides).
    pub max_relative_error: f32,
    /// Slack the Hausdorff bound may keep above the largest distance it found, relative
    /// (default 0.05). Smaller is tighter and slower.
    pub bound_tolerance: f32,
    /// A mesh that cannot be simplified (default [`SmallMesh::Error`]).
    pub small_mesh: SmallMesh,
}

impl Default for LodChainDescriptor {
    fn default() -> Self {
        Self {
            levels: 5,
            ratio: 0.5,
            camera: PixelErrorCamera::default(),
            normal_weight: 0.5,
            uv_weight: 0.5,
            lock_border: false,
            lock_seams: false,
            sloppy_fallback: true,
            max_relative_error: 1.0,
            bound_tolerance: 0.05,
            small_mesh: SmallMesh::Error,
        }
    }
}

/// What is wrong with a mesh, a descriptor or a camera.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LodChainError {
    /// An index list with no triangle.
    #[error("the mesh has no triangles")]
    NoTriangles,
    /// An index count that is not a multiple of 3.
    #[error("{0} indices is not a whole number of triangles")]
    PartialTriangle(usize),
    /// An index past the last vertex.
    #[error("triangle {triangle}: index {index} is out of range ({vertices} vertices)")]
    BadIndex {
        /// Which triangle.
        triangle: usize,
        /// The index.
        index: u32,
        /// How many vertices there are.
        vertices: usize,
    },
    /// A NaN or infinite coordinate.
    #[error("vertex {vertex}: {attribute} is not finite ({value:?})")]
    NotFinite {
        /// `position`, `normal` or `uv`.
        attribute: &'static str,
        /// Which vertex.
        vertex: usize,
        /// Its value.
        value: Vec<f32>,
    },
    /// An attribute with another number of entries than the positions.
    #[error("{attribute} has {got} entries, positions have {want}")]
    AttributeLength {
        /// `normal` or `uv`.
        attribute: &'static str,
        /// Its length.
        got: usize,
        /// The number of positions.
        want: usize,
    },
    /// Every triangle has zero area (or every vertex the same position).
    #[error("the mesh is degenerate: all {triangles} triangles have zero area")]
    Degenerate {
        /// How many triangles there are.
        triangles: usize,
    },
    /// No level could be made ([`SmallMesh::Error`]).
    #[error("the mesh ({triangles} triangles) is too small to simplify")]
    TooSmall {
        /// How many triangles there are.
        triangles: usize,
    },
    /// A descriptor field out of range.
    #[error("LodChainDescriptor::{field} = {value} is out of range ({expected})")]
    BadDescriptor {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A camera field out of range.
    #[error("PixelErrorCamera::{field} = {value} is out of range")]
    BadCamera {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f32,
    },
    /// A level error that is negative or not finite.
    #[error("level {level}: error {error} must be finite and >= 0")]
    BadError {
        /// Which level.
        level: usize,
        /// The error.
        error: f32,
    },
    /// A bounding radius that is negative or not finite.
    #[error("radius {0} must be finite and >= 0")]
    BadRadius(f32),
    /// An impostor at the end of the chain would never be shown: its picture is within the
    /// pixel error only from `from`, and the object is hidden beyond `hidden` (view-normalized
    /// distances).
    #[error(
        "the impostor would never be shown: its picture is within the pixel error only from {from:.3} (view-normalized), and the object is hidden beyond {hidden:.3}"
    )]
    ImpostorNeverShown {
        /// Where its picture is within the pixel error from.
        from: f32,
        /// The hide distance.
        hidden: f32,
    },
    /// The group the distances make is invalid.
    #[error(transparent)]
    Lod(#[from] LodError),
}

/// Which simplifier made a level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simplifier {
    /// LOD0: the mesh itself.
    Original,
    /// meshoptimizer's attribute-aware edge collapse (`meshopt_simplifyWithAttributes`).
    Regular,
    /// meshoptimizer's sloppy vertex clustering (`meshopt_simplifySloppy`).
    Sloppy,
}

/// One level of a chain: a compact vertex buffer (the original's vertices it uses) and indices.
#[derive(Clone, Debug, PartialEq)]
pub struct LodChainLevel {
    positions: Vec<[f32; 3]>,
    normals: Option<Vec<[f32; 3]>>,
    uvs: Option<Vec<[f32; 2]>>,
    indices: Vec<u32>,
    source_vertices: Vec<u32>,
    error: f32,
    simplifier: Simplifier,
    simplifier_error: f32,
    error_capped: bool,
    time: std::time::Duration,
}

impl LodChainLevel {
    /// Vertex positions (the original's, unmoved).
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }
    /// Normals, when the mesh had them.
    pub fn normals(&self) -> Option<&[[f32; 3]]> {
        self.normals.as_deref()
    }
    /// Texture coordinates, when the mesh had them.
    pub fn uvs(&self) -> Option<&[[f32; 2]]> {
        self.uvs.as_deref()
    }
    /// Triangle list into this level's vertices (ordered for the vertex cache).
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }
    /// For each vertex of this level, the original vertex it is (to carry other attributes).
    pub fn source_vertices(&self) -> &[u32] {
        &self.source_vertices
    }
    /// Number of triangles.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
    /// Upper bound of the two-sided Hausdorff distance between this level's surface and the
    /// original's, object units (0 for LOD0).
    pub fn error(&self) -> f32 {
        self.error
    }
    /// Whether the bound's work was capped on degenerate geometry (long slivers spanning the
    /// mesh, where finding distances exactly would cost without limit): [`error`](Self::error)
    /// is then still an upper bound, a looser one. False on well-shaped meshes.
    pub fn error_capped(&self) -> bool {
        self.error_capped
    }
    /// Which simplifier made this level.
    pub fn simplifier(&self) -> Simplifier {
        self.simplifier
    }
    /// meshoptimizer's own error estimate for the step from the previous level, in object units
    /// (a quadric estimate, not a bound; for comparison only).
    pub fn simplifier_error(&self) -> f32 {
        self.simplifier_error
    }
    /// Time taken to make this level: simplifying, measuring its bound and compacting it (wall
    /// clock; a level's bound runs while the next level is simplified, so the levels' times
    /// overlap).
    pub fn time(&self) -> std::time::Duration {
        self.time
    }
}

/// A sphere around the mesh: the centre of its bounding box and the largest distance from it to
/// a vertex a triangle uses. Selection distances are measured to this centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    /// Object-space centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
}

/// Levels of detail made from one mesh, finest first, each with its error bound.
#[derive(Clone, Debug, PartialEq)]
pub struct LodChain {
    levels: Vec<LodChainLevel>,
    sphere: BoundingSphere,
    camera: PixelErrorCamera,
}

impl LodChain {
    /// Builds the chain of `mesh` (see [`LodChainDescriptor`]). Errors name what is wrong with
    /// the mesh or the descriptor; nothing panics on bad input.
    pub fn build(mesh: &MeshData, descriptor: &LodChainDescriptor) -> Result<Self, LodChainError> {
        build::build(mesh, descriptor)
    }

    /// The levels, LOD0 (the mesh itself, compacted) first.
    pub fn levels(&self) -> &[LodChainLevel] {
        &self.levels
    }

    /// Each level's error bound, in order.
    pub fn errors(&self) -> Vec<f32> {
        self.levels.iter().map(|l| l.error).collect()
    }

    /// The sphere switch distances account for; select with the distance to its centre.
    pub fn bounding_sphere(&self) -> BoundingSphere {
        self.sphere
    }

    /// View-normalized switch distances for `camera` ([`switch_distances`]).
    pub fn switch_distances(&self, camera: &PixelErrorCamera) -> Result<Vec<f32>, LodChainError> {
        switch_distances(&self.errors(), self.sphere.radius, camera)
    }

    /// A group whose levels keep the projected error within `camera.pixel_error` pixels and
    /// which is hidden where the whole object covers less than that ([`pixel_error_group`]).
    pub fn lod_group(&self, camera: &PixelErrorCamera) -> Result<LodGroup, LodChainError> {
        pixel_error_group(&self.errors(), self.sphere.radius, camera)
    }

    /// [`Self::lod_group`] for the descriptor's camera.
    pub fn default_group(&self) -> Result<LodGroup, LodChainError> {
        self.lod_group(&self.camera)
    }

    /// A hysteresis to select with ([`suggested_hysteresis`]).
    pub fn suggested_hysteresis(&self, camera: &PixelErrorCamera) -> Result<f32, LodChainError> {
        suggested_hysteresis(&self.errors(), self.sphere.radius, camera)
    }

    /// The chain ending in the impostor of `layout` (baked from this mesh): the mesh levels that
    /// switch in before the impostor is within `camera.pixel_error`, then the impostor, as one
    /// group hidden where [`Self::lod_group`] is ([`impostor_placement`](crate::impostor::impostor_placement)
    /// says which levels give way). The impostor is level [`ImpostorPlacement::mesh_levels`](crate::impostor::ImpostorPlacement)
    /// of the group.
    pub fn impostor_group(
        &self,
        layout: &crate::impostor::ImpostorLayout,
        camera: &PixelErrorCamera,
    ) -> Result<(LodGroup, crate::impostor::ImpostorPlacement), LodChainError> {
        let distances = self.switch_distances(camera)?;
        let hidden = self.max_distance(camera)?;
        let own = crate::impostor::impostor_switch_distance(layout, camera)?;
        let placement = crate::impostor::impostor_placement(&distances, hidden, own)?;
        let levels = distances[..placement.mesh_levels]
            .iter()
            .copied()
            .chain(std::iter::once(placement.distance))
            .enumerate()
            .map(|(i, distance)| crate::select::LodLevel {
                distance,
                mesh: if i < placement.mesh_levels {
                    format!("lod{i}")
                } else {
                    "impostor".to_owned()
                },
            });
        let group = LodGroup::new(levels)?.with_max_distance(hidden)?;
        Ok((group, placement))
    }

    /// The max distance [`Self::lod_group`] sets ([`hide_distance`]).
    pub fn max_distance(&self, camera: &PixelErrorCamera) -> Result<f32, LodChainError> {
        hide_distance(self.sphere.radius, camera)
    }
}

/// A unit UV sphere as positions and indices (`rings` x `segments` quads, a seam of duplicated
/// vertices at u = 0), for examples and tests. Duplicated vertices (the seam's, each pole's) hold
/// bit-identical positions, so a simplifier that welds by position sees a closed surface.
pub fn uv_sphere(rings: u32, segments: u32) -> (Vec<[f32; 3]>, Vec<u32>) {
    use std::f32::consts::{PI, TAU};
    let (rings, segments) = (rings.max(2), segments.max(3));
    let mut positions = Vec::new();
    for r in 0..=rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = TAU * (s % segments) as f32 / segments as f32;
            positions.push(match r {
                0 => [0.0, 1.0, 0.0],
                r if r == rings => [0.0, -1.0, 0.0],
                _ => [
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    -theta.sin() * phi.sin(),
                ],
            });
        }
    }
    let row = segments + 1;
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            if r > 0 {
                indices.extend([a, b, a + 1]);
            }
            if r + 1 < rings {
                indices.extend([a + 1, b, b + 1]);
            }
        }
    }
    (positions, indices)
}
