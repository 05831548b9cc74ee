// passes/upsample — geometry-aware upsampling of the low-resolution buffer L to full resolution
// from a full-resolution depth/normal prepass (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1).
//
// For each full-res pixel: the full-res depth and normal from the prepass, then
// bilateral_upsample_at (its 2x2 nearest L samples, clamped to the viewport, and eq. 1).
// sigma_z = sigma_n = +inf gives plain bilinear upsampling through the same pass. With
// LODKIT_UPSAMPLE_MODULATE the upsampled color is multiplied by the full-resolution albedo: the
// composite of fine-grained resizing (sec. 4), where only the lighting went through L. With
// LODKIT_UPSAMPLE_PACKED, L is lodkit::gbuffer's packed layout (one rgba32uint texture) and the
// lookup is bilateral_upsample_packed_at: 4 low-resolution loads and 1 full-resolution load per
// pixel instead of 8 and 1.
// Built only from lodkit::fullscreen, lodkit::gbuffer, lodkit::bilateral.
//
// Entry points:
//   vs_main   fullscreen triangle, draw(0..3)
//   fs_main   @location(0) upsampled color
// Bindings (group 0): 0 low_color texture_2d<f32>, 1 low_geometry texture_2d<f32>,
//   2 full_geometry texture_2d<f32> (the prepass, gbuffer layout), 3 params: UpsampleParams;
//   with LODKIT_UPSAMPLE_MODULATE: 3 full_albedo texture_2d<f32>, 4 params. With
//   LODKIT_UPSAMPLE_PACKED the first two are one: 0 low texture_2d<u32>, and the rest move down
//   by one.
// Shader defs:
//   LODKIT_UPSAMPLE_MODULATE (bool) — multiply by full_albedo (the fine-grained composite).
//   LODKIT_UPSAMPLE_PACKED (bool) — L is one packed rgba32uint texture (lodkit::gbuffer).
#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
#import lodkit::gbuffer::{gbuffer_depth, gbuffer_normal}
#import lodkit::bilateral::{bilateral_relative_sigma, bilateral_upsample_at, bilateral_upsample_packed_at}

/// Per-frame parameters.
struct UpsampleParams {
    /// Size of the part of L rendered this frame (L is allocated once at full size and drawn
    /// through a viewport that shrinks with r).
    low_viewport: vec2<f32>,
    /// Size of the full-resolution target.
    full_size: vec2<f32>,
    /// Depth sigma as a fraction of the pixel's view depth (bilateral_relative_sigma).
    sigma_z: f32,
    sigma_n: f32,
    _pad0: f32,
    _pad1: f32,
}

#ifdef LODKIT_UPSAMPLE_PACKED
@group(0) @binding(0) var low: texture_2d<u32>;
@group(0) @binding(1) var full_geometry: texture_2d<f32>;
#ifdef LODKIT_UPSAMPLE_MODULATE
@group(0) @binding(2) var full_albedo: texture_2d<f32>;
@group(0) @binding(3) var<uniform> params: UpsampleParams;
#else
@group(0) @binding(2) var<uniform> params: UpsampleParams;
#endif
#else
@group(0) @binding(0) var low_color: texture_2d<f32>;
@group(0) @binding(1) var low_geometry: texture_2d<f32>;
@group(0) @binding(2) var full_geometry: texture_2d<f32>;
#ifdef LODKIT_UPSAMPLE_MODULATE
@group(0) @binding(3) var full_albedo: texture_2d<f32>;
@group(0) @binding(4) var<uniform> params: UpsampleParams;
#else
@group(0) @binding(3) var<uniform> params: UpsampleParams;
#endif
#endif

/// Fullscreen triangle.
@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> FullscreenVertex {
    return fullscreen_vertex(vertex_index);
}

/// Reconstructs the full-res pixel from L (times the full-res albedo with
/// LODKIT_UPSAMPLE_MODULATE).
@fragment
fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(v.position.xy);
    let full = textureLoad(full_geometry, pixel, 0);
    let depth = gbuffer_depth(full);
    let sigma_z = bilateral_relative_sigma(params.sigma_z, depth);
    var color: vec4<f32>;
#ifdef LODKIT_UPSAMPLE_PACKED
    color = bilateral_upsample_packed_at(
        low,
        params.low_viewport,
        params.full_size,
        v.position.xy,
        depth,
        gbuffer_normal(full),
        sigma_z,
        params.sigma_n,
    );
#else
    color = bilateral_upsample_at(
        low_color,
        low_geometry,
        params.low_viewport,
        params.full_size,
        v.position.xy,
        depth,
        gbuffer_normal(full),
        sigma_z,
        params.sigma_n,
    );
#endif
#ifdef LODKIT_UPSAMPLE_MODULATE
    return vec4<f32>(color.rgb * textureLoad(full_albedo, pixel, 0).rgb, color.a);
#else
    return color;
#endif
}
