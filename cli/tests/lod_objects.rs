//! `lodkit lod` switches an object as a whole: the meshes under one top-level node share their
//! switch distances (in world units: a mesh's view-normalized distance times its node's scale),
//! each level's the largest among them; `--per-mesh` gives each its own; `--object NODE` makes
//! the meshes below a named node an object of their own.

use serde_json::json;

use crate::cli::run;
use crate::support::Scratch;

/// A helmet of two parts under `root`: a coarse-detailed shell (a sphere of radius 1) and a
/// small, finely detailed visor (radius 0.3, its node scaled by 2), each a node of its own.
fn write_helmet(dir: &std::path::Path) {
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    for (radius, rings, segments) in [(1.0f32, 10, 20), (0.3, 24, 48)] {
        let (positions, indices) = lodkit::lod_chain::uv_sphere(rings, segments);
        let at = bin.len();
        for p in &positions {
            for x in p {
                bin.extend((x * radius).to_le_bytes());
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": bin.len() - at}));
        accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5126,
            "count": positions.len(), "type": "VEC3",
            "min": [-radius, -radius, -radius], "max": [radius, radius, radius]}));
        let at = bin.len();
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": bin.len() - at}));
        accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5125,
            "count": indices.len(), "type": "SCALAR"}));
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "root", "children": [1]},
            {"name": "helmet", "children": [2, 3]},
            {"name": "shell", "mesh": 0},
            {"name": "visor", "mesh": 1, "scale": [2.0, 2.0, 2.0], "translation": [0.0, 0.0, 0.8]},
        ],
        "meshes": [
            {"name": "shell", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
            {"name": "visor", "primitives": [{"attributes": {"POSITION": 2}, "indices": 3}]},
        ],
        "buffers": [{"uri": "h.bin", "byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    std::fs::write(dir.join("h.bin"), &bin).unwrap();
    std::fs::write(dir.join("h.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
}

/// Per mesh of the report: its object and its switch distances in world units (the visor's
/// node scale is 2), the hide distance last.
fn world_distances(dir: &std::path::Path, extra: &[&str]) -> Vec<(String, Vec<f64>)> {
    let mut args = vec![
        "lod", "h.gltf", "-o", "out.glb", "--levels", "3", "--report", "r.json",
    ];
    args.extend(extra);
    let (code, stdout, stderr) = run(dir, &args);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    report["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .zip([1.0, 2.0])
        .map(|(m, scale)| {
            let mut d: Vec<f64> = m["levels"]
                .as_array()
                .unwrap()
                .iter()
                .map(|l| l["switch_distance"].as_f64().unwrap() * scale)
                .collect();
            d.push(m["max_distance"].as_f64().unwrap() * scale);
            (m["object"].as_str().unwrap().to_owned(), d)
        })
        .collect()
}

/// By default the two parts, under one top-level node, switch at the same world distances,
/// each level's the farther of the two parts' own (what `--per-mesh` gives: the parts'
/// distances differ, so sharing changes something); naming the parts' nodes as objects gives
/// each its own again; `--one-object` is the top-level node's grouping here. Within 1e-5 relative: the shared distance goes through world units
/// (a multiplication and a division by the scale) and the report's f32.
#[test]
fn an_objects_meshes_switch_together() {
    let dir = Scratch::folder();
    write_helmet(&dir);
    let own = world_distances(&dir, &["--per-mesh"]);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * a.abs().max(b.abs());
    assert!(
        own[0]
            .1
            .iter()
            .zip(&own[1].1)
            .skip(1)
            .any(|(a, b)| !close(*a, *b)),
        "the parts' own distances differ: {own:?}"
    );
    let shared = world_distances(&dir, &[]);
    for (k, (object, d)) in shared.iter().enumerate() {
        assert_eq!(object, "root", "{shared:?}");
        for (i, x) in d.iter().enumerate() {
            let want = own[0].1[i].max(own[1].1[i]);
            assert!(
                close(*x, want),
                "mesh {k} level {i}: {x} against {want}: {shared:?}"
            );
        }
    }
    let whole = world_distances(&dir, &["--one-object"]);
    for ((object, d), (_, shared)) in whole.iter().zip(&shared) {
        assert_eq!(object, "the whole file");
        assert_eq!(d, shared, "one top-level node: the same object");
    }
    let (code, _, stderr) = run(&dir, &["lod", "h.gltf", "-o", "x.glb", "--object", "visr"]);
    assert_eq!(code, 2, "a misspelt node is an error: {stderr}");
    assert!(
        stderr.contains("--object visr: the file has no node"),
        "{stderr}"
    );
    let named = world_distances(&dir, &["--object", "shell", "--object", "visor"]);
    for (k, (object, d)) in named.iter().enumerate() {
        assert_eq!(object, ["shell", "visor"][k]);
        for (x, want) in d.iter().zip(&own[k].1) {
            assert!(
                close(*x, *want),
                "mesh {k}: {d:?} against its own {:?}",
                own[k].1
            );
        }
    }
}
