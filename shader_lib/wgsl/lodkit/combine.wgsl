// lodkit::combine — the combination rule of two LOD buffers (Scherzer & Wimmer 2008, sec. 3.4 and
// 3.5 step 2).
//
// Both ids 0 (n-instances) -> the newer color. Ids differ -> the closer fragment (depths compared
// in the older buffer's space: pass the newer depth reprojected). Same id (two LODs of one
// t-instance) -> the average of both colors, with no depth test, so coplanar LODs never z-fight.
// A tie in depth keeps the newer fragment. With display-time visibility (combine_shown) a sample
// not shown in the frame being displayed gives way to the other one.
//
// Exports:
//   LodSample { color, id, depth }   one LOD buffer texel
//   combine_samples(newer, older) -> vec4<f32>
//   combine_shown(newer, newer_shown, older, older_shown) -> vec4<f32>   exactly one shown: it;
//       both or neither: combine_samples
//   combine_texel(uv, size) -> vec2<u32>   the texel at a texture-space uv (clamped)
//   combine_uv(pixel, size) -> vec2<f32>   texture-space center of a pixel
//   combine_older_texel(pixel, size, newer_depth, first_depth, new_to_old) -> vec2<u32>   where
//       the older buffer is read: the reprojection refined at the older depth first_depth found
//       at the first estimate (lodkit::reproject::reproject_refine)
//   combine_texels(newer_color, newer_word, old, older_color, older_word, older_depth)
//       -> vec4<f32>   the combined color from the fetched texels (old = reproject(uv, newer
//       depth); words: lodkit::lod_buffer id words)
//   combine_at(newer_color, newer_id, newer_depth, older_color, older_id, older_depth, pixel,
//       new_to_old) -> vec4<f32>   the whole per-pixel combine (passes/combine.wgsl), to fold
//       into a full-screen pass an engine already has (tonemapping, TAA): no pass of its own.
//       The depths are the LOD buffers' depth attachments bound as texture_2d<f32>
//       (unfilterable float; a depth view of Depth32Float).
//   depth_closer(a, b) -> bool   a strictly closer than b under the depth convention
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z); off: 0 near.
#define_import_path lodkit::combine
#import lodkit::lod_buffer::{lod_buffer_id, lod_buffer_shown, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT}
#import lodkit::reproject::{reproject, reproject_base, reproject_from_base, reproject_refine, in_viewport}

/// One texel of a LOD buffer: color, instance id (0 = n-instance), clip depth.
struct LodSample {
    color: vec4<f32>,
    id: u32,
    depth: f32,
}

/// Whether clip depth `a` is strictly closer to the camera than `b`.
fn depth_closer(a: f32, b: f32) -> bool {
#ifdef LODKIT_REVERSE_Z
    return a > b;
#else
    return a < b;
#endif
}

/// Color of the combined pixel from the newer and the (reprojected) older LOD buffer sample.
fn combine_samples(newer: LodSample, older: LodSample) -> vec4<f32> {
    if (newer.id == 0u && older.id == 0u) {
        return newer.color;
    }
    if (newer.id == older.id) {
        return 0.5 * (newer.color + older.color);
    }
    if (depth_closer(older.depth, newer.depth)) {
        return older.color;
    }
    return newer.color;
}

/// combine_samples with display-time visibility: when exactly one sample is shown in the frame
/// being displayed (`newer_shown`, `older_shown`), its color; when both or neither are,
/// combine_samples (neither: the fragments are shown rather than a hole).
fn combine_shown(newer: LodSample, newer_shown: bool, older: LodSample, older_shown: bool) -> vec4<f32> {
    if (newer_shown != older_shown) {
        return select(older.color, newer.color, newer_shown);
    }
    return combine_samples(newer, older);
}

/// The texel of a `size` texture at texture-space `uv` (clamped to the texture).
fn combine_texel(uv: vec2<f32>, size: vec2<u32>) -> vec2<u32> {
    let inside = clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0));
    return min(vec2<u32>(inside * vec2<f32>(size)), size - vec2<u32>(1u));
}

/// Texture-space center of pixel `pixel` of a `size` target.
fn combine_uv(pixel: vec2<u32>, size: vec2<u32>) -> vec2<f32> {
    return (vec2<f32>(pixel) + 0.5) / vec2<f32>(size);
}

/// The older buffer's texel the combine reads for the newer pixel `pixel` with clip depth
/// `newer_depth`: the first estimate reprojects that depth; the older buffer's depth found there
/// (`first_depth`) may belong to another surface (a stipple hole, an edge), so the texel is where
/// the point of the pixel's ray at that older depth reprojects (the first estimate if none).
fn combine_older_texel(pixel: vec2<u32>, size: vec2<u32>, newer_depth: f32, first_depth: f32, new_to_old: mat4x4<f32>) -> vec2<u32> {
    let base = reproject_base(combine_uv(pixel, size), new_to_old);
    let first = reproject_from_base(base, newer_depth, new_to_old);
    let refined = reproject_refine(base, newer_depth, first_depth, new_to_old);
    return select(combine_texel(first.xy, size), combine_texel(refined.xy, size), in_viewport(refined.xy));
}

/// The combined color from the texels the combine reads: the newer color and id word at the
/// pixel, `old` = reproject(uv, newer depth, new_to_old), the older color, id word and depth at
/// combine_older_texel. Outside the older view the newer color; else combine_shown, the newer
/// sample shown if flagged for now, the older if flagged for next.
fn combine_texels(newer_color: vec4<f32>, newer_word: u32, old: vec3<f32>, older_color: vec4<f32>, older_word: u32, older_depth: f32) -> vec4<f32> {
    if (!in_viewport(old.xy)) {
        return newer_color;
    }
    let newer = LodSample(newer_color, lod_buffer_id(newer_word), old.z);
    let older = LodSample(older_color, lod_buffer_id(older_word), older_depth);
    let newer_shown = lod_buffer_shown(newer_word, LOD_BUFFER_SHOWN_NOW);
    let older_shown = lod_buffer_shown(older_word, LOD_BUFFER_SHOWN_NEXT);
    return combine_shown(newer, newer_shown, older, older_shown);
}

/// The whole per-pixel combine of frame-sequential LOD at `pixel` (what passes/combine.wgsl
/// draws), for an engine to call in a full-screen pass it already runs (tonemapping, TAA) and
/// save the pass. Six texel loads: the newer color, id and depth, the older depth at the first
/// estimate, the older color and id (plus the older depth there) at the refined texel.
fn combine_at(
    newer_color: texture_2d<f32>,
    newer_id: texture_2d<u32>,
    newer_depth: texture_2d<f32>,
    older_color: texture_2d<f32>,
    older_id: texture_2d<u32>,
    older_depth: texture_2d<f32>,
    pixel: vec2<u32>,
    new_to_old: mat4x4<f32>,
) -> vec4<f32> {
    let size = textureDimensions(newer_color, 0);
    let color = textureLoad(newer_color, pixel, 0);
    let depth = textureLoad(newer_depth, pixel, 0).x;
    let old = reproject(combine_uv(pixel, size), depth, new_to_old);
    if (!in_viewport(old.xy)) {
        return color;
    }
    let first_depth = textureLoad(older_depth, combine_texel(old.xy, size), 0).x;
    let older = combine_older_texel(pixel, size, depth, first_depth, new_to_old);
    return combine_texels(
        color,
        textureLoad(newer_id, pixel, 0).x,
        old,
        textureLoad(older_color, older, 0),
        textureLoad(older_id, older, 0).x,
        textureLoad(older_depth, older, 0).x,
    );
}
