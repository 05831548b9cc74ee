// lodkit::unpopping — alpha of each LOD in an unpopping transition (Giegl & Wimmer 2007, sec. 3,
// Fig. 2).
//
// GLSL twin of shader_lib/wgsl/lodkit/unpopping.wgsl; same semantics, `lodkit_` prefix.
//
// Exports:
//   lodkit_unpopping_alpha(t, incoming) -> float   alpha of the incoming (true) or outgoing LOD
//   lodkit_unpopping_is_opaque(t, incoming) -> bool   whether that LOD is the opaque one
// Shader defs: none.
#ifndef LODKIT_UNPOPPING_GLSL
#define LODKIT_UNPOPPING_GLSL

/// Alpha at progress `t` (clamped to [0, 1]) of the incoming LOD (min(2t, 1)) or of the
/// outgoing LOD (min(2(1 - t), 1)).
float lodkit_unpopping_alpha(float t, bool incoming) {
    float s = clamp(t, 0.0, 1.0);
    if (incoming) {
        return min(2.0 * s, 1.0);
    }
    return min(2.0 * (1.0 - s), 1.0);
}

/// Whether the LOD is the opaque, depth-writing one at progress `t`.
bool lodkit_unpopping_is_opaque(float t, bool incoming) {
    bool late = t >= 0.5;
    return incoming ? late : !late;
}

#endif // LODKIT_UNPOPPING_GLSL
