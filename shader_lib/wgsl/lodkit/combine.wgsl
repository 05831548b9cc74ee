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
//       new_to_old) -> vec4<f32>   the paper's per-pixel combine, to fold into a full-screen pass
//       an engine already has (depths: the depth attachments as texture_2d<f32>); still scenes
//   combine_at_moved(newer_color, ..., older_depth, pixel, new_to_old, motion) -> vec4<f32>
//       combine_at for a pixel whose surface moved by `motion` (its object motion); where the
//       moved read and its side texels miss the t-instance, combine_search_texel where the
//       camera alone puts the pixel
//   combine_object_motion(uv, depth, new_to_old, motion_vector) -> vec2<f32>   the object
//       motion from an engine's motion vector (uv now minus uv before, camera motion included)
//   depth_closer(a, b) -> bool   a strictly closer than b under the depth convention
// Pieces of the combine with the older level's coverage known (lodkit::combine_coverage puts
// them together in combine_pixel, for a pass drawn over the levels' silhouettes):
//   CombineRead { texel, color, found }   the older texel a pixel combines with, its color
//   COMBINE_COVER_REACH, COMBINE_BLOCK_REACH (texels), COMBINE_SNAP   combine_cover_texel's reach
//       where the older level is estimated / known to cover the pixel; combine_snap's margin
//   combine_region_position(pixel, size) -> vec4<f32>   clip position of a region vertex in pixels
//   combine_displayed_word(word, anchored, older_tau, pattern) -> u32   the older word shown at
//       this frame's threshold where its level is anchored to the screen pattern
//   combine_ray_offset(at, texel, size) -> f32   texels from texel's center to at
//   combine_cover_texel(older_id, older_depth, id, read, base, depth, new_to_old, motion,
//       reach) -> vec2<u32>   the neighbour holding id whose older sample lies on the pixel's ray
//   combine_snap(fraction) -> vec2<f32>   bilinear fractions within COMBINE_SNAP of 0 or 1 snapped
//   combine_own_color(older_color, older_id, id, at, fallback) -> vec4<f32>   the bilinear blend
//       of the texels around at holding id
//   combine_other_texel(older_id, id, read, at) -> vec2<u32>   the nearest texel not holding id
//   combine_read_own(older_color, older_id, older_depth, owner, uv, depth, new_to_old, motion,
//       reach) -> CombineRead   a t-instance's own older level, refined only on its own texels
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z); off: 0 near.
#define_import_path lodkit::combine
#import lodkit::lod_buffer::{lod_buffer_id, lod_buffer_shown, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT}
#import lodkit::reproject::{reproject, reproject_base, reproject_from_base, reproject_refine, in_viewport}
#import lodkit::visibility::visibility_shown

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
/// The older texel a pixel combines with and the older color to show for it.
struct CombineRead {
    texel: vec2<u32>,
    color: vec4<f32>,
    /// false: no older level at this pixel; it shows the newer buffer.
    found: bool,
}

/// combine_cover_texel's reach (texels) where the older level is estimated: the reach of the
/// four samples around a point, less 1/1000 (a pixel that did not move takes no neighbour).
const COMBINE_COVER_REACH: f32 = 0.999;
/// combine_cover_texel's reach where the older level is known to cover the pixel: the 3x3 block.
const COMBINE_BLOCK_REACH: f32 = 1.5;
/// Bilinear fractions within this of 0 or 1 are taken as that (combine_snap).
const COMBINE_SNAP: f32 = 0.01;
/// Clip position of a combine region's vertex at `pixel` (pixels, top-left origin) on a target
/// of `size` pixels.
fn combine_region_position(pixel: vec2<f32>, size: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0, 0.0, 1.0);
}

/// The older `word` with its shown-next flag from the screen `pattern` at `older_tau` where its
/// level is `anchored` to the screen (complementary to the newer level there); else `word`.
fn combine_displayed_word(word: u32, anchored: bool, older_tau: f32, pattern: f32) -> u32 {
    if (lod_buffer_id(word) == 0u || !anchored) {
        return word;
    }
    let next = LOD_BUFFER_SHOWN_NEXT << 30u;
    return select(word & ~next, word | next, visibility_shown(pattern, older_tau));
}

/// How far (texels, the larger axis) texture-space `at` lies from the center of `texel`.
fn combine_ray_offset(at: vec2<f32>, texel: vec2<u32>, size: vec2<u32>) -> f32 {
    let offset = abs(at * vec2<f32>(size) - (vec2<f32>(texel) + 0.5));
    return max(offset.x, offset.y);
}

