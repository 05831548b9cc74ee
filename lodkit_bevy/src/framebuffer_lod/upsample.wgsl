// lodkit_bevy upsample: reconstructs the low-resolution effect at every full-resolution pixel with
// lodkit's geometry-aware upsample (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1) and blends it
// into the camera's main texture before tonemapping.
//
// Each pixel's depth and normal come from Bevy's prepass; the 2x2 nearest low-resolution texels
// from the effect pass's color and geometry targets (lodkit::gbuffer layout). The depth sigma is
// relative (`settings.depth_sigma` times the pixel's view depth), so a slanted floor far away is
// not taken for an edge; +inf sigmas give plain bilinear upsampling through the same pass.
//
// Entry point: fragment (with Bevy's fullscreen vertex shader), @location(0) into the main texture.
// Bindings (group 0): 0-4 as lodkit_bevy::framebuffer_lod, 5 low_color, 6 low_geometry.
// Blend (set by the pipeline): Over = premultiplied alpha over the scene; Modulate = scene * color
// (fine-grained resizing, sec. 2.3: only the expensive factor went through the low-res pass).
// Shader defs: none.
#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput
#import lodkit::bilateral::bilateral_upsample_at
#import lodkit_bevy::framebuffer_lod::{settings, full_sample}

@group(0) @binding(5) var low_color: texture_2d<f32>;
@group(0) @binding(6) var low_geometry: texture_2d<f32>;

@fragment
fn fragment(in: FullscreenVertexOutput) -> @location(0) vec4<f32> {
    let here = full_sample(vec2<u32>(in.position.xy));
    return bilateral_upsample_at(
        low_color,
        low_geometry,
        settings.low_size,
        settings.full_size,
        in.position.xy,
        here.view_depth,
        here.view_normal,
        settings.depth_sigma * here.view_depth,
        settings.normal_sigma,
    );
}
