//! `lodkit lod` on `EXT_meshopt_compression` (what `gltfpack -c` writes): views compressed by
//! meshoptimizer's encoder in the test (positions as vertex data, normals octahedral-filtered
//! bytes, indices as a triangle stream), read back as the data they were made from, the output
//! written without the extension.

use serde_json::json;

use crate::cli::run;
use crate::support::Scratch;

/// A compressed view's JSON: `bytes` decoded from `source` (at `at` in buffer 0) into buffer
/// 1 at `offset`.
fn view(
    (offset, length): (usize, usize),
    (at, source): (usize, &[u8]),
    (stride, count): (usize, usize),
    (mode, filter): (&str, &str),
) -> serde_json::Value {
    json!({
        "buffer": 1, "byteOffset": offset, "byteLength": length,
        "byteStride": if mode == "ATTRIBUTES" { Some(stride) } else { None },
        "extensions": {"EXT_meshopt_compression": {
            "buffer": 0, "byteOffset": at, "byteLength": source.len(),
            "byteStride": stride, "count": count, "mode": mode, "filter": filter
        }}
    })
}

/// The little-endian f32s or normalized i8s of `count` elements of `n` components at `offset`
/// with `stride` in `bin`.
fn read(
    bin: &[u8],
    (offset, stride): (usize, usize),
    count: usize,
    n: usize,
    i8s: bool,
) -> Vec<Vec<f32>> {
    (0..count)
        .map(|k| {
            let at = offset + k * stride;
            (0..n)
                .map(|c| match i8s {
                    true => (bin[at + c] as i8 as f32 / 127.0).max(-1.0),
                    false => {
                        f32::from_le_bytes(bin[at + 4 * c..at + 4 * c + 4].try_into().unwrap())
                    }
                })
                .collect()
        })
        .collect()
}

