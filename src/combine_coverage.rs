//! Frame-sequential LOD's combine with the older level's coverage known: Rust twins of
//! `lodkit::combine_coverage` ([`combine_pixel`] and its routes), and the data texture the shader
//! reads ([`CombineData`]).
//!
//! Where the level not drawn this frame covers a pixel is known per t-instance, by a
//! [`CoverageRoute`] given as data: its silhouette's winding number ([`silhouette_covers`]), an
//! older-level depth pass the host draws, or the estimate from last frame's picture alone (the
//! paper's). A pass drawn over the levels' silhouettes
//! ([`silhouette_hull`](crate::silhouette::silhouette_hull)) calls the shader's `combine_pixel`
//! at each of its pixels. The host builds the frame's data for the older-level depth pass
//! ([`CombineData::depth_pass`], lodkit's default route), or from levels registered once per mesh
//! ([`CoverageLevels`]: their silhouettes, with no extra pass).

use glam::{Mat4, UVec2, UVec4, Vec2, Vec3, Vec4};

use crate::combine::older::{NOT_FOUND, depth_at, found, id_at, index_of, size_of};
use crate::combine::{
    COMBINE_COVER_REACH, COMBINE_SNAP, CombineRead, DepthConvention, LodImage,
    combine_displayed_word, combine_ray_offset, combine_read_own, combine_texel, combine_texels,
    combine_uv, depth_closer,
};
use crate::lod_buffer::lod_buffer_id;
use crate::reproject::{
    in_viewport, reproject, reproject_base, reproject_from_base, reproject_refine,
};
use crate::silhouette::{SILHOUETTE_ON, silhouette_covers, silhouette_texel};

mod data;
mod depth_pass;
mod levels;
mod ray;
pub use data::{
    COMBINE_DATA_WIDTH, COMBINE_MAX_HEIGHT, COMBINE_MAX_ID, CombineData, CombineDataDescriptor,
    CombineDataError, CombineObjectData, CoverageRoute,
};
pub use depth_pass::{DepthPassFrame, OlderDepth, combine_read_level_depth};
pub use levels::{
    CoverageError, CoverageFrame, CoverageLevel, CoverageLevels, LevelShape, MissingSilhouette,
    OlderLevel,
};
pub use ray::{
    COMBINE_RAY_REACH, COMBINE_RAY_STEPS, combine_behind_texel, combine_ray_texel,
    combine_read_known,
};

/// Texels per id in the data texture ([`CombineData`]): the record of t-instance `id` starts at
/// `id * 6`.
pub const COMBINE_RECORD: u32 = 6;

/// Record flag: the record describes a t-instance the combine knows (record 0, the frame's, has
/// it too).
pub const COMBINE_KNOWN: u32 = 1;
/// Record flag: the older level is displayed at the record's `older_tau` with the visibility
/// pattern anchored to the screen ([`combine_displayed_word`]).
pub const COMBINE_ANCHORED: u32 = 2;
/// Record flag: the older level's coverage is its silhouette (the record's table).
pub const COMBINE_ROUTE_SILHOUETTE: u32 = 4;
/// Record flag: the older level's coverage is the older-level depth pass.
pub const COMBINE_ROUTE_DEPTH_PASS: u32 = 8;
/// Frame flag (record 0): [`CombineNewer::motion`] is each pixel's object motion (a LOD pass's
/// or an engine's motion vectors); without it each t-instance is reprojected with its record's
/// matrix.
pub const COMBINE_OBJECT_MOTION: u32 = 16;
/// Frame flag (record 0): [`CombineNewer::level_depth`] holds the older-level depth pass.
pub const COMBINE_LEVEL_DEPTH: u32 = 32;
/// Frame flag (record 0): every t-instance the data describes takes the older-level depth pass
/// (set by [`CombineData::new`] when the descriptor reads the pass and its objects, at least
/// one, all take it, as [`CombineData::depth_pass`]'s do), so a pixel showing no t-instance
/// where the pass drew no level in front reads nothing older: the newer color. A t-instance left
/// out of the data is then not estimated at such pixels.
pub const COMBINE_ONLY_DEPTH_PASS: u32 = 64;

