// lodkit::impostor — octahedral impostors: an object drawn as a camera-facing card that shows
// pictures of it baked from many directions; the three frames nearest the view blended, each
// sampled after one parallax step from the depth stored with it.
//
// GLSL twin of shader_lib/wgsl/lodkit/impostor.wgsl; same semantics, `lodkit_` prefix. Space:
// the bounding sphere normalized to the unit sphere, y up; frame uv = (dot(q, right),
// -dot(q, up)) * 0.5 + 0.5, stored depth dot(q, dir) * 0.5 + 0.5; frame (i, j) at column i,
// row j of the atlas.
//
// Exports:
//   lodkit_impostor_sign(v) -> vec2   +1 or -1 per component (+1 for zero)
//   lodkit_impostor_octa_encode(d) -> vec2, lodkit_impostor_octa_decode(e) -> vec3
//   lodkit_impostor_hemi_encode(d) -> vec2, lodkit_impostor_hemi_decode(e) -> vec3
//   lodkit_impostor_encode(d, hemi) -> vec2, lodkit_impostor_decode(e, hemi) -> vec3
//   lodkit_impostor_frame_dir(frame, n, hemi) -> vec3
//   lodkit_impostor_frame_basis(dir) -> mat3   columns (right, up, dir)
//   lodkit_ImpostorBlend { frames: uvec2[3], weights: vec3 }
//   lodkit_impostor_blend(view, n, hemi) -> lodkit_ImpostorBlend
//   lodkit_impostor_ray_at_height(origin, ray, dir, height) -> vec3
//   lodkit_impostor_frame_uv(basis, q) -> vec2
//   lodkit_impostor_atlas_uv(frame, n, uv) -> vec2
//   lodkit_impostor_frame_inset(texels, level) -> float
//   lodkit_impostor_depth_height(depth) -> float
//   lodkit_ImpostorSample { color: vec4, normal: vec3, point: vec3 }
//   lodkit_impostor_sample_frame(frame, n, hemi, origin, ray, level) -> lodkit_ImpostorSample
//   lodkit_impostor_sample(n, hemi, origin, ray, level) -> lodkit_ImpostorSample   (hooks)
//   lodkit_impostor_keep(alpha) -> bool
// Hooks (GLSL cannot pass a texture to a function on every target, so the two sampling
// functions read the atlases through functions the includer defines after the include; they
// are compiled only where LODKIT_IMPOSTOR_HOOKS is defined before the include):
//   vec4 lodkit_impostor_fetch_color(vec2 uv, float level)   the colour atlas (linear, clamp)
//   vec4 lodkit_impostor_fetch_normal_depth(vec2 uv, float level)   the normal-depth atlas
//   uint lodkit_impostor_atlas_texels()   the atlases' side in texels at mip 0
// Shader defs: none.
#ifndef LODKIT_IMPOSTOR_GLSL
#define LODKIT_IMPOSTOR_GLSL

