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

#endif // LODKIT_REPROJECT_GLSL
