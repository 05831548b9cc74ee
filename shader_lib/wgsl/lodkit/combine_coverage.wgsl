// lodkit::combine_coverage — frame-sequential LOD's combine with the older level's coverage
// known (Scherzer & Wimmer 2008, sec. 3.4; sec. 4 estimates it from the older frame): where the
// level not drawn this frame covers a pixel, by a route per t-instance given as data, and the
// per-pixel entry a pass drawn over the levels' silhouettes calls.
//
// Routes: the older level's silhouette (its winding number, lodkit::silhouette), an older-level
// depth pass the host draws, or the estimate from last frame's picture. The data texture
// (texture_2d<u32>, lodkit::combine_coverage::CombineData in Rust; what GL 3.3 and WebGL2 read,
// unlike a storage buffer) holds per id a record of COMBINE_RECORD texels at id * 6: the columns
// of its new_to_old (f32 bits), its silhouette table (lodkit::silhouette::silhouette_covers),
// then (flags, older_tau bits, record count, 0); record 0 is the frame's (the camera's matrix,
// COMBINE_OBJECT_MOTION, COMBINE_LEVEL_DEPTH, COMBINE_ONLY_DEPTH_PASS, the record count); the
// binned silhouettes follow.
//
// Exports:
//   CombineNewer { color, word, depth, motion, pattern, level_depth }   the pixel's newer texel
//       as the engine read it, its object motion, the screen pattern there, the older-level
//       depth pass there
//   CombineObject { new_to_old, silhouette, flags, older_tau }   one id's record
//   COMBINE_RECORD, COMBINE_KNOWN, COMBINE_ANCHORED, COMBINE_ROUTE_SILHOUETTE,
//       COMBINE_ROUTE_DEPTH_PASS, COMBINE_OBJECT_MOTION, COMBINE_LEVEL_DEPTH,
//       COMBINE_ONLY_DEPTH_PASS   the layout's flags
//   combine_object(data, id) -> CombineObject   the record of id (unknown past the records)
//   combine_new_to_old(data, id) -> mat4x4<f32>   the matrix reprojecting a pixel holding id
//   combine_far_depth() -> f32   the far clip depth (an older-level depth pass's clear)
//   combine_by_silhouette(data, id) -> bool   whether id is a t-instance whose older level's
//       coverage is its silhouette
//   COMBINE_RAY_STEPS, COMBINE_RAY_REACH   how far and how close to the ray combine_ray_texel
//       looks
//   combine_ray_texel(older_id, older_depth, data, id, owned, base, depth, new_to_old, motion)
//       -> vec3<u32>   the older texel on the pixel's ray holding id (owned; else the nearest
//       within COMBINE_BLOCK_REACH) or another id that is no t-instance covering by its
//       silhouette; z: found
//   combine_read_known(older_color, older_id, older_depth, data, owner, uv, depth, new_to_old,
//       motion) -> CombineRead   the read of owner's older level where its coverage is known;
//       not found where none is held
//   combine_behind_texel(older_id, older_depth, data, id, at, base, depth, new_to_old, motion)
//       -> vec2<u32>   what lies behind id's older level, on the ray
//   combine_read_estimated(older_color, older_id, older_depth, data, uv, depth, base, old,
//       new_to_old, motion) -> CombineRead   a pixel showing no known t-instance, estimated
//   combine_read_level_depth(older_color, older_id, older_depth, data, level, id, uv, depth, old,
//       motion) -> CombineRead   by the older-level depth pass
//   COMBINE_HIDDEN_MARGIN   how far in front (a share of the view distance) an older object must
//       lie to hide a level
//   combine_clearly_closer(a, b) -> bool   whether clip depth a lies closer than b by more than
//       COMBINE_HIDDEN_MARGIN of b's view distance
//   combine_hider(older_id, older_depth, owner, at, depth) -> u32   the object other than owner
//       the older texel at `at` holds clearly closer than clip depth `depth`; 0: none
//   combine_hidden(older_id, older_depth, owner, at, depth) -> bool   whether the older texel at
//       `at` holds another object clearly closer than clip depth `depth` (owner's older level
//       hidden)
//   combine_known_covers(data, id, p) -> bool   whether id's older silhouette is known and covers
//       the pixel center p
//   combine_may_cover(data, id, p) -> bool   whether id is a t-instance whose older level may
//       cover the pixel center p (coverage not its silhouette, or its silhouette covers p)
//   combine_outline(older_id, id, at) -> i32   how last frame's picture decides a pixel center on
//       id's older silhouette: 1 covered, 0 not, SILHOUETTE_ON undecided
//   combine_read_silhouettes(older_color, older_id, older_depth, data, uv, depth, p)
//       -> CombineRead   a level whose silhouette covers the pixel (one showing no t-instance,
//       or what lies behind a level that does not cover it)
//   combine_read(older_color, older_id, older_depth, data, newer, pixel, base, old, m)
//       -> CombineRead   by the route of what the pixel shows
//   COMBINE_EDGE_REACH   how far outside the older view a reprojection is read at its edge
//   combine_edge_uv(uv, size) -> vec3<f32>   uv inside the view, the nearest edge texel's center
//       within COMBINE_EDGE_REACH texels outside it; z: 1 read, 0 too far out
//   combine_pixel(newer, pixel, older_color, older_id, older_depth, data) -> vec4<f32>   the
//       whole per-pixel combine (older depth: the depth attachment as texture_2d<f32>); a
//       reprojection outside the older view within COMBINE_EDGE_REACH is read at its edge
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z); off: 0 near.
#define_import_path lodkit::combine_coverage
#import lodkit::combine::{CombineRead, COMBINE_COVER_REACH, COMBINE_BLOCK_REACH, COMBINE_SNAP, combine_texel, combine_uv, combine_texels, combine_ray_offset, combine_cover_texel, combine_own_color, combine_other_texel, combine_read_own, combine_displayed_word, depth_closer}
#import lodkit::lod_buffer::lod_buffer_id
#import lodkit::reproject::{reproject, reproject_base, reproject_from_base, reproject_refine, in_viewport}
#import lodkit::silhouette::{silhouette_texel, silhouette_covers, SILHOUETTE_ON}

