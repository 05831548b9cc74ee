// lodkit::combine_coverage — frame-sequential LOD's combine with the older level's coverage
// known (Scherzer & Wimmer 2008, sec. 3.4; sec. 4 estimates it from the older frame): where the
// level not drawn this frame covers a pixel, by a route per t-instance given as data, and the
// per-pixel entry a pass drawn over the levels' silhouettes calls.
//
// GLSL twin of shader_lib/wgsl/lodkit/combine_coverage.wgsl; same semantics, `lodkit_` prefix.
// Routes: the older level's silhouette, an older-level depth pass the host draws, or the estimate
// from last frame's picture. The data texture (a usampler2D, lodkit::combine_coverage::
// CombineData in Rust) holds per id a record of LODKIT_COMBINE_RECORD texels at id * 6: the
// columns of its new_to_old (f32 bits), its silhouette table, then (flags, older_tau bits, record
// count, 0); record 0 is the frame's; the binned silhouettes follow.
//
// Exports:
//   lodkit_CombineNewer { color, word, depth, motion, pattern, level_depth }   the pixel's newer
//       texel as the engine read it, its object motion, the screen pattern there, the
//       older-level depth pass there
//   lodkit_CombineObject { new_to_old, silhouette, flags, older_tau }   one id's record
//   LODKIT_COMBINE_RECORD, LODKIT_COMBINE_KNOWN, LODKIT_COMBINE_ANCHORED,
//       LODKIT_COMBINE_ROUTE_SILHOUETTE, LODKIT_COMBINE_ROUTE_DEPTH_PASS,
//       LODKIT_COMBINE_OBJECT_MOTION, LODKIT_COMBINE_LEVEL_DEPTH, LODKIT_COMBINE_ONLY_DEPTH_PASS
//       the layout's flags
//   lodkit_combine_object(id) -> lodkit_CombineObject   the record of id (unknown past the records)
//   lodkit_combine_new_to_old(id) -> mat4   the matrix reprojecting a pixel holding id
//   lodkit_combine_far_depth() -> float   the far clip depth (an older-level depth pass's clear)
//   lodkit_combine_by_silhouette(id) -> bool   whether id is a t-instance whose older level's
//       coverage is its silhouette
//   LODKIT_COMBINE_RAY_STEPS, LODKIT_COMBINE_RAY_REACH   how far and how close to the ray
//       lodkit_combine_ray_texel looks
//   lodkit_combine_ray_texel(id, owned, base, depth, new_to_old, motion) -> uvec3   the older
//       texel on the pixel's ray holding id (owned; else the nearest within
//       LODKIT_COMBINE_BLOCK_REACH) or another id that is no t-instance covering by its
//       silhouette; z: found
//   lodkit_combine_read_known(owner, uv, depth, new_to_old, motion) -> lodkit_CombineRead   the
//       read of owner's older level where its coverage is known; not found where none is held
//   lodkit_combine_behind_texel(id, at, base, depth, new_to_old, motion) -> uvec2   what lies
//       behind id's older level, on the ray
//   lodkit_combine_read_estimated(uv, depth, base, old, new_to_old, motion) -> lodkit_CombineRead
//   lodkit_combine_read_level_depth(level, id, uv, depth, old, motion) -> lodkit_CombineRead
//   LODKIT_COMBINE_HIDDEN_MARGIN   how far in front (a share of the view distance) an older
//       object must lie to hide a level
//   lodkit_combine_clearly_closer(a, b) -> bool   whether clip depth a lies closer than b by
//       more than LODKIT_COMBINE_HIDDEN_MARGIN of b's view distance
//   lodkit_combine_hider(owner, at, depth) -> uint   the object other than owner the older
//       texel at `at` holds clearly closer than clip depth `depth`; 0: none
//   lodkit_combine_hidden(owner, at, depth) -> bool   whether the older texel at `at` holds
//       another object clearly closer than clip depth `depth`
//   lodkit_combine_known_covers(id, p) -> bool   whether id's older silhouette is known and
//       covers the pixel center p
//   lodkit_combine_may_cover(id, p) -> bool   whether id is a t-instance whose older level may
//       cover the pixel center p (coverage not its silhouette, or its silhouette covers p)
//   lodkit_combine_outline(id, at) -> int   how last frame's picture decides a pixel center on
//       id's older silhouette: 1 covered, 0 not, LODKIT_SILHOUETTE_ON undecided
//   lodkit_combine_read_silhouettes(uv, depth, p) -> lodkit_CombineRead   a level whose
//       silhouette covers the pixel (one showing no t-instance, or what lies behind a level that
//       does not cover it)
//   lodkit_combine_read(newer, pixel, base, old, m) -> lodkit_CombineRead   by the route of what
//       the pixel shows
//   LODKIT_COMBINE_EDGE_REACH   how far outside the older view a reprojection is read at its edge
//   lodkit_combine_edge_uv(uv, size) -> vec3   uv inside the view, the nearest edge texel's center
//       within LODKIT_COMBINE_EDGE_REACH texels outside it; z: 1 read, 0 too far out
//   lodkit_combine_pixel(newer, pixel) -> vec4   the whole per-pixel combine
// Hooks: the older buffer through lodkit/combine.glsl's (lodkit_combine_fetch_color, _word,
//   _depth, _size), the data texture through lodkit/silhouette.glsl's lodkit_silhouette_fetch.
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z); off: 0 near.
#ifndef LODKIT_COMBINE_COVERAGE_GLSL
#define LODKIT_COMBINE_COVERAGE_GLSL

