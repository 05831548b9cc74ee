// lodkit::bilateral — geometry-aware (joint bilateral) upsampling of a low-resolution buffer
// (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1).
//
// GLSL twin of shader_lib/wgsl/lodkit/bilateral.wgsl; same semantics, `lodkit_` prefix. Sample
// order: 0 = (x0, y0), 1 = (x0 + 1, y0), 2 = (x0, y0 + 1), 3 = (x0 + 1, y0 + 1).
//
// Exports:
//   LODKIT_BILATERAL_MIN_WEIGHT: float   fallback threshold on the sum of weights (1e-4)
//   LODKIT_BILATERAL_SIGMA_OFF: float   a sigma that turns its range term off (1e30; a shader
//       must not be given +inf)
//   LODKIT_BILATERAL_MIN_VIEW_DEPTH: float   the least view depth a relative sigma is taken of
//       (1e-6)
//   lodkit_bilateral_relative_sigma(relative, view_depth) -> float
//   lodkit_bilateral_range(difference, sigma) -> float
//   lodkit_bilateral_tent(f) -> vec4
//   lodkit_bilateral_weight(tent, depth_diff, normal_dist, sigma_z, sigma_n) -> float
//   lodkit_bilateral_upsample(f, values, depths, normals, depth, normal, sigma_z, sigma_n) -> vec4
//   lodkit_bilateral_upsample_projected(f, values, depths, projected, depth, here, sigma_z,
//       sigma_n) -> vec4
//   lodkit_bilateral_low_position(frag_coord, low_viewport, full_size) -> vec2
//   lodkit_bilateral_cell_origin(p, low_viewport) -> vec2
//   lodkit_BilateralCell { corners, fraction }
//   lodkit_bilateral_cell(frag_coord, low_viewport, full_size) -> lodkit_BilateralCell
//   lodkit_bilateral_cell_fraction(frag_coord, low_viewport, full_size) -> vec2
//   lodkit_bilateral_cell_texel(frag_coord, low_viewport, full_size, i) -> uvec2
//   lodkit_bilateral_upsample_texels(f, colors, geometry, depth, normal, sigma_z, sigma_n) -> vec4
//   lodkit_bilateral_upsample_at(low_color, low_geometry, low_viewport, full_size, frag_coord,
//       depth, normal, sigma_z, sigma_n) -> vec4   a macro: takes a sampler2D (OpenGL) or
//       sampler2D(texture, sampler) (Vulkan) for each texture
//   lodkit_bilateral_upsample_packed(f, texels, depth, normal, sigma_z, sigma_n) -> vec4
//   lodkit_bilateral_upsample_packed_at(low, low_viewport, full_size, frag_coord, depth, normal,
//       sigma_z, sigma_n) -> vec4   a macro: takes a usampler2D (OpenGL) or
//       usampler2D(texture, sampler) (Vulkan); four texel fetches (the fold-in upsample)
// Shader defs: none.
#ifndef LODKIT_BILATERAL_GLSL
#define LODKIT_BILATERAL_GLSL

#include "lodkit/normal_distance.glsl"
#include "lodkit/gbuffer.glsl"

/// Sum of weights below which eq. 1 falls back to the sample closest in depth.
const float LODKIT_BILATERAL_MIN_WEIGHT = 1e-4;

/// A sigma that turns its range term off (finite: a shader must not be given +inf).
const float LODKIT_BILATERAL_SIGMA_OFF = 1e30;

/// The least view depth a relative sigma is taken of (a pixel with no geometry gets a small
/// sigma, not a zero one).
const float LODKIT_BILATERAL_MIN_VIEW_DEPTH = 1e-6;

/// A depth sigma given as a fraction of the pixel's view depth, in the depth's units;
/// LODKIT_BILATERAL_SIGMA_OFF stays off.
float lodkit_bilateral_relative_sigma(float relative, float view_depth) {
    return relative >= LODKIT_BILATERAL_SIGMA_OFF ? relative : relative * max(view_depth, LODKIT_BILATERAL_MIN_VIEW_DEPTH);
}

/// Gaussian range filter exp(-difference^2 / (2 sigma^2)); 1 when sigma is LODKIT_BILATERAL_SIGMA_OFF.
float lodkit_bilateral_range(float difference, float sigma) {
    float s = difference / sigma;
    return exp(-0.5 * s * s);
}

/// Tent (bilinear) weights of the 2x2 samples for the fractional position `f`.
vec4 lodkit_bilateral_tent(vec2 f) {
    return vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
}

/// One weight of eq. 1, as one exponential of the summed exponents.
float lodkit_bilateral_weight(float tent, float depth_diff, float normal_dist, float sigma_z, float sigma_n) {
    float z = depth_diff / sigma_z;
    float n = normal_dist / sigma_n;
    return tent * exp(-0.5 * (z * z + n * n));
}

