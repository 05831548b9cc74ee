// lodkit::silhouette — whether a pixel center lies inside a mesh's silhouette, without
// rasterizing the mesh: frame-sequential LOD's exact coverage of the level not drawn this frame
// (Scherzer & Wimmer 2008, sec. 4, where the older frame only estimates it).
//
// GLSL twin of shader_lib/wgsl/lodkit/silhouette.wgsl; same semantics, `lodkit_` prefix. The
// sum of lodkit_silhouette_crossing over a mesh's silhouette segments (lodkit::silhouette::Surface
// in Rust finds them) is not 0 exactly where the mesh covers the point.
//
// Exports:
//   lodkit_silhouette_crossing(p, a, b) -> int   the winding contribution of segment a -> b around p
//   lodkit_silhouette_distance(p, a, b) -> float   distance from p to the segment a -> b
// Shader defs: none.
#ifndef LODKIT_SILHOUETTE_GLSL
#define LODKIT_SILHOUETTE_GLSL

/// The winding number contribution of the segment from `a` to `b` around the point `p`: +1 where
/// it crosses p's horizontal line upwards with p on its left, -1 downwards with p on its right,
/// else 0. A segment starting on the line counts, one ending on it does not.
int lodkit_silhouette_crossing(vec2 p, vec2 a, vec2 b) {
    float side = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    if (a.y <= p.y) {
        return (b.y > p.y && side > 0.0) ? 1 : 0;
    }
    return (b.y <= p.y && side < 0.0) ? -1 : 0;
}

/// Distance from `p` to the segment from `a` to `b` (to `a` when the two are one point).
float lodkit_silhouette_distance(vec2 p, vec2 a, vec2 b) {
    vec2 ab = b - a;
    float along = clamp(dot(p - a, ab) / max(dot(ab, ab), 1.0e-12), 0.0, 1.0);
    return length(p - (a + along * ab));
}

#endif // LODKIT_SILHOUETTE_GLSL
