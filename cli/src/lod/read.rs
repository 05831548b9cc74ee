//! Reading the triangle primitives of a glTF / GLB file, with every accessor checked against
//! its buffer before it is read (a short buffer is an error naming the accessor, not a panic).

use std::collections::HashMap;
use std::path::Path;

use gltf::Semantic;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::compressed;

/// One triangle primitive, as a list of vertices and a triangle list.
pub struct Primitive {
    /// Index of the primitive in its mesh.
    pub index: usize,
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<u32>,
    /// For each vertex, the vertex of the file's accessors it came from (differs when a
    /// non-indexed primitive was welded).
    pub file_vertex: Vec<u32>,
    /// Attributes other than POSITION, NORMAL and TEXCOORD_0 that are carried: (semantic name,
    /// accessor index).
    pub carried: Vec<(String, usize)>,
}

/// A mesh's triangle primitives and what was left out.
pub struct MeshInput {
    pub primitives: Vec<Primitive>,
    /// Primitives that are not triangles (carried unchanged into every level).
    pub other_primitives: Vec<usize>,
    pub warnings: Vec<String>,
}

/// Extensions a file may require that `lodkit lod` reads itself, which the gltf crate refuses
/// when they are required: `KHR_mesh_quantization` (attributes as integers, normalized or not,
/// which [`floats`] reads; what gltfpack writes by default). `EXT_meshopt_compression`
/// (`gltfpack -c`) is decoded on reading ([`compressed`]) and not written again.
const READ_HERE: [&str; 1] = ["KHR_mesh_quantization"];

/// A file as `lodkit lod` reads it.
pub struct Opened {
    pub document: gltf::Document,
    pub buffers: Vec<gltf::buffer::Data>,
    /// Extensions the file requires that were taken out of `extensionsRequired` for the gltf
    /// crate ([`READ_HERE`]): the output requires them again.
    pub required_here: Vec<String>,
}

/// Loads the document and its buffers.
pub fn open(path: &Path) -> Result<Opened, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read it: {e}"))?;
    check_positions(&bytes)?;
    let invalid = |e: gltf::Error| format!("not a valid glTF/GLB: {e}");
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).map_err(invalid)?;
    let mut root = gltf.document.into_json();
    // Decoded here, and written without: the output neither uses nor requires it.
    let taken = compressed::take(&mut root)?;
    let (required_here, other): (Vec<String>, Vec<String>) = root
        .extensions_required
        .drain(..)
        .partition(|e| READ_HERE.contains(&e.as_str()));
    root.extensions_required = other;
    // Validated here as `Gltf::from_slice` would have, without the extensions read above.
    let document = gltf::Document::from_json(root).map_err(invalid)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let buffers = if taken.views.is_empty() {
        gltf::import_buffers(&document, Some(base), gltf.blob)
            .map_err(|e| format!("cannot load its buffers: {e}"))?
    } else {
        compressed::load_buffers(&document, base, gltf.blob, &taken)?
    };
    Ok(Opened {
        document,
        buffers,
        required_here,
    })
}

/// That every primitive's POSITION names an accessor the file has. The gltf crate's validation
/// indexes the accessor list with it unchecked (gltf-json 1.4.1, `primitive_validate_hook`) and
/// panics on one past the end, so this is looked at first, in the JSON as it is. A file that is
/// not JSON (or not a GLB) is left to the gltf crate to refuse.
fn check_positions(bytes: &[u8]) -> Result<(), String> {
    let json = if bytes.starts_with(b"glTF") {
        match gltf::Glb::from_slice(bytes) {
            Ok(glb) => glb.json.into_owned(),
            Err(_) => return Ok(()),
        }
    } else {
        bytes.to_vec()
    };
    let Ok(root) = serde_json::from_slice::<serde_json::Value>(&json) else {
        return Ok(());
    };
    let accessors = root["accessors"].as_array().map_or(0, Vec::len);
    let meshes = root["meshes"]
        .as_array()
        .map(Vec::as_slice)
        .unwrap_or_default();
    for (m, mesh) in meshes.iter().enumerate() {
        let name = mesh["name"].as_str().unwrap_or("");
        let primitives = mesh["primitives"]
            .as_array()
            .map(Vec::as_slice)
            .unwrap_or_default();
        for (p, primitive) in primitives.iter().enumerate() {
            let position = &primitive["attributes"]["POSITION"];
            if let Some(index) = position.as_u64()
                && index >= accessors as u64
            {
                return Err(format!(
                    "mesh {m} '{name}' primitive {p}: POSITION is accessor {index}, but the \
                     file has {accessors} accessors"
                ));
            }
        }
    }
    Ok(())
}