/// The newer buffer's texel at the pixel being combined, as the engine read it (mirror of WGSL
/// `CombineNewer`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CombineNewer {
    /// Color.
    pub color: Vec4,
    /// Id word (`lodkit::lod_buffer`: instance id and display flags).
    pub word: u32,
    /// Clip depth.
    pub depth: f32,
    /// Object motion in texture-space uv (0 where nothing moves by itself or without motion).
    pub motion: Vec2,
    /// The visibility pattern's value at this pixel, anchored to the screen
    /// (`lodkit::visibility::visibility_screen_texel`): where the older level of an anchored
    /// record is displayed.
    pub pattern: f32,
    /// The older-level depth pass at this pixel (its far depth where none is drawn; read only
    /// with [`COMBINE_LEVEL_DEPTH`]).
    pub level_depth: f32,
}

/// One id's record in the data texture (mirror of WGSL `CombineObject`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CombineObject {
    /// This frame's clip space to last frame's for the id's points.
    pub new_to_old: Mat4,
    /// The older level's silhouette table (`lodkit::silhouette::bin_silhouette`).
    pub silhouette: UVec4,
    /// `COMBINE_*` flags.
    pub flags: u32,
    /// The threshold at which the older level is displayed this frame.
    pub older_tau: f32,
}

/// Texel `i` of record `id`; the index wraps as the shader's u32 arithmetic does (data that is not
/// [`CombineData`]'s reads as zeros or other records, never panics).
fn record_texel(data: &[[u32; 4]], id: u32, i: u32) -> UVec4 {
    silhouette_texel(data, id.wrapping_mul(COMBINE_RECORD).wrapping_add(i))
}

/// The record of `id` in the data texture; for an id past the records, the frame's matrix with
/// no flags (a t-instance the combine does not know).
pub fn combine_object(data: &[[u32; 4]], id: u32) -> CombineObject {
    let slots = silhouette_texel(data, 5).z;
    let k = if id < slots { id } else { 0 };
    let texel = |i: u32| record_texel(data, k, i);
    let column = |i: u32| Vec4::from_array(texel(i).to_array().map(f32::from_bits));
    let record = texel(5);
    CombineObject {
        new_to_old: Mat4::from_cols(column(0), column(1), column(2), column(3)),
        silhouette: texel(4),
        flags: if k == id { record.x } else { 0 },
        older_tau: f32::from_bits(record.y),
    }
}

/// The matrix that reprojects a pixel holding `id` (0: the camera's): the camera's where
/// [`CombineNewer::motion`] is the object motion ([`COMBINE_OBJECT_MOTION`]), else the record's.
pub fn combine_new_to_old(data: &[[u32; 4]], id: u32) -> Mat4 {
    let frame = combine_object(data, 0);
    if frame.flags & COMBINE_OBJECT_MOTION != 0 {
        frame.new_to_old
    } else {
        combine_object(data, id).new_to_old
    }
}

/// The far clip depth under the depth convention (what an older-level depth pass is cleared to).
pub fn combine_far_depth(convention: DepthConvention) -> f32 {
    match convention {
        DepthConvention::Standard => 1.0,
        DepthConvention::Reversed => 0.0,
    }
}

/// The older read, estimated from last frame's picture, of a pixel that shows no t-instance the
/// combine knows (`base` and `old`: the pixel's reprojection with `new_to_old`, moved by
/// `motion`): refined at whatever older surface it finds. Where the read holds a t-instance whose
/// coverage is known (silhouette or depth pass), that level does not cover the pixel: not found;
/// where it holds an estimated one, it is taken only where its sample lies on the pixel's ray
/// under that t-instance's own matrix (a group that moved away leaves no trace).
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_read_estimated(
    older: &LodImage,
    data: &[[u32; 4]],
    uv: Vec2,
    depth: f32,
    base: Vec4,
    old: Vec3,
    new_to_old: &Mat4,
    motion: Vec2,
) -> CombineRead {
    let size = size_of(older);
    let first = old.truncate() + motion;
    let first_depth = depth_at(older, combine_texel(first, size));
    let refined = reproject_refine(base, depth, first_depth, new_to_old).truncate() + motion;
    let read = combine_texel(if in_viewport(refined) { refined } else { first }, size);
    let g = id_at(older, read);
    let object = combine_object(data, g);
    if g != 0 && object.flags & COMBINE_KNOWN != 0 {
        if object.flags & (COMBINE_ROUTE_SILHOUETTE | COMBINE_ROUTE_DEPTH_PASS) != 0 {
            return NOT_FOUND;
        }
        let m = object.new_to_old;
        let ray = reproject_refine(reproject_base(uv, &m), depth, depth_at(older, read), &m);
        if combine_ray_offset(ray.truncate(), read, size) >= COMBINE_COVER_REACH {
            return NOT_FOUND;
        }
    }
    found(older, read)
}

