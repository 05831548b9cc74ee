// lodkit::lod_buffer — what a t-instance (or any object) writes into a LOD buffer for
// frame-sequential LOD (Scherzer & Wimmer 2008, sec. 3.2, 3.5).
//
// Two render targets: location 0 color (the engine's own format, e.g. rgba8unorm), location 1
// rg32uint = (instance id, depth bits). Id 0 means n-instance; ids are exact up to 2^32 - 1 (the
// paper's 16-bit float id is exact only to 2048). Depth is the fragment's clip depth as f32 bits,
// exact, in whatever convention the projection uses (standard or reversed Z).
// Bytes per pixel per LOD buffer: 4 (rgba8 color) + 8 (id/depth) = 12 (the paper: 7, with a 16-bit
// depth and an id exact to 2048); the pair of buffers: 24.
//
// Exports:
//   LodBufferOutput { color (location 0), id_depth (location 1) }   fragment output
//   lod_buffer_output(color, instance_id, depth) -> LodBufferOutput
//   lod_buffer_depth(id_depth) -> f32, lod_buffer_id(id_depth) -> u32   unpacking
// Usage: return lod_buffer_output(shaded, draw.instance_id, in.position.z);
// Shader defs: none.
#define_import_path lodkit::lod_buffer

/// Fragment output of a LOD buffer pass.
struct LodBufferOutput {
    @location(0) color: vec4<f32>,
    @location(1) id_depth: vec2<u32>,
}

/// Packs `color`, `instance_id` (0 = n-instance) and clip `depth` for the LOD buffer MRT.
fn lod_buffer_output(color: vec4<f32>, instance_id: u32, depth: f32) -> LodBufferOutput {
    return LodBufferOutput(color, vec2<u32>(instance_id, bitcast<u32>(depth)));
}

/// Instance id of a texel of the id/depth target.
fn lod_buffer_id(id_depth: vec2<u32>) -> u32 {
    return id_depth.x;
}

/// Clip depth of a texel of the id/depth target.
fn lod_buffer_depth(id_depth: vec2<u32>) -> f32 {
    return bitcast<f32>(id_depth.y);
}
