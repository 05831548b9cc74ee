//! `lodkit lod`: a glTF file in, the same file with each mesh's LOD chain out (`MSFT_lod`), read
//! back by a second reader (the `gltf` crate); bad inputs each get an error naming the file and
//! the mesh, never a panic.

use std::path::Path;

use serde_json::json;

use crate::cli::run;
use crate::support::Scratch;

/// A mesh to write: positions, optional indices, optional RGBA8 colors, primitive mode.
pub(crate) struct Fixture {
    positions: Vec<[f32; 3]>,
    indices: Option<Vec<u32>>,
    colors: bool,
    mode: u32,
}

pub(crate) fn sphere(rings: u32, segments: u32) -> Fixture {
    let (positions, indices) = lodkit::lod_chain::uv_sphere(rings, segments);
    Fixture {
        positions,
        indices: Some(indices),
        colors: false,
        mode: 4,
    }
}

/// Writes `name`.gltf and `name`.bin into `dir`; `edit` may change the JSON before it is saved.
pub(crate) fn write_gltf(
    dir: &Path,
    name: &str,
    f: &Fixture,
    edit: impl FnOnce(&mut serde_json::Value),
) {
    let mut bin: Vec<u8> = f
        .positions
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let pos_len = bin.len();
    let mut views = vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": pos_len})];
    let (lo, hi) = f.positions.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(mut lo, mut hi), p| {
            for ((l, h), x) in lo.iter_mut().zip(&mut hi).zip(p) {
                *l = l.min(*x);
                *h = h.max(*x);
            }
            (lo, hi)
        },
    );
    let mut accessors = vec![json!({
        "bufferView": 0, "componentType": 5126, "count": f.positions.len(), "type": "VEC3",
        "min": lo, "max": hi
    })];
    let mut attributes = json!({"POSITION": 0});
    if f.colors {
        let start = bin.len();
        for (k, _) in f.positions.iter().enumerate() {
            bin.extend([(k % 256) as u8, 128, 255, 255]);
        }
        views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start}));
        accessors.push(json!({
            "bufferView": views.len() - 1, "componentType": 5121, "normalized": true,
            "count": f.positions.len(), "type": "VEC4"
        }));
        attributes["COLOR_0"] = json!(accessors.len() - 1);
    }
    let mut primitive = json!({"attributes": attributes, "mode": f.mode});
    if let Some(indices) = &f.indices {
        let start = bin.len();
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start}));
        accessors.push(json!({
            "bufferView": views.len() - 1, "componentType": 5125, "count": indices.len(),
            "type": "SCALAR"
        }));
        primitive["indices"] = json!(accessors.len() - 1);
    }
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "thing", "translation": [1.0, 2.0, 3.0]}],
        "meshes": [{"name": "ball", "primitives": [primitive]}],
        "buffers": [{"uri": format!("{name}.bin"), "byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    edit(&mut doc);
    std::fs::write(dir.join(format!("{name}.bin")), &bin).unwrap();
    std::fs::write(
        dir.join(format!("{name}.gltf")),
        serde_json::to_vec(&doc).unwrap(),
    )
    .unwrap();
}

/// Triangles of the first primitive of `mesh`, read by the gltf crate (LOD0 of a non-indexed
/// input stays non-indexed).
fn triangles(mesh: &gltf::Mesh, buffers: &[gltf::buffer::Data]) -> usize {
    let p = mesh.primitives().next().unwrap();
    let reader = p.reader(|b| Some(&buffers[b.index()]));
    match reader.read_indices() {
        Some(i) => i.into_u32().count() / 3,
        None => reader.read_positions().unwrap().count() / 3,
    }
}

/// Checks the output the way a second reader sees it: LOD0's node carries `MSFT_lod` with the
/// level nodes in order (fewer triangles each), one decreasing screen coverage per level.
pub(crate) fn assert_levels_in_order(path: &Path, levels: usize) {
    let (doc, buffers, _) = gltf::import(path).unwrap();
    assert!(doc.extensions_used().any(|e| e == "MSFT_lod"));
    let lod0 = doc.nodes().next().unwrap();
    let ids: Vec<usize> = lod0.extension_value("MSFT_lod").unwrap()["ids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(ids.len(), levels - 1, "{ids:?}");
    let extras: serde_json::Value =
        serde_json::from_str(lod0.extras().as_ref().unwrap().get()).unwrap();
    let coverage: Vec<f64> = extras["MSFT_screencoverage"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(coverage.len(), levels);
    assert!(coverage.windows(2).all(|w| w[0] >= w[1]), "{coverage:?}");
    let mut counts = vec![triangles(&lod0.mesh().unwrap(), &buffers)];
    for &id in &ids {
        let node = doc.nodes().nth(id).unwrap();
        assert_eq!(node.transform().matrix(), lod0.transform().matrix());
        counts.push(triangles(&node.mesh().unwrap(), &buffers));
    }
    assert!(counts.windows(2).all(|w| w[0] > w[1]), "{counts:?}");
}

#[test]
fn lod_writes_msft_lod_levels_a_second_reader_loads_in_order() {
    let dir = Scratch::folder();
    write_gltf(&dir, "s", &sphere(12, 24), |_| {});
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "lod",
            "s.gltf",
            "-o",
            "out.glb",
            "--pixel-error",
            "1",
            "--levels",
            "4",
            "--report",
            "r.json",
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("switch distance"), "{stdout}");
    assert_levels_in_order(&dir.join("out.glb"), 4);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    let levels = report["meshes"][0]["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4);
    let d: Vec<f64> = levels
        .iter()
        .map(|l| l["switch_distance"].as_f64().unwrap())
        .collect();
    assert!(d.windows(2).all(|w| w[0] < w[1]), "{d:?}");
    // The same through a .gltf with its .bin beside it.
    let (code, _, stderr) = run(&dir, &["lod", "s.gltf", "-o", "out.gltf"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(dir.join("out.bin").exists());
    assert_levels_in_order(&dir.join("out.gltf"), 4);
}

#[test]
fn lod_indexes_a_non_indexed_mesh_and_carries_other_attributes() {
    let dir = Scratch::folder();
    let s = sphere(12, 24);
    let flat = Fixture {
        positions: s
            .indices
            .as_ref()
            .unwrap()
            .iter()
            .map(|&i| s.positions[i as usize])
            .collect(),
        indices: None,
        colors: true,
        mode: 4,
    };
    write_gltf(&dir, "flat", &flat, |_| {});
    let (code, _, stderr) = run(&dir, &["lod", "flat.gltf", "-o", "out.glb"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("COLOR_0") && stderr.contains("warning"),
        "{stderr}"
    );
    let (doc, _, _) = gltf::import(dir.join("out.glb")).unwrap();
    for mesh in doc.meshes().skip(1) {
        let p = mesh.primitives().next().unwrap();
        assert!(
            p.get(&gltf::Semantic::Colors(0)).is_some(),
            "COLOR_0 was carried"
        );
    }
    assert_levels_in_order(&dir.join("out.glb"), 4);
}

#[test]
fn lod_bad_inputs_name_the_file_and_mesh() {
    type Case = (
        &'static str,
        Fixture,
        fn(&mut serde_json::Value),
        &'static str,
    );
    let nan = {
        let mut s = sphere(6, 12);
        s.positions[5][1] = f32::NAN;
        s
    };
    let cases: Vec<Case> = vec![
        (
            "points",
            Fixture {
                mode: 0,
                ..sphere(6, 12)
            },
            |_| {},
            "no triangles (points or lines only)",
        ),
        (
            "lines",
            Fixture {
                mode: 1,
                ..sphere(6, 12)
            },
            |_| {},
            "no triangles (points or lines only)",
        ),
        (
            "flat",
            Fixture {
                positions: vec![[1.0, 1.0, 1.0]; 4],
                indices: Some(vec![0, 1, 2, 1, 2, 3]),
                colors: false,
                mode: 4,
            },
            |_| {},
            "degenerate",
        ),
        ("nan", nan, |_| {}, "not finite"),
        (
            "index",
            Fixture {
                positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                indices: Some(vec![0, 1, 9]),
                colors: false,
                mode: 4,
            },
            |_| {},
            "out of range",
        ),
        (
            "short",
            sphere(6, 12),
            |doc| {
                doc["bufferViews"][0]["byteLength"] =
                    json!(doc["buffers"][0]["byteLength"].as_u64().unwrap() + 64)
            },
            "past the end of buffer",
        ),
        (
            // The gltf crate's own validation indexed the empty list with it and panicked.
            "no_accessors",
            sphere(6, 12),
            |doc| doc["accessors"] = json!([]),
            "POSITION is accessor 0, but the file has 0 accessors",
        ),
    ];
    for (name, fixture, edit, want) in cases {
        let dir = Scratch::folder();
        write_gltf(&dir, name, &fixture, edit);
        let file = format!("{name}.gltf");
        let (code, _, stderr) = run(&dir, &["lod", &file, "-o", "out.glb", "--strict"]);
        assert_eq!(code, 1, "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        assert!(
            stderr.contains(&file) && stderr.contains("mesh 0 'ball'"),
            "{name}: {stderr}"
        );
        assert!(stderr.contains(want), "{name}: wanted `{want}` in {stderr}");
        assert!(
            !dir.join("out.glb").exists(),
            "{name}: wrote an output anyway"
        );
    }
    let dir = crate::cli::fixture(&[("text.gltf", b"this is not glTF")]);
    let (code, _, stderr) = run(&dir, &["lod", "text.gltf", "-o", "out.glb"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("text.gltf") && stderr.contains("not a valid glTF"),
        "{stderr}"
    );
    let (code, _, stderr) = run(&dir, &["lod", "missing.gltf", "-o", "out.glb"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("missing.gltf"), "{stderr}");
}

/// An outside loader: Babylon.js's glTF loader (npm `babylonjs-loaders`, headless in node with a
/// NullEngine) reads the levels through `MSFT_lod`. It loads the coarsest first: allowed `k`
/// levels it shows the k-th coarsest, so the triangle counts it ends with grow with `k` and are
/// our levels' counts in reverse.
#[test]
fn babylon_loads_the_msft_lod_levels_in_order() {
    let Some(mut node) = crate::support::node_script("babylon-lod.cjs", "babylonjs-loaders") else {
        return;
    };
    let dir = Scratch::folder();
    write_gltf(&dir, "s", &sphere(12, 24), |_| {});
    let (code, _, stderr) = run(
        &dir,
        &[
            "lod", "s.gltf", "-o", "out.glb", "--levels", "4", "--report", "r.json",
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    let out = node.arg(dir.join("out.glb")).arg("4").output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .expect("a JSON line");
    let got: serde_json::Value = serde_json::from_str(line).unwrap();
    let loads: Vec<u64> = got["loads"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            l.as_array()
                .unwrap()
                .iter()
                .map(|t| t.as_u64().unwrap())
                .sum()
        })
        .collect();
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    let mut ours: Vec<u64> = report["meshes"][0]["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["triangles"].as_u64().unwrap())
        .collect();
    ours.reverse();
    assert_eq!(loads, ours, "Babylon.js {}", got["babylon"]);
}

/// lodkit_bevy's `gltf_scene` example loads a committed file that `lodkit lod` made of the
/// repository's scene: it is exactly what the scene's writer and `lodkit lod` write now (a
/// change to either, or a hand edit, fails here), and it holds what the example is about.
#[test]
fn committed_gltf_scene_is_what_lodkit_lod_writes() {
    use lodkit_cli::demo::fixtures::gltf_scene::{ASSET, lod_args, write};
    let dir = Scratch::folder();
    write(&dir).unwrap();
    let out = dir.join("lod_scene.glb");
    let mut args = vec!["lod".to_owned(), "scene.gltf".to_owned()];
    args.extend(lod_args(&out));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, stderr) = run(&dir, &args);
    assert_eq!(code, 0, "{stderr}");
    let committed = crate::support::workspace_root().join(ASSET);
    let fix = "regenerate it with `bash scripts/gltf-scene.sh`";
    let on_disk =
        std::fs::read(&committed).unwrap_or_else(|e| panic!("{}: {e}; {fix}", committed.display()));
    assert!(
        same_glb(&on_disk, &std::fs::read(&out).unwrap()),
        "{} is stale or was edited by hand; {fix}",
        committed.display()
    );
    // Three objects with levels (the ball, the two-material tree, the ring), in order, and the
    // crate as it was: one level, no MSFT_lod.
    let (doc, _, _) = gltf::import(&committed).unwrap();
    let levels = |name: &str| {
        let node = doc.nodes().find(|n| n.name() == Some(name)).unwrap();
        node.extension_value("MSFT_lod")
            .map_or(0, |lod| lod["ids"].as_array().unwrap().len())
            + 1
    };
    assert_eq!(["ball", "tree", "ring", "crate"].map(levels), [4, 4, 4, 1]);
    let tree = doc.meshes().find(|m| m.name() == Some("tree")).unwrap();
    assert_eq!(tree.primitives().count(), 2);
    assert_eq!(doc.materials().count(), 5);
}

/// The same scene with impostors (`impostor_scene.glb`, what lodkit_bevy's `gltf_scene` example
/// draws with `--gltf`): the document is what the writer and `lodkit lod --impostor` write now,
/// all but where the buffer's bytes lie (the atlases are PNGs of a GPU's bake: their sizes, and
/// so every buffer view after them, differ with the GPU); each object ends in its impostor, whose
/// extras read as `ImpostorGltfExtras` of 8 x 8 frames of 32 texels.
#[test]
fn committed_impostor_scene_is_what_lodkit_lod_writes() {
    use lodkit_cli::demo::fixtures::gltf_scene::{IMPOSTOR_ASSET, impostor_lod_args, write};
    let _gpu = lodkit_test_gpu!();
    let dir = Scratch::folder();
    write(&dir).unwrap();
    let out = dir.join("impostor_scene.glb");
    let mut args = vec!["lod".to_owned(), "scene.gltf".to_owned()];
    args.extend(impostor_lod_args(&out));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, stderr) = run(&dir, &args);
    assert_eq!(code, 0, "{stderr}");
    let committed = crate::support::workspace_root().join(IMPOSTOR_ASSET);
    let fix = "regenerate it with `bash scripts/gltf-scene.sh`";
    let on_disk =
        std::fs::read(&committed).unwrap_or_else(|e| panic!("{}: {e}; {fix}", committed.display()));
    let document = |glb: &[u8]| {
        let (mut json, _) = glb_parts(glb).expect("a GLB");
        let o = json.as_object_mut().unwrap();
        o.remove("bufferViews");
        o.remove("buffers");
        json
    };
    assert!(
        document(&on_disk) == document(&std::fs::read(&out).unwrap()),
        "{} is stale or was edited by hand; {fix}",
        committed.display()
    );
    let (json, _) = glb_parts(&on_disk).unwrap();
    let nodes = json["nodes"].as_array().unwrap();
    for name in ["ball", "tree", "ring", "crate"] {
        let node = nodes.iter().find(|n| n["name"] == name).unwrap();
        let ids = node["extensions"]["MSFT_lod"]["ids"].as_array().unwrap();
        let last = &nodes[ids.last().unwrap().as_u64().unwrap() as usize];
        let extras: lodkit::impostor::ImpostorGltfExtras =
            serde_json::from_value(last["extras"]["lodkit_impostor"].clone())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((extras.frames, extras.frame_size), (8, 32), "{name}");
    }
}

/// The JSON chunk's value (numbers as the f32 they stand for: how a float is printed differs
/// with serde_json's features, which differ between a test build and `cargo run`) and the
/// binary chunk's bytes of a GLB file.
fn glb_parts(glb: &[u8]) -> Option<(serde_json::Value, &[u8])> {
    fn to_f32(v: serde_json::Value) -> serde_json::Value {
        use serde_json::Value;
        match v {
            Value::Number(n) if !n.is_u64() && !n.is_i64() => {
                serde_json::json!(n.as_f64().map(|x| x as f32))
            }
            Value::Array(a) => Value::Array(a.into_iter().map(to_f32).collect()),
            Value::Object(o) => Value::Object(o.into_iter().map(|(k, v)| (k, to_f32(v))).collect()),
            other => other,
        }
    }
    let word = |at: usize| Some(u32::from_le_bytes(glb.get(at..at + 4)?.try_into().ok()?) as usize);
    let json_len = word(12)?;
    let json = glb.get(20..20 + json_len)?;
    let bin = glb.get(20 + json_len + 8..)?;
    Some((to_f32(serde_json::from_slice(json).ok()?), bin))
}

fn same_glb(a: &[u8], b: &[u8]) -> bool {
    matches!((glb_parts(a), glb_parts(b)), (Some(x), Some(y)) if x == y)
}

/// A file as gltfpack writes it by default: `KHR_mesh_quantization` required (positions as
/// 16-bit integers, the node's scale and translation turning them back into metres; normals as
/// normalized bytes), with a light (`KHR_lights_punctual`, required as well). The gltf crate
/// refuses both required extensions on its own; `lodkit lod` reads the integers, makes the
/// chain in the integers' units and writes a file that requires both again and keeps the light.
#[test]
fn lod_reads_a_quantized_file_and_keeps_what_it_requires() {
    let (positions, indices) = lodkit::lod_chain::uv_sphere(12, 24);
    let quantize = |x: f32| ((x + 1.0) * 1000.0).round() as u16;
    let mut bin: Vec<u8> = Vec::new();
    for p in &positions {
        for &x in p {
            bin.extend(quantize(x).to_le_bytes());
        }
        bin.extend([0, 0]); // each element is 4-byte aligned
    }
    let normals_at = bin.len();
    for p in &positions {
        let n = glam::Vec3::from(*p).normalize();
        bin.extend([
            (n.x * 127.0) as i8 as u8,
            (n.y * 127.0) as i8 as u8,
            (n.z * 127.0) as i8 as u8,
            0,
        ]);
    }
    let indices_at = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let count = positions.len();
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_mesh_quantization", "KHR_lights_punctual"],
        "extensionsRequired": ["KHR_mesh_quantization", "KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"mesh": 0, "name": "ball", "scale": [0.001, 0.001, 0.001],
             "translation": [-1.0, -1.0, -1.0]},
            {"name": "lamp", "extensions": {"KHR_lights_punctual": {"light": 0}}},
        ],
        "meshes": [{"name": "ball", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"uri": "q.bin", "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": normals_at, "byteStride": 8},
            {"buffer": 0, "byteOffset": normals_at, "byteLength": indices_at - normals_at,
             "byteStride": 4},
            {"buffer": 0, "byteOffset": indices_at, "byteLength": bin.len() - indices_at},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5123, "count": count, "type": "VEC3",
             "min": [0, 0, 0], "max": [2000, 2000, 2000]},
            {"bufferView": 1, "componentType": 5120, "normalized": true, "count": count,
             "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": indices.len(), "type": "SCALAR"},
        ],
    });
    let dir = Scratch::folder();
    std::fs::write(dir.join("q.bin"), &bin).unwrap();
    std::fs::write(dir.join("q.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "lod", "q.gltf", "-o", "out.glb", "--levels", "3", "--report", "r.json",
        ],
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    let mesh = &report["meshes"][0];
    // The integers are read as their value (a radius of about 1000 units), not as normalized.
    let radius = mesh["radius"].as_f64().unwrap();
    assert!((900.0..2000.0).contains(&radius), "radius {radius}");
    let triangles: Vec<u64> = mesh["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["triangles"].as_u64().unwrap())
        .collect();
    assert_eq!(triangles.len(), 3, "{report}");
    assert!(triangles.windows(2).all(|w| w[0] > w[1]), "{triangles:?}");
    let out =
        gltf::Gltf::from_slice_without_validation(&std::fs::read(dir.join("out.glb")).unwrap())
            .unwrap();
    let root = out.document.into_json();
    for e in ["KHR_mesh_quantization", "KHR_lights_punctual"] {
        assert!(
            root.extensions_required.iter().any(|r| r == e),
            "{e} required"
        );
    }
    assert!(root.extensions_used.iter().any(|r| r == "MSFT_lod"));
    let lights = root
        .extensions
        .as_ref()
        .and_then(|x| x.khr_lights_punctual.as_ref())
        .map_or(0, |l| l.lights.len());
    assert_eq!(lights, 1, "the light is kept");
}
