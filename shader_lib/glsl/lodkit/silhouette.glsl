// lodkit::silhouette — whether a pixel center lies inside a mesh's silhouette, without
// rasterizing the mesh: frame-sequential LOD's exact coverage of the level not drawn this frame
// (Scherzer & Wimmer 2008, sec. 4, where the older frame only estimates it).
//
// GLSL twin of shader_lib/wgsl/lodkit/silhouette.wgsl; same semantics, `lodkit_` prefix. The
// sum of lodkit_silhouette_crossing over a mesh's silhouette segments (lodkit::silhouette::Surface
// in Rust finds them) is not 0 exactly where the mesh covers the point.
//
// A fragment shader tests an outline in a few steps when its segments are binned by pixel row in
// a data texture (lodkit::silhouette::bin_silhouette in Rust; a usampler2D, which GLSL 3.30 and
// GLSL ES 3.00 read): the winding number at a pixel sums only the segments whose y-range
// reaches its row.
//
// Exports:
//   LODKIT_SILHOUETTE_TIE (float)   how near (pixels) a point lies "on" an outline (0.001)
//   LODKIT_SILHOUETTE_ON (int)   what lodkit_silhouette_covers answers there (-1)
//   lodkit_silhouette_crossing(p, a, b) -> int   the winding contribution of segment a -> b around p
//   lodkit_silhouette_distance(p, a, b) -> float   distance from p to the segment a -> b
//   lodkit_silhouette_texel(index) -> uvec4   texel `index` of the data texture (row after row)
//   lodkit_silhouette_covers(table, p) -> int   1 where the outline whose table is `table` has a
//       winding number other than 0 around p, 0 where it has 0, LODKIT_SILHOUETTE_ON within
//       LODKIT_SILHOUETTE_TIE of a segment
// Hooks (GLSL cannot pass a texture to a function on every target, so the functions that read
// one call a function the includer defines, after its sampler; they are compiled only where
// LODKIT_SILHOUETTE_HOOKS is defined before the first include, as lodkit/combine_coverage.glsl
// does):
//   uvec4 lodkit_silhouette_fetch(uint index)   texel `index` of the data texture, e.g.
//       texelFetch(data, ivec2(index % width, index / width), 0)
// Shader defs: none.
#ifndef LODKIT_SILHOUETTE_GLSL
#define LODKIT_SILHOUETTE_GLSL

/// How near (pixels) a point must lie to an outline for lodkit_silhouette_covers to call it on
/// the outline.
const float LODKIT_SILHOUETTE_TIE = 0.001;

/// What lodkit_silhouette_covers answers for a point within LODKIT_SILHOUETTE_TIE of the outline.
const int LODKIT_SILHOUETTE_ON = -1;

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

#ifdef LODKIT_SILHOUETTE_HOOKS
/// Hook: texel `index` of the data texture (defined by the includer).
uvec4 lodkit_silhouette_fetch(uint index);

/// Texel `index` of the data texture (row after row), through the includer's hook.
uvec4 lodkit_silhouette_texel(uint index) {
    return lodkit_silhouette_fetch(index);
}

/// Whether the outline whose table is `table` covers the point `p` (pixels): 1 where its winding
/// number there is not 0, 0 where it is, LODKIT_SILHOUETTE_ON within LODKIT_SILHOUETTE_TIE of a
/// segment. Reads the row's texel and its segments only.
int lodkit_silhouette_covers(uvec4 table, vec2 p) {
    float row = floor(p.y) - float(table.y);
    float x0 = float(table.w & 0xffffu);
    float x1 = float(table.w >> 16u);
    if (row < 0.0 || row >= float(table.z) || p.x < x0 || p.x > x1) {
        return 0;
    }
    uvec4 entry = lodkit_silhouette_texel(table.x + uint(row));
    int winding = 0;
    bool on = false;
    for (uint k = 0u; k < entry.y; k++) {
        vec4 s = uintBitsToFloat(lodkit_silhouette_texel(entry.x + k));
        winding += lodkit_silhouette_crossing(p, s.xy, s.zw);
        on = on || lodkit_silhouette_distance(p, s.xy, s.zw) < LODKIT_SILHOUETTE_TIE;
    }
    if (on) {
        return LODKIT_SILHOUETTE_ON;
    }
    return winding != 0 ? 1 : 0;
}

#endif // LODKIT_SILHOUETTE_HOOKS

#endif // LODKIT_SILHOUETTE_GLSL
