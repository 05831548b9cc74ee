//! Writes a test asset for `lodkit lod`'s speed: a rock, an icosphere subdivided `--subdivisions`
//! times (20 * 4^n triangles: 1,310,720 at the default 8) whose radius is displaced by a sum of
//! waves, with vertex normals, as one GLB (positions, normals, 32-bit indices).
//! `scripts/lod-bench.sh` times `lodkit lod` and gltfpack on it side by side.
//!
//! ```sh
//! cargo run --release -p lodkit-cli --example rock -- OUT.glb [--subdivisions 8]
//! ```

use std::borrow::Cow;
use std::collections::HashMap;
use std::process::ExitCode;

use glam::Vec3;
use serde_json::json;

/// An icosphere of unit radius subdivided `n` times.
fn icosphere(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut p: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|v| Vec3::from(v).normalize())
    .to_vec();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..n {
        let mut middle: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 3 / 2);
        let mut mid = |a: u32, b: u32, p: &mut Vec<Vec3>| {
            *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                p.push(((p[a as usize] + p[b as usize]) * 0.5).normalize());
                p.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = (mid(a, b, &mut p), mid(b, c, &mut p), mid(c, a, &mut p));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    (p, tris)
}

/// The rock's radius along the unit direction `d`: waves of several sizes in fixed directions.
fn radius(d: Vec3) -> f32 {
    let mut r = 1.0;
    for k in 0..12u32 {
        let kf = k as f32;
        let dir = Vec3::new(
            (kf * 2.39).cos(),
            (kf * 1.17).sin(),
            (kf * 0.73 + 0.5).cos(),
        )
        .normalize();
        let frequency = 2.0 + 1.6 * kf;
        r += 0.12 / (1.0 + kf) * (frequency * d.dot(dir) + kf).sin();
    }
    r
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.iter().find(|a| !a.starts_with("--")) else {
        eprintln!("usage: rock OUT.glb [--subdivisions N]");
        return ExitCode::from(2);
    };
    let n: u32 = match args.iter().position(|a| a == "--subdivisions") {
        Some(i) => match args.get(i + 1).and_then(|s| s.parse().ok()) {
            Some(n) if n <= 10 => n,
            _ => {
                eprintln!("--subdivisions takes 0 to 10");
                return ExitCode::from(2);
            }
        },
        None => 8,
    };
    let (directions, tris) = icosphere(n);
    let positions: Vec<Vec3> = directions.iter().map(|&d| d * radius(d)).collect();
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for &[a, b, c] in &tris {
        let (pa, pb, pc) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        let face = (pb - pa).cross(pc - pa);
        for v in [a, b, c] {
            normals[v as usize] += face;
        }
    }
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let mut bin: Vec<u8> = Vec::new();
    bin.extend(
        positions
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes),
    );
    let normals_at = bin.len();
    bin.extend(
        normals
            .iter()
            .flat_map(|n| n.normalize_or(Vec3::Y).to_array())
            .flat_map(f32::to_le_bytes),
    );
    let indices_at = bin.len();
    bin.extend(tris.iter().flatten().flat_map(|i| i.to_le_bytes()));
    let count = positions.len();
    let gltf = json!({
        "asset": {"version": "2.0", "generator": "lodkit-cli example rock"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "rock"}],
        "meshes": [{"name": "rock", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": normals_at, "target": 34962},
            {"buffer": 0, "byteOffset": normals_at, "byteLength": indices_at - normals_at,
                "target": 34962},
            {"buffer": 0, "byteOffset": indices_at, "byteLength": bin.len() - indices_at,
                "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
                "min": lo.to_array(), "max": hi.to_array()},
            {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": tris.len() * 3, "type": "SCALAR"},
        ],
    });
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // to_vec computes it
        },
        json: Cow::Owned(serde_json::to_vec(&gltf).expect("JSON")),
        bin: Some(Cow::Owned(bin)),
    };
    let glb = match glb.to_vec() {
        Ok(bytes) => bytes,
        Err(e) => {
            eprintln!("error: writing the GLB: {e}");
            return ExitCode::FAILURE;
        }
    };
    if let Err(e) = std::fs::write(out, glb) {
        eprintln!("error: writing {out}: {e}");
        return ExitCode::FAILURE;
    }
    println!("{out}: {} triangles, {count} vertices", tris.len());
    ExitCode::SUCCESS
}