/// The newer buffer's texel at the pixel being combined, as the engine read it.
struct CombineNewer {
    color: vec4<f32>,
    /// Id word (lodkit::lod_buffer).
    word: u32,
    /// Clip depth.
    depth: f32,
    /// Object motion in texture-space uv (0 without).
    motion: vec2<f32>,
    /// The visibility pattern at this pixel, anchored to the screen
    /// (lodkit::visibility::visibility_screen_texel).
    pattern: f32,
    /// The older-level depth pass at this pixel (far where none; read with COMBINE_LEVEL_DEPTH).
    level_depth: f32,
}

/// One id's record in the data texture.
struct CombineObject {
    new_to_old: mat4x4<f32>,
    /// The older level's silhouette table (silhouette_covers).
    silhouette: vec4<u32>,
    /// COMBINE_* flags (0: an id the combine does not know).
    flags: u32,
    /// The threshold at which the older level is displayed this frame.
    older_tau: f32,
}

/// Texels per id record in the data texture.
const COMBINE_RECORD: u32 = 6u;
/// Record flag: a t-instance the combine knows.
const COMBINE_KNOWN: u32 = 1u;
/// Record flag: its older level is displayed at older_tau with the screen-anchored pattern.
const COMBINE_ANCHORED: u32 = 2u;
/// Record flag: its older level's coverage is its silhouette.
const COMBINE_ROUTE_SILHOUETTE: u32 = 4u;
/// Record flag: its older level's coverage is the older-level depth pass.
const COMBINE_ROUTE_DEPTH_PASS: u32 = 8u;
/// Frame flag (record 0): CombineNewer.motion is each pixel's object motion.
const COMBINE_OBJECT_MOTION: u32 = 16u;
/// Frame flag (record 0): CombineNewer.level_depth holds the older-level depth pass.
const COMBINE_LEVEL_DEPTH: u32 = 32u;
/// Frame flag (record 0): every t-instance the data describes takes the older-level depth pass.
const COMBINE_ONLY_DEPTH_PASS: u32 = 64u;