/// The bytes of element `k` of `accessor` (checked by [`check_accessor`] first).
pub fn element<'b>(
    accessor: &gltf::Accessor,
    buffers: &'b [gltf::buffer::Data],
    k: usize,
) -> &'b [u8] {
    let view = accessor.view().expect("checked");
    let stride = view.stride().unwrap_or(accessor.size());
    let start = view.offset() + accessor.offset() + k * stride;
    &buffers[view.buffer().index()][start..start + accessor.size()]
}

/// That `accessor` has a view, no sparse part, at least one element and lies inside its view
/// and its view inside the buffer's data.
pub fn check_accessor(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    what: &str,
) -> Result<(), String> {
    let name = format!("{what} (accessor {})", accessor.index());
    if accessor.sparse().is_some() {
        return Err(format!(
            "{name} is sparse, which `lodkit lod` does not read"
        ));
    }
    let Some(view) = accessor.view() else {
        return Err(format!("{name} has no buffer view"));
    };
    if accessor.count() == 0 {
        return Err(format!("{name} has no elements"));
    }
    let data = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
    if view.offset() + view.length() > data {
        return Err(format!(
            "{name}: buffer view {} (bytes {}..{}) reaches past the end of buffer {} ({data} bytes)",
            view.index(),
            view.offset(),
            view.offset() + view.length(),
            view.buffer().index()
        ));
    }
    let stride = view.stride().unwrap_or(accessor.size());
    let end = accessor.offset() + stride * (accessor.count() - 1) + accessor.size();
    if end > view.length() {
        return Err(format!(
            "{name}: {} elements need {end} bytes, buffer view {} has {}",
            accessor.count(),
            view.index(),
            view.length()
        ));
    }
    Ok(())
}

fn floats(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    what: &str,
    dims: Dimensions,
) -> Result<Vec<Vec<f32>>, String> {
    check_accessor(accessor, buffers, what)?;
    if accessor.dimensions() != dims {
        return Err(format!(
            "{what} (accessor {}) is {:?}, not {dims:?}",
            accessor.index(),
            accessor.dimensions()
        ));
    }
    let n = dims.multiplicity();
    let normalized = accessor.normalized();
    // glTF's decoding of normalized integers (signed: max(c / (2^(b-1) - 1), -1)); integers
    // that are not normalized (KHR_mesh_quantization's positions and texture coordinates) are
    // their value.
    let read = |b: &[u8], k: usize| -> f32 {
        let i16_at = |k: usize| i16::from_le_bytes([b[k * 2], b[k * 2 + 1]]);
        let u16_at = |k: usize| u16::from_le_bytes([b[k * 2], b[k * 2 + 1]]);
        match (accessor.data_type(), normalized) {
            (DataType::F32, _) => {
                f32::from_le_bytes(b[k * 4..k * 4 + 4].try_into().expect("4 bytes"))
            }
            (DataType::U8, true) => f32::from(b[k]) / 255.0,
            (DataType::U16, true) => f32::from(u16_at(k)) / 65535.0,
            (DataType::I8, true) => (f32::from(b[k] as i8) / 127.0).max(-1.0),
            (DataType::I16, true) => (f32::from(i16_at(k)) / 32767.0).max(-1.0),
            (DataType::U8, false) => f32::from(b[k]),
            (DataType::U16, false) => f32::from(u16_at(k)),
            (DataType::I8, false) => f32::from(b[k] as i8),
            (DataType::I16, false) => f32::from(i16_at(k)),
            (DataType::U32, _) => f32::NAN,
        }
    };
    if accessor.data_type() == DataType::U32 {
        return Err(format!(
            "{what} (accessor {}) holds U32, which no glTF vertex attribute may",
            accessor.index()
        ));
    }
    Ok((0..accessor.count())
        .map(|k| {
            let b = element(accessor, buffers, k);
            (0..n).map(|c| read(b, c)).collect()
        })
        .collect())
}

