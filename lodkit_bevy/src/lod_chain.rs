//! LOD levels built from one Bevy [`Mesh`]: [`lodkit::lod_chain`] simplifies it with
//! meshoptimizer into a chain of levels, each with a bound of its distance from the original,
//! and turns those errors into the switch distances that keep the shown level within a pixel
//! error of the original ([`PixelErrorCamera`]). [`MeshLodChain`] hands the levels back as
//! Bevy meshes, as [`LodLevels`] and as a [`FrameSequentialGroup`], so a group goes from one
//! mesh to smooth, error-bounded LOD in a few lines:
//!
//! ```no_run
//! # use bevy::prelude::*;
//! use lodkit_bevy::lod_chain::{LodChainDescriptor, MeshLodChain, PixelErrorCamera};
//! # fn spawn(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>,
//! #          material: Handle<StandardMaterial>, mesh: Mesh) -> Result<(), BevyError> {
//! let chain = MeshLodChain::build(&mesh, &LodChainDescriptor::default())?;
//! let camera = PixelErrorCamera { fov_y: std::f32::consts::FRAC_PI_4, viewport_height: 1080.0, ..default() };
//! let levels = chain.lod_levels(&mut meshes, |_| material.clone());
//! commands.spawn((levels, chain.group(&camera)?, Transform::default()));
//! # Ok(())
//! # }
//! ```
//!
//! Every vertex attribute of the mesh is carried to the levels (a level's vertices are a subset
//! of the mesh's, [`LodChainLevel::source_vertices`]); positions, normals (`ATTRIBUTE_NORMAL`)
//! and the first UV set (`ATTRIBUTE_UV_0`) steer the simplification. The group's distances are
//! view-normalized, as [`LodGroup`] is: the camera's LOD bias and field of view keep working.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, MeshVertexAttribute, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use lodkit::lod_chain::MeshData;
pub use lodkit::lod_chain::{
    LodChain, LodChainDescriptor, LodChainError, LodChainLevel, PixelErrorCamera, SmallMesh,
};
use lodkit::select::LodGroup;

use crate::frame_sequential::levels::{FrameSequentialGroup, LevelMaterial, LodLevel, LodLevels};

/// Why a mesh could not be made into a chain.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshLodChainError {
    /// Only triangle lists are simplified.
    #[error("the mesh is a {0:?}, not a triangle list")]
    NotTriangles(PrimitiveTopology),
    /// The build stopped on a panic (a bug in lodkit or a dependency: please report it).
    #[error("building the chain panicked (a bug: please report it)")]
    Panicked,
    /// The mesh's data has gone to the render world (`RenderAssetUsages::RENDER_WORLD` only).
    #[error("the mesh's vertex data is not in the main world (its asset usage lacks MAIN_WORLD)")]
    Extracted,
    /// No `ATTRIBUTE_POSITION`.
    #[error("the mesh has no positions")]
    NoPositions,
    /// An attribute the simplifier reads in another format than it takes (Bevy's
    /// `insert_attribute` already refuses a position, normal or UV in another format).
    #[error("{attribute} is {found}, the chain reads {expected}")]
    Format {
        /// The attribute's name.
        attribute: &'static str,
        /// The format found.
        found: &'static str,
        /// The format read.
        expected: &'static str,
    },
    /// An attribute with another number of entries than the positions.
    #[error("{attribute} has {got} entries, positions have {want}")]
    AttributeLength {
        /// The attribute's name.
        attribute: &'static str,
        /// Its length.
        got: usize,
        /// The number of positions.
        want: usize,
    },
    /// What the chain says of the mesh, the descriptor or the camera.
    #[error(transparent)]
    Chain(#[from] LodChainError),
}

/// A mesh's LOD chain with its levels as Bevy meshes, finest (the mesh itself) first.
#[derive(Clone, Debug)]
pub struct MeshLodChain {
    chain: LodChain,
    meshes: Vec<Mesh>,
}

