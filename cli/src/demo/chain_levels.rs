//! The levels of the demo's generated LOD group: one bumpy sphere whose chain
//! `lodkit::lod_chain` builds (the scene and the report's section are in
//! [`chain`](super::chain)).

use std::sync::OnceLock;

use glam::Vec3;
use lodkit::lod_chain::{LodChain, LodChainDescriptor, MeshData, PixelErrorCamera, uv_sphere};
use lodkit_scenes::mesh::Mesh;

/// The chain's reference camera: the scene's field of view on the default demo image's height
/// (180 pixels), one pixel of error.
pub const CAMERA: PixelErrorCamera = PixelErrorCamera {
    fov_y: 0.8,
    viewport_height: 180.0,
    pixel_error: 1.0,
    hysteresis: 0.0,
};

/// The base mesh: a unit UV sphere of 16 rings and 32 segments (960 triangles) with smooth
/// bumps, and its normals.
fn base() -> (Vec<[f32; 3]>, Vec<u32>, Vec<[f32; 3]>) {
    let (mut positions, indices) = uv_sphere(16, 32);
    for p in &mut positions {
        let bump = 1.0 + 0.06 * (5.0 * p[0]).sin() * (4.0 * p[1]).sin() * (3.0 * p[2] + 1.0).sin();
        *p = p.map(|c| c * bump);
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let v = |i: u32| Vec3::from(positions[i as usize]);
        let n = (v(t[1]) - v(t[0])).cross(v(t[2]) - v(t[0]));
        for &i in t {
            normals[i as usize] += n;
        }
    }
    let normals = normals
        .iter()
        .map(|n| n.normalize_or_zero().to_array())
        .collect();
    (positions, indices, normals)
}

/// The chain (built once: a few milliseconds).
pub fn chain() -> &'static LodChain {
    static CHAIN: OnceLock<LodChain> = OnceLock::new();
    CHAIN.get_or_init(|| {
        let (positions, indices, normals) = base();
        let descriptor = LodChainDescriptor {
            camera: CAMERA,
            ..Default::default()
        };
        LodChain::build(
            &MeshData {
                positions: &positions,
                indices: &indices,
                normals: Some(&normals),
                uvs: None,
            },
            &descriptor,
        )
        .expect("the demo's bumpy sphere has a chain")
    })
}

/// The number of levels of the chain.
pub fn levels() -> usize {
    chain().levels().len()
}

/// Level `level` as a demo mesh (`None` past the last level).
pub fn level_mesh(level: u32) -> Option<Mesh> {
    let level = chain().levels().get(level as usize)?;
    let normals = level.normals().expect("the base mesh has normals");
    Some(Mesh {
        vertices: level
            .positions()
            .iter()
            .zip(normals)
            .map(|(p, n)| [p[0], p[1], p[2], n[0], n[1], n[2]])
            .collect(),
        indices: level.indices().to_vec(),
    })
}
