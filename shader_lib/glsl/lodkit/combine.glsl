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
//   lodkit_combine_texel(uv, size) -> uvec2, lodkit_combine_uv(pixel, size) -> vec2
//   lodkit_combine_older_uv(pixel, size, newer_depth, first_depth, new_to_old, motion) -> vec2
//   lodkit_combine_older_texel(pixel, size, newer_depth, first_depth, new_to_old, motion) -> uvec2
//   lodkit_combine_side_texel(uv, size, axis) -> uvec2   the neighbour on uv's side on an axis
//   lodkit_combine_match_texel(id, ids, nearest, x, y) -> uvec2   the older texel of the newer
//       pixel's t-instance among the nearest, its side texels and the diagonal
//   lodkit_combine_ring_texel(center, size, k) -> uvec2   the k-th (0..8) texel of the 3x3 block
//       around center: the center, left, right, up, down, then the corners (clamped)
//   lodkit_combine_search_texel(older_id, id, center, fallback) -> uvec2   the first texel of
//       the 3x3 block around center holding instance id, else fallback (a macro: older_id a
//       usampler2D)
//   lodkit_combine_object_motion(uv, depth, new_to_old, motion_vector) -> vec2   object motion
//       from an engine's motion vector (uv now minus uv before, camera motion included)
//   lodkit_combine_texels(newer_color, newer_word, old, older_color, older_word, older_depth)
//       -> vec4
//   lodkit_combine_at(newer_color, newer_id, newer_depth, older_color, older_id, older_depth,
//       pixel, new_to_old) -> vec4   the whole per-pixel combine (a macro: takes sampler2D /
//       usampler2D, or sampler2D(texture, sampler) / usampler2D(texture, sampler) in Vulkan
//       GLSL, the depths as sampler2D of the depth attachments; pixel a uvec2); nothing moves
//   lodkit_combine_at_moved(newer_color, ..., older_depth, pixel, new_to_old, motion) -> vec4
//       the same for a pixel whose surface moved by itself (motion: its object motion, a vec2);
//       where the moved read misses the t-instance, lodkit_combine_search_texel where the camera
//       alone puts the pixel
//   lodkit_depth_closer(a, b) -> bool
// Pieces of the combine with the older level's coverage known (lodkit/combine_coverage.glsl puts
// them together in lodkit_combine_pixel), reading the older buffer through hooks:
//   lodkit_CombineRead { texel, color, found }   the older texel a pixel combines with
//   LODKIT_COMBINE_COVER_REACH, LODKIT_COMBINE_BLOCK_REACH (texels), LODKIT_COMBINE_SNAP
//   lodkit_combine_region_position(pixel, size) -> vec4   clip position of a region vertex
//   lodkit_combine_displayed_word(word, anchored, older_tau, pattern) -> uint   the older word
//       shown at this frame's threshold where its level is anchored to the screen pattern
//   lodkit_combine_ray_offset(at, texel, size) -> float   texels from texel's center to at
//   lodkit_combine_cover_texel(id, read, base, depth, new_to_old, motion, reach) -> uvec2   the
//       neighbour holding id whose older sample lies on the pixel's ray
//   lodkit_combine_snap(fraction) -> vec2   bilinear fractions within the snap of 0 or 1 snapped
//   lodkit_combine_own_color(id, at, fallback) -> vec4   the blend of the texels around at holding id
//   lodkit_combine_other_texel(id, read, at) -> uvec2   the nearest texel not holding id
//   lodkit_combine_read_own(owner, uv, depth, new_to_old, motion, reach) -> lodkit_CombineRead
// Hooks (GLSL cannot pass a texture to a function on every target, so the four functions above
// that read the older buffer call functions the includer defines, after its samplers; they are
// compiled only where LODKIT_COMBINE_HOOKS is defined before the first include, as
// lodkit/combine_coverage.glsl does; an undefined prototype would otherwise reach the driver as
// an empty function through naga's GLSL front end; texel = uvec2):
//   vec4 lodkit_combine_fetch_color(uvec2 texel)   the older buffer's color
//   uint lodkit_combine_fetch_word(uvec2 texel)   its id word
//   float lodkit_combine_fetch_depth(uvec2 texel)   its clip depth (the depth attachment)
//   uvec2 lodkit_combine_fetch_size()   its size
// Shader defs:
//   LODKIT_REVERSE_Z (bool, default off) — depth 1 is near and 0 far (reversed Z).
#ifndef LODKIT_COMBINE_GLSL
#define LODKIT_COMBINE_GLSL