impl MeshLodChain {
    /// Builds the chain of `mesh` (a triangle list, indexed or not) as `descriptor` says.
    pub fn build(mesh: &Mesh, descriptor: &LodChainDescriptor) -> Result<Self, MeshLodChainError> {
        if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
            return Err(MeshLodChainError::NotTriangles(mesh.primitive_topology()));
        }
        let positions = match mesh.try_attribute_option(Mesh::ATTRIBUTE_POSITION) {
            Err(_) => return Err(MeshLodChainError::Extracted),
            Ok(None) => return Err(MeshLodChainError::NoPositions),
            Ok(Some(VertexAttributeValues::Float32x3(p))) => p,
            Ok(Some(other)) => return Err(format_error("position", other, "Float32x3")),
        };
        let normals = match attribute(mesh, Mesh::ATTRIBUTE_NORMAL, "normal", positions.len())? {
            None => None,
            Some(VertexAttributeValues::Float32x3(n)) => Some(n.as_slice()),
            Some(other) => return Err(format_error("normal", other, "Float32x3")),
        };
        let uvs = match attribute(mesh, Mesh::ATTRIBUTE_UV_0, "uv_0", positions.len())? {
            None => None,
            Some(VertexAttributeValues::Float32x2(uv)) => Some(uv.as_slice()),
            Some(other) => return Err(format_error("uv_0", other, "Float32x2")),
        };
        let indices: Vec<u32> = match mesh.try_indices_option() {
            Err(_) => return Err(MeshLodChainError::Extracted),
            Ok(Some(indices)) => indices.iter().map(|i| i as u32).collect(),
            // A triangle list without indices: three vertices a triangle.
            Ok(None) => (0..positions.len() as u32).collect(),
        };
        // Every attribute is gathered at the levels' vertices: each needs one entry a position.
        for (attribute, values) in mesh.attributes() {
            if values.len() != positions.len() {
                return Err(MeshLodChainError::AttributeLength {
                    attribute: attribute.name,
                    got: values.len(),
                    want: positions.len(),
                });
            }
        }
        let chain = LodChain::build(
            &MeshData {
                positions,
                indices: &indices,
                normals,
                uvs,
            },
            descriptor,
        )?;
        let meshes = chain
            .levels()
            .iter()
            .map(|level| level_mesh(mesh, level))
            .collect();
        Ok(Self { chain, meshes })
    }

    /// The chain: each level's triangles, error bound and simplifier, the bounding sphere.
    pub fn chain(&self) -> &LodChain {
        &self.chain
    }

    /// The levels as meshes, finest first, with every attribute of the mesh they came from.
    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// The levels added to `meshes`, each with the material `material(level)` gives (a
    /// `Handle<StandardMaterial>` or a `Handle<FrameSequentialMaterial>`).
    pub fn lod_levels<M: Into<LevelMaterial>>(
        &self,
        meshes: &mut Assets<Mesh>,
        mut material: impl FnMut(usize) -> M,
    ) -> LodLevels {
        LodLevels(
            self.meshes
                .iter()
                .enumerate()
                .map(|(i, mesh)| LodLevel::new(meshes.add(mesh.clone()), material(i)))
                .collect(),
        )
    }

    /// The group whose switch distances keep the shown level within `camera`'s pixel error of
    /// the mesh (view-normalized distances from the group's origin, the bounding sphere's
    /// radius accounted for: [`LodChain::lod_group`]).
    pub fn lod_group(&self, camera: &PixelErrorCamera) -> Result<LodGroup, MeshLodChainError> {
        Ok(self.chain.lod_group(camera)?)
    }

    /// [`lod_group`](Self::lod_group) as a frame-sequential group (bounds from the meshes).
    pub fn group(
        &self,
        camera: &PixelErrorCamera,
    ) -> Result<FrameSequentialGroup, MeshLodChainError> {
        Ok(FrameSequentialGroup::new(self.lod_group(camera)?))
    }
}

/// `id`'s values (called `name` in errors), checked to have one entry per position.
fn attribute<'m>(
    mesh: &'m Mesh,
    id: MeshVertexAttribute,
    name: &'static str,
    want: usize,
) -> Result<Option<&'m VertexAttributeValues>, MeshLodChainError> {
    let values = mesh
        .try_attribute_option(id)
        .map_err(|_| MeshLodChainError::Extracted)?;
    if let Some(v) = values
        && v.len() != want
    {
        return Err(MeshLodChainError::AttributeLength {
            attribute: name,
            got: v.len(),
            want,
        });
    }
    Ok(values)
}

/// The error of an attribute found in another format than the chain reads.
fn format_error(
    attribute: &'static str,
    found: &VertexAttributeValues,
    expected: &'static str,
) -> MeshLodChainError {
    MeshLodChainError::Format {
        attribute,
        found: found.enum_variant_name(),
        expected,
    }
}

/// One level as a mesh: every attribute of `source` gathered at the level's source vertices.
fn level_mesh(source: &Mesh, level: &LodChainLevel) -> Mesh {
    let picks = level.source_vertices();
    let mut mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    );
    // `build` read the attributes, so they are in the main world.
    for (attribute, values) in source.attributes() {
        mesh.insert_attribute(*attribute, gather(values, picks));
    }
    mesh.insert_indices(Indices::U32(level.indices().to_vec()));
    mesh
}

