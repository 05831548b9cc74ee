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
//   combine_texel(uv, size) -> vec2<u32>   the texel at a texture-space uv (clamped)
//   combine_uv(pixel, size) -> vec2<f32>   texture-space center of a pixel
//   combine_older_uv(pixel, size, newer_depth, first_depth, new_to_old, motion) -> vec2<f32>
//       where the older buffer is read (texture-space uv): the reprojection refined at the older
//       depth first_depth found at the first estimate (lodkit::reproject::reproject_refine),
//       moved by the pixel's object motion (texture-space uv, lodkit::lod_buffer::
//       lod_buffer_motion; 0 if still)
//   combine_older_texel(pixel, size, newer_depth, first_depth, new_to_old, motion) -> vec2<u32>
//       the texel holding combine_older_uv
//   combine_side_texel(uv, size, axis) -> vec2<u32>   the texel next to the one holding uv, on
//       the side uv lies off its center along axis (0 x, 1 y)
//   combine_match_texel(id, ids, nearest, x, y) -> vec2<u32>   the older texel read for a newer
//       sample of instance id: the nearest, or where it holds another object, the side or
//       diagonal texel holding the same t-instance (ids: at nearest, x, y, (x.x, y.y)), so a
//       silhouette that moved by a fraction of a texel shows no background
//   combine_ring_texel(center, size, k) -> vec2<u32>   the k-th (0..8) texel of the 3x3 block
//       around center: the center, left, right, up, down, then the corners (clamped)
//   combine_search_texel(older_id, id, center, fallback) -> vec2<u32>   the first texel of the
//       3x3 block around center (combine_ring_texel order) whose id word holds instance id;
//       fallback if none does. Where a t-instance's LODs move differently (vertex animation that
//       depends on the surface point: a plant in the wind), the older LOD is searched where the
//       camera alone puts the pixel
//   combine_texels(newer_color, newer_word, old, older_color, older_word, older_depth)
//       -> vec4<f32>   the combined color from the fetched texels (old = reproject(uv, newer
//       depth); words: lodkit::lod_buffer id words)
//   combine_at(newer_color, newer_id, newer_depth, older_color, older_id, older_depth, pixel,
//       new_to_old) -> vec4<f32>   the whole per-pixel combine (passes/combine.wgsl), to fold
//       into a full-screen pass an engine already has (tonemapping, TAA): no pass of its own.
//       The depths are the LOD buffers' depth attachments bound as texture_2d<f32>
//       (unfilterable float; a depth view of Depth32Float). Nothing moves by itself.
//   combine_at_moved(newer_color, ..., older_depth, pixel, new_to_old, motion) -> vec4<f32>
//       combine_at for a pixel whose surface moved by itself: `motion` is its object motion
//       (the LOD pass's location 2, or combine_object_motion of the engine's motion vectors);
//       where neither the moved read nor its side texels hold the t-instance, the 3x3 block
//       where the camera alone puts the pixel is searched (combine_search_texel)
//   combine_object_motion(uv, depth, new_to_old, motion_vector) -> vec2<f32>   the object
//       motion of a pixel from an engine's motion vector (uv now minus uv in the previous frame,
//       camera motion included, as TAA uses): what the camera's reprojection does not explain
//   depth_closer(a, b) -> bool   a strictly closer than b under the depth convention
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z); off: 0 near.
#define_import_path lodkit::combine
#import lodkit::lod_buffer::{lod_buffer_id, lod_buffer_shown, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT}
#import lodkit::reproject::{reproject, reproject_base, reproject_from_base, reproject_refine, in_viewport}

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

/// The texel of a `size` texture at texture-space `uv` (clamped to the texture).
fn combine_texel(uv: vec2<f32>, size: vec2<u32>) -> vec2<u32> {
    let inside = clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0));
    return min(vec2<u32>(inside * vec2<f32>(size)), size - vec2<u32>(1u));
}

/// Texture-space center of pixel `pixel` of a `size` target.
fn combine_uv(pixel: vec2<u32>, size: vec2<u32>) -> vec2<f32> {
    return (vec2<f32>(pixel) + 0.5) / vec2<f32>(size);
}

/// Where in the older buffer (texture-space uv) the combine reads for the newer pixel `pixel`
/// with clip depth `newer_depth`: the first estimate reprojects that depth (moved by the object
/// motion `motion`); the older buffer's depth found there (`first_depth`) may belong to another
/// surface (a stipple hole, an edge), so the texel is where the point of the pixel's ray at that
/// older depth reprojects, moved by `motion` (the first estimate if that leaves the view).
fn combine_older_uv(pixel: vec2<u32>, size: vec2<u32>, newer_depth: f32, first_depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>) -> vec2<f32> {
    let base = reproject_base(combine_uv(pixel, size), new_to_old);
    let first = reproject_from_base(base, newer_depth, new_to_old).xy + motion;
    let refined = reproject_refine(base, newer_depth, first_depth, new_to_old).xy + motion;
    return select(first, refined, in_viewport(refined));
}

