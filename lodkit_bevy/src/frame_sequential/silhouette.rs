//! The silhouette of a level's mesh as this frame's camera sees it, for exact coverage without a
//! depth pass: the edges between the faces turned to the camera and those turned away, projected
//! to the screen and oriented the same way round every face they border. The winding number of
//! those segments around a pixel center is not 0 exactly where the mesh covers it (a closed mesh
//! covers a point where one of its front faces does), which is what rasterizing the mesh tells,
//! at the cost of a few dozen segments per level instead of the level's area in samples.

use bevy::mesh::{Indices, Mesh, PrimitiveTopology, VertexAttributeValues};
use std::sync::Arc;

use bevy::platform::collections::HashMap;

use bevy::prelude::*;

/// One silhouette segment in pixels (x right, y down, pixel centers at `i + 0.5`): from
/// `(x0, y0)` to `(x1, y1)`, its front face on the same side for every segment of a mesh.
pub type Segment = [f32; 4];

/// Why a mesh has no silhouette here (the combine then uses the older-level depth pass for it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoSilhouette {
    /// Not a triangle list, or no positions readable on the CPU (a mesh whose
    /// `RenderAssetUsages` leave it in the render world only).
    NoTriangles,
    /// An edge with no face on its other side, or more than two faces: coverage is then not
    /// bounded by the silhouette alone.
    NotClosed,
    /// A silhouette vertex at or behind the camera plane: its projection is undefined.
    BehindCamera,
}

/// A mesh's surface as its silhouettes need it: positions welded (one vertex per position),
/// triangles, and for each directed edge the edge running the other way on the face next to it.
/// Built once per mesh; [`Surface::silhouette`] then costs one facing test per triangle.
#[derive(Debug)]
pub struct Surface {
    points: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Per directed edge `3 * triangle + k` (from corner k to corner k + 1): its twin's index.
    twins: Vec<u32>,
}

impl Surface {
    /// The surface of `mesh`, if a closed triangle mesh with positions on the CPU. Vertices at
    /// the same position are one vertex (seams of texture coordinates or normals do not open
    /// the mesh); degenerate triangles are left out.
    pub fn new(mesh: &Mesh) -> Result<Self, NoSilhouette> {
        if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
            return Err(NoSilhouette::NoTriangles);
        }
        let Some(VertexAttributeValues::Float32x3(positions)) =
            mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            return Err(NoSilhouette::NoTriangles);
        };
        let indices: Vec<usize> = match mesh.indices() {
            Some(Indices::U16(i)) => i.iter().map(|&i| usize::from(i)).collect(),
            Some(Indices::U32(i)) => i.iter().map(|&i| i as usize).collect(),
            None => (0..positions.len()).collect(),
        };
        let (welded, points) = weld(positions);
        let mut triangles = Vec::new();
        for triangle in indices.chunks_exact(3) {
            let mut v = [0u32; 3];
            for (slot, &i) in v.iter_mut().zip(triangle) {
                *slot = *welded.get(i).ok_or(NoSilhouette::NoTriangles)?;
            }
            if v[0] != v[1] && v[1] != v[2] && v[2] != v[0] {
                triangles.push(v);
            }
        }
        let mut edges: HashMap<(u32, u32), u32> = HashMap::default();
        for (t, v) in triangles.iter().enumerate() {
            for k in 0..3 {
                if edges
                    .insert((v[k], v[(k + 1) % 3]), (3 * t + k) as u32)
                    .is_some()
                {
                    return Err(NoSilhouette::NotClosed);
                }
            }
        }
        let twins = triangles
            .iter()
            .flat_map(|v| (0..3).map(move |k| (v[(k + 1) % 3], v[k])))
            .map(|reverse| edges.get(&reverse).copied().ok_or(NoSilhouette::NotClosed))
            .collect::<Result<_, _>>()?;
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

    /// The silhouette under `clip_from_local` (the camera's clip_from_world times the level's
    /// world_from_local) seen from `eye` (the camera position in the mesh's space), on a target
    /// of `size` pixels. `front_ccw`: whether front faces wind counterclockwise in the mesh's
    /// space (false under a mirroring transform). Empty from inside the mesh (every face turned
    /// away: nothing covered).
    pub fn silhouette(
        &self,
        clip_from_local: Mat4,
        eye: Vec3,
        size: UVec2,
        front_ccw: bool,
    ) -> Result<Vec<Segment>, NoSilhouette> {
        let front: Vec<bool> = self
            .triangles
            .iter()
            .map(|v| {
                let [a, b, c] = v.map(|i| self.points[i as usize]);
                ((b - a).cross(c - a).dot(eye - a) > 0.0) == front_ccw
            })
            .collect();
        let half = size.as_vec2() / 2.0;
        let project = |id: u32| {
            let clip = clip_from_local * self.points[id as usize].extend(1.0);
            (clip.w > 1e-6).then(|| {
                let ndc = clip.truncate().truncate() / clip.w;
                Vec2::new((ndc.x + 1.0) * half.x, (1.0 - ndc.y) * half.y)
            })
        };
        let mut segments = Vec::new();
        for (e, &twin) in self.twins.iter().enumerate() {
            if front[e / 3] && !front[twin as usize / 3] {
                let v = self.triangles[e / 3];
                let (Some(a), Some(b)) = (project(v[e % 3]), project(v[(e + 1) % 3])) else {
                    return Err(NoSilhouette::BehindCamera);
                };
                segments.push([a.x, a.y, b.x, b.y]);
            }
        }
        Ok(segments)
    }
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
        let surface = Surface::new(mesh).map(Arc::new);
        self.0.insert(id, surface.clone());
        surface
    }
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

