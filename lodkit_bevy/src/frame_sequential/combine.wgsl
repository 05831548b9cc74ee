// lodkit_bevy's combine pass: lodkit's frame-sequential combine (lodkit::combine) over Bevy's
// frame. The newer LOD buffer is this frame's main pass (HDR color with the id word in alpha,
// and its depth), the older one last frame's copy; Bevy's reversed-Z depth
// (LODKIT_REVERSE_Z) and motion vectors (uv now minus uv then, camera motion included) give the
// reprojection and each pixel's object motion. Drawn with Bevy's fullscreen triangle, scissored
// to the rectangles of the groups in transition; writes alpha 1.
//
// The steps are lodkit::combine's combine_at_moved with the id words read from alpha: reproject
// the pixel into the older frame (refined at the older depth found there), moved by the object
// motion; where a t-instance's read lands on another id, the side and diagonal texels holding
// it (combine_match_texel), else the 3x3 block around the read (in combine_search_texel's
// order); then combine_texels. One difference: combine_at_moved searches the 3x3 block only
// for a pixel that moved by itself, around where the camera alone puts it; this pass searches
// around the moved read whenever the side texels miss, since a camera moving along its view
// axis moves silhouettes further than they reach.
#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput
#import lodkit::combine::{combine_uv, combine_texel, combine_side_texel, combine_match_texel, combine_ring_texel, combine_texels, combine_object_motion}
#import lodkit::reproject::{reproject_base, reproject_from_base, reproject_refine, in_viewport}
#import lodkit::lod_buffer::lod_buffer_id
#import lodkit_bevy::frame_sequential::lod_word_from_alpha

struct CombineParams {
    /// Last frame's clip_from_world times this frame's world_from_clip.
    new_to_old: mat4x4<f32>,
    /// x: 1 = read Bevy's motion vectors for object motion.
    flags: vec4<u32>,
}

@group(0) @binding(0) var newer_color: texture_2d<f32>;
@group(0) @binding(1) var newer_depth: texture_depth_2d;
@group(0) @binding(2) var older_color: texture_2d<f32>;
@group(0) @binding(3) var older_depth: texture_depth_2d;
@group(0) @binding(4) var motion_vectors: texture_2d<f32>;
@group(0) @binding(5) var<uniform> params: CombineParams;

fn older_id(texel: vec2<u32>) -> u32 {
    return lod_buffer_id(lod_word_from_alpha(textureLoad(older_color, texel, 0).a));
}

@fragment
fn fragment(in: FullscreenVertexOutput) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(in.position.xy);
    let size = textureDimensions(newer_color, 0);
    let newer = textureLoad(newer_color, pixel, 0);
    let depth = textureLoad(newer_depth, pixel, 0);
    let uv = combine_uv(pixel, size);
    let base = reproject_base(uv, params.new_to_old);
    let old = reproject_from_base(base, depth, params.new_to_old);
    let newer_word = lod_word_from_alpha(newer.a);
    if (!in_viewport(old.xy)) {
        return vec4<f32>(newer.rgb, 1.0);
    }
    var motion = vec2<f32>(0.0);
    if (params.flags.x != 0u) {
        motion = combine_object_motion(uv, depth, params.new_to_old, textureLoad(motion_vectors, pixel, 0).xy);
    }
    let first = old.xy + motion;
    let first_depth = textureLoad(older_depth, combine_texel(first, size), 0);
    let refined = reproject_refine(base, depth, first_depth, params.new_to_old).xy + motion;
    let at = select(first, refined, in_viewport(refined));
    let id = lod_buffer_id(newer_word);
    let read = combine_texel(at, size);
    let read_id = older_id(read);
    var texel = read;
    if (id != 0u && read_id != id) {
        let x = combine_side_texel(at, size, 0u);
        let y = combine_side_texel(at, size, 1u);
        let ids = vec4<u32>(read_id, older_id(x), older_id(y), older_id(vec2<u32>(x.x, y.y)));
        texel = combine_match_texel(id, ids, texel, x, y);
        // Still another object: the 3x3 block around the read (combine_search_texel's order),
        // for a silhouette that moved by more than the side texels reach (a camera moving
        // along its view axis, an object moving by itself).
        if (older_id(texel) != id) {
            for (var k = 1u; k < 9u; k++) {
                let t = combine_ring_texel(read, size, k);
                if (older_id(t) == id) {
                    texel = t;
                    break;
                }
            }
        }
    }
    let older = textureLoad(older_color, texel, 0);
    let color = combine_texels(
        vec4<f32>(newer.rgb, 1.0), newer_word, old,
        vec4<f32>(older.rgb, 1.0), lod_word_from_alpha(older.a), textureLoad(older_depth, texel, 0),
    );
    return vec4<f32>(color.rgb, 1.0);
}
