//! The fuzz target's corpus: meshes made here and glTF files read from a folder.

use std::path::Path;

use serde_json::{Value, json};

/// A corpus file: its name's extension, and the JSON and binary chunk (a `.gltf`'s buffer is
/// written as `<name>.bin` beside it).
#[derive(Clone)]
pub struct Sample {
    pub glb: bool,
    pub json: Value,
    pub bin: Vec<u8>,
}

pub fn sphere(rings: u32, segments: u32, indexed: bool, glb: bool) -> Sample {
    let (positions, indices) = lodkit::lod_chain::uv_sphere(rings, segments);
    let (positions, indices) = if indexed {
        (positions, Some(indices))
    } else {
        (
            indices.iter().map(|&i| positions[i as usize]).collect(),
            None,
        )
    };
    mesh_sample(&positions, indices.as_deref(), glb)
}

pub fn terrain(n: u32) -> Sample {
    let mut positions = Vec::new();
    for z in 0..=n {
        for x in 0..=n {
            let (fx, fz) = (x as f32 / n as f32, z as f32 / n as f32);
            positions.push([fx, 0.1 * (7.0 * fx).sin() * (5.0 * fz).cos(), fz]);
        }
    }
    let mut indices = Vec::new();
    for z in 0..n {
        for x in 0..n {
            let a = z * (n + 1) + x;
            indices.extend([a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2]);
        }
    }
    mesh_sample(&positions, Some(&indices), true)
}

fn mesh_sample(positions: &[[f32; 3]], indices: Option<&[u32]>, glb: bool) -> Sample {
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let (lo, hi) = positions.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(mut lo, mut hi), p| {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
            (lo, hi)
        },
    );
    let mut views = vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": bin.len()})];
    let mut accessors = vec![json!({"bufferView": 0, "componentType": 5126,
        "count": positions.len(), "type": "VEC3", "min": lo, "max": hi})];
    let mut primitive = json!({"attributes": {"POSITION": 0}});
    if let Some(indices) = indices {
        let at = bin.len();
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": bin.len() - at}));
        accessors.push(json!({"bufferView": 1, "componentType": 5125,
            "count": indices.len(), "type": "SCALAR"}));
        primitive["indices"] = json!(1);
    }
    let json = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [2.0, 0.0, 0.0]}],
        "meshes": [{"primitives": [primitive]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    Sample { glb, json, bin }
}

/// The sample with 16-bit normalized positions (`KHR_mesh_quantization`).
pub fn quantized(mut s: Sample) -> Sample {
    let count = s.json["accessors"][0]["count"].as_u64().unwrap_or(0) as usize;
    let mut q = Vec::with_capacity(count * 8);
    for k in 0..count {
        for c in 0..3 {
            let at = 12 * k + 4 * c;
            let x = f32::from_le_bytes(s.bin[at..at + 4].try_into().expect("4 bytes"));
            q.extend(((x.clamp(-1.0, 1.0) * 32767.0) as i16).to_le_bytes());
        }
        q.extend([0, 0]);
    }
    let rest = s.bin[12 * count..].to_vec();
    let at = q.len();
    s.bin = q;
    s.bin.extend(rest);
    s.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    s.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    s.json["bufferViews"][0] = json!({"buffer": 0, "byteOffset": 0, "byteLength": at,
        "byteStride": 8});
    if s.json["bufferViews"].get(1).is_some() {
        s.json["bufferViews"][1]["byteOffset"] = json!(at);
    }
    s.json["accessors"][0]["componentType"] = json!(5122);
    s.json["accessors"][0]["normalized"] = json!(true);
    s.json["accessors"][0]["min"] = json!([-32767, -32767, -32767]);
    s.json["accessors"][0]["max"] = json!([32767, 32767, 32767]);
    s.json["buffers"][0]["byteLength"] = json!(s.bin.len());
    s
}

/// A corpus file from disk (its external buffers inlined as the binary chunk when there is
/// one; images are dropped).
pub fn load(path: &Path) -> Option<Sample> {
    let bytes = std::fs::read(path).ok()?;
    if bytes.starts_with(b"glTF") {
        let glb = gltf::Glb::from_slice(&bytes).ok()?;
        let json = serde_json::from_slice(&glb.json).ok()?;
        let bin = glb.bin.map(|b| b.into_owned()).unwrap_or_default();
        return Some(Sample {
            glb: true,
            json,
            bin,
        });
    }
    let mut json: Value = serde_json::from_slice(&bytes).ok()?;
    let buffers = json["buffers"].as_array()?.clone();
    if buffers.len() != 1 {
        return None;
    }
    let uri = buffers[0]["uri"].as_str()?;
    let bin = std::fs::read(path.parent()?.join(percent(uri))).ok()?;
    json["buffers"][0].as_object_mut()?.remove("uri");
    if let Some(images) = json.as_object_mut()?.remove("images") {
        let _ = images;
        json.as_object_mut()?.remove("textures");
        strip_textures(&mut json);
    }
    Some(Sample {
        glb: false,
        json,
        bin,
    })
}

fn percent(uri: &str) -> String {
    percent_encoding::percent_decode_str(uri)
        .decode_utf8_lossy()
        .into_owned()
}

/// Drops every `*Texture` member of the materials (their textures are gone).
fn strip_textures(json: &mut Value) {
    if let Some(materials) = json["materials"].as_array_mut() {
        for m in materials {
            strip_texture_members(m);
        }
    }
}

fn strip_texture_members(v: &mut Value) {
    if let Some(o) = v.as_object_mut() {
        o.retain(|k, _| !k.ends_with("Texture"));
        for v in o.values_mut() {
            strip_texture_members(v);
        }
    }
}