fn indices(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    what: &str,
) -> Result<Vec<u32>, String> {
    check_accessor(accessor, buffers, what)?;
    let ok = accessor.dimensions() == Dimensions::Scalar
        && matches!(
            accessor.data_type(),
            DataType::U8 | DataType::U16 | DataType::U32
        );
    if !ok {
        return Err(format!(
            "{what} (accessor {}) is not a scalar of unsigned integers",
            accessor.index()
        ));
    }
    Ok((0..accessor.count())
        .map(|k| {
            let b = element(accessor, buffers, k);
            match accessor.data_type() {
                DataType::U8 => u32::from(b[0]),
                DataType::U16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        })
        .collect())
}

/// A strip or fan as a triangle list (glTF's orders).
fn to_list(mode: Mode, strip: &[u32]) -> Vec<u32> {
    let mut out = Vec::new();
    for k in 2..strip.len() {
        let t = match mode {
            Mode::TriangleStrip if k.is_multiple_of(2) => [strip[k - 2], strip[k - 1], strip[k]],
            Mode::TriangleStrip => [strip[k - 1], strip[k - 2], strip[k]],
            _ => [strip[0], strip[k - 1], strip[k]],
        };
        out.extend(t);
    }
    out
}

/// The triangle primitives of `mesh`.
pub fn mesh(mesh: &gltf::Mesh, buffers: &[gltf::buffer::Data]) -> Result<MeshInput, String> {
    let mut input = MeshInput {
        primitives: Vec::new(),
        other_primitives: Vec::new(),
        warnings: Vec::new(),
    };
    for (index, prim) in mesh.primitives().enumerate() {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            input.other_primitives.push(index);
            continue;
        }
        let what = |s: &str| format!("primitive {index} {s}");
        let position = prim
            .get(&Semantic::Positions)
            .ok_or_else(|| format!("primitive {index} has no POSITION"))?;
        let positions = floats(&position, buffers, &what("POSITION"), Dimensions::Vec3)?;
        let count = positions.len();
        let same_count = |a: &gltf::Accessor, name: &str| {
            if a.count() == count {
                Ok(())
            } else {
                Err(format!(
                    "primitive {index} {name} has {} elements, POSITION {count}",
                    a.count()
                ))
            }
        };
        let mut normals = None;
        let mut uvs = None;
        let mut carried = Vec::new();
        for (semantic, accessor) in prim.attributes() {
            same_count(&accessor, &semantic.to_string())?;
            match semantic {
                Semantic::Positions => {}
                Semantic::Normals => {
                    normals = Some(floats(
                        &accessor,
                        buffers,
                        &what("NORMAL"),
                        Dimensions::Vec3,
                    )?)
                }
                Semantic::TexCoords(0) => {
                    uvs = Some(floats(
                        &accessor,
                        buffers,
                        &what("TEXCOORD_0"),
                        Dimensions::Vec2,
                    )?)
                }
                other => {
                    check_accessor(&accessor, buffers, &what(&other.to_string()))?;
                    carried.push((other.to_string(), accessor.index()));
                }
            }
        }
        if prim.morph_targets().len() > 0 {
            input.warnings.push(format!(
                "primitive {index}: {} morph targets dropped from the generated levels",
                prim.morph_targets().len()
            ));
        }
        let (list, welded) = match prim.indices() {
            Some(a) => {
                let raw = indices(&a, buffers, &what("indices"))?;
                (to_list_or_keep(mode, raw), None)
            }
            None => {
                let (order, file_vertex) = weld(prim.attributes().map(|(_, a)| a), buffers);
                (to_list_or_keep(mode, order), Some(file_vertex))
            }
        };
        let file_vertex: Vec<u32> = welded.unwrap_or_else(|| (0..count as u32).collect());
        let pick3 = |v: &[Vec<f32>]| -> Vec<[f32; 3]> {
            file_vertex
                .iter()
                .map(|&k| {
                    let x = &v[k as usize];
                    [x[0], x[1], x[2]]
                })
                .collect()
        };
        input.primitives.push(Primitive {
            index,
            positions: pick3(&positions),
            normals: normals.as_deref().map(pick3),
            uvs: uvs.as_deref().map(|v| {
                file_vertex
                    .iter()
                    .map(|&k| [v[k as usize][0], v[k as usize][1]])
                    .collect()
            }),
            indices: list,
            file_vertex,
            carried,
        });
    }
    if input.primitives.is_empty() {
        return Err(if input.other_primitives.is_empty() {
            "it has no primitives".to_owned()
        } else {
            "it has no triangles (points or lines only)".to_owned()
        });
    }
    if !input.other_primitives.is_empty() {
        input.warnings.push(format!(
            "primitives {:?} are points or lines: carried unchanged into every level",
            input.other_primitives
        ));
    }
    Ok(input)
}

fn to_list_or_keep(mode: Mode, indices: Vec<u32>) -> Vec<u32> {
    match mode {
        Mode::Triangles => indices,
        _ => to_list(mode, &indices),
    }
}

/// A non-indexed primitive indexed: vertices equal in every attribute become one. Returns the
/// index list into the welded vertices and, per welded vertex, its first file vertex.
fn weld<'a>(
    attributes: impl Iterator<Item = gltf::Accessor<'a>>,
    buffers: &[gltf::buffer::Data],
) -> (Vec<u32>, Vec<u32>) {
    let attributes: Vec<gltf::Accessor> = attributes.collect();
    let count = attributes.first().map_or(0, |a| a.count());
    let mut seen: HashMap<Vec<u8>, u32> = HashMap::new();
    let mut file_vertex = Vec::new();
    let order = (0..count)
        .map(|k| {
            let key: Vec<u8> = attributes
                .iter()
                .flat_map(|a| element(a, buffers, k).iter().copied())
                .collect();
            *seen.entry(key).or_insert_with(|| {
                file_vertex.push(k as u32);
                file_vertex.len() as u32 - 1
            })
        })
        .collect();
    (order, file_vertex)
}
