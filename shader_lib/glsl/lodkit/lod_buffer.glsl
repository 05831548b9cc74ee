// lodkit::lod_buffer — what an object writes into a LOD buffer for frame-sequential LOD
// (Scherzer & Wimmer 2008, sec. 3.2, 3.5).
//
// GLSL twin of shader_lib/wgsl/lodkit/lod_buffer.wgsl; same semantics, `lodkit_` prefix.
// Location 0 color, location 1 rg32ui = (id word, floatBitsToUint(depth)); 12 bytes per pixel
// per LOD buffer with an rgba8 color. The id word: instance id in bits 0..29, display-time flags
// in bits 30 (shown now) and 31 (shown next frame).
//
// Exports:
//   lodkit_LodBufferOutput { color, id_depth }
//   LODKIT_LOD_BUFFER_ID_MASK, LODKIT_LOD_BUFFER_SHOWN_NOW, LODKIT_LOD_BUFFER_SHOWN_NEXT: uint
//   lodkit_lod_buffer_output(color, instance_id, depth) -> lodkit_LodBufferOutput   shown in both
//   lodkit_lod_buffer_output_flags(color, instance_id, depth, flags) -> lodkit_LodBufferOutput
//   lodkit_lod_buffer_depth(id_depth) -> float, lodkit_lod_buffer_id(id_depth) -> uint,
//   lodkit_lod_buffer_flags(id_depth) -> uint
//   lodkit_lod_buffer_shown(id_depth, flag) -> bool   n-instance, or the flag is set
// Usage: lodkit_LodBufferOutput o = lodkit_lod_buffer_output(c, id, gl_FragCoord.z);
//        out_color = o.color; out_id_depth = o.id_depth;
// Shader defs: none.
#ifndef LODKIT_LOD_BUFFER_GLSL
#define LODKIT_LOD_BUFFER_GLSL

/// Fragment output of a LOD buffer pass.
struct lodkit_LodBufferOutput {
    vec4 color;
    uvec2 id_depth;
};

/// Packs `color`, `instance_id` (0 = n-instance) and clip `depth`.
/// Bits of the id word that hold the instance id (ids exact up to 2^30 - 1).
const uint LODKIT_LOD_BUFFER_ID_MASK = 0x3fffffffu;
/// Flag: shown in the frame the buffer is rendered for.
const uint LODKIT_LOD_BUFFER_SHOWN_NOW = 1u;
/// Flag: shown in the next frame, when the buffer is the older one.
const uint LODKIT_LOD_BUFFER_SHOWN_NEXT = 2u;

/// Packs color, instance id, clip depth and display-time flags.
lodkit_LodBufferOutput lodkit_lod_buffer_output_flags(vec4 color, uint instance_id, float depth, uint flags) {
    uint word = (instance_id & LODKIT_LOD_BUFFER_ID_MASK) | ((flags & 3u) << 30u);
    return lodkit_LodBufferOutput(color, uvec2(word, floatBitsToUint(depth)));
}

/// Packs color, instance id (0 = n-instance) and clip depth, shown in both frames.
lodkit_LodBufferOutput lodkit_lod_buffer_output(vec4 color, uint instance_id, float depth) {
    return lodkit_lod_buffer_output_flags(color, instance_id, depth, LODKIT_LOD_BUFFER_SHOWN_NOW | LODKIT_LOD_BUFFER_SHOWN_NEXT);
}

/// Instance id of a texel of the id/depth target.
uint lodkit_lod_buffer_id(uvec2 id_depth) {
    return id_depth.x & LODKIT_LOD_BUFFER_ID_MASK;
}

/// Display-time flags of a texel.
uint lodkit_lod_buffer_flags(uvec2 id_depth) {
    return id_depth.x >> 30u;
}

/// Whether a texel is shown in the frame `flag` names (always for n-instances).
bool lodkit_lod_buffer_shown(uvec2 id_depth, uint flag) {
    return lodkit_lod_buffer_id(id_depth) == 0u || (lodkit_lod_buffer_flags(id_depth) & flag) != 0u;
}

/// Clip depth of a texel of the id/depth target.
float lodkit_lod_buffer_depth(uvec2 id_depth) {
    return uintBitsToFloat(id_depth.y);
}

#endif // LODKIT_LOD_BUFFER_GLSL