/// How far in front of a level's point, as a share of the point's view distance, an older object
/// must lie for [`combine_hidden`] to take it as hiding the level. Where two surfaces touch (a
/// trunk entering the ground), interpolated and reprojected depths put them a fraction of a
/// percent apart either way; a bare comparison then shows the ground through the trunk.
pub const COMBINE_HIDDEN_MARGIN: f32 = 0.01;

/// Whether clip depth `a` lies closer to the camera than `b` by more than
/// [`COMBINE_HIDDEN_MARGIN`] of `b`'s view distance (Rust twin of `combine_clearly_closer`).
/// Under a perspective projection whose far plane lies well past the scene (or at infinity),
/// 1 - depth (reversed Z: depth) is inversely proportional to the view distance, so the margin
/// is taken on that.
///
/// ```
/// # use lodkit::combine::DepthConvention::{Reversed, Standard};
/// # use lodkit::combine_coverage::combine_clearly_closer;
/// // 0.95 leaves 0.05 to the far plane: the margin is 0.0005 of depth.
/// assert!(!combine_clearly_closer(0.9498, 0.95, Standard)); // touching
/// assert!(combine_clearly_closer(0.949, 0.95, Standard));
/// assert!(!combine_clearly_closer(0.0504, 0.05, Reversed)); // 1 % closer needs 0.0505
/// assert!(combine_clearly_closer(0.051, 0.05, Reversed));
/// ```
pub fn combine_clearly_closer(a: f32, b: f32, convention: DepthConvention) -> bool {
    match convention {
        DepthConvention::Standard => a < b - COMBINE_HIDDEN_MARGIN * (1.0 - b),
        DepthConvention::Reversed => a > b * (1.0 + COMBINE_HIDDEN_MARGIN),
    }
}

/// The object other than `owner` (not the background) that the older texel at texture-space
/// `at` holds clearly closer than clip depth `depth` ([`combine_clearly_closer`]; Rust twin of
/// `combine_hider`): the older frame drew it in front of `owner`'s older level there. 0 where
/// there is none (or `at` is outside the view).
pub fn combine_hider(
    older: &LodImage,
    owner: u32,
    at: Vec2,
    depth: f32,
    convention: DepthConvention,
) -> u32 {
    let texel = combine_texel(at, size_of(older));
    let held = id_at(older, texel);
    let hides = in_viewport(at)
        && held != owner
        && held != 0
        && combine_clearly_closer(depth_at(older, texel), depth, convention);
    if hides { held } else { 0 }
}

/// Whether the older texel at texture-space `at` holds an object other than `owner` clearly
/// closer than clip depth `depth` ([`combine_hider`]; Rust twin of `combine_hidden`): there the
/// older frame drew that object in front of `owner`'s older level, so the older level's
/// silhouette covering the pixel does not make it visible.
pub fn combine_hidden(
    older: &LodImage,
    owner: u32,
    at: Vec2,
    depth: f32,
    convention: DepthConvention,
) -> bool {
    combine_hider(older, owner, at, depth, convention) != 0
}

/// Whether `id` is a t-instance whose older level's coverage is its silhouette (its record in
/// `data` is known and routed by the silhouette; Rust twin of `combine_by_silhouette`).
pub fn combine_by_silhouette(data: &[[u32; 4]], id: u32) -> bool {
    let wanted = COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE;
    id != 0 && combine_object(data, id).flags & wanted == wanted
}

