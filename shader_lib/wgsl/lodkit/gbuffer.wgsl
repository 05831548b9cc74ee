// lodkit::gbuffer — what the low-resolution pass of geometry-aware framebuffer LOD writes, and how
// the upsampler reads it back (Yang, Sander & Lawrence 2008, sec. 2.1).
//
// Layout (MRT, ordinary wgpu formats): location 0 color (the engine's format, e.g. rgba8unorm or
// rgba16float), location 1 geometry rgba16float = (view depth, normal.x, normal.y, normal.z).
// Depth is the positive view-space distance along the view axis (world units, so sigma_z is in
// world units too); the normal is in screen space ((0, 0, 1) faces the viewer).
// Bytes per pixel: 4 (rgba8 color) + 8 (geometry) = 12. The paper packs color, a 16-bit depth
// and an 8+8-bit normal into one 8-byte rgba16 target; lodkit does not offer that variant: it
// saves 4 bytes per low-res pixel (at r = 2, 1 byte per full-res pixel) but needs integer packing
// and loses the normal's z sign and depth precision.
//
// Exports:
//   GBufferOutput { color (location 0), geometry (location 1) }   fragment output of the L pass
//   gbuffer_output(color, view_depth, normal) -> GBufferOutput
//   gbuffer_pack_geometry(view_depth, normal) -> vec4<f32>   the location-1 texel
//   gbuffer_depth(geometry) -> f32, gbuffer_normal(geometry) -> vec3<f32>   unpacking
// Shader defs: none.
#define_import_path lodkit::gbuffer

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