/// The record of `id` in the data texture; past the records, the frame's matrix and no flags.
fn combine_object(data: texture_2d<u32>, id: u32) -> CombineObject {
    let slots = silhouette_texel(data, 5u).z;
    let k = select(0u, id, id < slots);
    let first = k * COMBINE_RECORD;
    let record = silhouette_texel(data, first + 5u);
    let m = mat4x4<f32>(
        bitcast<vec4<f32>>(silhouette_texel(data, first)),
        bitcast<vec4<f32>>(silhouette_texel(data, first + 1u)),
        bitcast<vec4<f32>>(silhouette_texel(data, first + 2u)),
        bitcast<vec4<f32>>(silhouette_texel(data, first + 3u)),
    );
    return CombineObject(m, silhouette_texel(data, first + 4u), select(0u, record.x, k == id), bitcast<f32>(record.y));
}

/// The matrix that reprojects a pixel holding `id`: the camera's with COMBINE_OBJECT_MOTION,
/// else the record's.
fn combine_new_to_old(data: texture_2d<u32>, id: u32) -> mat4x4<f32> {
    let frame = combine_object(data, 0u);
    if ((frame.flags & COMBINE_OBJECT_MOTION) != 0u) {
        return frame.new_to_old;
    }
    return combine_object(data, id).new_to_old;
}

/// The far clip depth (what an older-level depth pass is cleared to).
fn combine_far_depth() -> f32 {
#ifdef LODKIT_REVERSE_Z
    return 0.0;
#else
    return 1.0;
#endif
}

/// Whether `id` is a t-instance whose older level's coverage is its silhouette (its record in
/// `data` is known and routed by the silhouette).
fn combine_by_silhouette(data: texture_2d<u32>, id: u32) -> bool {
    // The record's flags alone (combine_object's, without its matrix and table).
    let wanted = COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE;
    let known = id != 0u && id < silhouette_texel(data, 5u).z;
    return known && (silhouette_texel(data, id * COMBINE_RECORD + 5u).x & wanted) == wanted;
}

/// Texels combine_ray_texel steps along the pixel's ray, each way.
const COMBINE_RAY_STEPS: u32 = 6u;
/// How far (texels, the larger axis) an older sample may lie from the pixel's ray for
/// combine_ray_texel to take it.
const COMBINE_RAY_REACH: f32 = 0.75;

/// The older texel on the pixel's ray (`base` = reproject_base under `new_to_old`, moved by
/// `motion`) that holds `id` (`owned`) or any other id (`!owned`) but a t-instance whose record
/// in `data` gives its silhouette as its coverage (such a level shows at the pixel only where its
/// silhouette covers it, and combine_read_silhouettes reads those): stepping a texel at a time
/// along the ray's image in the older buffer from the reprojection of `depth`, both ways, nearest
/// first, up to COMBINE_RAY_STEPS; the first whose older sample, refined at its own depth, lies
/// within COMBINE_RAY_REACH of it. `owned`, where none does, the nearest of the texels it
/// visited, if within COMBINE_BLOCK_REACH (the level covers the pixel, so only its color is
/// looked for: an object that moves by itself, read without its motion, can put its edge texels
/// a little farther off). z: 1 where found, 0 where none is. (`data` is read only where
/// `!owned`.)
fn combine_ray_texel(older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, id: u32, owned: bool, base: vec4<f32>, depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>) -> vec3<u32> {
    let size = textureDimensions(older_id, 0);
    let texels = vec2<f32>(size);
    let a = reproject_from_base(base, depth, new_to_old).xy + motion;
    // A second point of the ray at another finite depth gives the ray's image its direction.
    let other = select(depth * 0.5, depth * 0.5 + 0.5, depth < 0.5);
    let along = (reproject_from_base(base, other, new_to_old).xy + motion - a) * texels;
    let length_texels = length(along);
    let stride = select(vec2<f32>(0.0), along / max(length_texels, 1.0e-3), length_texels > 1.0e-3) / texels;
    var nearest = vec3<u32>(0u);
    var nearest_offset = COMBINE_BLOCK_REACH;
    for (var k = 0u; k <= 2u * COMBINE_RAY_STEPS; k++) {
        let j = f32((k + 1u) / 2u) * select(-1.0, 1.0, (k & 1u) == 1u);
        let at = a + j * stride;
        if (!in_viewport(at)) {
            continue;
        }
        let t = combine_texel(at, size);
        let held = lod_buffer_id(textureLoad(older_id, t, 0).x);
        if ((held == id) != owned || (!owned && combine_by_silhouette(data, held))) {
            continue;
        }
        let ray = reproject_refine(base, depth, textureLoad(older_depth, t, 0).x, new_to_old).xy + motion;
        let offset = combine_ray_offset(ray, t, size);
        if (offset < COMBINE_RAY_REACH) {
            return vec3<u32>(t, 1u);
        }
        if (owned && offset < nearest_offset) {
            nearest = vec3<u32>(t, 1u);
            nearest_offset = offset;
        }
    }
    return nearest;
}