/// The texel of the 3x3 block around `read` holding `id` whose older sample lies nearest the
/// pixel's ray (from `base`, moved by `motion`), if within `reach` texels; else `read`.
fn combine_cover_texel(older_id: texture_2d<u32>, older_depth: texture_2d<f32>, id: u32, read: vec2<u32>, base: vec4<f32>, depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>, reach: f32) -> vec2<u32> {
    let size = textureDimensions(older_id, 0);
    var best = read;
    var best_offset = reach;
    for (var k = 1u; k < 9u; k++) {
        let t = combine_ring_texel(read, size, k);
        if (lod_buffer_id(textureLoad(older_id, t, 0).x) == id) {
            let ray = reproject_refine(base, depth, textureLoad(older_depth, t, 0).x, new_to_old).xy;
            let offset = combine_ray_offset(ray + motion, t, size);
            if (offset < best_offset) {
                best = t;
                best_offset = offset;
            }
        }
    }
    return best;
}

/// Bilinear fractions with a value within COMBINE_SNAP of 0 or 1 taken as that.
fn combine_snap(fraction: vec2<f32>) -> vec2<f32> {
    let near = round(fraction);
    return select(fraction, near, abs(fraction - near) < vec2<f32>(COMBINE_SNAP));
}

/// The bilinear blend (combine_snap) of the 2x2 older texels around `at` holding `id`,
/// renormalized; `fallback` where none does.
fn combine_own_color(older_color: texture_2d<f32>, older_id: texture_2d<u32>, id: u32, at: vec2<f32>, fallback: vec4<f32>) -> vec4<f32> {
    let size = textureDimensions(older_color, 0);
    let f = at * vec2<f32>(size) - 0.5;
    let i0 = floor(f);
    let fr = combine_snap(f - i0);
    var sum = vec4<f32>(0.0);
    var weight = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let t = vec2<i32>(i0 + vec2<f32>(f32(k & 1u), f32(k >> 1u)));
        if (any(t < vec2<i32>(0)) || any(t >= vec2<i32>(size))) {
            continue;
        }
        let w = select(1.0 - fr.x, fr.x, (k & 1u) == 1u) * select(1.0 - fr.y, fr.y, (k >> 1u) == 1u);
        let texel = vec2<u32>(t);
        if (w > 0.0 && lod_buffer_id(textureLoad(older_id, texel, 0).x) == id) {
            sum += w * textureLoad(older_color, texel, 0);
            weight += w;
        }
    }
    if (weight <= 0.0) {
        return fallback;
    }
    return sum / weight;
}

/// The texel of the 3x3 block around `read` that does not hold `id`, nearest to `at`
/// (texture-space uv); `read` if every one holds it.
fn combine_other_texel(older_id: texture_2d<u32>, id: u32, read: vec2<u32>, at: vec2<f32>) -> vec2<u32> {
    let size = textureDimensions(older_id, 0);
    var best = read;
    var best_distance = 1.0e9;
    for (var k = 0u; k < 9u; k++) {
        let t = combine_ring_texel(read, size, k);
        if (lod_buffer_id(textureLoad(older_id, t, 0).x) != id) {
            let d = at * vec2<f32>(size) - (vec2<f32>(t) + 0.5);
            if (dot(d, d) < best_distance) {
                best = t;
                best_distance = dot(d, d);
            }
        }
    }
    return best;
}

/// The read of `owner`'s older level: refined at the older depth only where that texel holds
/// `owner`, else combine_cover_texel within `reach`; the color combine_own_color.
fn combine_read_own(older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, owner: u32, uv: vec2<f32>, depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>, reach: f32) -> CombineRead {
    let size = textureDimensions(older_color, 0);
    let base = reproject_base(uv, new_to_old);
    let first = reproject_from_base(base, depth, new_to_old).xy + motion;
    var at = first;
    let first_texel = combine_texel(first, size);
    if (lod_buffer_id(textureLoad(older_id, first_texel, 0).x) == owner) {
        let refined = reproject_refine(base, depth, textureLoad(older_depth, first_texel, 0).x, new_to_old).xy + motion;
        at = select(first, refined, in_viewport(refined));
    }
    var texel = combine_texel(at, size);
    if (lod_buffer_id(textureLoad(older_id, texel, 0).x) != owner) {
        texel = combine_cover_texel(older_id, older_depth, owner, texel, base, depth, new_to_old, motion, reach);
        if (lod_buffer_id(textureLoad(older_id, texel, 0).x) == owner) {
            at = reproject_refine(base, depth, textureLoad(older_depth, texel, 0).x, new_to_old).xy + motion;
        }
    }
    var color = textureLoad(older_color, texel, 0);
    if (lod_buffer_id(textureLoad(older_id, texel, 0).x) == owner) {
        color = combine_own_color(older_color, older_id, owner, at, color);
    }
    return CombineRead(texel, color, true);
}