// The hook functions of lodkit/combine.glsl and lodkit/silhouette.glsl (defined before either
// is first included).
#define LODKIT_COMBINE_HOOKS
#define LODKIT_SILHOUETTE_HOOKS
#include "lodkit/combine.glsl"
#include "lodkit/lod_buffer.glsl"
#include "lodkit/reproject.glsl"
#include "lodkit/silhouette.glsl"

/// The newer buffer's texel at the pixel being combined, as the engine read it.
struct lodkit_CombineNewer {
    vec4 color;
    /// Id word (lodkit/lod_buffer.glsl).
    uint word;
    /// Clip depth.
    float depth;
    /// Object motion in texture-space uv (0 without).
    vec2 motion;
    /// The visibility pattern at this pixel, anchored to the screen.
    float pattern;
    /// The older-level depth pass at this pixel (far where none).
    float level_depth;
};

/// One id's record in the data texture.
struct lodkit_CombineObject {
    mat4 new_to_old;
    /// The older level's silhouette table (lodkit_silhouette_covers).
    uvec4 silhouette;
    /// LODKIT_COMBINE_* flags (0: an id the combine does not know).
    uint flags;
    /// The threshold at which the older level is displayed this frame.
    float older_tau;
};

/// Texels per id record in the data texture.
const uint LODKIT_COMBINE_RECORD = 6u;
/// Record flag: a t-instance the combine knows.
const uint LODKIT_COMBINE_KNOWN = 1u;
/// Record flag: its older level is displayed at older_tau with the screen-anchored pattern.
const uint LODKIT_COMBINE_ANCHORED = 2u;
/// Record flag: its older level's coverage is its silhouette.
const uint LODKIT_COMBINE_ROUTE_SILHOUETTE = 4u;
/// Record flag: its older level's coverage is the older-level depth pass.
const uint LODKIT_COMBINE_ROUTE_DEPTH_PASS = 8u;
/// Frame flag (record 0): lodkit_CombineNewer.motion is each pixel's object motion.
const uint LODKIT_COMBINE_OBJECT_MOTION = 16u;
/// Frame flag (record 0): lodkit_CombineNewer.level_depth holds the older-level depth pass.
const uint LODKIT_COMBINE_LEVEL_DEPTH = 32u;
/// Frame flag (record 0): every t-instance the data describes takes the older-level depth pass.
const uint LODKIT_COMBINE_ONLY_DEPTH_PASS = 64u;

/// The record of `id` in the data texture; past the records, the frame's matrix and no flags.
lodkit_CombineObject lodkit_combine_object(uint id) {
    uint slots = lodkit_silhouette_texel(5u).z;
    uint k = id < slots ? id : 0u;
    uint first = k * LODKIT_COMBINE_RECORD;
    uvec4 record = lodkit_silhouette_texel(first + 5u);
    mat4 m = mat4(
        uintBitsToFloat(lodkit_silhouette_texel(first)),
        uintBitsToFloat(lodkit_silhouette_texel(first + 1u)),
        uintBitsToFloat(lodkit_silhouette_texel(first + 2u)),
        uintBitsToFloat(lodkit_silhouette_texel(first + 3u)));
    return lodkit_CombineObject(m, lodkit_silhouette_texel(first + 4u), k == id ? record.x : 0u, uintBitsToFloat(record.y));
}

