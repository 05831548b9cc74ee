// lodkit::visibility — visibility textures for frame-sequential LOD (Scherzer & Wimmer 2008,
// sec. 3.3, eq. 1, Fig. 2), looked up in object space (the paper) or anchored to the screen.
//
// GLSL twin of shader_lib/wgsl/lodkit/visibility.wgsl; same semantics, `lodkit_` prefix. Texel
// values lie in (0, 1): tau = 0 keeps nothing, tau = 1 everything. Uses texelFetch (no
// derivatives). lodkit_check_visibility is a macro: GLSL cannot pass a texture to a function in a
// way both OpenGL (sampler2D) and Vulkan (texture2D + sampler) accept, and a macro takes either,
// e.g. lodkit_check_visibility(sampler2D(vis_texture, vis_sampler), p, tau).
//
// Exports:
//   lodkit_visibility_coord(object_pos) -> vec2   (p.x + p.z, p.y + p.z), before animation
//   lodkit_visibility_threshold(progress, incoming) -> float   Fig. 2 schedule
//   lodkit_visibility_texel(size, object_pos) -> uvec2   texel looked up (repeat, nearest)
//   lodkit_check_visibility(vis_tex, object_pos, tau) -> bool   true = keep the fragment (macro)
//   lodkit_visibility_shown(v, tau) -> bool   v <= tau; tau < 0: the inverted pattern, v > 1 + tau
//   lodkit_visibility_threshold_complementary(progress, incoming) -> float   incoming progress,
//       outgoing -(1 - progress)
//   lodkit_visibility_flags_of(v, tau_now, tau_next) -> uint   the flags from a texel value
//   lodkit_visibility_flags(vis_tex, object_pos, tau_now, tau_next) -> uint   bit 0 shown at
//       tau_now, bit 1 at tau_next (macro)
//   lodkit_visibility_screen_texel(size, frag_coord) -> uvec2   the texel under a framebuffer
//       position of the texture tiled over the screen, one texel per pixel
//   lodkit_visibility_next_coord(frag_coord, then_clip, viewport) -> vec2   where the fragment is
//       expected in the next frame
//   lodkit_visibility_flags_screen(vis_tex, frag_coord, next_coord, tau_now, tau_next) -> uint
//       the flags with the pattern anchored to the screen (macro)
// Shader defs: none.
#ifndef LODKIT_VISIBILITY_GLSL
#define LODKIT_VISIBILITY_GLSL

#include "lodkit/unpopping.glsl"

/// Lookup coordinate of an object-space position: (p.x + p.z, p.y + p.z).
vec2 lodkit_visibility_coord(vec3 object_pos) {
    return object_pos.xy + vec2(object_pos.z);
}

/// Visibility threshold tau of one LOD at transition `progress` (Fig. 2).
float lodkit_visibility_threshold(float progress, bool incoming) {
    return lodkit_unpopping_alpha(progress, incoming);
}

/// The texel of a `size` visibility texture that `object_pos` looks up (repeat, nearest).
uvec2 lodkit_visibility_texel(uvec2 size, vec3 object_pos) {
    vec2 uv = fract(lodkit_visibility_coord(object_pos));
    return min(uvec2(uv * vec2(size)), size - uvec2(1u));
}

/// Whether texel value `v` is shown at threshold `tau` (tau < 0: the inverted pattern).
bool lodkit_visibility_shown(float v, float tau) {
    if (tau < 0.0) {
        return v > 1.0 + tau;
    }
    return v <= tau;
}

/// Visibility threshold of one LOD under the complementary schedule.
float lodkit_visibility_threshold_complementary(float progress, bool incoming) {
    float p = clamp(progress, 0.0, 1.0);
    if (incoming) {
        return p;
    }
    return -(1.0 - p);
}

/// Display-time flags from texel value `v`: bit 0 shown at tau_now, bit 1 at tau_next.
uint lodkit_visibility_flags_of(float v, float tau_now, float tau_next) {
    return uint(lodkit_visibility_shown(v, tau_now)) | (uint(lodkit_visibility_shown(v, tau_next)) << 1u);
}

/// The texel value at `object_pos` (repeat, nearest).
#define LODKIT_VISIBILITY_VALUE_(vis_tex, object_pos) \
    texelFetch((vis_tex), ivec2(lodkit_visibility_texel(uvec2(textureSize((vis_tex), 0)), (object_pos))), 0).r

/// Whether to keep a fragment at `object_pos` for threshold `tau` (lodkit_visibility_shown of its
/// texel; repeat, nearest).
#define lodkit_check_visibility(vis_tex, object_pos, tau) \
    lodkit_visibility_shown(LODKIT_VISIBILITY_VALUE_(vis_tex, object_pos), (tau))

/// Display-time flags of a fragment at `object_pos`: bit 0 shown at tau_now, bit 1 at tau_next.
#define lodkit_visibility_flags(vis_tex, object_pos, tau_now, tau_next) \
    lodkit_visibility_flags_of(LODKIT_VISIBILITY_VALUE_(vis_tex, object_pos), (tau_now), (tau_next))

/// The texel of a `size` visibility texture tiled over the framebuffer, one texel per pixel,
/// under framebuffer position `frag_coord` (repeat addressing, either sign; the position clamped
/// to +-2^24, the size to 1..2^24). The modulo runs on non-negative integers only (GLSL leaves %
/// of negative operands undefined).
uvec2 lodkit_visibility_screen_texel(uvec2 size, vec2 frag_coord) {
    ivec2 s = ivec2(clamp(size, uvec2(1u), uvec2(16777216u)));
    ivec2 p = ivec2(clamp(floor(frag_coord), vec2(-16777216.0), vec2(16777216.0)));
    return uvec2((p + s * (ivec2(16777216) / s + 1)) % s);
}

/// Where a fragment at `frag_coord` is expected in the next frame: as far again as it moved
/// since the previous one (`then_clip`: its point then, previous camera; `viewport` in pixels).
vec2 lodkit_visibility_next_coord(vec2 frag_coord, vec4 then_clip, vec2 viewport) {
    if (then_clip.w <= 0.0) {
        return frag_coord;
    }
    vec2 then_px = (then_clip.xy / then_clip.w * vec2(0.5, -0.5) + 0.5) * viewport;
    return 2.0 * frag_coord - then_px;
}

/// The texel value under framebuffer position `c` of the texture tiled over the screen.
#define LODKIT_VISIBILITY_SCREEN_VALUE_(vis_tex, c) \
    texelFetch((vis_tex), ivec2(lodkit_visibility_screen_texel(uvec2(textureSize((vis_tex), 0)), (c))), 0).r

/// Display-time flags with the pattern anchored to the screen: bit 0 from the texel under
/// `frag_coord` at tau_now, bit 1 from the texel under `next_coord` at tau_next.
#define lodkit_visibility_flags_screen(vis_tex, frag_coord, next_coord, tau_now, tau_next) \
    (uint(lodkit_visibility_shown(LODKIT_VISIBILITY_SCREEN_VALUE_(vis_tex, frag_coord), (tau_now))) \
        | (uint(lodkit_visibility_shown(LODKIT_VISIBILITY_SCREEN_VALUE_(vis_tex, next_coord), (tau_next))) << 1u))

#endif // LODKIT_VISIBILITY_GLSL
