// lodkit::silhouette — whether a pixel center lies inside a mesh's silhouette, without
// rasterizing the mesh: frame-sequential LOD's exact coverage of the level not drawn this frame
// (Scherzer & Wimmer 2008, sec. 4, where the older frame only estimates it).
//
// A closed mesh covers a point of the screen exactly where one of its front faces does; the
// boundary of that region is the silhouette: the edges between a face turned to the camera and
// one turned away, projected (the host finds them: lodkit::silhouette::Surface in Rust). With
// every segment oriented the same way round its front face, the sum of silhouette_crossing over
// the segments (the winding number) is not 0 exactly where the mesh covers the point.
//
// A fragment shader tests an outline in a few steps when its segments are binned by pixel row in
// a data texture (lodkit::silhouette::bin_silhouette in Rust; texture_2d<u32>, which GL 3.3,
// GLSL ES 3.00 and WebGL2 read, unlike a storage buffer): the winding number at a pixel sums
// only the segments whose y-range reaches its row.
//
// Exports:
//   SILHOUETTE_TIE: f32   how near (pixels) a point lies "on" an outline (0.001)
//   SILHOUETTE_ON: i32   what silhouette_covers answers there (-1)
//   silhouette_crossing(p, a, b) -> i32   the winding contribution of segment a -> b around p
//   silhouette_distance(p, a, b) -> f32   distance from p to the segment a -> b
//   silhouette_texel(data, index) -> vec4<u32>   texel `index` of a data texture laid out row
//       after row: (index % width, index / width)
//   silhouette_covers(data, table, p) -> i32   1 where the outline whose table is `table` (first
//       row's texel, first row, rows, columns first | end << 16) has a winding number other than
//       0 around p, 0 where it has 0, SILHOUETTE_ON within SILHOUETTE_TIE of a segment
// Shader defs: none.
#define_import_path lodkit::silhouette

/// How near (pixels) a point must lie to an outline for silhouette_covers to call it on the
/// outline: the CPU projects a mesh with other rounding than the rasterizer, a few millionths of
/// the target's size apart.
const SILHOUETTE_TIE: f32 = 0.001;

/// What silhouette_covers answers for a point within SILHOUETTE_TIE of the outline.
const SILHOUETTE_ON: i32 = -1;

/// The winding number contribution of the segment from `a` to `b` around the point `p` (all in
/// pixels, or any one 2D frame): +1 where it crosses p's horizontal line upwards with p on its
/// left (in that frame's handedness), -1 downwards with p on its right, else 0. A segment
/// starting on the line counts, one ending on it does not, so a closed outline through a vertex
/// on the line counts once.
fn silhouette_crossing(p: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> i32 {
    let side = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    if (a.y <= p.y) {
        return select(0, 1, b.y > p.y && side > 0.0);
    }
    return select(0, -1, b.y <= p.y && side < 0.0);
}

/// Distance from `p` to the segment from `a` to `b` (to `a` when the two are one point).
fn silhouette_distance(p: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> f32 {
    let ab = b - a;
    let along = clamp(dot(p - a, ab) / max(dot(ab, ab), 1.0e-12), 0.0, 1.0);
    return length(p - (a + along * ab));
}

/// Texel `index` of a data texture laid out row after row: (index % width, index / width).
fn silhouette_texel(data: texture_2d<u32>, index: u32) -> vec4<u32> {
    let width = textureDimensions(data, 0).x;
    return textureLoad(data, vec2<u32>(index % width, index / width), 0);
}

/// Whether the outline whose table is `table` covers the point `p` (pixels): 1 where its winding
/// number there is not 0, 0 where it is, SILHOUETTE_ON within SILHOUETTE_TIE of a segment. The
/// table (lodkit::silhouette::bin_silhouette): x the texel of its first row, y that row, z the
/// rows, w its columns (the first in the low 16 bits, one past the last in the high ones); a
/// row's texel holds (its first segment's texel, its segment count), a segment's the f32 bits
/// of (x0, y0, x1, y1). Reads the row's texel and its segments only.
fn silhouette_covers(data: texture_2d<u32>, table: vec4<u32>, p: vec2<f32>) -> i32 {
    let row = floor(p.y) - f32(table.y);
    let x0 = f32(table.w & 0xffffu);
    let x1 = f32(table.w >> 16u);
    if (row < 0.0 || row >= f32(table.z) || p.x < x0 || p.x > x1) {
        return 0;
    }
    let entry = silhouette_texel(data, table.x + u32(row));
    var winding = 0;
    var on = false;
    for (var k = 0u; k < entry.y; k++) {
        let s = bitcast<vec4<f32>>(silhouette_texel(data, entry.x + k));
        winding += silhouette_crossing(p, s.xy, s.zw);
        on = on || silhouette_distance(p, s.xy, s.zw) < SILHOUETTE_TIE;
    }
    if (on) {
        return SILHOUETTE_ON;
    }
    return select(0, 1, winding != 0);
}