/// `values` at `picks`, in the same format.
fn gather(values: &VertexAttributeValues, picks: &[u32]) -> VertexAttributeValues {
    macro_rules! gather {
        ($($variant:ident),*) => {
            match values {
                $(VertexAttributeValues::$variant(v) => VertexAttributeValues::$variant(
                    picks.iter().map(|&i| v[i as usize]).collect(),
                ),)*
            }
        };
    }
    gather!(
        Uint8,
        Uint8x2,
        Uint8x4,
        Sint8,
        Sint8x2,
        Sint8x4,
        Unorm8,
        Unorm8x2,
        Unorm8x4,
        Snorm8,
        Snorm8x2,
        Snorm8x4,
        Uint16,
        Uint16x2,
        Uint16x4,
        Sint16,
        Sint16x2,
        Sint16x4,
        Unorm16,
        Unorm16x2,
        Unorm16x4,
        Snorm16,
        Snorm16x2,
        Snorm16x4,
        Float16,
        Float16x2,
        Float16x4,
        Float32,
        Float32x2,
        Float32x3,
        Float32x4,
        Uint32,
        Uint32x2,
        Uint32x3,
        Uint32x4,
        Sint32,
        Sint32x2,
        Sint32x3,
        Sint32x4,
        Float64,
        Float64x2,
        Float64x3,
        Float64x4,
        Unorm10_10_10_2,
        Unorm8x4Bgra
    )
}

#[cfg(test)]
mod tests {
    use crate::lod_chain::*;

    fn sphere() -> Mesh {
        Sphere::new(1.0).mesh().uv(48, 24)
    }

    #[test]
    fn a_sphere_becomes_levels_with_every_attribute_and_a_group() {
        let mesh = sphere();
        let source = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
            Some(VertexAttributeValues::Float32x3(p)) => p.clone(),
            _ => unreachable!("Bevy's sphere has Float32x3 positions"),
        };
        let chain = MeshLodChain::build(&mesh, &LodChainDescriptor::default()).unwrap();
        assert!(chain.meshes().len() >= 3, "{} levels", chain.meshes().len());
        let names = |m: &Mesh| {
            let mut n: Vec<_> = m.attributes().map(|(a, _)| a.name).collect();
            n.sort();
            n
        };
        let mut triangles = usize::MAX;
        for (m, level) in chain.meshes().iter().zip(chain.chain().levels()) {
            assert_eq!(names(m), names(&mesh), "every attribute is carried");
            let n = m.indices().unwrap().len() / 3;
            assert_eq!(n, level.triangles());
            assert!(
                n < triangles,
                "each level is coarser: {n} after {triangles}"
            );
            triangles = n;
            // A level's vertices are the source's own (the same positions, picked).
            let Some(VertexAttributeValues::Float32x3(p)) = m.attribute(Mesh::ATTRIBUTE_POSITION)
            else {
                panic!("positions stay Float32x3")
            };
            for (q, &i) in p.iter().zip(level.source_vertices()) {
                assert_eq!(*q, source[i as usize]);
            }
        }
        let camera = PixelErrorCamera::default();
        let group = chain.lod_group(&camera).unwrap();
        assert_eq!(group.levels().len(), chain.meshes().len());
    }

    #[test]
    fn a_non_indexed_mesh_is_indexed_and_bad_meshes_are_named() {
        let mut mesh = sphere();
        let indices: Vec<usize> = mesh.indices().unwrap().iter().collect();
        // The same triangles without an index buffer: three vertices each.
        let positions = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
            Some(VertexAttributeValues::Float32x3(p)) => p.clone(),
            _ => unreachable!(),
        };
        let flat: Vec<[f32; 3]> = indices.iter().map(|&i| positions[i]).collect();
        let unindexed = Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        )
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, flat);
        let chain = MeshLodChain::build(&unindexed, &LodChainDescriptor::default()).unwrap();
        assert_eq!(chain.meshes()[0].indices().unwrap().len(), indices.len());

        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default());
        assert_eq!(
            MeshLodChain::build(&lines, &LodChainDescriptor::default()).unwrap_err(),
            MeshLodChainError::NotTriangles(PrimitiveTopology::LineList)
        );
        mesh.insert_attribute(Mesh::ATTRIBUTE_UV_0, vec![[0.0f32; 2]; 3]);
        let err = MeshLodChain::build(&mesh, &LodChainDescriptor::default()).unwrap_err();
        assert!(
            matches!(err, MeshLodChainError::AttributeLength { got: 3, .. }),
            "{err}"
        );
        // An attribute the chain does not read, too short: named, not a panic.
        let mut mesh = sphere();
        mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, vec![[1.0f32; 4]; 5]);
        let err = MeshLodChain::build(&mesh, &LodChainDescriptor::default()).unwrap_err();
        assert!(
            matches!(
                err,
                MeshLodChainError::AttributeLength {
                    attribute: "Vertex_Color",
                    got: 5,
                    ..
                }
            ),
            "{err}"
        );
        let bad = Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        )
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[f32::NAN; 3]; 3]);
        let err = MeshLodChain::build(&bad, &LodChainDescriptor::default()).unwrap_err();
        assert!(matches!(err, MeshLodChainError::Chain(_)), "{err}");
    }
}