#include "lodkit/lod_buffer.glsl"
#include "lodkit/reproject.glsl"
#include "lodkit/visibility.glsl"

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

/// The texel of a `size` texture at texture-space `uv` (clamped to the texture).
uvec2 lodkit_combine_texel(vec2 uv, uvec2 size) {
    vec2 inside = clamp(uv, vec2(0.0), vec2(1.0));
    return min(uvec2(inside * vec2(size)), size - uvec2(1u));
}

/// Texture-space center of pixel `pixel` of a `size` target.
vec2 lodkit_combine_uv(uvec2 pixel, uvec2 size) {
    return (vec2(pixel) + 0.5) / vec2(size);
}

/// Where in the older buffer (uv) the combine reads for the newer pixel: the reprojection refined
/// at the older depth, moved by the object motion.
vec2 lodkit_combine_older_uv(uvec2 pixel, uvec2 size, float newer_depth, float first_depth, mat4 new_to_old, vec2 motion) {
    vec4 base = lodkit_reproject_base(lodkit_combine_uv(pixel, size), new_to_old);
    vec2 first = lodkit_reproject_from_base(base, newer_depth, new_to_old).xy + motion;
    vec2 refined = lodkit_reproject_refine(base, newer_depth, first_depth, new_to_old).xy + motion;
    return lodkit_in_viewport(refined) ? refined : first;
}

/// The older buffer's texel at lodkit_combine_older_uv.
uvec2 lodkit_combine_older_texel(uvec2 pixel, uvec2 size, float newer_depth, float first_depth, mat4 new_to_old, vec2 motion) {
    return lodkit_combine_texel(lodkit_combine_older_uv(pixel, size, newer_depth, first_depth, new_to_old, motion), size);
}

/// The texel next to the one holding uv along `axis` (0 x, 1 y), on the side uv lies off its
/// center; the texel itself within 1/1000 texel of the center or at the border.
uvec2 lodkit_combine_side_texel(vec2 uv, uvec2 size, uint axis) {
    uvec2 texel = lodkit_combine_texel(uv, size);
    float offset = uv[axis] * float(size[axis]) - (float(texel[axis]) + 0.5);
    uvec2 side = texel;
    if (offset > 1e-3 && texel[axis] + 1u < size[axis]) {
        side[axis] = texel[axis] + 1u;
    } else if (offset < -1e-3 && texel[axis] > 0u) {
        side[axis] = texel[axis] - 1u;
    }
    return side;
}

/// The older texel for a newer sample of instance `id`: `nearest`, unless `id` is a
/// t-instance's and `nearest` holds another id; then the first of x, y and the diagonal
/// (x.x, y.y) holding `id` (`ids`: the ids at nearest, x, y and the diagonal).
uvec2 lodkit_combine_match_texel(uint id, uvec4 ids, uvec2 nearest, uvec2 x, uvec2 y) {
    if (id == 0u || ids.x == id) {
        return nearest;
    }
    if (ids.y == id) {
        return x;
    }
    if (ids.z == id) {
        return y;
    }
    return ids.w == id ? uvec2(x.x, y.y) : nearest;
}

