//! `EXT_meshopt_compression` (what `gltfpack -c` writes): buffer views whose bytes are stored
//! compressed in another buffer, decoded here with meshoptimizer's own decoders (the `meshopt`
//! crate) into the view's place in its fallback buffer, so that the rest of `lodkit lod` reads
//! plain accessors and writes a file without the extension. Everything is checked against the
//! file before a decoder sees it: bounds, strides, counts, modes and filters, a decoded size at
//! most [`MAX_EXPANSION`] times the compressed one (4 KiB at least), and fallback buffers at most
//! that many times the bytes the file's other buffers hold (a zero-filled stream compresses to
//! almost nothing, and a length taken on trust would allocate what the file never held).

use gltf::json;
use serde_json::Value;

/// The extension's name.
pub const EXTENSION: &str = "EXT_meshopt_compression";

/// How many times its compressed size a view may decode to. meshoptimizer's vertex codec spends
/// at least 2 bits per 16-byte group of a vertex byte column (1/64), its index codec at least
/// 4 bits per triangle; 256 leaves room for the stream headers while bounding the work.
pub const MAX_EXPANSION: usize = 256;

/// One compressed view, as the extension describes it.
struct Compressed {
    view: usize,
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
}

/// Whether `buffer` is a fallback buffer (no data of its own: its views are decoded into it).
pub fn is_fallback(buffer: &json::Buffer) -> bool {
    buffer
        .extensions
        .as_ref()
        .and_then(|e| e.others.get(EXTENSION))
        .is_some_and(|e| e["fallback"] == Value::Bool(true))
}

/// What [`take`] took out of a document.
pub struct Taken {
    /// The compressed views, to [`decode`] once the buffers are loaded.
    pub views: Vec<CompressedView>,
    /// Per buffer, whether it is a fallback buffer (no data of its own).
    pub fallback: Vec<bool>,
}

/// Takes the extension out of `root` (views, buffers, `extensionsUsed`, `extensionsRequired`)
/// and returns what it said.
pub fn take(root: &mut json::Root) -> Result<Taken, String> {
    let fallback = root.buffers.iter().map(is_fallback).collect();
    let mut out = Vec::new();
    for (v, view) in root.buffer_views.iter_mut().enumerate() {
        let Some(ext) = view
            .extensions
            .as_mut()
            .and_then(|e| e.others.remove(EXTENSION))
        else {
            continue;
        };
        let field = |name: &str| -> Result<usize, String> {
            ext[name]
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| {
                    format!("bufferView {v}: {EXTENSION}.{name} is missing or not a count")
                })
        };
        let text = |name: &str, default: &str| {
            ext.get(name)
                .map_or(Some(default.to_owned()), |s| s.as_str().map(str::to_owned))
                .ok_or_else(|| format!("bufferView {v}: {EXTENSION}.{name} is not a string"))
        };
        out.push(CompressedView(Compressed {
            view: v,
            buffer: field("buffer")?,
            offset: ext
                .get("byteOffset")
                .map_or(Ok(0), |_| field("byteOffset"))?,
            length: field("byteLength")?,
            stride: field("byteStride")?,
            count: field("count")?,
            mode: text("mode", "")?,
            filter: text("filter", "NONE")?,
        }));
    }
    for buffer in &mut root.buffers {
        if let Some(e) = buffer.extensions.as_mut() {
            e.others.remove(EXTENSION);
        }
    }
    root.extensions_used.retain(|e| e != EXTENSION);
    root.extensions_required.retain(|e| e != EXTENSION);
    Ok(Taken {
        views: out,
        fallback,
    })
}

