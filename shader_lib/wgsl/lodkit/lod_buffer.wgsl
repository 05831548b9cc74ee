// lodkit::lod_buffer — what a t-instance (or any object) writes into a LOD buffer for
// frame-sequential LOD (Scherzer & Wimmer 2008, sec. 3.2, 3.5).
//
// Two render targets: location 0 color (the engine's own format, e.g. rgba8unorm), location 1
// rg32uint = (id word, depth bits). The id word holds the instance id in bits 0..29 (id 0 means
// n-instance; ids are exact up to 2^30 - 1, the paper's 16-bit float id only to 2048) and two
// display-time visibility flags in bits 30 and 31: shown in the frame the buffer is rendered for
// (LOD_BUFFER_SHOWN_NOW) and in the next one, when it is the older buffer (LOD_BUFFER_SHOWN_NEXT).
// The combine pass shows a sample only in the frames its flag names; n-instances are always shown.
// Depth is the fragment's clip depth as f32 bits, exact, in whatever convention the projection
// uses (standard or reversed Z).
// Bytes per pixel per LOD buffer: 4 (rgba8 color) + 8 (id/depth) = 12 (the paper: 7, with a 16-bit
// depth and an id exact to 2048); the pair of buffers: 24.
//
// Exports:
//   LodBufferOutput { color (location 0), id_depth (location 1) }   fragment output
//   LOD_BUFFER_ID_MASK, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT: u32   id bits, flags
//   lod_buffer_output(color, instance_id, depth) -> LodBufferOutput   shown in both frames
//   lod_buffer_output_flags(color, instance_id, depth, flags) -> LodBufferOutput
//   lod_buffer_depth(id_depth) -> f32, lod_buffer_id(id_depth) -> u32,
//   lod_buffer_flags(id_depth) -> u32   unpacking
//   lod_buffer_shown(id_depth, flag) -> bool   n-instance, or the flag is set
// Usage: return lod_buffer_output(shaded, draw.instance_id, in.position.z); or with
//   lodkit::visibility::visibility_flags for display-time visibility (passes/lod_buffer_mesh.wgsl).
// Shader defs: none.
#define_import_path lodkit::lod_buffer

/// Fragment output of a LOD buffer pass.
struct LodBufferOutput {
    @location(0) color: vec4<f32>,
    @location(1) id_depth: vec2<u32>,
}

/// Bits of the id word that hold the instance id (ids exact up to 2^30 - 1).
const LOD_BUFFER_ID_MASK: u32 = 0x3fffffffu;
/// Flag: the fragment is shown in the frame its buffer is rendered for.
const LOD_BUFFER_SHOWN_NOW: u32 = 1u;
/// Flag: the fragment is shown in the next frame, when its buffer is the older one.
const LOD_BUFFER_SHOWN_NEXT: u32 = 2u;

/// Packs `color`, `instance_id` (bits above 29 are dropped), clip `depth` and the display-time
/// `flags` (LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT, e.g. from visibility_flags).
fn lod_buffer_output_flags(color: vec4<f32>, instance_id: u32, depth: f32, flags: u32) -> LodBufferOutput {
    let word = (instance_id & LOD_BUFFER_ID_MASK) | ((flags & 3u) << 30u);
    return LodBufferOutput(color, vec2<u32>(word, bitcast<u32>(depth)));
}

/// Packs `color`, `instance_id` (0 = n-instance) and clip `depth` for the LOD buffer MRT, shown
/// in both frames (the fragment stage discards what is not shown, as in the paper).
fn lod_buffer_output(color: vec4<f32>, instance_id: u32, depth: f32) -> LodBufferOutput {
    return lod_buffer_output_flags(color, instance_id, depth, LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT);
}

/// Instance id of a texel of the id/depth target.
fn lod_buffer_id(id_depth: vec2<u32>) -> u32 {
    return id_depth.x & LOD_BUFFER_ID_MASK;
}

/// Display-time flags of a texel (LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT).
fn lod_buffer_flags(id_depth: vec2<u32>) -> u32 {
    return id_depth.x >> 30u;
}

/// Whether a texel is shown in the frame `flag` names: always for n-instances (id 0).
fn lod_buffer_shown(id_depth: vec2<u32>, flag: u32) -> bool {
    return lod_buffer_id(id_depth) == 0u || (lod_buffer_flags(id_depth) & flag) != 0u;
}

/// Clip depth of a texel of the id/depth target.
fn lod_buffer_depth(id_depth: vec2<u32>) -> f32 {
    return bitcast<f32>(id_depth.y);
}