/// A sphere whose positions, octahedral normals and indices are compressed as gltfpack does:
/// `lodkit lod` reads the positions bit for bit, the normals within the 8-bit octahedral
/// encoding's error (0.02 of a unit vector, measured below 0.011) of the true ones, and the
/// triangles as they were; it writes levels, and a file that neither uses nor requires the
/// extension (its data is decoded) but still requires `KHR_mesh_quantization` (the normals are
/// bytes). A file whose view decodes to more than 256 times its compressed size, whose
/// compressed bytes lie outside the file, or whose fallback buffer claims 1 TiB, is refused with
/// an error saying so (no allocation of what the file never held).
#[test]
fn lod_reads_meshopt_compressed_views() {
    let (positions, indices) = lodkit::lod_chain::uv_sphere(12, 24);
    let count = positions.len();
    let normals: Vec<[f32; 4]> = positions
        .iter()
        .map(|p| {
            let n = glam::Vec3::from(*p).normalize();
            [n.x, n.y, n.z, 0.0]
        })
        .collect();
    let packed = meshopt::encode_filter_oct::<i8>(&normals, 8);
    let encoded = [
        meshopt::encode_vertex_buffer(&positions).unwrap(),
        meshopt::encode_vertex_buffer(&packed).unwrap(),
        meshopt::encode_index_buffer(&indices, count).unwrap(),
    ];
    let mut source = Vec::new();
    let mut at = Vec::new();
    for e in &encoded {
        at.push(source.len());
        source.extend(e);
        while source.len() % 4 != 0 {
            source.push(0);
        }
    }
    let sizes = [count * 12, count * 4, indices.len() * 4];
    let offsets = [0, sizes[0], sizes[0] + sizes[1]];
    let total = offsets[2] + sizes[2];
    let views: Vec<serde_json::Value> = [
        (12, count, "ATTRIBUTES", "NONE"),
        (4, count, "ATTRIBUTES", "OCTAHEDRAL"),
        (4, indices.len(), "TRIANGLES", "NONE"),
    ]
    .into_iter()
    .enumerate()
    .map(|(k, (stride, n, mode, filter))| {
        view(
            (offsets[k], sizes[k]),
            (at[k], &encoded[k]),
            (stride, n),
            (mode, filter),
        )
    })
    .collect();
    let extensions = ["EXT_meshopt_compression", "KHR_mesh_quantization"];
    let doc = |views: &[serde_json::Value], fallback_length: usize| {
        json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": extensions,
            "extensionsRequired": extensions,
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "name": "ball"}],
            "meshes": [{"name": "ball", "primitives": [
                {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
            "buffers": [
                {"uri": "c.bin", "byteLength": source.len()},
                {"byteLength": fallback_length,
                 "extensions": {"EXT_meshopt_compression": {"fallback": true}}},
            ],
            "bufferViews": views,
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
                 "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0]},
                {"bufferView": 1, "componentType": 5120, "normalized": true, "count": count,
                 "type": "VEC3"},
                {"bufferView": 2, "componentType": 5125, "count": indices.len(),
                 "type": "SCALAR"},
            ],
        })
    };
    let dir = Scratch::folder();
    std::fs::write(dir.join("c.bin"), &source).unwrap();
    std::fs::write(
        dir.join("c.gltf"),
        serde_json::to_vec(&doc(&views, total)).unwrap(),
    )
    .unwrap();
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "lod", "c.gltf", "-o", "out.glb", "--levels", "3", "--report", "r.json",
        ],
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    let triangles: Vec<u64> = report["meshes"][0]["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["triangles"].as_u64().unwrap())
        .collect();
    assert_eq!(
        triangles.first(),
        Some(&(indices.len() as u64 / 3)),
        "{report}"
    );
    assert!(triangles.windows(2).all(|w| w[0] > w[1]), "{triangles:?}");

    // Level 0 is the input's own mesh, its accessors now reading the decoded data.
    let glb = std::fs::read(dir.join("out.glb")).unwrap();
    let out = gltf::Gltf::from_slice_without_validation(&glb).unwrap();
    let bin = out.blob.clone().unwrap();
    let root = out.document.as_json();
    for list in [&root.extensions_used, &root.extensions_required] {
        assert!(
            !list.iter().any(|e| e == "EXT_meshopt_compression"),
            "{list:?}"
        );
    }
    assert!(
        root.extensions_required
            .iter()
            .any(|e| e == "KHR_mesh_quantization")
    );
    let place = |accessor: usize| {
        let a = &root.accessors[accessor];
        let v = &root.buffer_views[a.buffer_view.unwrap().value()];
        assert!(
            v.extensions.as_ref().is_none_or(|e| e.others.is_empty()),
            "{v:?}"
        );
        let offset =
            v.byte_offset.map_or(0, |o| o.0 as usize) + a.byte_offset.map_or(0, |o| o.0 as usize);
        (offset, v.byte_stride.map_or(0, |s| s.0))
    };
    let read_positions = read(&bin, place(0), count, 3, false);
    for (got, want) in read_positions.iter().zip(&positions) {
        assert_eq!(got.as_slice(), want.as_slice(), "positions bit for bit");
    }
    let worst = read(&bin, place(1), count, 3, true)
        .iter()
        .zip(&normals)
        .map(|(got, want)| {
            (glam::Vec3::from_slice(got) - glam::Vec3::from_slice(&want[..3])).length()
        })
        .fold(0.0f32, f32::max);
    assert!(worst < 0.02, "normals off by up to {worst}");
    let (offset, _) = place(2);
    let read_indices: Vec<u32> = (0..indices.len())
        .map(|k| u32::from_le_bytes(bin[offset + 4 * k..offset + 4 * k + 4].try_into().unwrap()))
        .collect();
    assert_eq!(read_indices, indices, "the triangles as they were");

    // Refused, saying why: a count past the bound, bytes outside the file, a forged fallback
    // length.
    let mut big = views.clone();
    big[0]["extensions"]["EXT_meshopt_compression"]["count"] = json!(1u64 << 40);
    let mut outside = views.clone();
    outside[2]["extensions"]["EXT_meshopt_compression"]["byteOffset"] = json!(source.len());
    for (name, views, fallback, says) in [
        ("big", big, total, "bufferView 0 (EXT_meshopt_compression)"),
        ("outside", outside, total, "are not in the file"),
        (
            "forged",
            views.clone(),
            1usize << 40,
            "fallback buffers claim",
        ),
    ] {
        let file = format!("{name}.gltf");
        let text = serde_json::to_vec(&doc(&views, fallback)).unwrap();
        std::fs::write(dir.join(&file), text).unwrap();
        let (code, stdout, stderr) = run(&dir, &["lod", &file, "-o", "x.glb"]);
        assert_eq!(code, 1, "{name}: {stdout}{stderr}");
        assert!(stderr.contains(says), "{name}: {stderr}");
    }
}