/// One id per position (and the positions by id), positions within a hair of each other (a
/// millionth of the mesh's extent, on every axis) taken as one: a seam's two copies of a vertex,
/// computed apart (a sphere's `sin(2 pi)`), are one vertex of the surface.
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

/// The winding number of `segments` around `point` (pixels): not 0 where the mesh they outline
/// covers the point. The combine shader's `silhouette_covers`, on the CPU.
#[cfg(test)]
pub fn winding(segments: &[Segment], point: Vec2) -> i32 {
    segments
        .iter()
        .map(|s| {
            let (a, b) = (Vec2::new(s[0], s[1]), Vec2::new(s[2], s[3]));
            let side = (b - a).perp_dot(point - a);
            if a.y <= point.y {
                i32::from(b.y > point.y && side > 0.0)
            } else {
                -i32::from(b.y <= point.y && side < 0.0)
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::asset::RenderAssetUsages;

    /// A camera at `eye` looking at the origin, 90 degrees, on a 64x48 target.
    fn camera(eye: Vec3) -> (Mat4, UVec2) {
        camera_toward(eye, Vec3::ZERO)
    }

    /// A camera at `eye` looking at `target`, 90 degrees, on a 64x48 target.
    fn camera_toward(eye: Vec3, target: Vec3) -> (Mat4, UVec2) {
        let size = UVec2::new(64, 48);
        let view = Transform::from_translation(eye)
            .looking_at(target, Vec3::Y)
            .to_matrix()
            .inverse();
        let proj = Mat4::from_cols_array(
            &glam::camera::rh::proj::directx::perspective_infinite_reverse(
                std::f32::consts::FRAC_PI_2,
                size.x as f32 / size.y as f32,
                0.1,
            )
            .to_cols_array(),
        );
        (proj * view, size)
    }

    /// Whether a front face of `mesh` covers pixel center `p`: rasterization, by brute force.
    fn covered(mesh: &Mesh, clip_from_local: Mat4, eye: Vec3, size: UVec2, p: Vec2) -> bool {
        let Some(VertexAttributeValues::Float32x3(pos)) = mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            unreachable!()
        };
        let idx: Vec<usize> = mesh.indices().unwrap().iter().collect();
        let to_px = |v: Vec3| {
            let c = clip_from_local * v.extend(1.0);
            let n = c.truncate().truncate() / c.w;
            Vec2::new(
                (n.x + 1.0) * size.x as f32 / 2.0,
                (1.0 - n.y) * size.y as f32 / 2.0,
            )
        };
        idx.chunks_exact(3).any(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from_array(pos[t[k]]));
            if (b - a).cross(c - a).dot(eye - a) <= 0.0 {
                return false;
            }
            let [a, b, c] = [a, b, c].map(to_px);
            let e = [
                (b - a).perp_dot(p - a),
                (c - b).perp_dot(p - b),
                (a - c).perp_dot(p - c),
            ];
            e.iter().all(|&x| x >= 0.0) || e.iter().all(|&x| x <= 0.0)
        })
    }

    /// Over every pixel center, the winding of the silhouette says covered exactly where a front
    /// face covers: a cube, and a coarse UV sphere (seams and poles welded), from a few sides.
    #[test]
    fn the_winding_of_the_silhouette_is_the_coverage() {
        let meshes = [
            Cuboid::new(1.0, 1.4, 0.8).mesh().build(),
            Sphere::new(0.9).mesh().uv(9, 6),
        ];
        for mesh in &meshes {
            for eye in [
                Vec3::new(0.3, 0.4, 2.5),
                Vec3::new(-2.0, 1.1, 0.7),
                Vec3::new(0.2, -1.7, -1.4),
            ] {
                let (clip, size) = camera(eye);
                let segments = Surface::new(mesh)
                    .unwrap()
                    .silhouette(clip, eye, size, true)
                    .unwrap();
                assert!(segments.len() >= 3);
                let mut inside = 0;
                for y in 0..size.y {
                    for x in 0..size.x {
                        let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                        let want = covered(mesh, clip, eye, size, p);
                        assert_eq!(winding(&segments, p) != 0, want, "{eye} at {p}");
                        inside += usize::from(want);
                    }
                }
                assert!(inside > 100, "{eye}: the mesh covers {inside} pixels");
            }
        }
    }

    /// A mesh with an open edge, one that is not triangles, and one reaching behind the camera
    /// have no silhouette.
    #[test]
    fn open_meshes_lines_and_meshes_behind_the_camera_have_none() {
        let eye = Vec3::new(0.0, 0.5, 3.0);
        let (clip, _) = camera(eye);
        let plane = Plane3d::default().mesh().size(1.0, 1.0).build();
        assert_eq!(Surface::new(&plane).err(), Some(NoSilhouette::NotClosed));
        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default())
            .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[0.0f32; 3]; 2]);
        assert_eq!(Surface::new(&lines).err(), Some(NoSilhouette::NoTriangles));
        // Looking away from the sphere: its silhouette lies behind the camera.
        let (away, size) = camera_toward(eye, Vec3::new(0.0, 0.5, 6.0));
        let sphere = Sphere::new(1.0).mesh().uv(9, 6);
        let sphere = Surface::new(&sphere).unwrap();
        assert_eq!(
            sphere.silhouette(away, eye, size, true),
            Err(NoSilhouette::BehindCamera)
        );
        // From inside a closed mesh every face is turned away: it covers nothing.
        let big = Sphere::new(5.0).mesh().uv(9, 6);
        let big = Surface::new(&big).unwrap();
        assert_eq!(big.silhouette(clip, eye, size, true), Ok(Vec::new()));
    }
}
