//! Writing the input document back with each mesh's levels as nodes tied together by
//! `MSFT_lod`, through the gltf crate's JSON types and GLB container.

use std::borrow::Cow;
use std::path::Path;

use gltf::json::{self, Index, validation::Checked};

mod impostor;

pub use impostor::ImpostorLevel;

/// One generated primitive of a level.
pub struct LevelPrimitive<'a> {
    /// The primitive of the input mesh it stands for (material, carried attributes).
    pub primitive: usize,
    pub positions: &'a [[f32; 3]],
    pub normals: Option<&'a [[f32; 3]]>,
    pub uvs: Option<&'a [[f32; 2]]>,
    pub indices: &'a [u32],
    /// For each vertex, the element of the input's accessors it came from.
    pub file_vertices: Vec<u32>,
    /// Carried attributes: (semantic, input accessor).
    pub carried: &'a [(String, usize)],
}

/// What [`Output::embed_images`] did not embed.
#[derive(Debug, Default)]
pub struct Embedded {
    /// One line per image left as it was (unreadable, an unknown type, outside the folder).
    pub warnings: Vec<String>,
    /// Relative paths of images left as URIs that the caller copies beside the output (KTX2
    /// and WebP files a texture names as its core source).
    pub copies: Vec<String>,
}

/// The output document and its one binary buffer.
pub struct Output {
    root: json::Root,
    bin: Vec<u8>,
}

fn pad4(bin: &mut Vec<u8>) {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
}

impl Output {
    /// The input document with all its buffers concatenated into one.
    pub fn new(document: gltf::Document, buffers: &[gltf::buffer::Data]) -> Self {
        let mut root = document.into_json();
        let mut bin = Vec::new();
        let mut starts = Vec::new();
        for b in buffers {
            pad4(&mut bin);
            starts.push(bin.len() as u64);
            bin.extend_from_slice(b);
        }
        for view in &mut root.buffer_views {
            let start = starts[view.buffer.value()];
            view.byte_offset = Some((view.byte_offset.map_or(0, |o| o.0) + start).into());
            view.buffer = Index::new(0);
        }
        root.buffers.clear();
        Output { root, bin }
    }

    /// Requires `extensions` again (those the reader took out of `extensionsRequired` because
    /// it reads them itself: the input's own accessors still use them).
    pub fn require(&mut self, extensions: &[String]) {
        for e in extensions {
            if !self.root.extensions_required.contains(e) {
                self.root.extensions_required.push(e.clone());
            }
        }
    }

    /// Embeds every image the input names by a relative URI (a file beside it, `base` its
    /// folder) in the output's binary buffer (a buffer view and a MIME type in place of the
    /// URI), so the output is whole wherever it is written, `.glb` or `.gltf`. A `data:` URI
    /// stays as it is. Returns a warning for each image left as it was (a file that cannot be
    /// read, or of a type glTF does not embed by MIME type: PNG, JPEG, WebP, KTX2), and the
    /// KTX2 and WebP files a texture names as its core source, which keep their URI (a core
    /// source may only be PNG or JPEG by MIME type) and are to be copied beside the output.
    pub fn embed_images(&mut self, base: &std::path::Path) -> Embedded {
        let mut embedded = Embedded::default();
        let warnings = &mut embedded.warnings;
        // Images a texture names as its core `source`: glTF allows only PNG and JPEG there
        // (KTX2 and WebP belong in KHR_texture_basisu and EXT_texture_webp).
        let core_sources: Vec<usize> = self
            .root
            .textures
            .iter()
            .map(|t| t.source.value())
            .collect();
        for i in 0..self.root.images.len() {
            let Some(uri) = self.root.images[i].uri.clone() else {
                continue;
            };
            if uri.starts_with("data:") {
                continue;
            }
            let Some(path) = local_path(&uri) else {
                warnings.push(format!(
                    "image {i} '{uri}': outside the input's folder, left as a URI"
                ));
                continue;
            };
            let Some(mime) = mime_type(&path) else {
                warnings.push(format!(
                    "image {i} '{uri}': not PNG, JPEG, WebP or KTX2, left as a URI (copy it \
                     beside the output)"
                ));
                continue;
            };
            if matches!(mime, "image/ktx2" | "image/webp") && core_sources.contains(&i) {
                // Embedded, it would carry a MIME type a core source may not have: the file is
                // copied beside the output instead, at the same relative path.
                embedded.copies.push(path.clone());
                continue;
            }
            let bytes = match std::fs::read(base.join(&path)) {
                Ok(b) => b,
                Err(e) => {
                    warnings.push(format!(
                        "image {i} '{uri}': cannot read it ({e}), left as a URI"
                    ));
                    continue;
                }
            };
            pad4(&mut self.bin);
            let offset = self.bin.len();
            self.bin.extend_from_slice(&bytes);
            let view = self.root.push(json::buffer::View {
                buffer: Index::new(0),
                byte_length: bytes.len().into(),
                byte_offset: Some(offset.into()),
                byte_stride: None,
                name: None,
                target: None,
                extensions: None,
                extras: Default::default(),
            });
            let image = &mut self.root.images[i];
            image.uri = None;
            image.buffer_view = Some(view);
            image.mime_type = Some(json::image::MimeType(mime.to_owned()));
        }
        embedded
    }

