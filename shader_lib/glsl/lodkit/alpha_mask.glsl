// lodkit::alpha_mask — alpha-tested LODs (billboard impostors, foliage cards): a coverage mask
// looked up at the fragment's object-space position (Scherzer & Wimmer 2008, sec. 1, 3.3).
//
// GLSL twin of shader_lib/wgsl/lodkit/alpha_mask.wgsl; same semantics, `lodkit_` prefix.
// uv = p.xy * rect.xy + rect.zw; rect.x == 0: no mask; a texel >= 0.5 is covered.
//
// Exports:
//   lodkit_alpha_mask_uv(p, rect) -> vec2
//   lodkit_alpha_mask_inside(uv) -> bool
//   lodkit_alpha_mask_texel(uv, size) -> uvec2
//   lodkit_alpha_mask_keep(mask, p, rect) -> bool   a macro: takes a sampler2D, or
//       sampler2D(texture, sampler) in Vulkan GLSL
// Usage: if (!lodkit_alpha_mask_keep(mask_tex, object_pos, alpha_rect)) discard;
// Shader defs: none.
#ifndef LODKIT_ALPHA_MASK_GLSL
#define LODKIT_ALPHA_MASK_GLSL

/// Mask uv of object-space position `p`.
vec2 lodkit_alpha_mask_uv(vec3 p, vec4 rect) {
    return p.xy * rect.xy + rect.zw;
}

/// Whether uv lies within the mask, [0, 1) on both axes.
bool lodkit_alpha_mask_inside(vec2 uv) {
    return all(greaterThanEqual(uv, vec2(0.0))) && all(lessThan(uv, vec2(1.0)));
}

/// The texel of a `size` mask at uv (clamped).
uvec2 lodkit_alpha_mask_texel(vec2 uv, uvec2 size) {
    vec2 inside = clamp(uv, vec2(0.0), vec2(1.0));
    return min(uvec2(inside * vec2(size)), size - uvec2(1u));
}

/// Whether the fragment at object-space p survives the alpha test (always without a mask).
#define lodkit_alpha_mask_keep(mask, p, rect) \
    ((rect).x == 0.0 || (lodkit_alpha_mask_inside(lodkit_alpha_mask_uv((p), (rect))) && \
        texelFetch((mask), ivec2(lodkit_alpha_mask_texel(lodkit_alpha_mask_uv((p), (rect)), \
            uvec2(textureSize((mask), 0)))), 0).x >= 0.5))

#endif // LODKIT_ALPHA_MASK_GLSL