/// The buffers of `document`, each fallback buffer zero-filled and its compressed views decoded
/// into it (`base`: the file's folder; `blob`: a GLB's binary chunk).
pub fn load_buffers(
    document: &gltf::Document,
    base: &std::path::Path,
    blob: Option<Vec<u8>>,
    taken: &Taken,
) -> Result<Vec<gltf::buffer::Data>, String> {
    let root = document.as_json();
    // The buffers with data of their own, loaded by the gltf crate (which takes every buffer
    // without a URI for the GLB's binary chunk): the fallback buffers left out, the views'
    // buffer indices unused there.
    let mut own = root.clone();
    own.buffers = root
        .buffers
        .iter()
        .zip(&taken.fallback)
        .filter(|(_, fallback)| !**fallback)
        .map(|(b, _)| b.clone())
        .collect();
    for view in &mut own.buffer_views {
        view.buffer = json::Index::new(0);
    }
    let own = gltf::Document::from_json_without_validation(own);
    // The fallback buffers may hold at most MAX_EXPANSION times the bytes the file really
    // loaded (not what its views claim, which `decode` checks against these bytes later).
    let loaded: Vec<Vec<u8>> = gltf::import_buffers(&own, Some(base), blob)
        .map_err(|e| format!("cannot load its buffers: {e}"))?
        .into_iter()
        .map(|d| d.0)
        .collect();
    let held = loaded.iter().fold(0usize, |n, b| n.saturating_add(b.len()));
    let budget = held.saturating_mul(MAX_EXPANSION).max(4096);
    let fallback = root
        .buffers
        .iter()
        .zip(&taken.fallback)
        .filter(|(_, f)| **f)
        .fold(0usize, |n, (b, _)| {
            n.saturating_add(b.byte_length.0 as usize)
        });
    if fallback > budget {
        return Err(format!(
            "its {EXTENSION} fallback buffers claim {fallback} bytes, more than {MAX_EXPANSION} \
             times the {held} bytes of its other buffers, from which their views decode"
        ));
    }
    let mut loaded = loaded.into_iter();
    let mut buffers: Vec<Vec<u8>> = Vec::with_capacity(root.buffers.len());
    for (b, fallback) in root.buffers.iter().zip(&taken.fallback) {
        buffers.push(match fallback {
            // Within the budget above: no overflow rounding it up.
            true => vec![0; (b.byte_length.0 as usize).next_multiple_of(4)],
            false => loaded.next().unwrap_or_default(),
        });
    }
    decode(&taken.views, &root.buffer_views, &mut buffers)?;
    Ok(buffers.into_iter().map(gltf::buffer::Data).collect())
}

/// A compressed view [`take`] found.
pub struct CompressedView(Compressed);

/// Decodes each view into its place in its buffer (`views` as the document has them).
pub fn decode(
    compressed: &[CompressedView],
    views: &[json::buffer::View],
    buffers: &mut [Vec<u8>],
) -> Result<(), String> {
    for CompressedView(c) in compressed {
        let at = format!("bufferView {} ({EXTENSION})", c.view);
        let source = buffers
            .get(c.buffer)
            .and_then(|b| b.get(c.offset..c.offset.checked_add(c.length)?))
            .ok_or_else(|| {
                format!(
                    "{at}: bytes {}..+{} of buffer {} are not in the file",
                    c.offset, c.length, c.buffer
                )
            })?
            .to_vec();
        let size = c
            .count
            .checked_mul(c.stride)
            .filter(|&s| s <= c.length.saturating_mul(MAX_EXPANSION).max(4096))
            .ok_or_else(|| {
                format!(
                    "{at}: {} elements of {} bytes from {} compressed bytes is more than \
                     {MAX_EXPANSION} times as much",
                    c.count, c.stride, c.length
                )
            })?;
        let mut bytes = decode_view(c, &source).map_err(|e| format!("{at}: {e}"))?;
        filter(c, &mut bytes).map_err(|e| format!("{at}: {e}"))?;
        debug_assert_eq!(bytes.len(), size);
        let view = &views[c.view];
        let start = view.byte_offset.map_or(0, |o| o.0 as usize);
        let target = buffers
            .get_mut(view.buffer.value())
            .and_then(|b| b.get_mut(start..start.checked_add(size)?))
            .filter(|_| view.byte_length.0 as usize >= size)
            .ok_or_else(|| {
                format!(
                    "{at}: its {size} decoded bytes do not fit the view ({} bytes at {start} of \
                     buffer {})",
                    view.byte_length.0,
                    view.buffer.value()
                )
            })?;
        target.copy_from_slice(&bytes);
    }
    Ok(())
}