    fn view(&mut self, bytes: &[u8], target: json::buffer::Target) -> Index<json::buffer::View> {
        self.strided_view(bytes, Some(target), None)
    }

    /// `bytes` appended to the buffer (4-aligned) as a view, with a target (none for an image)
    /// and a stride.
    fn strided_view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
        stride: Option<usize>,
    ) -> Index<json::buffer::View> {
        pad4(&mut self.bin);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: bytes.len().into(),
            byte_offset: Some(offset.into()),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target: target.map(Checked::Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    fn floats<const N: usize>(
        &mut self,
        values: &[[f32; N]],
        bounds: bool,
    ) -> Index<json::Accessor> {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let view = self.view(&bytes, json::buffer::Target::ArrayBuffer);
        let (min, max) = if bounds {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for v in values {
                for ((l, h), x) in lo.iter_mut().zip(&mut hi).zip(v) {
                    *l = l.min(*x);
                    *h = h.max(*x);
                }
            }
            (
                Some(json::Value::from(lo.to_vec())),
                Some(json::Value::from(hi.to_vec())),
            )
        } else {
            (None, None)
        };
        let type_ = match N {
            2 => json::accessor::Type::Vec2,
            _ => json::accessor::Type::Vec3,
        };
        self.accessor(
            view,
            values.len(),
            json::accessor::ComponentType::F32,
            type_,
            min,
            max,
        )
    }

    fn accessor(
        &mut self,
        view: Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        min: Option<json::Value>,
        max: Option<json::Value>,
    ) -> Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: count.into(),
            component_type: Checked::Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Checked::Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A copy of input accessor `source` holding only `elements`, in that order.
    fn carried(&mut self, source: usize, elements: &[u32]) -> Index<json::Accessor> {
        let original = self.root.accessors[source].clone();
        let view_index = original.buffer_view.expect("checked on reading");
        let view = &self.root.buffer_views[view_index.value()];
        let size = element_size(&original);
        let stride = view.byte_stride.map_or(size, |s| s.0);
        let start = (view.byte_offset.map_or(0, |o| o.0) + original.byte_offset.map_or(0, |o| o.0))
            as usize;
        // Vertex attribute elements start on 4-byte boundaries.
        let padded = size.div_ceil(4) * 4;
        let mut bytes = Vec::with_capacity(elements.len() * padded);
        for &e in elements {
            let at = start + e as usize * stride;
            bytes.extend_from_slice(&self.bin[at..at + size]);
            bytes.resize(bytes.len() + padded - size, 0);
        }
        let stride = (padded != size).then_some(padded);
        let view = self.strided_view(&bytes, Some(json::buffer::Target::ArrayBuffer), stride);
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: elements.len().into(),
            min: None,
            max: None,
            sparse: None,
            ..original
        })
    }

    /// Adds a mesh for each generated level of input mesh `mesh` (levels 1.. of `levels`), then
    /// the `impostor` level if any, a node for each beside every node that shows `mesh`, and
    /// `MSFT_lod` with the screen coverages on those nodes. Returns the new nodes' indices per
    /// input node.
    pub fn add_levels(
        &mut self,
        mesh: usize,
        levels: &[Vec<LevelPrimitive>],
        impostor: Option<&ImpostorLevel>,
        coverage: &[f32],
    ) -> Vec<Vec<usize>> {
        let source = self.root.meshes[mesh].clone();
        let base = source.name.clone().unwrap_or_else(|| format!("mesh{mesh}"));
        let mut lod_meshes = Vec::new();
        for (i, level) in levels.iter().enumerate().skip(1) {
            let mut primitives = Vec::new();
            for p in level {
                let original = &source.primitives[p.primitive];
                let mut attributes = std::collections::BTreeMap::new();
                let pos = self.floats(p.positions, true);
                attributes.insert(Checked::Valid(json::mesh::Semantic::Positions), pos);
                if let Some(n) = p.normals {
                    let a = self.floats(n, false);
                    attributes.insert(Checked::Valid(json::mesh::Semantic::Normals), a);
                }
                if let Some(uv) = p.uvs {
                    let a = self.floats(uv, false);
                    attributes.insert(Checked::Valid(json::mesh::Semantic::TexCoords(0)), a);
                }
                for (semantic, accessor) in p.carried {
                    let a = self.carried(*accessor, &p.file_vertices);
                    let key = original
                        .attributes
                        .keys()
                        .find(|k| matches!(k, Checked::Valid(s) if s.to_string() == *semantic))
                        .cloned()
                        .expect("carried from this primitive");
                    attributes.insert(key, a);
                }
                let bytes: Vec<u8> = p.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
                let view = self.view(&bytes, json::buffer::Target::ElementArrayBuffer);
                let indices = self.accessor(
                    view,
                    p.indices.len(),
                    json::accessor::ComponentType::U32,
                    json::accessor::Type::Scalar,
                    None,
                    None,
                );
                primitives.push(json::mesh::Primitive {
                    attributes,
                    extensions: None,
                    extras: Default::default(),
                    indices: Some(indices),
                    material: original.material,
                    mode: Checked::Valid(json::mesh::Mode::Triangles),
                    targets: None,
                });
            }
            // Points and lines stay as they are in every level.
            for (k, p) in source.primitives.iter().enumerate() {
                if level.iter().all(|l| l.primitive != k) && !is_triangles(p) {
                    primitives.push(p.clone());
                }
            }
            lod_meshes.push(self.root.push(json::Mesh {
                extensions: None,
                extras: Default::default(),
                name: Some(format!("{base}_LOD{i}")),
                primitives,
                weights: None,
            }));
        }
        lod_meshes.extend(impostor.map(|i| i.mesh));
        let showing: Vec<usize> = (0..self.root.nodes.len())
            .filter(|&n| self.root.nodes[n].mesh.map(|m| m.value()) == Some(mesh))
            .collect();
        let mut added = Vec::new();
        for n in showing {
            let node = self.root.nodes[n].clone();
            let ids: Vec<usize> = lod_meshes
                .iter()
                .enumerate()
                .map(|(k, &m)| {
                    let name = node.name.clone().unwrap_or_else(|| format!("node{n}"));
                    let is_impostor = impostor.is_some() && k + 1 == lod_meshes.len();
                    let extras = impostor.filter(|_| is_impostor).map(|i| {
                        json::extras::RawValue::from_string(i.extras.to_string()).expect("JSON")
                    });
                    self.root
                        .push(json::Node {
                            mesh: Some(m),
                            name: Some(format!("{name}_LOD{}", k + 1)),
                            children: None,
                            extensions: None,
                            // A card has no joints: the impostor of a skinned mesh shows its
                            // bind pose, unskinned.
                            skin: if is_impostor { None } else { node.skin },
                            extras,
                            camera: None,
                            weights: None,
                            ..node.clone()
                        })
                        .value()
                })
                .collect();
            let lod = json::Value::from(serde_json_map([("ids", json::Value::from(ids.clone()))]));
            let node = &mut self.root.nodes[n];
            node.extensions
                .get_or_insert_with(Default::default)
                .others
                .insert("MSFT_lod".to_owned(), lod);
            let extras =
                serde_json_map([("MSFT_screencoverage", json::Value::from(coverage.to_vec()))]);
            node.extras = Some(
                json::extras::RawValue::from_string(json::Value::from(extras).to_string())
                    .expect("JSON"),
            );
            added.push(ids);
        }
        if !self.root.extensions_used.iter().any(|e| e == "MSFT_lod") {
            self.root.extensions_used.push("MSFT_lod".to_owned());
        }
        added
    }

    /// Writes the document: GLB when `path` ends in `.glb`, else glTF JSON with the buffer in
    /// `<stem>.bin` beside it.
    pub fn write(mut self, path: &Path) -> Result<(), String> {
        pad4(&mut self.bin);
        let glb = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
        let uri = (!glb).then(|| {
            let stem = path
                .file_stem()
                .map_or("out".into(), |s| s.to_string_lossy());
            format!("{stem}.bin")
        });
        self.root.buffers = vec![json::Buffer {
            byte_length: self.bin.len().into(),
            name: None,
            uri: uri.clone(),
            extensions: None,
            extras: Default::default(),
        }];
        let text = without_nulls(&self.root.to_vec().map_err(|e| e.to_string())?)?;
        let io = |e: std::io::Error| format!("cannot write `{}`: {e}", path.display());
        if glb {
            let glb = gltf::binary::Glb {
                header: gltf::binary::Header {
                    magic: *b"glTF",
                    version: 2,
                    length: 0, // to_vec computes it
                },
                json: Cow::Owned(text),
                bin: Some(Cow::Owned(self.bin)),
            };
            let bytes = glb.to_vec().map_err(|e| e.to_string())?;
            std::fs::write(path, bytes).map_err(io)
        } else {
            std::fs::write(path, text).map_err(io)?;
            let bin_path = path.with_file_name(uri.expect("set for .gltf"));
            std::fs::write(bin_path, &self.bin).map_err(io)
        }
    }
}

