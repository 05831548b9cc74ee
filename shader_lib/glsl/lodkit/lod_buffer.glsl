// lodkit::lod_buffer — what an object writes into a LOD buffer for frame-sequential LOD
// (Scherzer & Wimmer 2008, sec. 3.2, 3.5).
//
// GLSL twin of shader_lib/wgsl/lodkit/lod_buffer.wgsl; same semantics, `lodkit_` prefix.
// Location 0 color, location 1 rg32ui = (instance id, floatBitsToUint(depth)); 12 bytes per pixel
// per LOD buffer with an rgba8 color.
//
// Exports:
//   lodkit_LodBufferOutput { color, id_depth }
//   lodkit_lod_buffer_output(color, instance_id, depth) -> lodkit_LodBufferOutput
//   lodkit_lod_buffer_depth(id_depth) -> float, lodkit_lod_buffer_id(id_depth) -> uint
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
lodkit_LodBufferOutput lodkit_lod_buffer_output(vec4 color, uint instance_id, float depth) {
    return lodkit_LodBufferOutput(color, uvec2(instance_id, floatBitsToUint(depth)));
}

/// Instance id of a texel of the id/depth target.
uint lodkit_lod_buffer_id(uvec2 id_depth) {
    return id_depth.x;
}

/// Clip depth of a texel of the id/depth target.
float lodkit_lod_buffer_depth(uvec2 id_depth) {
    return uintBitsToFloat(id_depth.y);
}

#endif // LODKIT_LOD_BUFFER_GLSL
