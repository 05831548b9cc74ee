// lodkit::lod_buffer — what an object writes into a LOD buffer for frame-sequential LOD
// (Scherzer & Wimmer 2008, sec. 3.2, 3.5).
//
// GLSL twin of shader_lib/wgsl/lodkit/lod_buffer.wgsl; same semantics, `lodkit_` prefix.
// Location 0 color, location 1 r32ui, the id word (instance id in bits 0..29, display-time flags
// in bits 30 (shown now) and 31 (shown next frame)); each LOD buffer's own depth attachment keeps
// the depth. 8 bytes per pixel per LOD buffer beyond the depth attachment with an rgba8 color.
//
// Exports:
//   lodkit_LodBufferOutput { color, id }
//   LODKIT_LOD_BUFFER_ID_MASK, LODKIT_LOD_BUFFER_SHOWN_NOW, LODKIT_LOD_BUFFER_SHOWN_NEXT: uint
//   lodkit_lod_buffer_output_flags(color, instance_id, flags) -> lodkit_LodBufferOutput
//   lodkit_lod_buffer_output(color, instance_id, depth) -> lodkit_LodBufferOutput   shown in both
//       frames (depth is kept by the depth attachment; the parameter is not stored)
//   lodkit_lod_buffer_id(word) -> uint, lodkit_lod_buffer_flags(word) -> uint
//   lodkit_lod_buffer_shown(word, flag) -> bool   n-instance, or the flag is set
//   lodkit_LodBufferMotionOutput { color, id, motion }   with location 2 (rg16f), the object motion
//   lodkit_lod_buffer_output_motion(color, instance_id, flags, motion) -> lodkit_LodBufferMotionOutput
//   lodkit_lod_buffer_motion(then_clip, now_clip) -> vec2   object motion in texture-space uv
//       (the surface point then minus now, both in the previous frame's clip space; 0 behind it)
// Usage: lodkit_LodBufferOutput o = lodkit_lod_buffer_output(c, id, gl_FragCoord.z);
//        out_color = o.color; out_id = o.id;
// Shader defs: none.
#ifndef LODKIT_LOD_BUFFER_GLSL
#define LODKIT_LOD_BUFFER_GLSL

/// Fragment output of a LOD buffer pass.
struct lodkit_LodBufferOutput {
    vec4 color;
    uint id;
};

/// Bits of the id word that hold the instance id (ids exact up to 2^30 - 1).
const uint LODKIT_LOD_BUFFER_ID_MASK = 0x3fffffffu;
/// Flag: shown in the frame the buffer is rendered for.
const uint LODKIT_LOD_BUFFER_SHOWN_NOW = 1u;
/// Flag: shown in the next frame, when the buffer is the older one.
const uint LODKIT_LOD_BUFFER_SHOWN_NEXT = 2u;

/// Packs color, instance id and display-time flags.
lodkit_LodBufferOutput lodkit_lod_buffer_output_flags(vec4 color, uint instance_id, uint flags) {
    return lodkit_LodBufferOutput(color, (instance_id & LODKIT_LOD_BUFFER_ID_MASK) | ((flags & 3u) << 30u));
}

/// Packs color and instance id (0 = n-instance), shown in both frames; depth is not stored.
lodkit_LodBufferOutput lodkit_lod_buffer_output(vec4 color, uint instance_id, float depth) {
    return lodkit_lod_buffer_output_flags(color, instance_id, LODKIT_LOD_BUFFER_SHOWN_NOW | LODKIT_LOD_BUFFER_SHOWN_NEXT);
}

/// Instance id of an id word.
uint lodkit_lod_buffer_id(uint word) {
    return word & LODKIT_LOD_BUFFER_ID_MASK;
}

/// Display-time flags of an id word.
uint lodkit_lod_buffer_flags(uint word) {
    return word >> 30u;
}

/// Whether a texel is shown in the frame `flag` names (always for n-instances).
bool lodkit_lod_buffer_shown(uint word, uint flag) {
    return lodkit_lod_buffer_id(word) == 0u || (lodkit_lod_buffer_flags(word) & flag) != 0u;
}

/// Fragment output of a LOD buffer pass whose objects may move by themselves.
struct lodkit_LodBufferMotionOutput {
    vec4 color;
    uint id;
    vec2 motion;
};

/// lodkit_lod_buffer_output_flags with the fragment's object motion.
lodkit_LodBufferMotionOutput lodkit_lod_buffer_output_motion(vec4 color, uint instance_id, uint flags, vec2 motion) {
    lodkit_LodBufferOutput o = lodkit_lod_buffer_output_flags(color, instance_id, flags);
    return lodkit_LodBufferMotionOutput(o.color, o.id, motion);
}

/// Object motion in texture-space uv: the surface point then minus now, both in the previous
/// frame's clip space; 0 when either has w <= 0.
vec2 lodkit_lod_buffer_motion(vec4 then_clip, vec4 now_clip) {
    if (then_clip.w <= 0.0 || now_clip.w <= 0.0) {
        return vec2(0.0);
    }
    return (then_clip.xy / then_clip.w - now_clip.xy / now_clip.w) * vec2(0.5, -0.5);
}

#endif // LODKIT_LOD_BUFFER_GLSL