/// Eq. 1 with the normals already through the foreshortening map (`projected`, `here`), with the
/// closest-depth fallback (the first of equals); no loop or dynamic indexing, the normal distance
/// squared.
vec4 lodkit_bilateral_upsample_projected(vec2 f, vec4 values[4], vec4 depths, vec2 projected[4], float depth, vec2 here, float sigma_z, float sigma_n) {
    // Differences scaled by 1 / sigma (0 for sigma = +inf: no range term).
    float inv_z = 1.0 / sigma_z;
    float inv_n = 1.0 / sigma_n;
    vec4 dz = depths - depth;
    vec4 z = dz * inv_z;
    vec2 n0 = (projected[0] - here) * inv_n;
    vec2 n1 = (projected[1] - here) * inv_n;
    vec2 n2 = (projected[2] - here) * inv_n;
    vec2 n3 = (projected[3] - here) * inv_n;
    vec4 nn = vec4(dot(n0, n0), dot(n1, n1), dot(n2, n2), dot(n3, n3));
    vec4 w = lodkit_bilateral_tent(f) * exp(-0.5 * (z * z + nn));
    float total = w.x + w.y + w.z + w.w;
    if (total < LODKIT_BILATERAL_MIN_WEIGHT) {
        vec4 a = abs(dz);
        float m = min(min(a.x, a.y), min(a.z, a.w));
        return a.x == m ? values[0] : (a.y == m ? values[1] : (a.z == m ? values[2] : values[3]));
    }
    return (w.x * values[0] + w.y * values[1] + w.z * values[2] + w.w * values[3]) * (1.0 / total);
}

/// Eq. 1 over the 2x2 low-res samples; the sample closest in depth when the weights vanish.
vec4 lodkit_bilateral_upsample(vec2 f, vec4 values[4], vec4 depths, vec3 normals[4], float depth, vec3 normal, float sigma_z, float sigma_n) {
    vec2 projected[4] = vec2[4](lodkit_foreshortened_normal(normals[0]), lodkit_foreshortened_normal(normals[1]), lodkit_foreshortened_normal(normals[2]), lodkit_foreshortened_normal(normals[3]));
    return lodkit_bilateral_upsample_projected(f, values, depths, projected, depth, lodkit_foreshortened_normal(normal), sigma_z, sigma_n);
}

/// Continuous position of a full-res pixel in L's texel grid (texel centers at integers).
vec2 lodkit_bilateral_low_position(vec2 frag_coord, vec2 low_viewport, vec2 full_size) {
    return frag_coord * low_viewport / full_size - 0.5;
}

/// Top-left texel of the 2x2 cell around position `p`, kept inside the viewport.
vec2 lodkit_bilateral_cell_origin(vec2 p, vec2 low_viewport) {
    return clamp(floor(p), vec2(0.0), max(low_viewport - 2.0, vec2(0.0)));
}

/// The 2x2 cell of a full-res pixel: texels 0 and 3 as (x0, y0, x1, y1), clamped to the
/// viewport, and the pixel's fraction between them.
struct lodkit_BilateralCell {
    uvec4 corners;
    vec2 fraction;
};

/// The cell of the full-res pixel at `frag_coord`: what every lookup of this module fetches.
lodkit_BilateralCell lodkit_bilateral_cell(vec2 frag_coord, vec2 low_viewport, vec2 full_size) {
    vec2 p = lodkit_bilateral_low_position(frag_coord, low_viewport, full_size);
    vec2 origin = lodkit_bilateral_cell_origin(p, low_viewport);
    uvec2 last = uvec2(max(low_viewport - 1.0, vec2(0.0)));
    uvec2 first = uvec2(origin);
    uvec4 corners = uvec4(min(first, last), min(first + 1u, last));
    return lodkit_BilateralCell(corners, clamp(p - origin, vec2(0.0), vec2(1.0)));
}

/// Fraction `f` between the 2x2 L texels of the full-res pixel at `frag_coord`.
vec2 lodkit_bilateral_cell_fraction(vec2 frag_coord, vec2 low_viewport, vec2 full_size) {
    return lodkit_bilateral_cell(frag_coord, low_viewport, full_size).fraction;
}

/// L texel `i` (0..3) of the 2x2 cell of the full-res pixel at `frag_coord`.
uvec2 lodkit_bilateral_cell_texel(vec2 frag_coord, vec2 low_viewport, vec2 full_size, uint i) {
    uvec4 c = lodkit_bilateral_cell(frag_coord, low_viewport, full_size).corners;
    return uvec2((i & 1u) != 0u ? c.z : c.x, (i & 2u) != 0u ? c.w : c.y);
}