/// The k-th (0..8) texel of the 3x3 block around `center`: the center, then left, right, up,
/// down, then the corners (top left, top right, bottom left, bottom right); clamped to `size`.
uvec2 lodkit_combine_ring_texel(uvec2 center, uvec2 size, uint k) {
    ivec2 offset = ivec2(0);
    if (k >= 5u) {
        offset = ivec2(int((k - 5u) % 2u) * 2 - 1, int((k - 5u) / 2u) * 2 - 1);
    } else if (k >= 1u) {
        int s = int((k - 1u) % 2u) * 2 - 1;
        offset = k <= 2u ? ivec2(s, 0) : ivec2(0, s);
    }
    return uvec2(clamp(ivec2(center) + offset, ivec2(0), ivec2(max(size, uvec2(1u))) - ivec2(1)));
}

/// The k-th texel of the 3x3 block around `c` in id texture `oid`.
#define LODKIT_COMBINE_RING_(oid, c, k) lodkit_combine_ring_texel((c), uvec2(textureSize((oid), 0)), (k))
/// Whether the k-th texel around `c` holds instance `id`.
#define LODKIT_COMBINE_HIT_(oid, id, c, k) (LODKIT_COMBINE_ID_(oid, LODKIT_COMBINE_RING_(oid, c, k)) == (id))
/// The first texel of the 3x3 block around `c` (lodkit_combine_ring_texel order) whose id word in
/// `oid` (usampler2D) holds instance `id`; `fb` if none does.
#define lodkit_combine_search_texel(oid, id, c, fb) \
    (LODKIT_COMBINE_HIT_(oid, id, c, 0u) ? LODKIT_COMBINE_RING_(oid, c, 0u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 1u) ? LODKIT_COMBINE_RING_(oid, c, 1u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 2u) ? LODKIT_COMBINE_RING_(oid, c, 2u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 3u) ? LODKIT_COMBINE_RING_(oid, c, 3u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 4u) ? LODKIT_COMBINE_RING_(oid, c, 4u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 5u) ? LODKIT_COMBINE_RING_(oid, c, 5u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 6u) ? LODKIT_COMBINE_RING_(oid, c, 6u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 7u) ? LODKIT_COMBINE_RING_(oid, c, 7u) \
    : LODKIT_COMBINE_HIT_(oid, id, c, 8u) ? LODKIT_COMBINE_RING_(oid, c, 8u) : (fb))

/// The object motion at uv with clip depth `depth` from an engine's motion vector.
vec2 lodkit_combine_object_motion(vec2 uv, float depth, mat4 new_to_old, vec2 motion_vector) {
    return uv - motion_vector - lodkit_reproject(uv, depth, new_to_old).xy;
}

/// The combined color from the fetched texels.
vec4 lodkit_combine_texels(vec4 newer_color, uint newer_word, vec3 old, vec4 older_color, uint older_word, float older_depth) {
    if (!lodkit_in_viewport(old.xy)) {
        return newer_color;
    }
    lodkit_LodSample newer = lodkit_LodSample(newer_color, lodkit_lod_buffer_id(newer_word), old.z);
    lodkit_LodSample older = lodkit_LodSample(older_color, lodkit_lod_buffer_id(older_word), older_depth);
    bool newer_shown = lodkit_lod_buffer_shown(newer_word, LODKIT_LOD_BUFFER_SHOWN_NOW);
    bool older_shown = lodkit_lod_buffer_shown(older_word, LODKIT_LOD_BUFFER_SHOWN_NEXT);
    return lodkit_combine_shown(newer, newer_shown, older, older_shown);
}

/// The size of the buffers.
#define LODKIT_COMBINE_SIZE_(nc) uvec2(textureSize((nc), 0))
/// The newer clip depth at the pixel.
#define LODKIT_COMBINE_DEPTH_(nd, px) texelFetch((nd), ivec2(px), 0).x
/// The newer pixel reprojected with its own depth.
#define LODKIT_COMBINE_OLD_(nc, nd, px, m) \
    lodkit_reproject(lodkit_combine_uv((px), LODKIT_COMBINE_SIZE_(nc)), LODKIT_COMBINE_DEPTH_(nd, px), (m))