/// Whether `id` is a t-instance whose older level's coverage is its silhouette, and that
/// silhouette covers (or passes through) the pixel center `p` (Rust twin of
/// `combine_known_covers`).
pub fn combine_known_covers(data: &[[u32; 4]], id: u32, p: Vec2) -> bool {
    let o = combine_object(data, id);
    let wanted = COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE;
    id != 0 && o.flags & wanted == wanted && silhouette_covers(data, o.silhouette, p) != 0
}

/// Whether `id`'s older level may cover the pixel center `p` under this frame's camera: `id` is
/// a t-instance (its record is known) whose coverage is not its silhouette, or whose silhouette
/// covers (or passes through) `p`. Any other object is drawn this frame at its own level: where
/// a pixel shows a t-instance, it lost the depth test there and is not in front of it now (Rust
/// twin of `combine_may_cover`).
pub fn combine_may_cover(data: &[[u32; 4]], id: u32, p: Vec2) -> bool {
    let o = combine_object(data, id);
    if id == 0 || o.flags & COMBINE_KNOWN == 0 {
        return false;
    }
    o.flags & COMBINE_ROUTE_SILHOUETTE == 0 || silhouette_covers(data, o.silhouette, p) != 0
}

/// How last frame's picture decides a pixel center that lies on `id`'s older silhouette
/// ([`SILHOUETTE_ON`]), from the older texel at texture-space `at` (the center's reprojection):
/// where the picture sampled that very point (`at` in the view, within [`COMBINE_SNAP`] of the
/// texel's center: camera and level still), 1 if the texel holds `id` and 0 if not; elsewhere
/// [`SILHOUETTE_ON`] (undecided: the rasterizer may break the tie either way). Rust twin of
/// `combine_outline`.
pub fn combine_outline(older: &LodImage, id: u32, at: Vec2) -> i32 {
    let size = size_of(older);
    let texel = combine_texel(at, size);
    if !in_viewport(at) || combine_ray_offset(at, texel, size) >= COMBINE_SNAP {
        return SILHOUETTE_ON;
    }
    i32::from(id_at(older, texel) == id)
}

/// For a pixel that shows no t-instance, or behind a t-instance's level drawn now whose older
/// silhouette does not cover it (`depth` that level's): the older read ([`combine_read_known`])
/// of the first t-instance whose older level's silhouette covers the pixel center `p` (pixels),
/// that no other t-instance whose silhouette covers it too hides there ([`combine_hider`],
/// [`combine_known_covers`]), and whose older level the read finds, read with that t-instance's
/// own matrix and no motion (the pixel's own motion, if any, is that of what it shows, not of
/// the level behind it); not found where none does. A
/// center on a silhouette ([`SILHOUETTE_ON`]) is covered only where [`combine_outline`] decides
/// it covered; undecided, the rasterizer may break the tie either way, and the older level
/// taken where it would not draw it is a ghost.
pub fn combine_read_silhouettes(
    older: &LodImage,
    data: &[[u32; 4]],
    uv: Vec2,
    depth: f32,
    p: Vec2,
    convention: DepthConvention,
) -> CombineRead {
    let slots = silhouette_texel(data, 5).z;
    let wanted = COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE;
    for g in 1..slots {
        if record_texel(data, g, 5).x & wanted != wanted {
            continue;
        }
        let mut covers = silhouette_covers(data, record_texel(data, g, 4), p);
        if covers == 0 {
            continue;
        }
        let m = combine_object(data, g).new_to_old;
        if covers == SILHOUETTE_ON {
            covers = combine_outline(older, g, reproject(uv, depth, &m).truncate());
        }
        if covers != 1 {
            continue;
        }
        let point = reproject(uv, depth, &m);
        let front = combine_hider(older, g, point.truncate(), point.z, convention);
        if front != 0 && combine_known_covers(data, front, p) {
            continue;
        }
        let read = combine_read_known(older, data, g, uv, depth, &m, Vec2::ZERO);
        if read.found {
            return read;
        }
    }
    NOT_FOUND
}

