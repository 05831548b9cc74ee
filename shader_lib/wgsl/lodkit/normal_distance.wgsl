// lodkit::normal_distance — foreshortened distance between screen-space normals
// (Yang, Sander & Lawrence 2008, sec. 2.2, after Toler-Franklin et al. 2007).
//
// Each normal (nx, ny, nz) is mapped to (nx / nz, ny / nz, 1) before the Euclidean distance is
// taken, so orientation differences near grazing angles weigh more than the same angle facing the
// viewer. Normals are in screen space: (0, 0, 1) points toward the viewer.
//
// Exports:
//   NORMAL_DISTANCE_MIN_Z: f32   smallest nz used in the division (1/64); see foreshortened_normal
//   foreshortened_normal(n) -> vec2<f32>   (nx / nz, ny / nz) with nz clamped below by NORMAL_DISTANCE_MIN_Z
//   foreshortened_normal_distance(a, b) -> f32   |foreshortened(a) - foreshortened(b)|
// Shader defs: none.
#define_import_path lodkit::normal_distance

/// Smallest z used when dividing by a normal's z: 1/64, so a projected component never exceeds 64.
const NORMAL_DISTANCE_MIN_Z: f32 = 0.015625;

/// The normal `n` seen through the foreshortening map: (n.x / n.z, n.y / n.z).
/// Grazing or back-facing normals (n.z < 1/64) are divided by 1/64 instead, which keeps the
/// direction in xy and bounds each component by 64 times |n.xy|. Inputs must be finite.
fn foreshortened_normal(n: vec3<f32>) -> vec2<f32> {
    return n.xy / max(n.z, NORMAL_DISTANCE_MIN_Z);
}

/// Euclidean distance between (a.x/a.z, a.y/a.z, 1) and (b.x/b.z, b.y/b.z, 1); 0 for equal normals.
/// Grazing normals are guarded as in `foreshortened_normal`, so the result is always finite for
/// finite inputs.
fn foreshortened_normal_distance(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return distance(foreshortened_normal(a), foreshortened_normal(b));
}