/// Where the older buffer is read (uv; refined at the older depth of the first estimate, moved
/// by `mo`).
#define LODKIT_COMBINE_AT_(nc, nd, od, px, m, mo) \
    lodkit_combine_older_uv((px), LODKIT_COMBINE_SIZE_(nc), LODKIT_COMBINE_DEPTH_(nd, px), \
        texelFetch((od), ivec2(lodkit_combine_texel(LODKIT_COMBINE_OLD_(nc, nd, px, m).xy + (mo), LODKIT_COMBINE_SIZE_(nc))), 0).x, (m), (mo))
/// The instance id at texel `t` of an id texture.
#define LODKIT_COMBINE_ID_(tex, t) lodkit_lod_buffer_id(texelFetch((tex), ivec2(t), 0).x)
/// A texel around the read position: `axis` 2 the one holding it, 0 or 1 its side texel, 3 the
/// diagonal.
#define LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, axis) \
    ((axis) == 2u ? lodkit_combine_texel(LODKIT_COMBINE_AT_(nc, nd, od, px, m, mo), LODKIT_COMBINE_SIZE_(nc)) \
        : (axis) == 3u ? uvec2(LODKIT_COMBINE_AROUND_X_(nc, nd, od, px, m, mo, 0u).x, LODKIT_COMBINE_AROUND_X_(nc, nd, od, px, m, mo, 1u).y) \
        : LODKIT_COMBINE_AROUND_X_(nc, nd, od, px, m, mo, axis))
/// The side texel of the read position on `axis`.
#define LODKIT_COMBINE_AROUND_X_(nc, nd, od, px, m, mo, axis) \
    lodkit_combine_side_texel(LODKIT_COMBINE_AT_(nc, nd, od, px, m, mo), LODKIT_COMBINE_SIZE_(nc), (axis))
/// The older texel read: the one holding the read position, or a side or diagonal texel of the
/// newer pixel's t-instance (lodkit_combine_match_texel).
#define LODKIT_COMBINE_MATCHED_(nc, nid, nd, oid, od, px, m, mo) \
    (lodkit_combine_match_texel(LODKIT_COMBINE_ID_(nid, px), \
        uvec4(LODKIT_COMBINE_ID_(oid, LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 2u)), \
            LODKIT_COMBINE_ID_(oid, LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 0u)), \
            LODKIT_COMBINE_ID_(oid, LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 1u)), \
            LODKIT_COMBINE_ID_(oid, LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 3u))), \
        LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 2u), LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 0u), \
        LODKIT_COMBINE_AROUND_(nc, nd, od, px, m, mo, 1u)))
/// The older texel read: the matched one, or where it misses the newer pixel's t-instance and
/// the pixel moved, lodkit_combine_search_texel around where the camera alone puts it.
#define LODKIT_COMBINE_OLDER_(nc, nid, nd, oid, od, px, m, mo) \
    ivec2((LODKIT_COMBINE_ID_(oid, LODKIT_COMBINE_MATCHED_(nc, nid, nd, oid, od, px, m, mo)) != LODKIT_COMBINE_ID_(nid, px) \
        && LODKIT_COMBINE_ID_(nid, px) != 0u && any(notEqual((mo), vec2(0.0)))) \
        ? lodkit_combine_search_texel((oid), LODKIT_COMBINE_ID_(nid, px), \
            lodkit_combine_texel(LODKIT_COMBINE_OLD_(nc, nd, px, m).xy, LODKIT_COMBINE_SIZE_(nc)), \
            LODKIT_COMBINE_MATCHED_(nc, nid, nd, oid, od, px, m, mo)) \
        : LODKIT_COMBINE_MATCHED_(nc, nid, nd, oid, od, px, m, mo))

/// The whole per-pixel combine at `px` (uvec2) where nothing moves by itself.
#define lodkit_combine_at(nc, nid, nd, oc, oid, od, px, m) \
    lodkit_combine_at_moved(nc, nid, nd, oc, oid, od, px, m, vec2(0.0))

