// lodkit::visibility — visibility textures for frame-sequential LOD (Scherzer & Wimmer 2008,
// sec. 3.3, eq. 1, Fig. 2), looked up in object space (the paper) or anchored to the screen.
//
// A t-instance's fragments are kept where the visibility texture at the fragment's object-space
// position (or, anchored to the screen, under the pixel where it is displayed) is at most tau
// (eq. 1 discards visTex(p) > tau). Texel values lie in (0, 1), so
// tau = 0 keeps nothing and tau = 1 keeps everything. The lookup uses textureLoad (no sampler, no
// derivatives), so it also works in depth-only and shadow passes.
//
// Exports:
//   visibility_coord(object_pos) -> vec2<f32>   (p.x + p.z, p.y + p.z); use the position BEFORE
//                                               animation/skinning so the pattern sticks to the object
//   visibility_threshold(progress, incoming) -> f32   Fig. 2: incoming 0 -> 1 over the first half,
//                                                      outgoing 1 -> 0 over the second
//   visibility_texel(size, object_pos) -> vec2<u32>   texel looked up (repeat addressing, nearest)
//   check_visibility(vis_tex, object_pos, tau) -> bool   true = keep the fragment
//   visibility_shown(v, tau) -> bool   texel v shown at tau: v <= tau; for tau < 0 the inverted
//                                      pattern, v > 1 + tau (-0 counts as 0)
//   visibility_threshold_complementary(progress, incoming) -> f32   the complementary schedule:
//       incoming progress (v <= p), outgoing -(1 - progress) (v > p)
//   visibility_flags_of(v, tau_now, tau_next) -> u32   the flags from a looked-up texel value
//   visibility_flags(vis_tex, object_pos, tau_now, tau_next) -> u32   display-time visibility of
//       a fragment: bit 0 shown at tau_now (the frame rendered), bit 1 at tau_next (the next frame)
//   visibility_screen_texel(size, frag_coord) -> vec2<u32>   the texel under framebuffer
//       position frag_coord of the texture tiled over the screen, one texel per pixel
//   visibility_next_coord(frag_coord, then_clip, viewport) -> vec2<f32>   where the fragment is
//       expected in the next frame (as far again as it moved since the previous one)
//   visibility_flags_screen(vis_tex, frag_coord, next_coord, tau_now, tau_next) -> u32
//       visibility_flags with the pattern anchored to the screen: bit 0 from the texel under the
//       pixel displayed now, bit 1 from the one under next_coord. The pattern holds still on
//       screen while objects and camera move, as a dither does; under motion a pixel changes
//       only where the threshold passes its texel (see docs/frame-sequential.md)
// The texture repeats once per object-space unit: scale object_pos to change the pattern's size.
// Shader defs: none.
#define_import_path lodkit::visibility
#import lodkit::unpopping::unpopping_alpha

/// Lookup coordinate of an object-space position: (p.x + p.z, p.y + p.z).
fn visibility_coord(object_pos: vec3<f32>) -> vec2<f32> {
    return object_pos.xy + vec2<f32>(object_pos.z);
}

/// Visibility threshold tau of one LOD of a t-instance at transition `progress` in [0, 1]
/// (Fig. 2): the incoming LOD min(2 progress, 1), the outgoing min(2 (1 - progress), 1). Both are 1
/// at progress 0.5 (every fragment of both LODs drawn). The same schedule as unpopping's alpha.
fn visibility_threshold(progress: f32, incoming: bool) -> f32 {
    return unpopping_alpha(progress, incoming);
}

/// The texel of a `size` visibility texture that `object_pos` looks up: repeat addressing,
/// nearest texel.
fn visibility_texel(size: vec2<u32>, object_pos: vec3<f32>) -> vec2<u32> {
    let uv = fract(visibility_coord(object_pos));
    return min(vec2<u32>(uv * vec2<f32>(size)), size - vec2<u32>(1u));
}

/// Whether texel value `v` is shown at threshold `tau`: v <= tau for tau >= 0 (eq. 1); for
/// tau < 0 the inverted pattern, v > 1 + tau, which the complementary schedule gives the outgoing
/// LOD. -0 counts as 0 (nothing shown), so both ends of a schedule are exact.
fn visibility_shown(v: f32, tau: f32) -> bool {
    if (tau < 0.0) {
        return v > 1.0 + tau;
    }
    return v <= tau;
}

