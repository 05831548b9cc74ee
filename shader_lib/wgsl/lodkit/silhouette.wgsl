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
// Exports:
//   silhouette_crossing(p, a, b) -> i32   the winding contribution of segment a -> b around p
//   silhouette_distance(p, a, b) -> f32   distance from p to the segment a -> b
// Shader defs: none.
#define_import_path lodkit::silhouette

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
