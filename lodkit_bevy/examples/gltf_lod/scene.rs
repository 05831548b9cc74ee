//! The example's glTF file, written as `lodkit lod` writes its levels: a coarse level's node named
//! only by the finest node's `MSFT_lod` extension, and `MSFT_screencoverage` in its extras.

use std::path::Path;

use bevy::mesh::{Indices, VertexAttributeValues};
use bevy::prelude::*;
use serde_json::{Value, json};

/// The viewport aspect `lodkit lod` writes coverages for (its default `--aspect`).
const ASPECT: f32 = 16.0 / 9.0;

/// One mesh's bytes and accessors as the file lays them out.
struct Written {
    accessors: Vec<Value>,
    views: Vec<Value>,
    bin: Vec<u8>,
}

impl Written {
    /// Appends `bytes` as a buffer view, returns its index.
    fn view(&mut self, bytes: &[u8], target: u32) -> usize {
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": offset, "byteLength": bytes.len(), "target": target,
        }));
        self.views.len() - 1
    }

    /// Adds `mesh` (positions, normals, u32 indices) as glTF mesh primitive attributes.
    fn primitive(&mut self, mesh: &Mesh, material: usize) -> Value {
        let Some(VertexAttributeValues::Float32x3(positions)) =
            mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            unreachable!("Bevy's primitives have Float32x3 positions")
        };
        let Some(VertexAttributeValues::Float32x3(normals)) =
            mesh.attribute(Mesh::ATTRIBUTE_NORMAL)
        else {
            unreachable!("Bevy's primitives have Float32x3 normals")
        };
        let indices: Vec<u32> = match mesh.indices() {
            Some(Indices::U32(i)) => i.clone(),
            Some(Indices::U16(i)) => i.iter().map(|&i| u32::from(i)).collect(),
            None => (0..positions.len() as u32).collect(),
        };
        let floats = |v: &[[f32; 3]]| -> Vec<u8> {
            v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect()
        };
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let p = self.view(&floats(positions), 34962);
        let n = self.view(&floats(normals), 34962);
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let i = self.view(&bytes, 34963);
        let base = self.accessors.len();
        self.accessors.extend([
            json!({"bufferView": p, "componentType": 5126, "count": positions.len(), "type": "VEC3", "min": lo, "max": hi}),
            json!({"bufferView": n, "componentType": 5126, "count": normals.len(), "type": "VEC3"}),
            json!({"bufferView": i, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}),
        ]);
        json!({
            "attributes": {"POSITION": base, "NORMAL": base + 1},
            "indices": base + 2,
            "material": material,
        })
    }
}

/// Screen coverage at view-normalized distance `d` of a mesh whose box has half-diagonal
/// `radius` (`lodkit lod`'s definition).
fn coverage(radius: f32, d: f32) -> f32 {
    std::f32::consts::PI * radius * radius / (4.0 * ASPECT * d * d)
}

/// Writes `dir/scene.gltf` and `dir/scene.bin`: two spheres switching to their coarse level at
/// view-normalized distance `switch` (hidden beyond 100), and a cube without levels.
pub fn write(dir: &Path, switch: f32) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let radius = 0.8;
    let fine = Sphere::new(radius).mesh().uv(32, 16);
    let coarse = Sphere::new(radius).mesh().uv(10, 6);
    let cube = Cuboid::new(0.8, 0.8, 0.8).mesh().build();
    let mut w = Written {
        accessors: Vec::new(),
        views: Vec::new(),
        bin: Vec::new(),
    };
    // Materials: 0 orange, 1 teal, 2 the second sphere's coarse level, 3 grey.
    let meshes = vec![
        json!({"name": "a", "primitives": [w.primitive(&fine, 0)]}),
        json!({"name": "a_LOD1", "primitives": [w.primitive(&coarse, 0)]}),
        json!({"name": "b", "primitives": [w.primitive(&fine, 1)]}),
        json!({"name": "b_LOD1", "primitives": [w.primitive(&coarse, 2)]}),
        json!({"name": "cube", "primitives": [w.primitive(&cube, 3)]}),
    ];
    let box_radius = radius * 3f32.sqrt();
    let screen = json!([coverage(box_radius, switch), coverage(box_radius, 100.0)]);
    let lod = |id: usize, x: f32, mesh: usize| {
        json!({
            "name": if mesh == 0 { "a" } else { "b" },
            "mesh": mesh,
            "translation": [x, 0.0, 0.0],
            "extensions": {"MSFT_lod": {"ids": [id]}},
            "extras": {"MSFT_screencoverage": screen},
        })
    };
    let material = |rgb: [f32; 3]| json!({"pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}});
    let document = json!({
        "asset": {"version": "2.0", "generator": "lodkit_bevy gltf_lod example"},
        "extensionsUsed": ["MSFT_lod"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            lod(3, -1.1, 0),
            lod(4, 1.1, 2),
            {"name": "cube", "mesh": 4, "translation": [0.0, -0.2, -2.5]},
            {"name": "a_LOD1", "mesh": 1, "translation": [-1.1, 0.0, 0.0]},
            {"name": "b_LOD1", "mesh": 3, "translation": [1.1, 0.0, 0.0]},
        ],
        "meshes": meshes,
        "materials": [
            material([0.94, 0.55, 0.2]),
            material([0.2, 0.7, 0.85]),
            material([0.2, 0.55, 0.75]),
            material([0.6, 0.6, 0.6]),
        ],
        "accessors": w.accessors,
        "bufferViews": w.views,
        "buffers": [{"uri": "scene.bin", "byteLength": w.bin.len()}],
    });
    std::fs::write(dir.join("scene.bin"), &w.bin)?;
    std::fs::write(
        dir.join("scene.gltf"),
        serde_json::to_string_pretty(&document).expect("JSON"),
    )
}