/// The matrix that reprojects a pixel holding `id`: the camera's with
/// LODKIT_COMBINE_OBJECT_MOTION, else the record's.
mat4 lodkit_combine_new_to_old(uint id) {
    lodkit_CombineObject frame = lodkit_combine_object(0u);
    if ((frame.flags & LODKIT_COMBINE_OBJECT_MOTION) != 0u) {
        return frame.new_to_old;
    }
    return lodkit_combine_object(id).new_to_old;
}

/// The far clip depth (what an older-level depth pass is cleared to).
float lodkit_combine_far_depth() {
#ifdef LODKIT_REVERSE_Z
    return 0.0;
#else
    return 1.0;
#endif
}

/// Whether `id` is a t-instance whose older level's coverage is its silhouette (its record is
/// known and routed by the silhouette).
bool lodkit_combine_by_silhouette(uint id) {
    // The record's flags alone (lodkit_combine_object's, without its matrix and table).
    uint wanted = LODKIT_COMBINE_KNOWN | LODKIT_COMBINE_ROUTE_SILHOUETTE;
    bool known = id != 0u && id < lodkit_silhouette_texel(5u).z;
    return known && (lodkit_silhouette_texel(id * LODKIT_COMBINE_RECORD + 5u).x & wanted) == wanted;
}

/// Texels lodkit_combine_ray_texel steps along the pixel's ray, each way.
const uint LODKIT_COMBINE_RAY_STEPS = 6u;
/// How far (texels, the larger axis) an older sample may lie from the pixel's ray for
/// lodkit_combine_ray_texel to take it.
const float LODKIT_COMBINE_RAY_REACH = 0.75;

/// The older texel on the pixel's ray (`base` = lodkit_reproject_base under `new_to_old`, moved
/// by `motion`) that holds `id` (`owned`) or any other id (`!owned`) but a t-instance whose
/// record gives its silhouette as its coverage (such a level shows at the pixel only where its
/// silhouette covers it, and lodkit_combine_read_silhouettes reads those): stepping a texel at a
/// time along the ray's image in the older buffer from the reprojection of `depth`, both ways,
/// nearest first, up to LODKIT_COMBINE_RAY_STEPS; the first whose older sample, refined at its
/// own depth, lies within LODKIT_COMBINE_RAY_REACH of it; `owned`, where none does, the nearest
/// of the texels it visited, if within LODKIT_COMBINE_BLOCK_REACH (the level covers the pixel,
/// so only its color is looked for). z: 1 where found, 0 where none is.
uvec3 lodkit_combine_ray_texel(uint id, bool owned, vec4 base, float depth, mat4 new_to_old, vec2 motion) {
    uvec2 size = lodkit_combine_fetch_size();
    vec2 texels = vec2(size);
    vec2 a = lodkit_reproject_from_base(base, depth, new_to_old).xy + motion;
    // A second point of the ray at another finite depth gives the ray's image its direction.
    float other = depth < 0.5 ? depth * 0.5 + 0.5 : depth * 0.5;
    vec2 along = (lodkit_reproject_from_base(base, other, new_to_old).xy + motion - a) * texels;
    float length_texels = length(along);
    vec2 stride = (length_texels > 1.0e-3 ? along / max(length_texels, 1.0e-3) : vec2(0.0)) / texels;
    uvec3 nearest = uvec3(0u);
    float nearest_offset = LODKIT_COMBINE_BLOCK_REACH;
    for (uint k = 0u; k <= 2u * LODKIT_COMBINE_RAY_STEPS; k++) {
        float j = float((k + 1u) / 2u) * ((k & 1u) == 1u ? 1.0 : -1.0);
        vec2 at = a + j * stride;
        if (!lodkit_in_viewport(at)) {
            continue;
        }
        uvec2 t = lodkit_combine_texel(at, size);
        uint held = lodkit_lod_buffer_id(lodkit_combine_fetch_word(t));
        if ((held == id) != owned || (!owned && lodkit_combine_by_silhouette(held))) {
            continue;
        }
        vec2 ray = lodkit_reproject_refine(base, depth, lodkit_combine_fetch_depth(t), new_to_old).xy + motion;
        float offset = lodkit_combine_ray_offset(ray, t, size);
        if (offset < LODKIT_COMBINE_RAY_REACH) {
            return uvec3(t, 1u);
        }
        if (owned && offset < nearest_offset) {
            nearest = uvec3(t, 1u);
            nearest_offset = offset;
        }
    }
    return nearest;
}