/// The whole per-pixel combine at `px` (uvec2) of a pixel whose surface moved by `mo` (vec2,
/// object motion), for a full-screen pass the engine already has.
#define lodkit_combine_at_moved(nc, nid, nd, oc, oid, od, px, m, mo) \
    lodkit_combine_texels(texelFetch((nc), ivec2(px), 0), texelFetch((nid), ivec2(px), 0).x, LODKIT_COMBINE_OLD_(nc, nd, px, m), \
        texelFetch((oc), LODKIT_COMBINE_OLDER_(nc, nid, nd, oid, od, px, m, mo), 0), \
        texelFetch((oid), LODKIT_COMBINE_OLDER_(nc, nid, nd, oid, od, px, m, mo), 0).x, \
        texelFetch((od), LODKIT_COMBINE_OLDER_(nc, nid, nd, oid, od, px, m, mo), 0).x)

/// The older texel a pixel combines with and the older color to show for it.
struct lodkit_CombineRead {
    uvec2 texel;
    vec4 color;
    /// false: no older level at this pixel; it shows the newer buffer.
    bool found;
};

/// lodkit_combine_cover_texel's reach (texels) where the older level is estimated.
const float LODKIT_COMBINE_COVER_REACH = 0.999;
/// lodkit_combine_cover_texel's reach where the older level is known to cover the pixel.
const float LODKIT_COMBINE_BLOCK_REACH = 1.5;
/// Bilinear fractions within this of 0 or 1 are taken as that.
const float LODKIT_COMBINE_SNAP = 0.01;

#ifdef LODKIT_COMBINE_HOOKS
/// Hook: the older buffer's color at `texel` (defined by the includer).
vec4 lodkit_combine_fetch_color(uvec2 texel);
/// Hook: the older buffer's id word at `texel`.
uint lodkit_combine_fetch_word(uvec2 texel);
/// Hook: the older buffer's clip depth at `texel`.
float lodkit_combine_fetch_depth(uvec2 texel);
/// Hook: the older buffer's size.
uvec2 lodkit_combine_fetch_size();
#endif // LODKIT_COMBINE_HOOKS

/// Clip position of a combine region's vertex at `pixel` (pixels, top-left origin).
vec4 lodkit_combine_region_position(vec2 pixel, vec2 size) {
    return vec4(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0, 0.0, 1.0);
}

/// The older `word` with its shown-next flag from the screen `pattern` at `older_tau` where its
/// level is `anchored`; else `word`.
uint lodkit_combine_displayed_word(uint word, bool anchored, float older_tau, float pattern) {
    if (lodkit_lod_buffer_id(word) == 0u || !anchored) {
        return word;
    }
    uint next = LODKIT_LOD_BUFFER_SHOWN_NEXT << 30u;
    return lodkit_visibility_shown(pattern, older_tau) ? (word | next) : (word & ~next);
}

/// How far (texels, the larger axis) texture-space `at` lies from the center of `texel`.
float lodkit_combine_ray_offset(vec2 at, uvec2 texel, uvec2 size) {
    vec2 offset = abs(at * vec2(size) - (vec2(texel) + 0.5));
    return max(offset.x, offset.y);
}

#ifdef LODKIT_COMBINE_HOOKS
/// The texel of the 3x3 block around `read` holding `id` whose older sample lies nearest the
/// pixel's ray (from `base`, moved by `motion`), if within `reach` texels; else `read`.
uvec2 lodkit_combine_cover_texel(uint id, uvec2 read, vec4 base, float depth, mat4 new_to_old, vec2 motion, float reach) {
    uvec2 size = lodkit_combine_fetch_size();
    uvec2 best = read;
    float best_offset = reach;
    for (uint k = 1u; k < 9u; k++) {
        uvec2 t = lodkit_combine_ring_texel(read, size, k);
        if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(t)) == id) {
            vec2 ray = lodkit_reproject_refine(base, depth, lodkit_combine_fetch_depth(t), new_to_old).xy;
            float offset = lodkit_combine_ray_offset(ray + motion, t, size);
            if (offset < best_offset) {
                best = t;
                best_offset = offset;
            }
        }
    }
    return best;
}
#endif // LODKIT_COMBINE_HOOKS

