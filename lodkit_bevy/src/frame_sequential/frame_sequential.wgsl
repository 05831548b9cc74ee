// lodkit_bevy::frame_sequential — what a Bevy material calls to draw a level of a LOD group
// into the camera's LOD buffer (frame-sequential LOD, Scherzer & Wimmer 2008).
//
// The main pass's HDR color is the LOD buffer: a fragment's alpha carries its LOD-buffer id
// word (lodkit::lod_buffer: instance id and the display-time flags), 1 for everything drawn
// normally (an n-instance), -(id * 4 + flags) for a level of a group in transition; the combine
// pass reads it back and writes alpha 1 again. The level's per-frame data comes in Bevy's
// MeshTag (see tag.rs for the layout).
//
// Exports:
//   lod_tag_id(tag) -> u32, lod_tag_tau(tag) -> f32, lod_tag_tau_next(tag) -> f32,
//   lod_tag_object_anchored(tag) -> bool   the tag's fields
//   lod_fragment_alpha(vis_tex, tag, frag_coord, next_coord, pattern_pos) -> f32   the alpha a
//       level's fragment writes: 1 for an n-instance; for a t-instance its id word, with the
//       flags from the visibility pattern anchored to the screen (frag_coord now, next_coord
//       where the fragment is expected next frame) or to the object (pattern_pos)
//   lod_word_from_alpha(alpha) -> u32   the id word an alpha carries (0 for alpha >= 0)
#define_import_path lodkit_bevy::frame_sequential
#import lodkit::visibility::{visibility_flags, visibility_flags_screen}

const LOD_TAG_ID_BITS: u32 = 9u;
const LOD_TAG_TAU_BITS: u32 = 11u;
const LOD_TAG_TAU_STEPS: f32 = 1023.0;

fn lod_tag_id(tag: u32) -> u32 {
    return tag & ((1u << LOD_TAG_ID_BITS) - 1u);
}

fn lod_tag_tau(tag: u32) -> f32 {
    return f32((tag >> LOD_TAG_ID_BITS) & ((1u << LOD_TAG_TAU_BITS) - 1u)) / LOD_TAG_TAU_STEPS - 1.0;
}

fn lod_tag_tau_next(tag: u32) -> f32 {
    return f32((tag >> (LOD_TAG_ID_BITS + LOD_TAG_TAU_BITS)) & ((1u << LOD_TAG_TAU_BITS) - 1u)) / LOD_TAG_TAU_STEPS - 1.0;
}

fn lod_tag_object_anchored(tag: u32) -> bool {
    return (tag >> 31u) != 0u;
}

/// The main-pass alpha of a level's fragment (see the header).
fn lod_fragment_alpha(vis_tex: texture_2d<f32>, tag: u32, frag_coord: vec2<f32>, next_coord: vec2<f32>, pattern_pos: vec3<f32>) -> f32 {
    let id = lod_tag_id(tag);
    if (id == 0u) {
        return 1.0;
    }
    var flags: u32;
    if (lod_tag_object_anchored(tag)) {
        flags = visibility_flags(vis_tex, pattern_pos, lod_tag_tau(tag), lod_tag_tau_next(tag));
    } else {
        flags = visibility_flags_screen(vis_tex, frag_coord, next_coord, lod_tag_tau(tag), lod_tag_tau_next(tag));
    }
    // The flags go in lodkit::lod_buffer's bits 30 and 31 once decoded; here in bits 0 and 1.
    return -f32(id * 4u + flags);
}

/// The lodkit::lod_buffer id word an alpha carries: 0 (an n-instance) for alpha >= 0.
fn lod_word_from_alpha(alpha: f32) -> u32 {
    if (alpha >= 0.0) {
        return 0u;
    }
    let v = u32(round(-alpha));
    return (v >> 2u) | ((v & 3u) << 30u);
}
