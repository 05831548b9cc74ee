// passes/upsample — geometry-aware upsampling of the low-resolution buffer L to full resolution
// from a full-resolution depth/normal prepass (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1).
//
// For each full-res pixel: its position in L's viewport, the 2x2 nearest L samples (clamped to
// the viewport), the full-res depth and normal from the prepass, and bilateral_upsample.
// sigma_z = sigma_n = +inf gives plain bilinear upsampling through the same pass.
// Built only from lodkit::fullscreen, lodkit::gbuffer, lodkit::bilateral.
//
// Entry points:
//   vs_main   fullscreen triangle, draw(0..3)
//   fs_main   @location(0) upsampled color
// Bindings (group 0): 0 low_color texture_2d<f32>, 1 low_geometry texture_2d<f32>,
//   2 full_geometry texture_2d<f32> (the prepass, gbuffer layout), 3 params: UpsampleParams.
// Shader defs: none.
#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
#import lodkit::gbuffer::{gbuffer_depth, gbuffer_normal}
#import lodkit::bilateral::bilateral_upsample

/// Per-frame parameters.
struct UpsampleParams {
    /// Size of the part of L rendered this frame (L is allocated once at full size and drawn
    /// through a viewport that shrinks with r).
    low_viewport: vec2<f32>,
    /// Size of the full-resolution target.
    full_size: vec2<f32>,
    sigma_z: f32,
    sigma_n: f32,
    _pad0: f32,
    _pad1: f32,
}

@group(0) @binding(0) var low_color: texture_2d<f32>;
@group(0) @binding(1) var low_geometry: texture_2d<f32>;
@group(0) @binding(2) var full_geometry: texture_2d<f32>;
@group(0) @binding(3) var<uniform> params: UpsampleParams;

/// Fullscreen triangle.
@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> FullscreenVertex {
    return fullscreen_vertex(vertex_index);
}

/// Reconstructs the full-res pixel from L.
@fragment
fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(v.position.xy);
    let p = (v.position.xy) * params.low_viewport / params.full_size - 0.5;
    let last = max(params.low_viewport - 1.0, vec2<f32>(0.0));
    let base = clamp(floor(p), vec2<f32>(0.0), max(last - 1.0, vec2<f32>(0.0)));
    let f = clamp(p - base, vec2<f32>(0.0), vec2<f32>(1.0));
    var values: array<vec4<f32>, 4>;
    var normals: array<vec3<f32>, 4>;
    var depths: vec4<f32>;
    for (var i = 0u; i < 4u; i++) {
        let texel = vec2<u32>(min(base + vec2<f32>(f32(i & 1u), f32(i >> 1u)), last));
        values[i] = textureLoad(low_color, texel, 0);
        let g = textureLoad(low_geometry, texel, 0);
        depths[i] = gbuffer_depth(g);
        normals[i] = gbuffer_normal(g);
    }
    let full = textureLoad(full_geometry, pixel, 0);
    return bilateral_upsample(f, values, depths, normals, gbuffer_depth(full), gbuffer_normal(full), params.sigma_z, params.sigma_n);
}
