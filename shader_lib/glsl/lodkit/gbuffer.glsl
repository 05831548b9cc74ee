// lodkit::gbuffer — what the low-resolution pass of geometry-aware framebuffer LOD writes, and how
// the upsampler reads it back (Yang, Sander & Lawrence 2008, sec. 2.1).
//
// GLSL twin of shader_lib/wgsl/lodkit/gbuffer.wgsl; same semantics, `lodkit_` prefix.
// Location 0 color, location 1 rgba16f geometry = (view depth, normal.xyz); 12 bytes per pixel
// with an rgba8 color. Packed layout (one rgba32ui target, 16 bytes): x, y = color as halves,
// z = view depth bits, w = the foreshortened normal as halves; the halves are lodkit's own
// conversion (round to nearest, ties away from zero; clamped to 65504; below 2^-14: zero), as
// in the WGSL module.
//
// Exports:
//   lodkit_GBufferOutput { color, geometry }
//   lodkit_gbuffer_output(color, view_depth, normal) -> lodkit_GBufferOutput
//   lodkit_gbuffer_pack_geometry(view_depth, normal) -> vec4
//   lodkit_gbuffer_depth(geometry) -> float, lodkit_gbuffer_normal(geometry) -> vec3
//   LODKIT_GBUFFER_HALF_MAX: float   largest half (65504)
//   lodkit_gbuffer_pack_half2(v) -> uint, lodkit_gbuffer_unpack_half2(word) -> vec2
//   lodkit_gbuffer_pack_texel(color, view_depth, normal) -> uvec4
//   lodkit_gbuffer_texel_color(texel) -> vec4, lodkit_gbuffer_texel_depth(texel) -> float,
//   lodkit_gbuffer_texel_projected_normal(texel) -> vec2
// Shader defs: none.
#ifndef LODKIT_GBUFFER_GLSL
#define LODKIT_GBUFFER_GLSL

#include "lodkit/normal_distance.glsl"

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

/// Largest finite half float; larger magnitudes are packed as this.
const float LODKIT_GBUFFER_HALF_MAX = 65504.0;

/// `v` as two halves in one word (x in the low 16 bits); see the header for the rounding.
uint lodkit_gbuffer_pack_half2(vec2 v) {
    vec2 a = min(abs(v), vec2(LODKIT_GBUFFER_HALF_MAX));
    // Scaling by 2^-112 moves the exponent to the half's bias; below 2^-14 the product would be a
    // denormal (which a GPU may flush) and is not read. A zero is written without its sign.
    uvec2 bits = (floatBitsToUint(a * 1.92592994e-34) + uvec2(0x1000u)) >> uvec2(13u);
    uvec2 sign_bits = (floatBitsToUint(v) >> uvec2(16u)) & uvec2(0x8000u);
    // Per component: mix() over integer vectors needs GLSL 4.50 or GLSL ES 3.10.
    const float tiny = 6.10351562e-5;
    uvec2 h = uvec2(a.x >= tiny ? bits.x | sign_bits.x : 0u, a.y >= tiny ? bits.y | sign_bits.y : 0u);
    return h.x | (h.y << 16u);
}

/// The two halves of `word` (x from the low 16 bits) as floats.
vec2 lodkit_gbuffer_unpack_half2(uint word) {
    uint lo = ((word << 13u) & 0x0fffe000u) | ((word << 16u) & 0x80000000u);
    uint hi = ((word >> 3u) & 0x0fffe000u) | (word & 0x80000000u);
    return uintBitsToFloat(uvec2(lo, hi)) * 5.19229686e33;
}

/// The packed texel (one rgba32ui target).
uvec4 lodkit_gbuffer_pack_texel(vec4 color, float view_depth, vec3 normal) {
    return uvec4(lodkit_gbuffer_pack_half2(color.xy), lodkit_gbuffer_pack_half2(color.zw),
                 floatBitsToUint(view_depth), lodkit_gbuffer_pack_half2(lodkit_foreshortened_normal(normal)));
}

/// Color of a packed texel.
vec4 lodkit_gbuffer_texel_color(uvec4 texel) {
    return vec4(lodkit_gbuffer_unpack_half2(texel.x), lodkit_gbuffer_unpack_half2(texel.y));
}

/// View depth of a packed texel.
float lodkit_gbuffer_texel_depth(uvec4 texel) {
    return uintBitsToFloat(texel.z);
}

/// The normal of a packed texel through the foreshortening map.
vec2 lodkit_gbuffer_texel_projected_normal(uvec4 texel) {
    return lodkit_gbuffer_unpack_half2(texel.w);
}

#endif // LODKIT_GBUFFER_GLSL
