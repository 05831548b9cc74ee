// lodkit::combine — the combination rule of two LOD buffers (Scherzer & Wimmer 2008, sec. 3.4).
//
// GLSL twin of shader_lib/wgsl/lodkit/combine.wgsl; same semantics, `lodkit_` prefix.
// Both ids 0 -> newer; ids differ -> closer; same id -> average; depth tie -> newer.
//
// Exports:
//   lodkit_LodSample { color, id, depth }
//   lodkit_combine_samples(newer, older) -> vec4
//   lodkit_combine_shown(newer, newer_shown, older, older_shown) -> vec4   exactly one shown: it;
//       both or neither: lodkit_combine_samples
//   lodkit_depth_closer(a, b) -> bool
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z).
#ifndef LODKIT_COMBINE_GLSL
#define LODKIT_COMBINE_GLSL

/// One texel of a LOD buffer: color, instance id (0 = n-instance), clip depth.
struct lodkit_LodSample {
    vec4 color;
    uint id;
    float depth;
};

/// Whether clip depth `a` is strictly closer to the camera than `b`.
bool lodkit_depth_closer(float a, float b) {
#ifdef LODKIT_REVERSE_Z
    return a > b;
#else
    return a < b;
#endif
}

/// Color of the combined pixel from the newer and the (reprojected) older LOD buffer sample.
vec4 lodkit_combine_samples(lodkit_LodSample newer, lodkit_LodSample older) {
    if (newer.id == 0u && older.id == 0u) {
        return newer.color;
    }
    if (newer.id == older.id) {
        return 0.5 * (newer.color + older.color);
    }
    if (lodkit_depth_closer(older.depth, newer.depth)) {
        return older.color;
    }
    return newer.color;
}

/// lodkit_combine_samples with display-time visibility.
vec4 lodkit_combine_shown(lodkit_LodSample newer, bool newer_shown, lodkit_LodSample older, bool older_shown) {
    if (newer_shown != older_shown) {
        return newer_shown ? newer.color : older.color;
    }
    return lodkit_combine_samples(newer, older);
}

#endif // LODKIT_COMBINE_GLSL
