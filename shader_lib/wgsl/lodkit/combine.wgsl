// lodkit::combine — the combination rule of two LOD buffers (Scherzer & Wimmer 2008, sec. 3.4 and
// 3.5 step 2).
//
// Both ids 0 (n-instances) -> the newer color. Ids differ -> the closer fragment (depths compared
// in the older buffer's space: pass the newer depth reprojected). Same id (two LODs of one
// t-instance) -> the average of both colors, with no depth test, so coplanar LODs never z-fight.
// A tie in depth keeps the newer fragment. With display-time visibility (combine_shown) a sample
// not shown in the frame being displayed gives way to the other one.
//
// Exports:
//   LodSample { color, id, depth }   one LOD buffer texel
//   combine_samples(newer, older) -> vec4<f32>
//   combine_shown(newer, newer_shown, older, older_shown) -> vec4<f32>   exactly one shown: it;
//       both or neither: combine_samples
//   depth_closer(a, b) -> bool   a strictly closer than b under the depth convention
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z); off: 0 near.
#define_import_path lodkit::combine

/// One texel of a LOD buffer: color, instance id (0 = n-instance), clip depth.
struct LodSample {
    color: vec4<f32>,
    id: u32,
    depth: f32,
}

/// Whether clip depth `a` is strictly closer to the camera than `b`.
fn depth_closer(a: f32, b: f32) -> bool {
#ifdef LODKIT_REVERSE_Z
    return a > b;
#else
    return a < b;
#endif
}

/// Color of the combined pixel from the newer and the (reprojected) older LOD buffer sample.
fn combine_samples(newer: LodSample, older: LodSample) -> vec4<f32> {
    if (newer.id == 0u && older.id == 0u) {
        return newer.color;
    }
    if (newer.id == older.id) {
        return 0.5 * (newer.color + older.color);
    }
    if (depth_closer(older.depth, newer.depth)) {
        return older.color;
    }
    return newer.color;
}

/// combine_samples with display-time visibility: when exactly one sample is shown in the frame
/// being displayed (`newer_shown`, `older_shown`), its color; when both or neither are,
/// combine_samples (neither: the fragments are shown rather than a hole).
fn combine_shown(newer: LodSample, newer_shown: bool, older: LodSample, older_shown: bool) -> vec4<f32> {
    if (newer_shown != older_shown) {
        return select(older.color, newer.color, newer_shown);
    }
    return combine_samples(newer, older);
}