/// The read of `owner`'s older level where its coverage is known to include the pixel:
/// lodkit_combine_read_own within the 3x3 block; where that finds no texel of `owner`, the one
/// lodkit_combine_ray_texel finds on the pixel's ray; none: not found (the older buffer does not
/// hold that part of the level, and another object's texel would show through it).
lodkit_CombineRead lodkit_combine_read_known(uint owner, vec2 uv, float depth, mat4 new_to_old, vec2 motion) {
    lodkit_CombineRead read = lodkit_combine_read_own(owner, uv, depth, new_to_old, motion, LODKIT_COMBINE_BLOCK_REACH);
    if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(read.texel)) == owner) {
        return read;
    }
    vec4 base = lodkit_reproject_base(uv, new_to_old);
    uvec3 hit = lodkit_combine_ray_texel(owner, true, base, depth, new_to_old, motion);
    if (hit.z == 0u) {
        return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
    }
    vec2 at = lodkit_reproject_refine(base, depth, lodkit_combine_fetch_depth(hit.xy), new_to_old).xy + motion;
    vec4 color = lodkit_combine_own_color(owner, at, lodkit_combine_fetch_color(hit.xy));
    return lodkit_CombineRead(hit.xy, color, true);
}

/// The older texel showing what lies behind `id`'s older level at the pixel, where that level is
/// known not to cover it: lodkit_combine_ray_texel's texel of another id on the pixel's ray
/// (`base`, `depth`: the newer level's; not a t-instance covering by its silhouette); none:
/// lodkit_combine_other_texel around `at` (which may be such a level's texel).
uvec2 lodkit_combine_behind_texel(uint id, vec2 at, vec4 base, float depth, mat4 new_to_old, vec2 motion) {
    uvec3 hit = lodkit_combine_ray_texel(id, false, base, depth, new_to_old, motion);
    if (hit.z == 1u) {
        return hit.xy;
    }
    return lodkit_combine_other_texel(id, lodkit_combine_texel(at, lodkit_combine_fetch_size()), at);
}

/// The estimated read of a pixel showing no known t-instance; a known t-instance's texel only
/// where its route is the estimate and its sample lies on the pixel's ray under its own matrix.
lodkit_CombineRead lodkit_combine_read_estimated(vec2 uv, float depth, vec4 base, vec3 old, mat4 new_to_old, vec2 motion) {
    uvec2 size = lodkit_combine_fetch_size();
    vec2 first = old.xy + motion;
    vec2 refined = lodkit_reproject_refine(base, depth, lodkit_combine_fetch_depth(lodkit_combine_texel(first, size)), new_to_old).xy + motion;
    uvec2 read = lodkit_combine_texel(lodkit_in_viewport(refined) ? refined : first, size);
    uint g = lodkit_lod_buffer_id(lodkit_combine_fetch_word(read));
    lodkit_CombineObject object = lodkit_combine_object(g);
    if (g != 0u && (object.flags & LODKIT_COMBINE_KNOWN) != 0u) {
        if ((object.flags & (LODKIT_COMBINE_ROUTE_SILHOUETTE | LODKIT_COMBINE_ROUTE_DEPTH_PASS)) != 0u) {
            return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
        }
        mat4 m = object.new_to_old;
        vec2 ray = lodkit_reproject_refine(lodkit_reproject_base(uv, m), depth, lodkit_combine_fetch_depth(read), m).xy;
        if (lodkit_combine_ray_offset(ray, read, size) >= LODKIT_COMBINE_COVER_REACH) {
            return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
        }
    }
    return lodkit_CombineRead(read, lodkit_combine_fetch_color(read), true);
}

