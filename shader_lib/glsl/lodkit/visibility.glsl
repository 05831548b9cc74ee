// lodkit::visibility — object-space visibility textures for frame-sequential LOD
// (Scherzer & Wimmer 2008, sec. 3.3, eq. 1, Fig. 2).
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

#endif // LODKIT_VISIBILITY_GLSL