/// The read of `owner`'s older level where its coverage is known to include the pixel:
/// combine_read_own within the 3x3 block; where that finds no texel of `owner`, the one
/// combine_ray_texel finds on the pixel's ray (`data` passed on to it); none: not found (the
/// older buffer does not hold that part of the level, and another object's texel would show
/// through it).
fn combine_read_known(older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, owner: u32, uv: vec2<f32>, depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>) -> CombineRead {
    let read = combine_read_own(older_color, older_id, older_depth, owner, uv, depth, new_to_old, motion, COMBINE_BLOCK_REACH);
    if (lod_buffer_id(textureLoad(older_id, read.texel, 0).x) == owner) {
        return read;
    }
    let base = reproject_base(uv, new_to_old);
    let hit = combine_ray_texel(older_id, older_depth, data, owner, true, base, depth, new_to_old, motion);
    if (hit.z == 0u) {
        return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
    }
    let at = reproject_refine(base, depth, textureLoad(older_depth, hit.xy, 0).x, new_to_old).xy + motion;
    let color = combine_own_color(older_color, older_id, owner, at, textureLoad(older_color, hit.xy, 0));
    return CombineRead(hit.xy, color, true);
}

/// The older texel showing what lies behind `id`'s older level at the pixel, where that level is
/// known not to cover it: combine_ray_texel's texel of another id on the pixel's ray (`base`,
/// `depth`: the newer level's; not a t-instance covering by its silhouette, `data`); none:
/// combine_other_texel around `at` (which may be such a level's texel).
fn combine_behind_texel(older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, id: u32, at: vec2<f32>, base: vec4<f32>, depth: f32, new_to_old: mat4x4<f32>, motion: vec2<f32>) -> vec2<u32> {
    let hit = combine_ray_texel(older_id, older_depth, data, id, false, base, depth, new_to_old, motion);
    if (hit.z == 1u) {
        return hit.xy;
    }
    return combine_other_texel(older_id, id, combine_texel(at, textureDimensions(older_id, 0)), at);
}

/// The estimated read of a pixel showing no known t-instance; a known t-instance's texel only
/// where its route is the estimate and its sample lies on the pixel's ray under its own matrix.
fn combine_read_estimated(older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, uv: vec2<f32>, depth: f32, base: vec4<f32>, old: vec3<f32>, new_to_old: mat4x4<f32>, motion: vec2<f32>) -> CombineRead {
    let size = textureDimensions(older_color, 0);
    let first = old.xy + motion;
    let refined = reproject_refine(base, depth, textureLoad(older_depth, combine_texel(first, size), 0).x, new_to_old).xy + motion;
    let read = combine_texel(select(first, refined, in_viewport(refined)), size);
    let g = lod_buffer_id(textureLoad(older_id, read, 0).x);
    let object = combine_object(data, g);
    if (g != 0u && (object.flags & COMBINE_KNOWN) != 0u) {
        if ((object.flags & (COMBINE_ROUTE_SILHOUETTE | COMBINE_ROUTE_DEPTH_PASS)) != 0u) {
            return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
        }
        let m = object.new_to_old;
        let ray = reproject_refine(reproject_base(uv, m), depth, textureLoad(older_depth, read, 0).x, m).xy;
        if (combine_ray_offset(ray, read, size) >= COMBINE_COVER_REACH) {
            return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
        }
    }
    return CombineRead(read, textureLoad(older_color, read, 0), true);
}

