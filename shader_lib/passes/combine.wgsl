// passes/combine — the frame-sequential combination pass (Scherzer & Wimmer 2008, sec. 3.4):
// merges the LOD buffer rendered this frame with the one from the frame before, reprojected.
//
// For each pixel: read the newer color and id/depth; reproject (uv, depth) into the older buffer
// (the depth-independent part interpolated from the vertex stage), then once more at the older
// buffer's depth there (lodkit::reproject::reproject_refine: the older surface's own parallax);
// outside it -> newer color; else combine_shown(newer with its reprojected depth, older texel),
// the newer sample shown if its LOD_BUFFER_SHOWN_NOW flag is set, the older one if its
// LOD_BUFFER_SHOWN_NEXT flag is (display-time visibility; n-instances always).
// Built only from lodkit::fullscreen, lodkit::lod_buffer, lodkit::reproject, lodkit::combine.
//
// Entry points:
//   vs_main   fullscreen triangle, draw(0..3)
//   fs_main   @location(0) combined color
//   texel_of(uv, size) -> vec2<u32>   helper: the texel at a texture-space uv
// Bindings (group 0): 0 newer_color texture_2d<f32>, 1 newer_id_depth texture_2d<u32>,
//   2 older_color texture_2d<f32>, 3 older_id_depth texture_2d<u32>, 4 params: CombineParams.
// Shader defs: LODKIT_REVERSE_Z (bool, default off) — passed on to lodkit::combine.
#import lodkit::fullscreen::fullscreen_vertex
#import lodkit::lod_buffer::{lod_buffer_id, lod_buffer_depth, lod_buffer_shown, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT}
#import lodkit::reproject::{reproject_base, reproject_from_base, reproject_refine, in_viewport}
#import lodkit::combine::{LodSample, combine_shown}

/// Per-frame parameters.
struct CombineParams {
    /// P_old V_old V_new^-1 P_new^-1.
    new_to_old: mat4x4<f32>,
}

@group(0) @binding(0) var newer_color: texture_2d<f32>;
@group(0) @binding(1) var newer_id_depth: texture_2d<u32>;
@group(0) @binding(2) var older_color: texture_2d<f32>;
@group(0) @binding(3) var older_id_depth: texture_2d<u32>;
@group(0) @binding(4) var<uniform> params: CombineParams;

/// Fullscreen triangle, plus the depth-independent part of the reprojection (affine in uv, so it
/// interpolates exactly and the fragment stage only adds depth x one column).
struct CombineVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) old_base: vec4<f32>,
}

/// Fullscreen triangle with the interpolated reprojection base.
@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> CombineVertex {
    let v = fullscreen_vertex(vertex_index);
    return CombineVertex(v.position, reproject_base(v.uv, params.new_to_old));
}

/// The texel of a `size` texture at texture-space `uv`.
fn texel_of(uv: vec2<f32>, size: vec2<u32>) -> vec2<u32> {
    return min(vec2<u32>(uv * vec2<f32>(size)), size - vec2<u32>(1u));
}

/// Combines the two LOD buffers at this pixel.
@fragment
fn fs_main(v: CombineVertex) -> @location(0) vec4<f32> {
    let size = textureDimensions(newer_color, 0);
    let pixel = vec2<u32>(v.position.xy);
    let newer_texel = textureLoad(newer_id_depth, pixel, 0).xy;
    let newer_depth = lod_buffer_depth(newer_texel);
    let color = textureLoad(newer_color, pixel, 0);
    let old = reproject_from_base(v.old_base, newer_depth, params.new_to_old);
    if (!in_viewport(old.xy)) {
        return color;
    }
    // The first estimate uses the newer pixel's depth; the older surface there may be another
    // one (a stipple hole, an edge): look again where the older surface itself reprojects.
    let first = texel_of(old.xy, size);
    let first_depth = lod_buffer_depth(textureLoad(older_id_depth, first, 0).xy);
    let refined = reproject_refine(v.old_base, newer_depth, first_depth, params.new_to_old);
    let old_pixel = select(first, texel_of(refined.xy, size), in_viewport(refined.xy));
    let older_texel = textureLoad(older_id_depth, old_pixel, 0).xy;
    let newer = LodSample(color, lod_buffer_id(newer_texel), old.z);
    let older = LodSample(
        textureLoad(older_color, old_pixel, 0),
        lod_buffer_id(older_texel),
        lod_buffer_depth(older_texel),
    );
    return combine_shown(
        newer,
        lod_buffer_shown(newer_texel, LOD_BUFFER_SHOWN_NOW),
        older,
        lod_buffer_shown(older_texel, LOD_BUFFER_SHOWN_NEXT),
    );
}
