// lodkit::normal_distance — foreshortened distance between screen-space normals
// (Yang, Sander & Lawrence 2008, sec. 2.2, after Toler-Franklin et al. 2007).
//
// GLSL twin of shader_lib/wgsl/lodkit/normal_distance.wgsl; same semantics, `lodkit_` prefix.
// Each normal (nx, ny, nz) is mapped to (nx / nz, ny / nz, 1) before the Euclidean distance is
// taken. Normals are in screen space: (0, 0, 1) points toward the viewer.
//
// Exports:
//   LODKIT_NORMAL_DISTANCE_MIN_Z: float   smallest nz used in the division (1/64)
//   lodkit_foreshortened_normal(n) -> vec2   (nx / nz, ny / nz) with nz clamped below
//   lodkit_foreshortened_normal_distance(a, b) -> float   |foreshortened(a) - foreshortened(b)|
// Shader defs: none.
#ifndef LODKIT_NORMAL_DISTANCE_GLSL
#define LODKIT_NORMAL_DISTANCE_GLSL

/// Smallest z used when dividing by a normal's z: 1/64, so a projected component never exceeds 64.
const float LODKIT_NORMAL_DISTANCE_MIN_Z = 0.015625;

/// The normal `n` seen through the foreshortening map: (n.x / n.z, n.y / n.z).
/// Grazing or back-facing normals (n.z < 1/64) are divided by 1/64 instead.
vec2 lodkit_foreshortened_normal(vec3 n) {
    return n.xy / max(n.z, LODKIT_NORMAL_DISTANCE_MIN_Z);
}

/// Euclidean distance between (a.x/a.z, a.y/a.z, 1) and (b.x/b.z, b.y/b.z, 1); 0 for equal normals.
float lodkit_foreshortened_normal_distance(vec3 a, vec3 b) {
    return distance(lodkit_foreshortened_normal(a), lodkit_foreshortened_normal(b));
}

#endif // LODKIT_NORMAL_DISTANCE_GLSL
