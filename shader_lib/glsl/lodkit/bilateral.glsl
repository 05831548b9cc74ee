// lodkit::bilateral — geometry-aware (joint bilateral) upsampling of a low-resolution buffer
// (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1).
//
// GLSL twin of shader_lib/wgsl/lodkit/bilateral.wgsl; same semantics, `lodkit_` prefix. Sample
// order: 0 = (x0, y0), 1 = (x0 + 1, y0), 2 = (x0, y0 + 1), 3 = (x0 + 1, y0 + 1).
//
// Exports:
//   LODKIT_BILATERAL_MIN_WEIGHT: float   fallback threshold on the sum of weights (1e-4)
//   lodkit_bilateral_range(difference, sigma) -> float
//   lodkit_bilateral_tent(f) -> vec4
//   lodkit_bilateral_weight(tent, depth_diff, normal_dist, sigma_z, sigma_n) -> float
//   lodkit_bilateral_upsample(f, values, depths, normals, depth, normal, sigma_z, sigma_n) -> vec4
// Shader defs: none.
#ifndef LODKIT_BILATERAL_GLSL
#define LODKIT_BILATERAL_GLSL

#include "lodkit/normal_distance.glsl"

/// Sum of weights below which eq. 1 falls back to the sample closest in depth.
const float LODKIT_BILATERAL_MIN_WEIGHT = 1e-4;

/// Gaussian range filter exp(-difference^2 / (2 sigma^2)); 1 when sigma is +inf.
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

/// Eq. 1 over the 2x2 low-res samples, with the closest-depth fallback.
vec4 lodkit_bilateral_upsample(vec2 f, vec4 values[4], vec4 depths, vec3 normals[4], float depth, vec3 normal, float sigma_z, float sigma_n) {
    vec4 tent = lodkit_bilateral_tent(f);
    vec2 here = lodkit_foreshortened_normal(normal);
    vec4 sum = vec4(0.0);
    float total = 0.0;
    uint closest = 0u;
    for (uint i = 0u; i < 4u; i++) {
        float normal_dist = distance(lodkit_foreshortened_normal(normals[i]), here);
        float w = lodkit_bilateral_weight(tent[i], depths[i] - depth, normal_dist, sigma_z, sigma_n);
        sum += w * values[i];
        total += w;
        if (abs(depths[i] - depth) < abs(depths[closest] - depth)) {
            closest = i;
        }
    }
    if (total < LODKIT_BILATERAL_MIN_WEIGHT) {
        return values[closest];
    }
    return sum / total;
}

#endif // LODKIT_BILATERAL_GLSL
