// lodkit::fullscreen — the fullscreen-triangle vertex stage every screen-space pass uses.
//
// GLSL twin of shader_lib/wgsl/lodkit/fullscreen.wgsl; same semantics, `lodkit_` prefix.
// Three vertices, no vertex buffer. uv is in texture space ((0,0) top-left) as Vulkan/wgpu
// sample it; on OpenGL, whose texture origin is bottom-left, flip uv.y when sampling.
//
// Exports:
//   lodkit_FullscreenVertex { position, uv }
//   lodkit_fullscreen_uv(vertex_index) -> vec2   (0,0), (2,0), (0,2)
//   lodkit_fullscreen_position(vertex_index) -> vec4   clip position, z = 0, w = 1
//   lodkit_fullscreen_vertex(vertex_index) -> lodkit_FullscreenVertex
// Usage (Vulkan GLSL):
//   void main() { lodkit_FullscreenVertex v = lodkit_fullscreen_vertex(uint(gl_VertexIndex));
//                 gl_Position = v.position; out_uv = v.uv; }
// Shader defs: none.
#ifndef LODKIT_FULLSCREEN_GLSL
#define LODKIT_FULLSCREEN_GLSL

/// Output of a fullscreen vertex stage: clip position and texture-space uv.
struct lodkit_FullscreenVertex {
    vec4 position;
    vec2 uv;
};

/// Texture-space uv of vertex `vertex_index` (0, 1 or 2): (0,0), (2,0), (0,2).
vec2 lodkit_fullscreen_uv(uint vertex_index) {
    return vec2(float((vertex_index << 1u) & 2u), float(vertex_index & 2u));
}

/// Clip-space position of vertex `vertex_index` of the fullscreen triangle (z = 0, w = 1).
vec4 lodkit_fullscreen_position(uint vertex_index) {
    vec2 uv = lodkit_fullscreen_uv(vertex_index);
    return vec4(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
}

/// Position and uv of vertex `vertex_index`.
lodkit_FullscreenVertex lodkit_fullscreen_vertex(uint vertex_index) {
    return lodkit_FullscreenVertex(lodkit_fullscreen_position(vertex_index), lodkit_fullscreen_uv(vertex_index));
}

#endif // LODKIT_FULLSCREEN_GLSL