/// The read with the older-level depth pass (`level` at the pixel) for a pixel showing `id`:
/// the level drawn there (the t-instance the older buffer holds where its depth reprojects, else
/// `id`'s; for a pixel showing none, only in front of what it shows) read where its surface was
/// (nothing, the newer color, where none of its texels lies near), else what lies behind `id`'s
/// own level.
fn combine_read_level_depth(older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, level: f32, id: u32, uv: vec2<f32>, depth: f32, old: vec3<f32>, motion: vec2<f32>) -> CombineRead {
    let size = textureDimensions(older_color, 0);
    // A pixel showing no t-instance shows a level only in front of what it shows.
    let covered = depth_closer(level, select(combine_far_depth(), depth, id == 0u));
    var owner = id;
    if (covered) {
        let at = reproject(uv, level, combine_new_to_old(data, id)).xy + motion;
        let read = combine_texel(at, size);
        let g = lod_buffer_id(textureLoad(older_id, read, 0).x);
        if (g != 0u && (combine_object(data, g).flags & COMBINE_KNOWN) != 0u) {
            owner = g;
        } else {
            // The read may miss another t-instance's level: the nearest one of the 3x3 block.
            let o = lod_buffer_id(textureLoad(older_id, combine_other_texel(older_id, 0u, read, at), 0).x);
            owner = select(id, o, o != 0u && (combine_object(data, o).flags & COMBINE_KNOWN) != 0u);
        }
    }
    if (owner == 0u) {
        return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
    }
    if (covered) {
        let m = combine_new_to_old(data, owner);
        let base = reproject_base(uv, m);
        let first = reproject_from_base(base, level, m).xy;
        var at = first + motion;
        var texel = combine_texel(at, size);
        if (lod_buffer_id(textureLoad(older_id, texel, 0).x) != owner) {
            texel = combine_cover_texel(older_id, older_depth, owner, texel, base, level, m, motion, COMBINE_BLOCK_REACH);
        }
        // The pixel's object motion is its newer level's: where the older level's points moved
        // otherwise (a sway), the level is found where the camera alone puts it.
        if (lod_buffer_id(textureLoad(older_id, texel, 0).x) != owner) {
            texel = combine_texel(first, size);
            at = first;
            if (lod_buffer_id(textureLoad(older_id, texel, 0).x) != owner) {
                texel = combine_cover_texel(older_id, older_depth, owner, texel, base, level, m, vec2<f32>(0.0), COMBINE_BLOCK_REACH);
            }
        }
        // No texel of the level near where it was (hidden last frame, or drawn there as an
        // n-instance on its transition's first frame): the newer color, not what the read holds.
        if (lod_buffer_id(textureLoad(older_id, texel, 0).x) != owner) {
            return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
        }
        let color = combine_own_color(older_color, older_id, owner, at, textureLoad(older_color, texel, 0));
        return CombineRead(texel, color, true);
    }
    let at = old.xy + motion;
    let texel = combine_other_texel(older_id, owner, combine_texel(at, size), at);
    return CombineRead(texel, textureLoad(older_color, texel, 0), true);
}

/// How far in front of a level's point, as a share of the point's view distance, an older object
/// must lie for combine_hidden to take it as hiding the level. Where two surfaces touch (a trunk
/// entering the ground), interpolated and reprojected depths put them a fraction of a percent
/// apart either way; a bare comparison then shows the ground through the trunk.
const COMBINE_HIDDEN_MARGIN: f32 = 0.01;