/// The older read of the pixel `pixel` showing `newer`, by the coverage route of what it shows
/// (`m`, `base`, `old`: its reprojection, [`combine_new_to_old`]): a t-instance's own older
/// level by its record's route (its silhouette, the depth pass, or estimated; estimated for a
/// t-instance without a record; by its silhouette, where it covers the pixel or passes through
/// its center undecided by [`combine_outline`], the texel in front where [`combine_hider`] finds
/// another object there that [`combine_may_cover`], else the level's own; where the silhouette
/// does not cover the pixel, what lies behind the level: another level whose silhouette covers it
/// ([`combine_read_silhouettes`]), else [`combine_behind_texel`] under the camera's
/// reprojection alone, the frame's matrix and no motion: what lies behind a level does not move
/// with it); for a pixel showing none, a level the depth pass drew there in front of it, else
/// nothing where every t-instance takes the depth pass ([`COMBINE_ONLY_DEPTH_PASS`]), else a
/// level whose silhouette covers it, else the estimate.
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_read(
    older: &LodImage,
    data: &[[u32; 4]],
    newer: &CombineNewer,
    pixel: UVec2,
    base: Vec4,
    old: Vec3,
    m: &Mat4,
    convention: DepthConvention,
) -> CombineRead {
    let size = size_of(older);
    let id = lod_buffer_id(newer.word);
    let uv = combine_uv(pixel, size);
    let p = pixel.as_vec2() + 0.5;
    let depth = newer.depth;
    let motion = newer.motion;
    let object = combine_object(data, id);
    if id != 0 {
        if object.flags & (COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE)
            == COMBINE_KNOWN | COMBINE_ROUTE_SILHOUETTE
        {
            let read_at = old.truncate() + motion;
            let mut own = silhouette_covers(data, object.silhouette, p);
            if own == SILHOUETTE_ON {
                own = combine_outline(older, id, read_at);
            }
            // Covered, or on the outline where last frame's picture does not decide: the level
            // drawn now covers the pixel, so the older level taken there is no ghost.
            if own != 0 {
                let front = combine_hider(older, id, read_at, old.z, convention);
                if front != 0 && combine_may_cover(data, front, p) {
                    return found(older, combine_texel(read_at, size));
                }
                return combine_read_known(older, data, id, uv, depth, m, motion);
            }
            // Behind the level: another t-instance's older level whose silhouette covers the
            // pixel, else what the ray finds.
            let behind = combine_read_silhouettes(older, data, uv, depth, p, convention);
            if behind.found {
                return behind;
            }
            // What lies behind the level moves as the camera alone moves it: the matrix and
            // motion of the pixel are the level's own.
            let camera = combine_object(data, 0).new_to_old;
            let behind = reproject_base(uv, &camera);
            let behind_at = reproject_from_base(behind, depth, &camera).truncate();
            let texel = combine_behind_texel(
                older,
                data,
                id,
                behind_at,
                behind,
                depth,
                &camera,
                Vec2::ZERO,
            );
            return found(older, texel);
        }
        if object.flags & (COMBINE_KNOWN | COMBINE_ROUTE_DEPTH_PASS)
            == COMBINE_KNOWN | COMBINE_ROUTE_DEPTH_PASS
        {
            return combine_read_level_depth(
                older,
                data,
                newer.level_depth,
                id,
                uv,
                depth,
                old,
                motion,
                convention,
            );
        }
        return combine_read_own(older, id, uv, depth, m, motion, COMBINE_COVER_REACH);
    }
    let far = combine_far_depth(convention);
    let frame = combine_object(data, 0);
    if frame.flags & COMBINE_LEVEL_DEPTH != 0 && depth_closer(newer.level_depth, far, convention) {
        return combine_read_level_depth(
            older,
            data,
            newer.level_depth,
            0,
            uv,
            depth,
            old,
            motion,
            convention,
        );
    }
    if frame.flags & COMBINE_ONLY_DEPTH_PASS != 0 {
        return NOT_FOUND;
    }
    let r = combine_read_silhouettes(older, data, uv, depth, p, convention);
    if r.found {
        return r;
    }
    combine_read_estimated(older, data, uv, depth, base, old, m, motion)
}

