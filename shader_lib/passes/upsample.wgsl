// passes/upsample — geometry-aware upsampling of the low-resolution buffer L to full resolution
// from a full-resolution depth/normal prepass (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1).
//
// For each full-res pixel: the full-res depth and normal from the prepass, then
// bilateral_upsample_at (its 2x2 nearest L samples, clamped to the viewport, and eq. 1).
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
#import lodkit::bilateral::bilateral_upsample_at

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
    let full = textureLoad(full_geometry, vec2<u32>(v.position.xy), 0);
    return bilateral_upsample_at(
        low_color,
        low_geometry,
        params.low_viewport,
        params.full_size,
        v.position.xy,
        gbuffer_depth(full),
        gbuffer_normal(full),
        params.sigma_z,
        params.sigma_n,
    );
}
