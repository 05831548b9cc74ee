// lodkit::reproject — back-projection of a pixel of the newer LOD buffer into the older one
// (Scherzer & Wimmer 2008, sec. 3.4, eq. 2).
//
// GLSL twin of shader_lib/wgsl/lodkit/reproject.wgsl; same semantics, `lodkit_` prefix. uv is in
// texture space with (0,0) at the top-left (Vulkan); on OpenGL flip y before and after.
//
// Exports:
//   lodkit_reproject(uv, depth, new_to_old) -> vec3   (old uv, old depth); uv (-1,-1) if behind
//   lodkit_reproject_base(uv, new_to_old) -> vec4   depth-independent part, linear in uv
//   lodkit_reproject_from_base(base, depth, new_to_old) -> vec3   reproject() given that part
//   lodkit_in_viewport(uv) -> bool
//   lodkit_reproject_refine(base, depth, old_depth, new_to_old) -> vec3   the point on the pixel's
//       ray at old depth old_depth, reprojected (the first estimate where there is none)
// Shader defs: none.
#ifndef LODKIT_REPROJECT_GLSL
#define LODKIT_REPROJECT_GLSL

/// new_to_old x (ndc.x, ndc.y, 0, 1) for texture-space `uv`: affine in uv.
vec4 lodkit_reproject_base(vec2 uv, mat4 new_to_old) {
    return new_to_old * vec4(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
}

/// Finishes lodkit_reproject from `base` = lodkit_reproject_base(uv, new_to_old).
vec3 lodkit_reproject_from_base(vec4 base, float depth, mat4 new_to_old) {
    vec4 old = base + depth * new_to_old[2];
    if (old.w <= 0.0) {
        return vec3(-1.0, -1.0, depth);
    }
    vec3 p = old.xyz / old.w;
    return vec3(p.x * 0.5 + 0.5, 0.5 - p.y * 0.5, p.z);
}

/// Position in the older LOD buffer of the newer buffer's pixel at `uv` with clip `depth`.
vec3 lodkit_reproject(vec2 uv, float depth, mat4 new_to_old) {
    return lodkit_reproject_from_base(lodkit_reproject_base(uv, new_to_old), depth, new_to_old);
}

/// Whether `uv` lies inside the older buffer ([0, 1] on both axes).
bool lodkit_in_viewport(vec2 uv) {
    return all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)));
}

/// Reprojects the point on this pixel's ray whose old clip depth is `old_depth` (the first
/// estimate, `depth`, where there is none).
vec3 lodkit_reproject_refine(vec4 base, float depth, float old_depth, mat4 new_to_old) {
    // Solved or not is read from num and den, never from the quotient (see the WGSL form).
    vec4 c = new_to_old[2];
    float num = old_depth * base.w - base.z;
    float den = c.z - old_depth * c.w;
    bool solved = abs(den) >= 1.17549435e-38 && abs(num) <= 3.0e38 * min(abs(den), 1.0);
    return lodkit_reproject_from_base(base, solved ? num / den : depth, new_to_old);
}

#endif // LODKIT_REPROJECT_GLSL