/// Whether `g` names a t-instance the combine knows.
#define LODKIT_COMBINE_IS_KNOWN_(g) ((g) != 0u && (lodkit_combine_object(g).flags & LODKIT_COMBINE_KNOWN) != 0u)

/// The read with the older-level depth pass (`level` at the pixel) for a pixel showing `id`:
/// the level drawn there (the t-instance the older buffer holds where its depth reprojects, else
/// `id`'s; for a pixel showing none, only in front of what it shows) read where its surface was
/// (nothing, the newer color, where none of its texels lies near), else what lies behind `id`'s
/// own level.
lodkit_CombineRead lodkit_combine_read_level_depth(float level, uint id, vec2 uv, float depth, vec3 old, vec2 motion) {
    uvec2 size = lodkit_combine_fetch_size();
    // A pixel showing no t-instance shows a level only in front of what it shows.
    bool covered = lodkit_depth_closer(level, id == 0u ? depth : lodkit_combine_far_depth());
    uint owner = id;
    if (covered) {
        vec2 at = lodkit_reproject(uv, level, lodkit_combine_new_to_old(id)).xy + motion;
        uvec2 read = lodkit_combine_texel(at, size);
        uint g = lodkit_lod_buffer_id(lodkit_combine_fetch_word(read));
        if (LODKIT_COMBINE_IS_KNOWN_(g)) {
            owner = g;
        } else {
            // The read may miss another t-instance's level: the nearest one of the 3x3 block.
            uint o = lodkit_lod_buffer_id(lodkit_combine_fetch_word(lodkit_combine_other_texel(0u, read, at)));
            owner = LODKIT_COMBINE_IS_KNOWN_(o) ? o : id;
        }
    }
    if (owner == 0u) {
        return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
    }
    if (covered) {
        mat4 m = lodkit_combine_new_to_old(owner);
        vec4 base = lodkit_reproject_base(uv, m);
        vec2 first = lodkit_reproject_from_base(base, level, m).xy;
        vec2 at = first + motion;
        uvec2 texel = lodkit_combine_texel(at, size);
        if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) != owner) {
            texel = lodkit_combine_cover_texel(owner, texel, base, level, m, motion, LODKIT_COMBINE_BLOCK_REACH);
        }
        // The pixel's object motion is its newer level's: where the older level's points moved
        // otherwise (a sway), the level is found where the camera alone puts it.
        if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) != owner) {
            texel = lodkit_combine_texel(first, size);
            at = first;
            if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) != owner) {
                texel = lodkit_combine_cover_texel(owner, texel, base, level, m, vec2(0.0), LODKIT_COMBINE_BLOCK_REACH);
            }
        }
        // No texel of the level near where it was (hidden last frame, or drawn there as an
        // n-instance on its transition's first frame): the newer color, not what the read holds.
        if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) != owner) {
            return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
        }
        vec4 color = lodkit_combine_own_color(owner, at, lodkit_combine_fetch_color(texel));
        return lodkit_CombineRead(texel, color, true);
    }
    vec2 at = old.xy + motion;
    uvec2 texel = lodkit_combine_other_texel(owner, lodkit_combine_texel(at, size), at);
    return lodkit_CombineRead(texel, lodkit_combine_fetch_color(texel), true);
}

/// How far in front of a level's point, as a share of the point's view distance, an older object
/// must lie for lodkit_combine_hidden to take it as hiding the level. Where two surfaces touch (a
/// trunk entering the ground), interpolated and reprojected depths put them a fraction of a
/// percent apart either way; a bare comparison then shows the ground through the trunk.
const float LODKIT_COMBINE_HIDDEN_MARGIN = 0.01;

/// Whether clip depth `a` lies closer to the camera than `b` by more than
/// LODKIT_COMBINE_HIDDEN_MARGIN of `b`'s view distance. Under a perspective projection whose far
/// plane lies well past the scene (or at infinity), 1 - depth (reversed Z: depth) is inversely
/// proportional to the view distance, so the margin is taken on that.
bool lodkit_combine_clearly_closer(float a, float b) {
#ifdef LODKIT_REVERSE_Z
    return a > b * (1.0 + LODKIT_COMBINE_HIDDEN_MARGIN);
#else
    return a < b - LODKIT_COMBINE_HIDDEN_MARGIN * (1.0 - b);
#endif
}