/// How far (texels, the larger axis) outside the older view a pixel's reprojection may land and
/// still be read at the older buffer's edge ([`combine_edge_uv`]).
pub const COMBINE_EDGE_REACH: f32 = 4.0;

/// Where the combine reads for texture-space `uv` of an older buffer of `size` texels (Rust twin
/// of `combine_edge_uv`, whose z is 1 where this is `Some`): `uv` itself inside the view;
/// outside it, within [`COMBINE_EDGE_REACH`] texels, the nearest edge texel's center; `None`
/// farther out. A camera that turns or moves sideways brings a strip of the picture into view
/// each frame; its older level is read from the edge of last frame's picture instead of being
/// left to the level drawn now on every other frame.
///
/// ```
/// # use glam::{UVec2, Vec2};
/// # use lodkit::combine_coverage::combine_edge_uv;
/// let size = UVec2::new(10, 10);
/// assert_eq!(combine_edge_uv(Vec2::new(0.42, 0.5), size), Some(Vec2::new(0.42, 0.5)));
/// // 2 texels left of the view: the left column's center, on the same row.
/// assert_eq!(combine_edge_uv(Vec2::new(-0.2, 0.5), size), Some(Vec2::new(0.05, 0.5)));
/// assert_eq!(combine_edge_uv(Vec2::new(-0.5, 0.5), size), None); // 5 texels out
/// ```
pub fn combine_edge_uv(uv: Vec2, size: UVec2) -> Option<Vec2> {
    if in_viewport(uv) {
        return Some(uv);
    }
    let half = 0.5 / size.as_vec2();
    let inside = uv.clamp(half, Vec2::ONE - half);
    let beyond = (uv - inside).abs() * size.as_vec2();
    (beyond.max_element() <= COMBINE_EDGE_REACH).then_some(inside)
}

/// The whole per-pixel combine of frame-sequential LOD with the older level's coverage known
/// (the Rust twin of `combine_pixel`): `newer` as read at `pixel`, the older buffer `older`
/// (last frame's picture), the frame's data texture `data` ([`CombineData`]:
/// the camera's matrix, per t-instance its matrix, display threshold and coverage route, the
/// silhouettes). Reprojected farther than [`COMBINE_EDGE_REACH`] texels outside the older view
/// ([`combine_edge_uv`]), or where no older level is found, the newer color;
/// else [`combine_texels`] with the older word displayed at this frame's threshold
/// ([`combine_displayed_word`]). `None` when `pixel` lies outside `older` or `older` lacks texels.
pub fn combine_pixel(
    newer: &CombineNewer,
    pixel: UVec2,
    older: &LodImage,
    data: &[[u32; 4]],
    convention: DepthConvention,
) -> Option<Vec4> {
    let n = older.width as usize * older.height as usize;
    let complete = older.colors.len() == n && older.ids.len() == n && older.depths.len() == n;
    if n == 0 || !complete || pixel.x >= older.width || pixel.y >= older.height {
        return None;
    }
    let size = size_of(older);
    let id = lod_buffer_id(newer.word);
    let m = combine_new_to_old(data, id);
    let base = reproject_base(combine_uv(pixel, size), &m);
    let reprojected = reproject_from_base(base, newer.depth, &m);
    let Some(edge) = combine_edge_uv(reprojected.truncate(), size) else {
        return Some(newer.color);
    };
    let old = edge.extend(reprojected.z);
    let read = combine_read(older, data, newer, pixel, base, old, &m, convention);
    if !read.found {
        return Some(newer.color);
    }
    let word = older.word(index_of(older, read.texel));
    let o = combine_object(data, lod_buffer_id(word));
    let anchored = o.flags & (COMBINE_KNOWN | COMBINE_ANCHORED) == COMBINE_KNOWN | COMBINE_ANCHORED;
    let shown = combine_displayed_word(word, anchored, o.older_tau, newer.pattern);
    Some(combine_texels(
        newer.color,
        newer.word,
        old,
        read.color,
        shown,
        depth_at(older, read.texel),
        convention,
    ))
}
