// lodkit::gbuffer — what the low-resolution pass of geometry-aware framebuffer LOD writes, and how
// the upsampler reads it back (Yang, Sander & Lawrence 2008, sec. 2.1).
//
// Layout (MRT, ordinary wgpu formats): location 0 color (the engine's format, e.g. rgba8unorm or
// rgba16float), location 1 geometry rgba16float = (view depth, normal.x, normal.y, normal.z).
// Depth is the positive view-space distance along the view axis (world units, so sigma_z is in
// world units too); the normal is in screen space ((0, 0, 1) faces the viewer).
// Bytes per pixel: 4 (rgba8 color) + 8 (geometry) = 12.
//
// Packed layout (one rgba32uint target, 16 bytes per pixel, HDR color kept): the upsampler reads
// one texel per cell corner instead of two. x = half(color.r) | half(color.g) << 16, y = the same
// for (b, a), z = the f32 bits of the view depth, w = the normal through lodkit::normal_distance's
// foreshortening map (nx / nz, ny / nz) as two halves: what eq. 1 compares, so the upsampler
// divides nothing. Halves are written by lodkit's own conversion (no float16 capability needed):
// round to nearest (ties away from zero), magnitudes clamped to 65504, those below 2^-14 (the
// smallest normal half) written as +0. The paper's variant (a 16-bit depth and an 8+8-bit
// normal in one rgba16 target) loses the normal's z sign and depth precision; lodkit does not
// offer it.
//
// Exports:
//   GBufferOutput { color (location 0), geometry (location 1) }   fragment output of the L pass
//   gbuffer_output(color, view_depth, normal) -> GBufferOutput
//   gbuffer_pack_geometry(view_depth, normal) -> vec4<f32>   the location-1 texel
//   gbuffer_depth(geometry) -> f32, gbuffer_normal(geometry) -> vec3<f32>   unpacking
//   GBUFFER_HALF_MAX: f32   largest half (65504)
//   gbuffer_pack_half2(v) -> u32, gbuffer_unpack_half2(word) -> vec2<f32>   two halves in a word
//   gbuffer_pack_texel(color, view_depth, normal) -> vec4<u32>   the packed texel
//   gbuffer_texel_color(texel) -> vec4<f32>, gbuffer_texel_depth(texel) -> f32,
//   gbuffer_texel_projected_normal(texel) -> vec2<f32>   unpacking the packed texel
// Shader defs: none.
#define_import_path lodkit::gbuffer
#import lodkit::normal_distance::foreshortened_normal

/// Fragment output of the low-resolution pass.
struct GBufferOutput {
    @location(0) color: vec4<f32>,
    @location(1) geometry: vec4<f32>,
}

/// The geometry texel: (view depth, normal).
fn gbuffer_pack_geometry(view_depth: f32, normal: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(view_depth, normal);
}

/// Color and geometry of a low-resolution pixel, ready to return from a fragment stage.
fn gbuffer_output(color: vec4<f32>, view_depth: f32, normal: vec3<f32>) -> GBufferOutput {
    return GBufferOutput(color, gbuffer_pack_geometry(view_depth, normal));
}

/// View depth stored in a geometry texel.
fn gbuffer_depth(geometry: vec4<f32>) -> f32 {
    return geometry.x;
}

/// Screen-space normal stored in a geometry texel (as written; half precision).
fn gbuffer_normal(geometry: vec4<f32>) -> vec3<f32> {
    return geometry.yzw;
}

/// Largest finite half float; larger magnitudes are packed as this.
const GBUFFER_HALF_MAX: f32 = 65504.0;

/// `v` as two IEEE half floats in one word, x in the low 16 bits: rounded to nearest (ties away
/// from zero), magnitudes clamped to GBUFFER_HALF_MAX, those below 2^-14 written as +0 (a zero's
/// sign is not kept: GPUs need not keep it, so the word must not depend on it). Inputs must be
/// finite.
fn gbuffer_pack_half2(v: vec2<f32>) -> u32 {
    let a = min(abs(v), vec2<f32>(GBUFFER_HALF_MAX));
    // Scaling by 2^-112 moves the exponent to the half's bias: the half is then the float's bits
    // shifted right by 13, after adding half of the dropped last place. Below 2^-14 the product
    // would be a denormal (which a GPU may flush): those magnitudes are not read.
    let bits = (bitcast<vec2<u32>>(a * 1.92592994e-34) + vec2<u32>(0x1000u)) >> vec2<u32>(13u);
    let sign = (bitcast<vec2<u32>>(v) >> vec2<u32>(16u)) & vec2<u32>(0x8000u);
    // One select per component: naga writes a select with a vector condition as
    // mix(a, b, bvec), which GLSL before 4.50 and GLSL ES 3.00 (GL 3.3, GLES 3.0, WebGL2) only
    // have for float vectors; a scalar condition becomes `?:`, which every version has.
    let tiny = 6.10351562e-5;
    let h = vec2<u32>(
        select(0u, bits.x | sign.x, a.x >= tiny),
        select(0u, bits.y | sign.y, a.y >= tiny),
    );
    return h.x | (h.y << 16u);
}

/// The two halves of `word` (x from the low 16 bits) as floats; exact for what
/// gbuffer_pack_half2 writes.
fn gbuffer_unpack_half2(word: u32) -> vec2<f32> {
    // Each half's magnitude goes to a float's bits 13..27 and its sign to bit 31: that float
    // times 2^112 is the half's value.
    let lo = ((word << 13u) & 0x0fffe000u) | ((word << 16u) & 0x80000000u);
    let hi = ((word >> 3u) & 0x0fffe000u) | (word & 0x80000000u);
    return bitcast<vec2<f32>>(vec2<u32>(lo, hi)) * 5.19229686e33;
}

/// The packed texel (one rgba32uint target): color as halves, the view depth as f32 bits, the
/// foreshortened normal as halves.
fn gbuffer_pack_texel(color: vec4<f32>, view_depth: f32, normal: vec3<f32>) -> vec4<u32> {
    return vec4<u32>(
        gbuffer_pack_half2(color.xy),
        gbuffer_pack_half2(color.zw),
        bitcast<u32>(view_depth),
        gbuffer_pack_half2(foreshortened_normal(normal)),
    );
}

/// Color of a packed texel (half precision).
fn gbuffer_texel_color(texel: vec4<u32>) -> vec4<f32> {
    return vec4<f32>(gbuffer_unpack_half2(texel.x), gbuffer_unpack_half2(texel.y));
}

/// View depth of a packed texel (full precision).
fn gbuffer_texel_depth(texel: vec4<u32>) -> f32 {
    return bitcast<f32>(texel.z);
}

/// The normal of a packed texel through the foreshortening map, (nx / nz, ny / nz) as
/// lodkit::normal_distance's foreshortened_normal gives it (half precision).
fn gbuffer_texel_projected_normal(texel: vec4<u32>) -> vec2<f32> {
    return gbuffer_unpack_half2(texel.w);
}