/// The object other than `owner` (not the background) that the older texel at texture-space `at`
/// holds clearly closer than clip depth `depth` (lodkit_combine_clearly_closer): the older frame
/// drew it in front of `owner`'s older level there. 0 where there is none (or `at` is outside
/// the view).
uint lodkit_combine_hider(uint owner, vec2 at, float depth) {
    uvec2 texel = lodkit_combine_texel(at, lodkit_combine_fetch_size());
    uint held = lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel));
    bool hides = lodkit_in_viewport(at) && held != owner && held != 0u && lodkit_combine_clearly_closer(lodkit_combine_fetch_depth(texel), depth);
    return hides ? held : 0u;
}

/// Whether the older texel at texture-space `at` holds an object other than `owner` clearly
/// closer than clip depth `depth` (lodkit_combine_hider): there the older frame drew that object
/// in front of `owner`'s older level.
bool lodkit_combine_hidden(uint owner, vec2 at, float depth) {
    return lodkit_combine_hider(owner, at, depth) != 0u;
}

/// Whether `id` is a t-instance whose older level's coverage is its silhouette, and that
/// silhouette covers (or passes through) the pixel center `p`.
bool lodkit_combine_known_covers(uint id, vec2 p) {
    lodkit_CombineObject o = lodkit_combine_object(id);
    uint wanted = LODKIT_COMBINE_KNOWN | LODKIT_COMBINE_ROUTE_SILHOUETTE;
    return id != 0u && (o.flags & wanted) == wanted && lodkit_silhouette_covers(o.silhouette, p) != 0;
}

/// Whether `id`'s older level may cover the pixel center `p` under this frame's camera: `id` is
/// a t-instance (its record is known) whose coverage is not its silhouette, or whose silhouette
/// covers (or passes through) `p`. Any other object is drawn this frame at its own level: where
/// a pixel shows a t-instance, it lost the depth test there and is not in front of it now.
bool lodkit_combine_may_cover(uint id, vec2 p) {
    lodkit_CombineObject o = lodkit_combine_object(id);
    if (id == 0u || (o.flags & LODKIT_COMBINE_KNOWN) == 0u) {
        return false;
    }
    return (o.flags & LODKIT_COMBINE_ROUTE_SILHOUETTE) == 0u || lodkit_silhouette_covers(o.silhouette, p) != 0;
}

/// How last frame's picture decides a pixel center that lies on `id`'s older silhouette
/// (LODKIT_SILHOUETTE_ON), from the older texel at texture-space `at` (the center's
/// reprojection): where the picture sampled that very point (`at` in the view, within
/// LODKIT_COMBINE_SNAP of the texel's center: camera and level still), 1 if the texel holds `id`
/// and 0 if not; elsewhere LODKIT_SILHOUETTE_ON (undecided: the rasterizer may break the tie
/// either way).
int lodkit_combine_outline(uint id, vec2 at) {
    uvec2 size = lodkit_combine_fetch_size();
    uvec2 texel = lodkit_combine_texel(at, size);
    if (!lodkit_in_viewport(at) || lodkit_combine_ray_offset(at, texel, size) >= LODKIT_COMBINE_SNAP) {
        return LODKIT_SILHOUETTE_ON;
    }
    return lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) == id ? 1 : 0;
}