/// The JSON `text` with every `null` member left out (outside `extras`, which are the app's):
/// the gltf crate writes an absent optional member of some extensions as `null`
/// (`KHR_texture_transform.texCoord`, `KHR_materials_volume.attenuationDistance`), which the
/// Khronos validator rejects; glTF gives `null` no meaning anywhere.
fn without_nulls(text: &[u8]) -> Result<Vec<u8>, String> {
    fn strip(value: &mut json::Value) {
        match value {
            json::Value::Object(members) => {
                members.retain(|_, v| !v.is_null());
                for (key, v) in members.iter_mut() {
                    if key != "extras" {
                        strip(v);
                    }
                }
            }
            json::Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut value: json::Value = serde_json::from_slice(text).map_err(|e| e.to_string())?;
    strip(&mut value);
    serde_json::to_vec(&value).map_err(|e| e.to_string())
}

fn serde_json_map<const N: usize>(
    entries: [(&str, json::Value); N],
) -> serde_json::Map<String, json::Value> {
    entries
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect()
}

fn is_triangles(p: &json::mesh::Primitive) -> bool {
    matches!(
        p.mode,
        Checked::Valid(
            json::mesh::Mode::Triangles
                | json::mesh::Mode::TriangleStrip
                | json::mesh::Mode::TriangleFan
        )
    )
}

/// Bytes of one element of `accessor`.
fn element_size(accessor: &json::Accessor) -> usize {
    let component = match &accessor.component_type {
        Checked::Valid(t) => match t.0 {
            json::accessor::ComponentType::I8 | json::accessor::ComponentType::U8 => 1,
            json::accessor::ComponentType::I16 | json::accessor::ComponentType::U16 => 2,
            _ => 4,
        },
        Checked::Invalid => 4,
    };
    let count = match &accessor.type_ {
        Checked::Valid(t) => t.multiplicity(),
        Checked::Invalid => 1,
    };
    component * count
}

/// The path of a URI naming a file at or below the input's folder, `%XX` escapes decoded;
/// `None` for one that climbs out of it or names an absolute path (reading it would take some
/// other local file into the output).
pub(super) fn local_path(uri: &str) -> Option<String> {
    let path = percent_decoded(uri);
    let inside = std::path::Path::new(&path).components().all(|c| {
        matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    });
    inside.then_some(path)
}

/// A relative URI's path: `%XX` escapes decoded (a malformed one is kept as written).
fn percent_decoded(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        let hex = bytes
            .get(k + 1..k + 3)
            .filter(|h| h.iter().all(u8::is_ascii_hexdigit))
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[k], hex) {
            (b'%', Some(b)) => {
                out.push(b);
                k += 3;
            }
            (b, _) => {
                out.push(b);
                k += 1;
            }
        }
    }
    String::from_utf8(out).unwrap_or_else(|_| uri.to_owned())
}

/// The MIME type glTF embeds an image file as, by its extension.
fn mime_type(path: &str) -> Option<&'static str> {
    let ext = std::path::Path::new(path)
        .extension()?
        .to_str()?
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some("image/png"),
        "jpg" | "jpeg" => Some("image/jpeg"),
        "webp" => Some("image/webp"),
        "ktx2" => Some("image/ktx2"),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_are_percent_decoded_and_typed() {
        assert_eq!(
            percent_decoded("Flight%20Helmet/a%2Bb.png"),
            "Flight Helmet/a+b.png"
        );
        assert_eq!(percent_decoded("50%.png"), "50%.png", "a lone % stays");
        assert_eq!(
            percent_decoded("a%+5.png"),
            "a%+5.png",
            "two hex digits or nothing"
        );
        assert_eq!(mime_type("x/Y.JPG"), Some("image/jpeg"));
        assert_eq!(mime_type("x.ktx2"), Some("image/ktx2"));
        assert_eq!(mime_type("x.dds"), None);
    }
}