/// Eq. 1 from four fetched L texels (lodkit gbuffer layout).
vec4 lodkit_bilateral_upsample_texels(vec2 f, vec4 colors[4], vec4 geometry[4], float depth, vec3 normal, float sigma_z, float sigma_n) {
    vec4 depths = vec4(lodkit_gbuffer_depth(geometry[0]), lodkit_gbuffer_depth(geometry[1]), lodkit_gbuffer_depth(geometry[2]), lodkit_gbuffer_depth(geometry[3]));
    vec3 normals[4] = vec3[4](lodkit_gbuffer_normal(geometry[0]), lodkit_gbuffer_normal(geometry[1]), lodkit_gbuffer_normal(geometry[2]), lodkit_gbuffer_normal(geometry[3]));
    return lodkit_bilateral_upsample(f, colors, depths, normals, depth, normal, sigma_z, sigma_n);
}

#define LODKIT_BILATERAL_FETCH_(tex, fc, vp, fs, i) texelFetch((tex), ivec2(lodkit_bilateral_cell_texel((fc), (vp), (fs), (i))), 0)

/// The full lookup for the full-res pixel at `frag_coord`: fetches the 2x2 L texels and applies eq. 1.
#define lodkit_bilateral_upsample_at(low_color, low_geometry, low_viewport, full_size, frag_coord, depth, normal, sigma_z, sigma_n) \
    lodkit_bilateral_upsample_texels( \
        lodkit_bilateral_cell_fraction((frag_coord), (low_viewport), (full_size)), \
        vec4[4](LODKIT_BILATERAL_FETCH_(low_color, frag_coord, low_viewport, full_size, 0u), LODKIT_BILATERAL_FETCH_(low_color, frag_coord, low_viewport, full_size, 1u), \
                LODKIT_BILATERAL_FETCH_(low_color, frag_coord, low_viewport, full_size, 2u), LODKIT_BILATERAL_FETCH_(low_color, frag_coord, low_viewport, full_size, 3u)), \
        vec4[4](LODKIT_BILATERAL_FETCH_(low_geometry, frag_coord, low_viewport, full_size, 0u), LODKIT_BILATERAL_FETCH_(low_geometry, frag_coord, low_viewport, full_size, 1u), \
                LODKIT_BILATERAL_FETCH_(low_geometry, frag_coord, low_viewport, full_size, 2u), LODKIT_BILATERAL_FETCH_(low_geometry, frag_coord, low_viewport, full_size, 3u)), \
        (depth), (normal), (sigma_z), (sigma_n))

/// Eq. 1 from four packed L texels (lodkit gbuffer packed layout).
vec4 lodkit_bilateral_upsample_packed(vec2 f, uvec4 texels[4], float depth, vec3 normal, float sigma_z, float sigma_n) {
    vec4 values[4] = vec4[4](lodkit_gbuffer_texel_color(texels[0]), lodkit_gbuffer_texel_color(texels[1]), lodkit_gbuffer_texel_color(texels[2]), lodkit_gbuffer_texel_color(texels[3]));
    vec4 depths = vec4(lodkit_gbuffer_texel_depth(texels[0]), lodkit_gbuffer_texel_depth(texels[1]), lodkit_gbuffer_texel_depth(texels[2]), lodkit_gbuffer_texel_depth(texels[3]));
    vec2 projected[4] = vec2[4](lodkit_gbuffer_texel_projected_normal(texels[0]), lodkit_gbuffer_texel_projected_normal(texels[1]), lodkit_gbuffer_texel_projected_normal(texels[2]), lodkit_gbuffer_texel_projected_normal(texels[3]));
    return lodkit_bilateral_upsample_projected(f, values, depths, projected, depth, lodkit_foreshortened_normal(normal), sigma_z, sigma_n);
}

#define LODKIT_BILATERAL_CORNERS_(fc, vp, fs) lodkit_bilateral_cell((fc), (vp), (fs)).corners
#define LODKIT_BILATERAL_CORNER_(tex, c, cx, cy) texelFetch((tex), ivec2((c).cx, (c).cy), 0)

/// The full lookup from a packed L: four texel fetches, then eq. 1 (the fold-in upsample).
#define lodkit_bilateral_upsample_packed_at(low, low_viewport, full_size, frag_coord, depth, normal, sigma_z, sigma_n) \
    lodkit_bilateral_upsample_packed( \
        lodkit_bilateral_cell_fraction((frag_coord), (low_viewport), (full_size)), \
        uvec4[4](LODKIT_BILATERAL_CORNER_(low, LODKIT_BILATERAL_CORNERS_(frag_coord, low_viewport, full_size), x, y), \
                 LODKIT_BILATERAL_CORNER_(low, LODKIT_BILATERAL_CORNERS_(frag_coord, low_viewport, full_size), z, y), \
                 LODKIT_BILATERAL_CORNER_(low, LODKIT_BILATERAL_CORNERS_(frag_coord, low_viewport, full_size), x, w), \
                 LODKIT_BILATERAL_CORNER_(low, LODKIT_BILATERAL_CORNERS_(frag_coord, low_viewport, full_size), z, w)), \
        (depth), (normal), (sigma_z), (sigma_n))

#endif // LODKIT_BILATERAL_GLSL
