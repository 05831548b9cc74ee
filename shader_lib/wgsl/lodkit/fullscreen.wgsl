// lodkit::fullscreen — the fullscreen-triangle vertex stage every screen-space pass uses.
//
// Three vertices, no vertex buffer: draw(0..3, 0..1). The triangle (-1,-1), (3,-1), (-1,3) covers
// the viewport; uv is in texture space ((0,0) top-left, (1,1) bottom-right), as wgpu samples it.
//
// Exports:
//   FullscreenVertex { position (builtin), uv (location 0) }   vertex output
//   fullscreen_uv(vertex_index) -> vec2<f32>   (0,0), (2,0), (0,2)
//   fullscreen_position(vertex_index) -> vec4<f32>   clip position, z = 0, w = 1
//   fullscreen_vertex(vertex_index) -> FullscreenVertex   both of the above
// Usage:
//   @vertex fn vs(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
// Shader defs: none.
#define_import_path lodkit::fullscreen

/// Output of a fullscreen vertex stage: clip position and texture-space uv.
struct FullscreenVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

/// Texture-space uv of vertex `vertex_index` (0, 1 or 2) of the fullscreen triangle:
/// (0,0), (2,0), (0,2). Interpolated, it is exactly the pixel's uv inside the viewport.
fn fullscreen_uv(vertex_index: u32) -> vec2<f32> {
    return vec2<f32>(f32((vertex_index << 1u) & 2u), f32(vertex_index & 2u));
}

/// Clip-space position of vertex `vertex_index` of the fullscreen triangle (z = 0, w = 1).
fn fullscreen_position(vertex_index: u32) -> vec4<f32> {
    let uv = fullscreen_uv(vertex_index);
    return vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
}

/// Position and uv of vertex `vertex_index`, ready to return from a `@vertex` entry point.
fn fullscreen_vertex(vertex_index: u32) -> FullscreenVertex {
    return FullscreenVertex(fullscreen_position(vertex_index), fullscreen_uv(vertex_index));
}