/// For a pixel showing no t-instance, or behind a t-instance's level drawn now whose older
/// silhouette does not cover it (`depth` that level's): the read (lodkit_combine_read_known) of
/// the first t-instance whose older silhouette covers the pixel center `p` (on its outline, only
/// where lodkit_combine_outline decides it covered: undecided, the rasterizer may break the tie
/// either way, and a level taken where it would not draw it is a ghost), is not hidden there by another
/// t-instance whose silhouette covers it too (lodkit_combine_hider, lodkit_combine_known_covers),
/// and whose older level the read finds; none: not found.
lodkit_CombineRead lodkit_combine_read_silhouettes(vec2 uv, float depth, vec2 p) {
    uint slots = lodkit_silhouette_texel(5u).z;
    uint wanted = LODKIT_COMBINE_KNOWN | LODKIT_COMBINE_ROUTE_SILHOUETTE;
    for (uint g = 1u; g < slots; g++) {
        if ((lodkit_silhouette_texel(g * LODKIT_COMBINE_RECORD + 5u).x & wanted) != wanted) {
            continue;
        }
        int covers = lodkit_silhouette_covers(lodkit_silhouette_texel(g * LODKIT_COMBINE_RECORD + 4u), p);
        if (covers == 0) {
            continue;
        }
        mat4 m = lodkit_combine_object(g).new_to_old;
        if (covers == LODKIT_SILHOUETTE_ON) {
            covers = lodkit_combine_outline(g, lodkit_reproject(uv, depth, m).xy);
        }
        if (covers != 1) {
            continue;
        }
        vec3 point = lodkit_reproject(uv, depth, m);
        uint front = lodkit_combine_hider(g, point.xy, point.z);
        if (front != 0u && lodkit_combine_known_covers(front, p)) {
            continue;
        }
        lodkit_CombineRead read = lodkit_combine_read_known(g, uv, depth, m, vec2(0.0));
        if (read.found) {
            return read;
        }
    }
    return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
}

/// The older read of `pixel` by the route of what it shows: a t-instance's own by its record's
/// (estimated without one; with its silhouette, where it covers the pixel or passes through its
/// center undecided by lodkit_combine_outline, the texel in front where lodkit_combine_hider
/// finds another object there that lodkit_combine_may_cover, else the level's own; where it does
/// not cover the pixel, what lies behind the level: another level whose silhouette covers it, else
/// lodkit_combine_behind_texel under the camera's reprojection alone, the frame's matrix and no
/// motion: what lies behind a level does not move with it); else the depth pass's level in front
/// of what the pixel shows, nothing where every t-instance takes the depth pass
/// (LODKIT_COMBINE_ONLY_DEPTH_PASS), a covering silhouette, the estimate.
lodkit_CombineRead lodkit_combine_read(lodkit_CombineNewer newer, uvec2 pixel, vec4 base, vec3 old, mat4 m) {
    uvec2 size = lodkit_combine_fetch_size();
    uint id = lodkit_lod_buffer_id(newer.word);
    vec2 uv = lodkit_combine_uv(pixel, size);
    vec2 p = vec2(pixel) + 0.5;
    lodkit_CombineObject object = lodkit_combine_object(id);
    uint silhouette = LODKIT_COMBINE_KNOWN | LODKIT_COMBINE_ROUTE_SILHOUETTE;
    uint depth_pass = LODKIT_COMBINE_KNOWN | LODKIT_COMBINE_ROUTE_DEPTH_PASS;
    vec2 at = old.xy + newer.motion;
    if (id != 0u) {
        if ((object.flags & silhouette) != silhouette) {
            if ((object.flags & depth_pass) == depth_pass) {
                return lodkit_combine_read_level_depth(newer.level_depth, id, uv, newer.depth, old, newer.motion);
            }
            return lodkit_combine_read_own(id, uv, newer.depth, m, newer.motion, LODKIT_COMBINE_COVER_REACH);
        }
        int own = lodkit_silhouette_covers(object.silhouette, p);
        if (own == LODKIT_SILHOUETTE_ON) {
            own = lodkit_combine_outline(id, at);
        }
        // Covered, or on the outline where last frame's picture does not decide: the level drawn
        // now covers the pixel, so the older level taken there is no ghost.
        if (own != 0) {
            uint front = lodkit_combine_hider(id, at, old.z);
            if (front != 0u && lodkit_combine_may_cover(front, p)) {
                uvec2 held = lodkit_combine_texel(at, size);
                return lodkit_CombineRead(held, lodkit_combine_fetch_color(held), true);
            }
            return lodkit_combine_read_known(id, uv, newer.depth, m, newer.motion);
        }
        // Its older level does not cover the pixel: what lies behind it, read below.
    } else {
        lodkit_CombineObject frame = lodkit_combine_object(0u);
        if ((frame.flags & LODKIT_COMBINE_LEVEL_DEPTH) != 0u && lodkit_depth_closer(newer.level_depth, lodkit_combine_far_depth())) {
            return lodkit_combine_read_level_depth(newer.level_depth, 0u, uv, newer.depth, old, newer.motion);
        }
        // Every t-instance's older level is in the depth pass, and none lies in front here.
        if ((frame.flags & LODKIT_COMBINE_ONLY_DEPTH_PASS) != 0u) {
            return lodkit_CombineRead(uvec2(0u), vec4(0.0), false);
        }
    }
    // Another t-instance's older level whose silhouette covers the pixel; else, behind a level,
    // what the ray finds, and for a pixel showing no t-instance the estimate.
    lodkit_CombineRead r = lodkit_combine_read_silhouettes(uv, newer.depth, p);
    if (r.found) {
        return r;
    }
    if (id != 0u) {
        // What lies behind the level moves as the camera alone moves it: the matrix and motion
        // of the pixel are the level's own.
        mat4 camera = lodkit_combine_object(0u).new_to_old;
        vec4 behind = lodkit_reproject_base(uv, camera);
        vec2 behind_at = lodkit_reproject_from_base(behind, newer.depth, camera).xy;
        uvec2 texel = lodkit_combine_behind_texel(id, behind_at, behind, newer.depth, camera, vec2(0.0));
        return lodkit_CombineRead(texel, lodkit_combine_fetch_color(texel), true);
    }
    return lodkit_combine_read_estimated(uv, newer.depth, base, old, m, newer.motion);
}

