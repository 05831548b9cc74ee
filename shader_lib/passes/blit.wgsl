// passes/blit — a plain fullscreen copy: samples one texture and writes it to the target.
//
// The baseline every screen-space pass of lodkit is measured against, and the smallest complete
// pipeline built from the modules.
//
// Entry points:
//   vs_main   fullscreen triangle (lodkit::fullscreen), draw(0..3)
//   fs_main   @location(0) color = textureSampleLevel(source, source_sampler, uv, 0)
// Bindings (group 0): 0 source: texture_2d<f32>, 1 source_sampler: sampler.
// Shader defs: none.
#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var source_sampler: sampler;

/// Fullscreen triangle.
@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> FullscreenVertex {
    return fullscreen_vertex(vertex_index);
}

/// Copies the source texel under the pixel.
@fragment
fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    return textureSampleLevel(source, source_sampler, v.uv, 0.0);
}