/// Visibility threshold of one LOD under the complementary schedule: the incoming LOD shows the
/// texels v <= progress, the outgoing LOD the others (tau = -(1 - progress), the inverted
/// pattern). Spreads the change at silhouettes over the whole transition; no LOD is complete
/// in between (see docs/frame-sequential.md).
fn visibility_threshold_complementary(progress: f32, incoming: bool) -> f32 {
    let p = clamp(progress, 0.0, 1.0);
    if (incoming) {
        return p;
    }
    return -(1.0 - p);
}

/// Display-time flags from texel value `v`: bit 0 shown at `tau_now`, bit 1 at `tau_next`.
fn visibility_flags_of(v: f32, tau_now: f32, tau_next: f32) -> u32 {
    return u32(visibility_shown(v, tau_now)) | (u32(visibility_shown(v, tau_next)) << 1u);
}

/// Whether to keep a fragment at object-space position `object_pos` for threshold `tau`: keeps
/// it where the texel (repeat addressing, nearest) is shown at tau (visibility_shown).
fn check_visibility(vis_tex: texture_2d<f32>, object_pos: vec3<f32>, tau: f32) -> bool {
    let texel = visibility_texel(textureDimensions(vis_tex, 0), object_pos);
    return visibility_shown(textureLoad(vis_tex, texel, 0).r, tau);
}

/// Display-time visibility flags of a fragment: bit 0 set when it is shown at `tau_now` (the
/// frame being rendered), bit 1 at `tau_next` (the next frame, when this LOD buffer is the older
/// one). Write them with lodkit::lod_buffer::lod_buffer_output_flags.
fn visibility_flags(vis_tex: texture_2d<f32>, object_pos: vec3<f32>, tau_now: f32, tau_next: f32) -> u32 {
    let texel = visibility_texel(textureDimensions(vis_tex, 0), object_pos);
    return visibility_flags_of(textureLoad(vis_tex, texel, 0).r, tau_now, tau_next);
}

/// The texel of a `size` visibility texture tiled over the framebuffer, one texel per pixel,
/// under framebuffer position `frag_coord` (pixels; repeat addressing, either sign; the position
/// clamped to +-2^24 pixels, the size to 1..2^24). The modulo runs on non-negative integers only.
fn visibility_screen_texel(size: vec2<u32>, frag_coord: vec2<f32>) -> vec2<u32> {
    let s = vec2<i32>(clamp(size, vec2<u32>(1u), vec2<u32>(16777216u)));
    let p = vec2<i32>(clamp(floor(frag_coord), vec2<f32>(-16777216.0), vec2<f32>(16777216.0)));
    return vec2<u32>((p + s * (vec2<i32>(16777216) / s + 1)) % s);
}

/// Where a fragment at framebuffer position `frag_coord` is expected in the next frame: as far
/// again as it moved since the previous one (constant screen velocity). `then_clip` is its
/// surface point in the previous frame seen by the previous camera (clip space), `viewport` the
/// framebuffer size in pixels; `frag_coord` itself when then_clip lies behind that camera.
fn visibility_next_coord(frag_coord: vec2<f32>, then_clip: vec4<f32>, viewport: vec2<f32>) -> vec2<f32> {
    if (then_clip.w <= 0.0) {
        return frag_coord;
    }
    let then_px = (then_clip.xy / then_clip.w * vec2<f32>(0.5, -0.5) + 0.5) * viewport;
    return 2.0 * frag_coord - then_px;
}

/// Display-time flags with the pattern anchored to the screen: bit 0 set when the texel under
/// `frag_coord` (the pixel displayed in the frame rendered) is shown at `tau_now`, bit 1 when
/// the texel under `next_coord` (where the fragment is displayed in the next frame,
/// visibility_next_coord) is shown at `tau_next`.
fn visibility_flags_screen(vis_tex: texture_2d<f32>, frag_coord: vec2<f32>, next_coord: vec2<f32>, tau_now: f32, tau_next: f32) -> u32 {
    let size = textureDimensions(vis_tex, 0);
    let now = textureLoad(vis_tex, visibility_screen_texel(size, frag_coord), 0).r;
    let next = textureLoad(vis_tex, visibility_screen_texel(size, next_coord), 0).r;
    return u32(visibility_shown(now, tau_now)) | (u32(visibility_shown(next, tau_next)) << 1u);
}