/// How far (texels, the larger axis) outside the older view a pixel's reprojection may land and
/// still be read at the older buffer's edge (lodkit_combine_edge_uv).
const float LODKIT_COMBINE_EDGE_REACH = 4.0;

/// Where the combine reads for texture-space uv of the older buffer (size texels): uv itself
/// inside the view; outside it, within LODKIT_COMBINE_EDGE_REACH texels, the nearest edge texel's
/// center (z 1); farther out, z 0 (nothing to read).
vec3 lodkit_combine_edge_uv(vec2 uv, uvec2 size) {
    if (lodkit_in_viewport(uv)) {
        return vec3(uv, 1.0);
    }
    vec2 half_texel = 0.5 / vec2(size);
    vec2 inside = clamp(uv, half_texel, 1.0 - half_texel);
    vec2 beyond = abs(uv - inside) * vec2(size);
    return vec3(inside, max(beyond.x, beyond.y) <= LODKIT_COMBINE_EDGE_REACH ? 1.0 : 0.0);
}

/// The per-pixel combine with the older level's coverage known, for a pass drawn over the
/// levels' silhouettes: `newer` as read at `pixel`; the older buffer and the data texture through
/// the hooks. Reprojected farther than LODKIT_COMBINE_EDGE_REACH texels outside the older view, or
/// no older level found: the newer color; else lodkit_combine_texels.
vec4 lodkit_combine_pixel(lodkit_CombineNewer newer, uvec2 pixel) {
    uvec2 size = lodkit_combine_fetch_size();
    mat4 m = lodkit_combine_new_to_old(lodkit_lod_buffer_id(newer.word));
    vec4 base = lodkit_reproject_base(lodkit_combine_uv(pixel, size), m);
    vec3 reprojected = lodkit_reproject_from_base(base, newer.depth, m);
    vec3 edge = lodkit_combine_edge_uv(reprojected.xy, size);
    if (edge.z == 0.0) {
        return newer.color;
    }
    vec3 old = vec3(edge.xy, reprojected.z);
    lodkit_CombineRead read = lodkit_combine_read(newer, pixel, base, old, m);
    if (!read.found) {
        return newer.color;
    }
    uint word = lodkit_combine_fetch_word(read.texel);
    lodkit_CombineObject o = lodkit_combine_object(lodkit_lod_buffer_id(word));
    uint anchored = LODKIT_COMBINE_KNOWN | LODKIT_COMBINE_ANCHORED;
    uint shown = lodkit_combine_displayed_word(word, (o.flags & anchored) == anchored, o.older_tau, newer.pattern);
    return lodkit_combine_texels(newer.color, newer.word, old, read.color, shown, lodkit_combine_fetch_depth(read.texel));
}

#endif // LODKIT_COMBINE_COVERAGE_GLSL