/// Whether clip depth `a` lies closer to the camera than `b` by more than COMBINE_HIDDEN_MARGIN
/// of `b`'s view distance. Under a perspective projection whose far plane lies well past the
/// scene (or at infinity), 1 - depth (reversed Z: depth) is inversely proportional to the view
/// distance, so the margin is taken on that.
fn combine_clearly_closer(a: f32, b: f32) -> bool {
#ifdef LODKIT_REVERSE_Z
    return a > b * (1.0 + COMBINE_HIDDEN_MARGIN);
#else
    return a < b - COMBINE_HIDDEN_MARGIN * (1.0 - b);
#endif
}

/// The object other than `owner` (not the background) that the older texel at texture-space `at`
/// holds clearly closer than clip depth `depth` (combine_clearly_closer): the older frame drew it
/// in front of `owner`'s older level there. 0 where there is none (or `at` is outside the view).
fn combine_hider(older_id: texture_2d<u32>, older_depth: texture_2d<f32>, owner: u32, at: vec2<f32>, depth: f32) -> u32 {
    let texel = combine_texel(at, textureDimensions(older_id, 0));
    let held = lod_buffer_id(textureLoad(older_id, texel, 0).x);
    let hides = in_viewport(at) && held != owner && held != 0u && combine_clearly_closer(textureLoad(older_depth, texel, 0).x, depth);
    return select(0u, held, hides);
}

/// Whether the older texel at texture-space `at` holds an object other than `owner` clearly
/// closer than clip depth `depth` (combine_hider): there the older frame drew that object in
/// front of `owner`'s older level.
fn combine_hidden(older_id: texture_2d<u32>, older_depth: texture_2d<f32>, owner: u32, at: vec2<f32>, depth: f32) -> bool {
    return combine_hider(older_id, older_depth, owner, at, depth) != 0u;
}

/// Whether `id` is a t-instance whose older level's coverage is its silhouette, and that
/// silhouette covers (or passes through) the pixel center `p`.
fn combine_known_covers(data: texture_2d<u32>, id: u32, p: vec2<f32>) -> bool {
    let o = combine_object(data, id);
    let wanted = COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE;
    return id != 0u && (o.flags & wanted) == wanted && silhouette_covers(data, o.silhouette, p) != 0;
}

/// Whether `id`'s older level may cover the pixel center `p` under this frame's camera: `id` is
/// a t-instance (its record is known) whose coverage is not its silhouette, or whose silhouette
/// covers (or passes through) `p`. Any other object is drawn this frame at its own level: where
/// a pixel shows a t-instance, it lost the depth test there and is not in front of it now.
fn combine_may_cover(data: texture_2d<u32>, id: u32, p: vec2<f32>) -> bool {
    let o = combine_object(data, id);
    if (id == 0u || (o.flags & COMBINE_KNOWN) == 0u) {
        return false;
    }
    return (o.flags & COMBINE_ROUTE_SILHOUETTE) == 0u || silhouette_covers(data, o.silhouette, p) != 0;
}

/// How last frame's picture decides a pixel center that lies on `id`'s older silhouette
/// (SILHOUETTE_ON), from the older texel at texture-space `at` (the center's reprojection): where
/// the picture sampled that very point (`at` in the view, within COMBINE_SNAP of the texel's
/// center: camera and level still), 1 if the texel holds `id` and 0 if not; elsewhere
/// SILHOUETTE_ON (undecided: the rasterizer may break the tie either way).
fn combine_outline(older_id: texture_2d<u32>, id: u32, at: vec2<f32>) -> i32 {
    let size = textureDimensions(older_id, 0);
    let texel = combine_texel(at, size);
    if (!in_viewport(at) || combine_ray_offset(at, texel, size) >= COMBINE_SNAP) {
        return SILHOUETTE_ON;
    }
    return select(0, 1, lod_buffer_id(textureLoad(older_id, texel, 0).x) == id);
}