/// +1 or -1 by the sign of each component; +1 for either zero.
vec2 lodkit_impostor_sign(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

/// Unit direction d on the octahedron unfolded into [-1, 1]^2 (+y at the centre).
vec2 lodkit_impostor_octa_encode(vec3 d) {
    vec2 p = d.xz / (abs(d.x) + abs(d.y) + abs(d.z));
    if (d.y >= 0.0) {
        return p;
    }
    return (vec2(1.0) - abs(p.yx)) * lodkit_impostor_sign(p);
}

/// Inverse of lodkit_impostor_octa_encode.
vec3 lodkit_impostor_octa_decode(vec2 e) {
    float y = 1.0 - abs(e.x) - abs(e.y);
    vec2 xz = e;
    if (y < 0.0) {
        xz = (vec2(1.0) - abs(e.yx)) * lodkit_impostor_sign(e);
    }
    return normalize(vec3(xz.x, y, xz.y));
}

/// Unit direction d of the upper hemisphere (y clamped to >= 0) on [-1, 1]^2; straight below
/// maps to (1, 1).
vec2 lodkit_impostor_hemi_encode(vec3 d) {
    if (abs(d.x) + abs(d.z) == 0.0 && d.y < 0.0) {
        return vec2(1.0);
    }
    vec2 p = d.xz / max(abs(d.x) + max(d.y, 0.0) + abs(d.z), 1e-30);
    return vec2(p.x + p.y, p.x - p.y);
}

/// Inverse of lodkit_impostor_hemi_encode.
vec3 lodkit_impostor_hemi_decode(vec2 e) {
    vec2 p = vec2(e.x + e.y, e.x - e.y) * 0.5;
    return normalize(vec3(p.x, 1.0 - abs(p.x) - abs(p.y), p.y));
}

/// The hemi map when hemi, else the full octahedral map.
vec2 lodkit_impostor_encode(vec3 d, bool hemi) {
    if (hemi) {
        return lodkit_impostor_hemi_encode(d);
    }
    return lodkit_impostor_octa_encode(d);
}

/// Inverse of lodkit_impostor_encode.
vec3 lodkit_impostor_decode(vec2 e, bool hemi) {
    if (hemi) {
        return lodkit_impostor_hemi_decode(e);
    }
    return lodkit_impostor_octa_decode(e);
}

/// The direction frame `frame` of an n x n grid was baked from.
vec3 lodkit_impostor_frame_dir(uvec2 frame, uint n, bool hemi) {
    vec2 e = vec2(frame) * (2.0 / float(max(n, 2u) - 1u)) - 1.0;
    return lodkit_impostor_decode(e, hemi);
}

/// The frame's axes as columns (right, up, dir); at the poles up is -z (above) or +z (below).
mat3 lodkit_impostor_frame_basis(vec3 dir) {
    vec3 reference = vec3(0.0, 1.0, 0.0);
    if (abs(dir.x) + abs(dir.z) < 1e-6) {
        reference = vec3(0.0, 0.0, dir.y > 0.0 ? -1.0 : 1.0);
    }
    vec3 right = normalize(cross(reference, dir));
    return mat3(right, cross(dir, right), dir);
}

/// The three frames around a view direction and their barycentric weights.
struct lodkit_ImpostorBlend {
    uvec2 frames[3];
    vec3 weights;
};

/// The frames of an n x n grid (n < 2 taken as 2) to blend for unit view direction `view`.
lodkit_ImpostorBlend lodkit_impostor_blend(vec3 view, uint n, bool hemi) {
    float last = float(max(n, 2u) - 1u);
    vec2 g = clamp(lodkit_impostor_encode(view, hemi) * 0.5 + 0.5, vec2(0.0), vec2(1.0)) * last;
    vec2 cell = min(floor(g), vec2(last - 1.0));
    vec2 f = g - cell;
    uvec2 c = uvec2(cell);
    lodkit_ImpostorBlend b;
    b.frames[1] = c + uvec2(1u, 0u);
    b.frames[2] = c + uvec2(0u, 1u);
    if (f.x + f.y <= 1.0) {
        b.frames[0] = c;
        b.weights = vec3(1.0 - f.x - f.y, f.x, f.y);
    } else {
        b.frames[0] = c + uvec2(1u, 1u);
        b.weights = vec3(f.x + f.y - 1.0, 1.0 - f.y, 1.0 - f.x);
    }
    return b;
}

/// The point of the ray origin + t ray at `height` above the plane of frame direction dir.
vec3 lodkit_impostor_ray_at_height(vec3 origin, vec3 ray, vec3 dir, float height) {
    float t = (height - dot(origin, dir)) / min(dot(ray, dir), -1e-4);
    return origin + t * ray;
}

/// The uv of point q in the frame with axes `basis` (row 0 at the top).
vec2 lodkit_impostor_frame_uv(mat3 basis, vec3 q) {
    return vec2(dot(q, basis[0]), -dot(q, basis[1])) * 0.5 + 0.5;
}

/// The atlas uv of frame uv `uv` in frame `frame`, uv clamped to [0, 1].
vec2 lodkit_impostor_atlas_uv(uvec2 frame, uint n, vec2 uv) {
    return (vec2(frame) + clamp(uv, vec2(0.0), vec2(1.0))) / float(n);
}

/// How far inside its frame (frame uv) a sample at mip `level` of an atlas whose frames are
/// `texels` texels wide stays: half a texel of the coarsest mip trilinear filtering reads there
/// (at most 0.5, the frame's centre).
float lodkit_impostor_frame_inset(float texels, float level) {
    return min(0.5 * exp2(ceil(max(level, 0.0))) / texels, 0.5);
}

/// The height [-1, 1] above a frame's plane of a stored depth in [0, 1].
float lodkit_impostor_depth_height(float depth) {
    return depth * 2.0 - 1.0;
}

/// What one impostor fragment sees.
struct lodkit_ImpostorSample {
    vec4 color;
    vec3 normal;
    vec3 point;
};

#ifdef LODKIT_IMPOSTOR_HOOKS
/// Hook: the colour atlas at `uv`, mip `level` (defined by the includer).
vec4 lodkit_impostor_fetch_color(vec2 uv, float level);
/// Hook: the normal-depth atlas at `uv`, mip `level`.
vec4 lodkit_impostor_fetch_normal_depth(vec2 uv, float level);
/// Hook: the atlases' side in texels at mip 0.
uint lodkit_impostor_atlas_texels();

/// One frame's look along the ray (one parallax step), read inside the frame's inset
/// (lodkit_impostor_frame_inset); coverage 0 outside the frame's square.
lodkit_ImpostorSample lodkit_impostor_sample_frame(uvec2 frame, uint n, bool hemi, vec3 origin, vec3 ray, float level) {
    vec3 dir = lodkit_impostor_frame_dir(frame, n, hemi);
    mat3 basis = lodkit_impostor_frame_basis(dir);
    float inset = lodkit_impostor_frame_inset(float(lodkit_impostor_atlas_texels()) / float(n), level);
    vec2 lo = vec2(inset);
    vec2 hi = vec2(1.0 - inset);
    vec2 uv0 = lodkit_impostor_frame_uv(basis, lodkit_impostor_ray_at_height(origin, ray, dir, 0.0));
    float depth0 = lodkit_impostor_fetch_normal_depth(lodkit_impostor_atlas_uv(frame, n, clamp(uv0, lo, hi)), level).w;
    vec3 point = lodkit_impostor_ray_at_height(origin, ray, dir, lodkit_impostor_depth_height(depth0));
    vec2 uv = lodkit_impostor_frame_uv(basis, point);
    vec2 atlas = lodkit_impostor_atlas_uv(frame, n, clamp(uv, lo, hi));
    vec4 color = lodkit_impostor_fetch_color(atlas, level);
    if (any(notEqual(uv, clamp(uv, vec2(0.0), vec2(1.0))))) {
        color.w = 0.0;
    }
    vec3 normal = lodkit_impostor_fetch_normal_depth(atlas, level).xyz * 2.0 - 1.0;
    return lodkit_ImpostorSample(color, normal, point);
}

/// The blended look of an impostor along the ray origin + t ray, at mip `level`.
lodkit_ImpostorSample lodkit_impostor_sample(uint n, bool hemi, vec3 origin, vec3 ray, float level) {
    lodkit_ImpostorBlend b = lodkit_impostor_blend(normalize(-ray), n, hemi);
    lodkit_ImpostorSample s0 = lodkit_impostor_sample_frame(b.frames[0], n, hemi, origin, ray, level);
    lodkit_ImpostorSample s1 = lodkit_impostor_sample_frame(b.frames[1], n, hemi, origin, ray, level);
    lodkit_ImpostorSample s2 = lodkit_impostor_sample_frame(b.frames[2], n, hemi, origin, ray, level);
    vec3 w = b.weights;
    vec4 color = w.x * s0.color + w.y * s1.color + w.z * s2.color;
    vec3 normal = w.x * s0.normal + w.y * s1.normal + w.z * s2.normal;
    float length_squared = dot(normal, normal);
    vec3 unit = length_squared > 1e-12 ? normal * inversesqrt(length_squared) : vec3(0.0);
    return lodkit_ImpostorSample(color, unit, w.x * s0.point + w.y * s1.point + w.z * s2.point);
}
#endif

/// The impostor's alpha test: keep the fragment when the blended coverage is at least 0.5.
bool lodkit_impostor_keep(float alpha) {
    return alpha >= 0.5;
}

#endif