/// Bilinear fractions with a value within LODKIT_COMBINE_SNAP of 0 or 1 taken as that.
vec2 lodkit_combine_snap(vec2 fraction) {
    vec2 near = roundEven(fraction);
    vec2 off = abs(fraction - near);
    return vec2(off.x < LODKIT_COMBINE_SNAP ? near.x : fraction.x, off.y < LODKIT_COMBINE_SNAP ? near.y : fraction.y);
}

#ifdef LODKIT_COMBINE_HOOKS
/// The bilinear blend (lodkit_combine_snap) of the 2x2 older texels around `at` holding `id`,
/// renormalized; `fallback` where none does.
vec4 lodkit_combine_own_color(uint id, vec2 at, vec4 fallback) {
    uvec2 size = lodkit_combine_fetch_size();
    vec2 f = at * vec2(size) - 0.5;
    vec2 i0 = floor(f);
    vec2 fr = lodkit_combine_snap(f - i0);
    vec4 sum = vec4(0.0);
    float weight = 0.0;
    for (uint k = 0u; k < 4u; k++) {
        ivec2 t = ivec2(i0 + vec2(float(k & 1u), float(k >> 1u)));
        if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, ivec2(size)))) {
            continue;
        }
        float w = ((k & 1u) == 1u ? fr.x : 1.0 - fr.x) * ((k >> 1u) == 1u ? fr.y : 1.0 - fr.y);
        uvec2 texel = uvec2(t);
        if (w > 0.0 && lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) == id) {
            sum += w * lodkit_combine_fetch_color(texel);
            weight += w;
        }
    }
    if (weight <= 0.0) {
        return fallback;
    }
    return sum / weight;
}

/// The texel of the 3x3 block around `read` that does not hold `id`, nearest to `at`; `read` if
/// every one holds it.
uvec2 lodkit_combine_other_texel(uint id, uvec2 read, vec2 at) {
    uvec2 size = lodkit_combine_fetch_size();
    uvec2 best = read;
    float best_distance = 1.0e9;
    for (uint k = 0u; k < 9u; k++) {
        uvec2 t = lodkit_combine_ring_texel(read, size, k);
        if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(t)) != id) {
            vec2 d = at * vec2(size) - (vec2(t) + 0.5);
            if (dot(d, d) < best_distance) {
                best = t;
                best_distance = dot(d, d);
            }
        }
    }
    return best;
}

/// The read of `owner`'s older level: refined at the older depth only where that texel holds
/// `owner`, else lodkit_combine_cover_texel within `reach`; the color lodkit_combine_own_color.
lodkit_CombineRead lodkit_combine_read_own(uint owner, vec2 uv, float depth, mat4 new_to_old, vec2 motion, float reach) {
    uvec2 size = lodkit_combine_fetch_size();
    vec4 base = lodkit_reproject_base(uv, new_to_old);
    vec2 first = lodkit_reproject_from_base(base, depth, new_to_old).xy + motion;
    vec2 at = first;
    uvec2 first_texel = lodkit_combine_texel(first, size);
    if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(first_texel)) == owner) {
        vec2 refined = lodkit_reproject_refine(base, depth, lodkit_combine_fetch_depth(first_texel), new_to_old).xy + motion;
        at = lodkit_in_viewport(refined) ? refined : first;
    }
    uvec2 texel = lodkit_combine_texel(at, size);
    if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) != owner) {
        texel = lodkit_combine_cover_texel(owner, texel, base, depth, new_to_old, motion, reach);
        if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) == owner) {
            at = lodkit_reproject_refine(base, depth, lodkit_combine_fetch_depth(texel), new_to_old).xy + motion;
        }
    }
    vec4 color = lodkit_combine_fetch_color(texel);
    if (lodkit_lod_buffer_id(lodkit_combine_fetch_word(texel)) == owner) {
        color = lodkit_combine_own_color(owner, at, color);
    }
    return lodkit_CombineRead(texel, color, true);
}

#endif // LODKIT_COMBINE_HOOKS

#endif // LODKIT_COMBINE_GLSL