/// For a pixel showing no t-instance, or behind a t-instance's level drawn now whose older
/// silhouette does not cover it (`depth` that level's): the read (combine_read_known) of the
/// first t-instance whose older silhouette covers the pixel center `p` (on its outline, only
/// where combine_outline decides it covered: undecided, the rasterizer may break the tie either
/// way, and a level taken where it would not draw it is a ghost), is not hidden there by another
/// t-instance whose silhouette covers it too (combine_hider, combine_known_covers), and whose
/// older level the read finds; none: not found.
fn combine_read_silhouettes(older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, uv: vec2<f32>, depth: f32, p: vec2<f32>) -> CombineRead {
    let slots = silhouette_texel(data, 5u).z;
    let wanted = COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE;
    for (var g = 1u; g < slots; g++) {
        if ((silhouette_texel(data, g * COMBINE_RECORD + 5u).x & wanted) != wanted) {
            continue;
        }
        var covers = silhouette_covers(data, silhouette_texel(data, g * COMBINE_RECORD + 4u), p);
        if (covers == 0) {
            continue;
        }
        let m = combine_object(data, g).new_to_old;
        if (covers == SILHOUETTE_ON) {
            covers = combine_outline(older_id, g, reproject(uv, depth, m).xy);
        }
        if (covers != 1) {
            continue;
        }
        let point = reproject(uv, depth, m);
        let front = combine_hider(older_id, older_depth, g, point.xy, point.z);
        if (front != 0u && combine_known_covers(data, front, p)) {
            continue;
        }
        let read = combine_read_known(older_color, older_id, older_depth, data, g, uv, depth, m, vec2<f32>(0.0));
        if (read.found) {
            return read;
        }
    }
    return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
}

/// The older read of `pixel` by the route of what it shows: a t-instance's own by its record's
/// (estimated without one; with its silhouette, where it covers the pixel or passes through its
/// center undecided by combine_outline, the texel in front where combine_hider finds another
/// object there that combine_may_cover, else the level's own; where it does not cover the
/// pixel, what lies behind the level: another level whose silhouette covers it, else
/// combine_behind_texel under the camera's reprojection alone, the frame's matrix and no motion:
/// what lies behind a level does not move with it); else the depth pass's level in front of what
/// the pixel shows, nothing where every t-instance takes the depth pass (COMBINE_ONLY_DEPTH_PASS),
/// a covering silhouette, the estimate.
fn combine_read(older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>, newer: CombineNewer, pixel: vec2<u32>, base: vec4<f32>, old: vec3<f32>, m: mat4x4<f32>) -> CombineRead {
    let size = textureDimensions(older_color, 0);
    let id = lod_buffer_id(newer.word);
    let uv = combine_uv(pixel, size);
    let p = vec2<f32>(pixel) + 0.5;
    let object = combine_object(data, id);
    let at = old.xy + newer.motion;
    if (id != 0u) {
        if ((object.flags & (COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE)) != (COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE)) {
            if ((object.flags & (COMBINE_KNOWN | COMBINE_ROUTE_DEPTH_PASS)) == (COMBINE_KNOWN | COMBINE_ROUTE_DEPTH_PASS)) {
                return combine_read_level_depth(older_color, older_id, older_depth, data, newer.level_depth, id, uv, newer.depth, old, newer.motion);
            }
            return combine_read_own(older_color, older_id, older_depth, id, uv, newer.depth, m, newer.motion, COMBINE_COVER_REACH);
        }
        var own = silhouette_covers(data, object.silhouette, p);
        if (own == SILHOUETTE_ON) {
            own = combine_outline(older_id, id, at);
        }
        // Covered, or on the outline where last frame's picture does not decide: the level drawn
        // now covers the pixel, so the older level taken there is no ghost.
        if (own != 0) {
            let front = combine_hider(older_id, older_depth, id, at, old.z);
            if (front != 0u && combine_may_cover(data, front, p)) {
                let held = combine_texel(at, size);
                return CombineRead(held, textureLoad(older_color, held, 0), true);
            }
            return combine_read_known(older_color, older_id, older_depth, data, id, uv, newer.depth, m, newer.motion);
        }
        // Its older level does not cover the pixel: what lies behind it, read below.
    } else {
        let frame = combine_object(data, 0u);
        if ((frame.flags & COMBINE_LEVEL_DEPTH) != 0u && depth_closer(newer.level_depth, combine_far_depth())) {
            return combine_read_level_depth(older_color, older_id, older_depth, data, newer.level_depth, 0u, uv, newer.depth, old, newer.motion);
        }
        // Every t-instance's older level is in the depth pass, and none lies in front here.
        if ((frame.flags & COMBINE_ONLY_DEPTH_PASS) != 0u) {
            return CombineRead(vec2<u32>(0u), vec4<f32>(0.0), false);
        }
    }
    // Another t-instance's older level whose silhouette covers the pixel; else, behind a level,
    // what the ray finds, and for a pixel showing no t-instance the estimate.
    let r = combine_read_silhouettes(older_color, older_id, older_depth, data, uv, newer.depth, p);
    if (r.found) {
        return r;
    }
    if (id != 0u) {
        // What lies behind the level moves as the camera alone moves it: the matrix and motion
        // of the pixel are the level's own.
        let camera = combine_object(data, 0u).new_to_old;
        let behind = reproject_base(uv, camera);
        let behind_at = reproject_from_base(behind, newer.depth, camera).xy;
        let texel = combine_behind_texel(older_id, older_depth, data, id, behind_at, behind, newer.depth, camera, vec2<f32>(0.0));
        return CombineRead(texel, textureLoad(older_color, texel, 0), true);
    }
    return combine_read_estimated(older_color, older_id, older_depth, data, uv, newer.depth, base, old, m, newer.motion);
}