/// The older buffer's texel at combine_older_uv.
fn combine_older_texel(pixel: vec2<u32>, size: vec2<u32>, newer_depth: f32, first_depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>) -> vec2<u32> {
    return combine_texel(combine_older_uv(pixel, size, newer_depth, first_depth, new_to_old, motion), size);
}

/// The texel next to the one holding texture-space `uv`, along `axis` (0 x, 1 y) on the side
/// `uv` lies off that texel's center; the texel itself when `uv` is within 1/1000 texel of the
/// center on that axis or the neighbour would leave the texture.
fn combine_side_texel(uv: vec2<f32>, size: vec2<u32>, axis: u32) -> vec2<u32> {
    let texel = combine_texel(uv, size);
    let offset = uv[axis] * f32(size[axis]) - (f32(texel[axis]) + 0.5);
    var side = texel;
    if (offset > 1e-3 && texel[axis] + 1u < size[axis]) {
        side[axis] = texel[axis] + 1u;
    } else if (offset < -1e-3 && texel[axis] > 0u) {
        side[axis] = texel[axis] - 1u;
    }
    return side;
}

/// The older texel to read for a newer sample of instance `id`: `nearest` (the texel holding the
/// read position) unless `id` is a t-instance's and `nearest` holds another id; then the first
/// of its side texels `x`, `y` (combine_side_texel) and the diagonal (x.x, y.y) that holds `id`,
/// if any. `ids` are the instance ids at nearest, x, y and the diagonal. The read position lies
/// among these four texel centers, so where it is on the object's side of a straight edge, one
/// of them is too: a silhouette that moved by a fraction of a texel shows no background.
fn combine_match_texel(id: u32, ids: vec4<u32>, nearest: vec2<u32>, x: vec2<u32>, y: vec2<u32>) -> vec2<u32> {
    if (id == 0u || ids.x == id) {
        return nearest;
    }
    if (ids.y == id) {
        return x;
    }
    if (ids.z == id) {
        return y;
    }
    return select(nearest, vec2<u32>(x.x, y.y), ids.w == id);
}

/// The k-th (0..8) texel of the 3x3 block around `center`: the center, then left, right, up,
/// down, then the corners (top left, top right, bottom left, bottom right); clamped to the
/// texture of size `size`.
fn combine_ring_texel(center: vec2<u32>, size: vec2<u32>, k: u32) -> vec2<u32> {
    var offset = vec2<i32>(0);
    if (k >= 5u) {
        offset = vec2<i32>(i32((k - 5u) % 2u) * 2 - 1, i32((k - 5u) / 2u) * 2 - 1);
    } else if (k >= 1u) {
        let sign = i32((k - 1u) % 2u) * 2 - 1;
        offset = select(vec2<i32>(0, sign), vec2<i32>(sign, 0), k <= 2u);
    }
    return vec2<u32>(clamp(vec2<i32>(center) + offset, vec2<i32>(0), vec2<i32>(max(size, vec2<u32>(1u))) - vec2<i32>(1)));
}

/// The first texel of the 3x3 block around `center` (combine_ring_texel order) whose id word in
/// `older_id` holds instance `id`; `fallback` if none does. Nine id loads at most.
fn combine_search_texel(older_id: texture_2d<u32>, id: u32, center: vec2<u32>, fallback: vec2<u32>) -> vec2<u32> {
    let size = textureDimensions(older_id, 0);
    for (var k = 0u; k < 9u; k++) {
        let t = combine_ring_texel(center, size, k);
        if (lod_buffer_id(textureLoad(older_id, t, 0).x) == id) {
            return t;
        }
    }
    return fallback;
}

/// The object motion of the surface at texture-space `uv` with clip depth `depth` from an
/// engine's motion vector `motion_vector` (uv now minus uv in the previous frame, camera motion
/// included): where the surface was minus where the camera's reprojection puts it.
fn combine_object_motion(uv: vec2<f32>, depth: f32, new_to_old: mat4x4<f32>, motion_vector: vec2<f32>) -> vec2<f32> {
    return uv - motion_vector - reproject(uv, depth, new_to_old).xy;
}

