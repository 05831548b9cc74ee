//! The older levels' silhouettes for the combine (`OlderCoverage::Silhouette`): each level
//! mesh's [`Surface`] (lodkit::silhouette: positions welded, edges linked to their twins), built
//! once from the Bevy `Mesh` and kept until the mesh changes; each frame the plugin asks it for
//! the silhouette under this frame's camera and the group's transform, which the combine's data
//! holds binned by pixel row (`lodkit::combine_coverage::CombineData`) and tests at each pixel
//! against its row's segments (`lodkit::silhouette::silhouette_covers`).

use std::sync::Arc;

use bevy::mesh::{Indices, Mesh, PrimitiveTopology, VertexAttributeValues};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use lodkit::silhouette::{Segment, SilhouetteError, Surface};

use super::rects::to_lodkit;

/// Why a level has no silhouette here (the older-level depth pass then draws it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NoSilhouette {
    /// Not a triangle list, or no positions readable on the CPU (not loaded yet, or a mesh
    /// whose `RenderAssetUsages` leave it in the render world only).
    NoTriangles,
    /// lodkit found none: an open or badly wound mesh, or one reaching behind the camera.
    Surface(SilhouetteError),
}

impl From<SilhouetteError> for NoSilhouette {
    fn from(error: SilhouetteError) -> Self {
        Self::Surface(error)
    }
}

/// The surface of a Bevy `mesh` (a triangle list with `Float32x3` positions).
pub fn surface_of(mesh: &Mesh) -> Result<Surface, NoSilhouette> {
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(NoSilhouette::NoTriangles);
    }
    let Some(VertexAttributeValues::Float32x3(positions)) =
        mesh.attribute(Mesh::ATTRIBUTE_POSITION)
    else {
        return Err(NoSilhouette::NoTriangles);
    };
    let indices: Option<Vec<u32>> = match mesh.indices() {
        Some(Indices::U16(i)) => Some(i.iter().map(|&i| u32::from(i)).collect()),
        Some(Indices::U32(i)) => Some(i.clone()),
        None => None,
    };
    Ok(Surface::new(positions, indices.as_deref())?)
}

/// Each level mesh's [`Surface`] (or why it has none), built the first time a silhouette of it
/// is needed and forgotten when the mesh changes or goes.
#[derive(Resource, Default)]
pub struct Surfaces(HashMap<AssetId<Mesh>, Result<Arc<Surface>, NoSilhouette>>);

impl Surfaces {
    /// The surface of mesh `id`; `NoTriangles` while the mesh is not in `meshes` (not loaded, or
    /// kept in the render world only), without remembering that.
    pub fn get(
        &mut self,
        id: AssetId<Mesh>,
        meshes: &Assets<Mesh>,
    ) -> Result<Arc<Surface>, NoSilhouette> {
        if let Some(surface) = self.0.get(&id) {
            return surface.clone();
        }
        let mesh = meshes.get(id).ok_or(NoSilhouette::NoTriangles)?;
        let surface = surface_of(mesh).map(Arc::new);
        self.0.insert(id, surface.clone());
        surface
    }
}

/// What [`outline`] needs of the frame: the camera and the group's transform.
pub struct OutlineView {
    /// The camera's clip_from_world.
    pub clip_from_world: Mat4,
    /// The camera's position (world).
    pub eye: Vec3,
    /// The group's world_from_local.
    pub model: Mat4,
    /// The target's size in pixels.
    pub size: UVec2,
}

/// The silhouette (segments in pixels) of mesh `id` under `view`, and the triangles whose facing
/// it tested.
pub fn outline(
    surfaces: &mut Surfaces,
    meshes: &Assets<Mesh>,
    id: AssetId<Mesh>,
    view: &OutlineView,
) -> Result<(Vec<Segment>, u64), NoSilhouette> {
    let surface = surfaces.get(id, meshes)?;
    let eye = view.model.inverse().transform_point3(view.eye);
    let segments = surface.silhouette(
        to_lodkit(view.clip_from_world * view.model),
        glam::Vec3::from_array(eye.to_array()),
        (view.size.x, view.size.y),
        view.model.determinant() > 0.0,
    )?;
    Ok((segments, surface.triangles() as u64))
}

/// Forgets the surfaces of meshes that changed or went.
pub fn forget_changed_meshes(
    mut surfaces: ResMut<Surfaces>,
    mut events: MessageReader<AssetEvent<Mesh>>,
) {
    for event in events.read() {
        if let AssetEvent::Modified { id }
        | AssetEvent::Removed { id }
        | AssetEvent::Unused { id } = event
        {
            surfaces.0.remove(id);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::asset::RenderAssetUsages;

    /// Bevy's own meshes (seams and poles included) are closed surfaces; a plane is open, a line
    /// list has no triangles, and a mesh without positions none either.
    #[test]
    fn bevy_meshes_become_surfaces_or_say_why_not() {
        for mesh in [
            Cuboid::new(1.0, 1.4, 0.8).mesh().build(),
            Sphere::new(0.9).mesh().uv(9, 6),
            Sphere::new(0.9).mesh().uv(48, 24),
            Sphere::new(0.9).mesh().ico(3).unwrap(),
        ] {
            let surface = surface_of(&mesh).unwrap();
            assert!(surface.triangles() > 0);
        }
        let plane = Plane3d::default().mesh().size(1.0, 1.0).build();
        assert!(matches!(
            surface_of(&plane),
            Err(NoSilhouette::Surface(SilhouetteError::NotClosed { .. }))
        ));
        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default())
            .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[0.0f32; 3]; 2]);
        assert_eq!(surface_of(&lines).err(), Some(NoSilhouette::NoTriangles));
        let empty = Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        );
        assert_eq!(surface_of(&empty).err(), Some(NoSilhouette::NoTriangles));
    }
}
