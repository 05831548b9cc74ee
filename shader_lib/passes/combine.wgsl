// passes/combine — the frame-sequential combination pass (Scherzer & Wimmer 2008, sec. 3.4):
// merges the LOD buffer rendered this frame with the one from the frame before, reprojected.
//
// For each pixel, lodkit::combine::combine_at_moved: read the newer color, id word, depth and
// object motion; reproject (uv, depth) into the older buffer, then once more at the older
// buffer's depth there (the older surface's own parallax), and move by the object motion the LOD
// pass wrote (where a swaying or moving surface was); outside the older view -> newer color; else
// combine_shown, the newer sample shown if its LOD_BUFFER_SHOWN_NOW flag is set, the older one if
// its LOD_BUFFER_SHOWN_NEXT flag is (display-time visibility; n-instances always). An engine with
// a full-screen pass of its own calls combine_at_moved (or combine_at) there instead.
// With LODKIT_COMBINE_KNOWN: lodkit::combine_coverage::combine_pixel, which knows where each
// t-instance's older level covers the screen from the frame's data texture (its silhouette, the
// older-level depth pass at binding 9, or the estimate, per t-instance).
// Built only from lodkit::fullscreen, lodkit::combine and lodkit::combine_coverage.
//
// Entry points:
//   vs_main   fullscreen triangle, draw(0..3)
//   fs_main   @location(0) combined color
// Bindings (group 0): 0 newer_color texture_2d<f32>, 1 newer_id texture_2d<u32>, 2 newer_depth
//   texture_2d<f32> (the depth attachment), 3 older_color, 4 older_id, 5 older_depth,
//   6 object_motion texture_2d<f32> (the LOD pass's location 2, this frame; a 1x1 texture
//   holding 0 for buffers without a motion target: every pixel reads its one texel), 7 params:
//   CombineParams, 8 data texture_2d<u32> (lodkit::combine_coverage::CombineData; read with
//   LODKIT_COMBINE_KNOWN), 9 level_depth texture_2d<f32> (the older-level depth pass at the
//   target's size, or a 1x1 texture when the data says it is not read), 10 pattern
//   texture_2d<f32> (the visibility pattern the LOD pass anchors to the screen, red channel, read
//   with LODKIT_COMBINE_KNOWN at each pixel for the older levels the data displays at an
//   older_tau; a 1x1 texture when none is).
// Shader defs: LODKIT_REVERSE_Z (bool, default off) — passed on to lodkit::combine.
//   LODKIT_COMBINE_STILL (bool, default off) — for buffers without object motion: combine_at,
//   which does not read binding 6 and whose 3x3 search is dead code once the driver folds the
//   zero motion (one fetch fewer on the main path, and no search for a GPU that runs both sides
//   of a branch to pay for; `lodkit check --stats` does not fold, so still counts it).
//   LODKIT_COMBINE_KNOWN (bool, default off) — combine_pixel with the data at binding 8.
#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
#import lodkit::combine::{combine_at, combine_at_moved}
#import lodkit::combine_coverage::{CombineNewer, combine_pixel}
#import lodkit::visibility::visibility_screen_texel

/// Per-frame parameters.
struct CombineParams {
    /// P_old V_old V_new^-1 P_new^-1.
    new_to_old: mat4x4<f32>,
}

@group(0) @binding(0) var newer_color: texture_2d<f32>;
@group(0) @binding(1) var newer_id: texture_2d<u32>;
@group(0) @binding(2) var newer_depth: texture_2d<f32>;
@group(0) @binding(3) var older_color: texture_2d<f32>;
@group(0) @binding(4) var older_id: texture_2d<u32>;
@group(0) @binding(5) var older_depth: texture_2d<f32>;
@group(0) @binding(6) var object_motion: texture_2d<f32>;
@group(0) @binding(7) var<uniform> params: CombineParams;
@group(0) @binding(8) var data: texture_2d<u32>;
@group(0) @binding(9) var level_depth: texture_2d<f32>;
@group(0) @binding(10) var pattern: texture_2d<f32>;

/// Fullscreen triangle.
@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> FullscreenVertex {
    return fullscreen_vertex(vertex_index);
}

/// Combines the two LOD buffers at this pixel.
@fragment
fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(v.position.xy);
#ifdef LODKIT_COMBINE_KNOWN
    let motion = textureLoad(object_motion, min(pixel, textureDimensions(object_motion, 0) - 1u), 0).xy;
    let level = textureLoad(level_depth, min(pixel, textureDimensions(level_depth, 0) - 1u), 0).x;
    let shown = textureLoad(pattern, visibility_screen_texel(textureDimensions(pattern, 0), v.position.xy), 0).r;
    let newer = CombineNewer(textureLoad(newer_color, pixel, 0), textureLoad(newer_id, pixel, 0).x, textureLoad(newer_depth, pixel, 0).x, motion, shown, level);
    return combine_pixel(newer, pixel, older_color, older_id, older_depth, data);
#else ifdef LODKIT_COMBINE_STILL
    return combine_at(newer_color, newer_id, newer_depth, older_color, older_id, older_depth, pixel, params.new_to_old);
#else
    let motion = textureLoad(object_motion, min(pixel, textureDimensions(object_motion, 0) - 1u), 0).xy;
    return combine_at_moved(newer_color, newer_id, newer_depth, older_color, older_id, older_depth, pixel, params.new_to_old, motion);
#endif
}