/// How far (texels, the larger axis) outside the older view a pixel's reprojection may land and
/// still be read at the older buffer's edge (combine_edge_uv).
const COMBINE_EDGE_REACH: f32 = 4.0;

/// Where the combine reads for texture-space `uv` of the older buffer (`size` texels): `uv` itself
/// inside the view; outside it, within COMBINE_EDGE_REACH texels, the nearest edge texel's center
/// (z 1); farther out, z 0 (nothing to read). A camera that turns or moves sideways brings a strip
/// of the picture into view each frame; its level is read from the edge of last frame's picture,
/// not left to the level drawn now on every other frame.
fn combine_edge_uv(uv: vec2<f32>, size: vec2<u32>) -> vec3<f32> {
    if (in_viewport(uv)) {
        return vec3<f32>(uv, 1.0);
    }
    let half = 0.5 / vec2<f32>(size);
    let inside = clamp(uv, half, 1.0 - half);
    let beyond = abs(uv - inside) * vec2<f32>(size);
    return vec3<f32>(inside, select(0.0, 1.0, max(beyond.x, beyond.y) <= COMBINE_EDGE_REACH));
}

/// The per-pixel combine with the older level's coverage known, for a pass drawn over the
/// levels' silhouettes: `newer` as read at `pixel`, the older color, id words and depth, the
/// frame's `data`. Reprojected farther than COMBINE_EDGE_REACH texels outside the older view, or
/// no older level found: the newer color; else combine_texels.
fn combine_pixel(newer: CombineNewer, pixel: vec2<u32>, older_color: texture_2d<f32>, older_id: texture_2d<u32>, older_depth: texture_2d<f32>, data: texture_2d<u32>) -> vec4<f32> {
    let size = textureDimensions(older_color, 0);
    let m = combine_new_to_old(data, lod_buffer_id(newer.word));
    let base = reproject_base(combine_uv(pixel, size), m);
    let reprojected = reproject_from_base(base, newer.depth, m);
    let edge = combine_edge_uv(reprojected.xy, size);
    if (edge.z == 0.0) {
        return newer.color;
    }
    let old = vec3<f32>(edge.xy, reprojected.z);
    let read = combine_read(older_color, older_id, older_depth, data, newer, pixel, base, old, m);
    if (!read.found) {
        return newer.color;
    }
    let word = textureLoad(older_id, read.texel, 0).x;
    let o = combine_object(data, lod_buffer_id(word));
    let anchored = (o.flags & (COMBINE_KNOWN | COMBINE_ANCHORED)) == (COMBINE_KNOWN | COMBINE_ANCHORED);
    let shown = combine_displayed_word(word, anchored, o.older_tau, newer.pattern);
    return combine_texels(newer.color, newer.word, old, read.color, shown, textureLoad(older_depth, read.texel, 0).x);
}
