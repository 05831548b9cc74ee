// lodkit::gbuffer — what the low-resolution pass of geometry-aware framebuffer LOD writes, and how
// the upsampler reads it back (Yang, Sander & Lawrence 2008, sec. 2.1).
//
// GLSL twin of shader_lib/wgsl/lodkit/gbuffer.wgsl; same semantics, `lodkit_` prefix.
// Location 0 color, location 1 rgba16f geometry = (view depth, normal.xyz); 12 bytes per pixel
// with an rgba8 color.
//
// Exports:
//   lodkit_GBufferOutput { color, geometry }
//   lodkit_gbuffer_output(color, view_depth, normal) -> lodkit_GBufferOutput
//   lodkit_gbuffer_pack_geometry(view_depth, normal) -> vec4
//   lodkit_gbuffer_depth(geometry) -> float, lodkit_gbuffer_normal(geometry) -> vec3
// Shader defs: none.
#ifndef LODKIT_GBUFFER_GLSL
#define LODKIT_GBUFFER_GLSL

/// Fragment output of the low-resolution pass.
struct lodkit_GBufferOutput {
    vec4 color;
    vec4 geometry;
};

/// The geometry texel: (view depth, normal).
vec4 lodkit_gbuffer_pack_geometry(float view_depth, vec3 normal) {
    return vec4(view_depth, normal);
}

/// Color and geometry of a low-resolution pixel.
lodkit_GBufferOutput lodkit_gbuffer_output(vec4 color, float view_depth, vec3 normal) {
    return lodkit_GBufferOutput(color, lodkit_gbuffer_pack_geometry(view_depth, normal));
}

/// View depth stored in a geometry texel.
float lodkit_gbuffer_depth(vec4 geometry) {
    return geometry.x;
}

/// Screen-space normal stored in a geometry texel.
vec3 lodkit_gbuffer_normal(vec4 geometry) {
    return geometry.yzw;
}

#endif // LODKIT_GBUFFER_GLSL
