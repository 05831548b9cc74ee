// lodkit::unpopping — alpha of each LOD in an unpopping transition (Giegl & Wimmer 2007, sec. 3,
// Fig. 2).
//
// One LOD is always drawn opaque with depth writes; the other is alpha-blended with depth test
// and no depth writes. For t < 0.5 the outgoing LOD is opaque and the incoming fades in (2t);
// from t = 0.5 the incoming is opaque and the outgoing fades out (2(1 - t)). The pipeline states
// and draw order come from the host (lodkit::unpopping::unpopping_plan).
//
// Exports:
//   unpopping_alpha(t, incoming) -> f32   alpha of the incoming (true) or outgoing (false) LOD
//   unpopping_is_opaque(t, incoming) -> bool   whether that LOD is the opaque, depth-writing one
// Shader defs: none.
#define_import_path lodkit::unpopping

/// Alpha at progress `t` (clamped to [0, 1]) of the incoming LOD (min(2t, 1)) or of the
/// outgoing LOD (min(2(1 - t), 1)). Both are 1 at t = 0.5.
fn unpopping_alpha(t: f32, incoming: bool) -> f32 {
    let s = clamp(t, 0.0, 1.0);
    if (incoming) {
        return min(2.0 * s, 1.0);
    }
    return min(2.0 * (1.0 - s), 1.0);
}

/// Whether the LOD is the opaque, depth-writing one at progress `t`: the outgoing for t < 0.5,
/// the incoming from 0.5 on.
fn unpopping_is_opaque(t: f32, incoming: bool) -> bool {
    let late = t >= 0.5;
    return select(!late, late, incoming);
}