/// The bytes of one view, by its mode.
fn decode_view(c: &Compressed, source: &[u8]) -> Result<Vec<u8>, String> {
    let fail = |e: meshopt::Error| format!("meshoptimizer could not decode it: {e:?}");
    match (c.mode.as_str(), c.stride) {
        ("ATTRIBUTES", s) if s % 4 == 0 && (4..=256).contains(&s) => {
            attributes(source, c.count, s).map_err(fail)
        }
        ("TRIANGLES", 2) if c.count.is_multiple_of(3) => {
            let v = meshopt::decode_index_buffer::<u16>(source, c.count).map_err(fail)?;
            Ok(v.iter().flat_map(|i| i.to_le_bytes()).collect())
        }
        ("TRIANGLES", 4) if c.count.is_multiple_of(3) => {
            let v = meshopt::decode_index_buffer::<u32>(source, c.count).map_err(fail)?;
            Ok(v.iter().flat_map(|i| i.to_le_bytes()).collect())
        }
        ("INDICES", 2) => {
            let v = meshopt::decode_index_sequence::<u16>(source, c.count).map_err(fail)?;
            Ok(v.iter().flat_map(|i| i.to_le_bytes()).collect())
        }
        ("INDICES", 4) => {
            let v = meshopt::decode_index_sequence::<u32>(source, c.count).map_err(fail)?;
            Ok(v.iter().flat_map(|i| i.to_le_bytes()).collect())
        }
        (mode, stride) => Err(format!(
            "mode {mode:?} with byteStride {stride} and count {}: the extension allows \
             ATTRIBUTES (a stride of 4 to 256, a multiple of 4), TRIANGLES (2 or 4, a count \
             divisible by 3) and INDICES (2 or 4)",
            c.count
        )),
    }
}

/// `N` bytes, whatever `N` (arrays have `Default` up to 32 elements only).
#[derive(Clone, Copy)]
struct Element<const N: usize>([u8; N]);

impl<const N: usize> Default for Element<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

fn attributes_of<const N: usize>(source: &[u8], count: usize) -> meshopt::Result<Vec<u8>> {
    let v = meshopt::decode_vertex_buffer::<Element<N>>(source, count)?;
    Ok(v.iter().flat_map(|e| e.0).collect())
}

/// Vertex data of `count` elements of `stride` bytes (a multiple of 4, 4 to 256).
fn attributes(source: &[u8], count: usize, stride: usize) -> meshopt::Result<Vec<u8>> {
    macro_rules! by_stride {
        ($($n:literal)*) => {
            match stride {
                $($n => attributes_of::<$n>(source, count),)*
                _ => unreachable!("checked: a multiple of 4 from 4 to 256"),
            }
        };
    }
    by_stride!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108
        112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196
        200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)
}

/// Undoes the view's filter on its decoded bytes (filters apply to ATTRIBUTES only).
fn filter(c: &Compressed, bytes: &mut [u8]) -> Result<(), String> {
    if c.filter != "NONE" && c.mode != "ATTRIBUTES" {
        return Err(format!(
            "filter {:?} on mode {:?}: the extension filters ATTRIBUTES only",
            c.filter, c.mode
        ));
    }
    match (c.filter.as_str(), c.stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => {
            let mut v: Vec<[i8; 4]> = bytes
                .chunks_exact(4)
                .map(|b| [b[0] as i8, b[1] as i8, b[2] as i8, b[3] as i8])
                .collect();
            meshopt::decode_filter_oct(&mut v);
            for (to, from) in bytes.chunks_exact_mut(4).zip(&v) {
                to.copy_from_slice(&from.map(|x| x as u8));
            }
        }
        ("OCTAHEDRAL", 8) | ("QUATERNION", 8) => {
            let mut v: Vec<[i16; 4]> = bytes
                .chunks_exact(8)
                .map(|b| std::array::from_fn(|k| i16::from_le_bytes([b[2 * k], b[2 * k + 1]])))
                .collect();
            if c.filter == "OCTAHEDRAL" {
                meshopt::decode_filter_oct(&mut v);
            } else {
                meshopt::decode_filter_quat(&mut v);
            }
            for (to, from) in bytes.chunks_exact_mut(8).zip(&v) {
                for (k, x) in from.iter().enumerate() {
                    to[2 * k..2 * k + 2].copy_from_slice(&x.to_le_bytes());
                }
            }
        }
        ("EXPONENTIAL", s) if s % 4 == 0 => {
            // Each 32-bit word is filtered alone: one word a row is the same as N.
            let mut v: Vec<[u32; 1]> = bytes
                .chunks_exact(4)
                .map(|b| [u32::from_le_bytes([b[0], b[1], b[2], b[3]])])
                .collect();
            meshopt::decode_filter_exp(&mut v);
            for (to, from) in bytes.chunks_exact_mut(4).zip(&v) {
                to.copy_from_slice(&from[0].to_le_bytes());
            }
        }
        (filter, stride) => {
            return Err(format!(
                "filter {filter:?} with byteStride {stride}: the extension allows NONE, \
                 OCTAHEDRAL (a stride of 4 or 8), QUATERNION (8) and EXPONENTIAL"
            ));
        }
    }
    Ok(())
}