/// The combined color from the texels the combine reads: the newer color and id word at the
/// pixel, `old` = reproject(uv, newer depth, new_to_old), the older color, id word and depth at
/// combine_older_texel. Outside the older view the newer color; else combine_shown, the newer
/// sample shown if flagged for now, the older if flagged for next.
fn combine_texels(newer_color: vec4<f32>, newer_word: u32, old: vec3<f32>, older_color: vec4<f32>, older_word: u32, older_depth: f32) -> vec4<f32> {
    if (!in_viewport(old.xy)) {
        return newer_color;
    }
    let newer = LodSample(newer_color, lod_buffer_id(newer_word), old.z);
    let older = LodSample(older_color, lod_buffer_id(older_word), older_depth);
    let newer_shown = lod_buffer_shown(newer_word, LOD_BUFFER_SHOWN_NOW);
    let older_shown = lod_buffer_shown(older_word, LOD_BUFFER_SHOWN_NEXT);
    return combine_shown(newer, newer_shown, older, older_shown);
}

/// The whole per-pixel combine of frame-sequential LOD at `pixel` (what passes/combine.wgsl
/// draws), for an engine to call in a full-screen pass it already runs (tonemapping, TAA) and
/// save the pass. Seven texel loads: the newer color, id and depth, the older depth at the
/// first estimate, the older color, id and depth at the refined texel; four more id loads where
/// a t-instance's read lands on another object (combine_match_texel). For scenes where nothing
/// moves by itself; else combine_at_moved.
fn combine_at(
    newer_color: texture_2d<f32>,
    newer_id: texture_2d<u32>,
    newer_depth: texture_2d<f32>,
    older_color: texture_2d<f32>,
    older_id: texture_2d<u32>,
    older_depth: texture_2d<f32>,
    pixel: vec2<u32>,
    new_to_old: mat4x4<f32>,
) -> vec4<f32> {
    return combine_at_moved(newer_color, newer_id, newer_depth, older_color, older_id, older_depth, pixel, new_to_old, vec2<f32>(0.0));
}

/// combine_at for a pixel whose surface moved by itself since the older frame: the older buffer
/// is read where the surface was, `motion` (its object motion in texture-space uv) away from
/// where the camera's reprojection puts it. With the motion of the LOD pass's location 2 a
/// swaying or moving t-instance keeps its older LOD under its newer one: no background shows
/// through where both cover the pixel. Where the moved read and its side texels hold another
/// object and the pixel moved, the older LOD moved otherwise (its surface at this pixel is
/// another point of the animated object): up to nine more id loads search the 3x3 block where
/// the camera alone puts the pixel (combine_search_texel).
fn combine_at_moved(
    newer_color: texture_2d<f32>,
    newer_id: texture_2d<u32>,
    newer_depth: texture_2d<f32>,
    older_color: texture_2d<f32>,
    older_id: texture_2d<u32>,
    older_depth: texture_2d<f32>,
    pixel: vec2<u32>,
    new_to_old: mat4x4<f32>,
    motion: vec2<f32>,
) -> vec4<f32> {
    let size = textureDimensions(newer_color, 0);
    let color = textureLoad(newer_color, pixel, 0);
    let depth = textureLoad(newer_depth, pixel, 0).x;
    // reproject and combine_older_uv, with the pixel's reprojection base and first estimate
    // computed once: the same values, 73 ALU ops on this path instead of 91 (`--stats`).
    let base = reproject_base(combine_uv(pixel, size), new_to_old);
    let old = reproject_from_base(base, depth, new_to_old);
    if (!in_viewport(old.xy)) {
        return color;
    }
    let first = old.xy + motion;
    let first_depth = textureLoad(older_depth, combine_texel(first, size), 0).x;
    let refined = reproject_refine(base, depth, first_depth, new_to_old).xy + motion;
    let at = select(first, refined, in_viewport(refined));
    let newer_word = textureLoad(newer_id, pixel, 0).x;
    let id = lod_buffer_id(newer_word);
    var older = combine_texel(at, size);
    var older_word = textureLoad(older_id, older, 0).x;
    if (id != 0u && lod_buffer_id(older_word) != id) {
        // Three more id loads, only where a t-instance's older read found another object.
        let x = combine_side_texel(at, size, 0u);
        let y = combine_side_texel(at, size, 1u);
        let ids = vec4<u32>(
            lod_buffer_id(older_word),
            lod_buffer_id(textureLoad(older_id, x, 0).x),
            lod_buffer_id(textureLoad(older_id, y, 0).x),
            lod_buffer_id(textureLoad(older_id, vec2<u32>(x.x, y.y), 0).x),
        );
        older = combine_match_texel(id, ids, older, x, y);
        older_word = textureLoad(older_id, older, 0).x;
        if (lod_buffer_id(older_word) != id && any(motion != vec2<f32>(0.0))) {
            // The older LOD moved otherwise than the newer one (their surfaces at this pixel are
            // different points of an animated object): look where the camera alone puts it.
            older = combine_search_texel(older_id, id, combine_texel(old.xy, size), older);
            older_word = textureLoad(older_id, older, 0).x;
        }
    }
    return combine_texels(
        color,
        newer_word,
        old,
        textureLoad(older_color, older, 0),
        older_word,
        textureLoad(older_depth, older, 0).x,
    );
}
