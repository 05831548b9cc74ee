//! The fuzz target's mutations and how a mutated sample is written.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use crate::corpus::Sample;

/// xorshift64*: the mutations' random numbers.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Values a number in the JSON is set to.
fn interesting(rng: &mut Rng, was: &Value) -> Value {
    let n = was.as_i64().unwrap_or(1);
    match rng.below(12) {
        0 => json!(0),
        1 => json!(-1),
        2 => json!(n + 1),
        3 => json!(n - 1),
        4 => json!(n * 2),
        5 => json!(u32::MAX),
        6 => json!(i64::from(i32::MAX) + 1),
        7 => json!(1e308),
        8 => json!(3),
        9 => json!("x"),
        10 => Value::Null,
        _ => json!(rng.below(70_000)),
    }
}

/// One mutation; returns what it did.
pub fn mutate(rng: &mut Rng, s: &mut Sample) -> String {
    let pick = |rng: &mut Rng, s: &Sample, key: &str| {
        let n = s.json[key].as_array().map_or(0, Vec::len);
        (n > 0).then(|| rng.below(n))
    };
    match rng.below(14) {
        0 | 1 => {
            let flips = 1 + rng.below(8);
            for _ in 0..flips {
                if !s.bin.is_empty() {
                    let at = rng.below(s.bin.len());
                    s.bin[at] ^= 1 << rng.below(8);
                }
            }
            format!("{flips} bit flips in the binary data")
        }
        2 => {
            // A whole float: NaN, infinity, huge; or an index past the end.
            let at = rng.below(s.bin.len().max(4) / 4) * 4;
            let value: u32 = match rng.below(4) {
                0 => f32::NAN.to_bits(),
                1 => f32::INFINITY.to_bits(),
                2 => 1e30f32.to_bits(),
                _ => u32::MAX,
            };
            if at + 4 <= s.bin.len() {
                s.bin[at..at + 4].copy_from_slice(&value.to_le_bytes());
            }
            format!("word at {at} set to {value:#x}")
        }
        3 => {
            let keep = rng.below(s.bin.len() + 1);
            s.bin.truncate(keep);
            format!("binary data cut to {keep} bytes")
        }
        4 | 5 => {
            let Some(k) = pick(rng, s, "accessors") else {
                return "no accessor".into();
            };
            let key = [
                "count",
                "byteOffset",
                "componentType",
                "bufferView",
                "normalized",
            ][rng.below(5)];
            let was = s.json["accessors"][k][key].clone();
            s.json["accessors"][k][key] = match key {
                "componentType" => json!([5120, 5121, 5122, 5123, 5125, 5126, 5124][rng.below(7)]),
                _ => interesting(rng, &was),
            };
            if rng.below(4) == 0 {
                s.json["accessors"][k]["type"] =
                    json!(["SCALAR", "VEC2", "VEC3", "VEC4", "MAT4", "MAT2"][rng.below(6)]);
            }
            format!("accessors[{k}].{key}")
        }
        6 => {
            let Some(k) = pick(rng, s, "bufferViews") else {
                return "no view".into();
            };
            let key = ["byteOffset", "byteLength", "byteStride", "buffer"][rng.below(4)];
            let was = s.json["bufferViews"][k][key].clone();
            s.json["bufferViews"][k][key] = interesting(rng, &was);
            format!("bufferViews[{k}].{key}")
        }
        7 => {
            let Some(m) = pick(rng, s, "meshes") else {
                return "no mesh".into();
            };
            let Some(p) = s.json.pointer_mut(&format!("/meshes/{m}/primitives/0")) else {
                return "no primitive".into();
            };
            if !p.is_object() {
                return "no primitive".into();
            }
            match rng.below(3) {
                0 => p["mode"] = json!(rng.below(8)),
                1 => p["indices"] = json!(rng.below(4)),
                _ => p["attributes"]["POSITION"] = json!(rng.below(4)),
            }
            format!("meshes[{m}].primitives[0]")
        }
        8 => {
            let Some(n) = pick(rng, s, "nodes") else {
                return "no node".into();
            };
            let child = rng.below(s.json["nodes"].as_array().map_or(1, Vec::len) + 1);
            s.json["nodes"][n]["children"] = json!([child, n]);
            format!("nodes[{n}].children = [{child}, {n}]")
        }
        9 => {
            let Some(n) = pick(rng, s, "nodes") else {
                return "no node".into();
            };
            s.json["nodes"][n]["mesh"] = json!(rng.below(4));
            format!("nodes[{n}].mesh")
        }
        10 => {
            let length = interesting(rng, &json!(s.bin.len()));
            let uri_too = rng.below(2) == 0;
            let Some(buffer) = s.json.pointer_mut("/buffers/0").filter(|b| b.is_object()) else {
                return "no buffer".into();
            };
            buffer["byteLength"] = length;
            if uri_too {
                buffer["uri"] = json!(
                    [
                        "../../etc/passwd",
                        "data:application/octet-stream;base64,AAA",
                        "x.bin"
                    ][rng.below(3)]
                );
            }
            "buffers[0]".into()
        }
        11 => {
            let Some(n) = pick(rng, s, "nodes") else {
                return "no node".into();
            };
            let count = s.json["nodes"].as_array().map_or(1, Vec::len);
            let ids: Vec<usize> = (0..1 + rng.below(3))
                .map(|_| rng.below(count + 2))
                .collect();
            s.json["nodes"][n]["extensions"] = json!({"MSFT_lod": {"ids": ids}});
            s.json["extensionsUsed"] = json!(["MSFT_lod"]);
            format!("nodes[{n}] MSFT_lod ids {ids:?}")
        }
        12 => {
            // A member removed.
            let key = [
                "accessors",
                "bufferViews",
                "buffers",
                "meshes",
                "scenes",
                "asset",
            ][rng.below(6)];
            s.json.as_object_mut().map(|o| o.remove(key));
            format!("{key} removed")
        }
        _ => {
            let names = [
                "KHR_draco_mesh_compression",
                "EXT_meshopt_compression",
                "KHR_mesh_quantization",
                "X_unknown",
            ];
            let name = names[rng.below(names.len())];
            s.json["extensionsRequired"] = json!([name]);
            "extensionsRequired".into()
        }
    }
}

/// Writes `s` as `dir/in.glb` or `dir/in.gltf` (+ `in.bin`); the GLB's chunk length may be
/// forged by a mutation of the container (a quarter of GLB inputs).
pub fn write(s: &Sample, dir: &Path, rng: &mut Rng) -> std::io::Result<PathBuf> {
    let json = serde_json::to_vec(&s.json).expect("JSON");
    if s.glb {
        let mut json = json;
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = s.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut out = Vec::new();
        let total = 12 + 8 + json.len() + 8 + bin.len();
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
        if rng.below(4) == 0 {
            let at = [8, 12, 20 + json.len()][rng.below(3)];
            let forged = [0u32, 1, u32::MAX, (total * 2) as u32][rng.below(4)];
            out[at..at + 4].copy_from_slice(&forged.to_le_bytes());
        }
        let path = dir.join("in.glb");
        std::fs::write(&path, out)?;
        Ok(path)
    } else {
        let mut json_value = s.json.clone();
        if json_value["buffers"][0].get("uri").is_none()
            && let Some(b) = json_value["buffers"].get_mut(0)
        {
            b["uri"] = json!("in.bin");
        }
        std::fs::write(dir.join("in.bin"), &s.bin)?;
        let path = dir.join("in.gltf");
        std::fs::write(&path, serde_json::to_vec(&json_value).expect("JSON"))?;
        Ok(path)
    }
}
