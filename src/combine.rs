//! The combination rule of two LOD buffers (Scherzer & Wimmer 2008, sec. 3.4): Rust twins of
//! `lodkit::combine`. [`combine_at`] is the paper's rule read where the camera's reprojection
//! puts each pixel; the pieces from [`combine_read_own`] on read the older level where it is
//! known to cover the pixel (put together in
//! [`combine_coverage::combine_pixel`](crate::combine_coverage::combine_pixel)).

use glam::{Mat4, UVec2, UVec4, Vec2, Vec3, Vec4};

pub(crate) mod older;
mod rects;
pub use older::{
    COMBINE_BLOCK_REACH, COMBINE_COVER_REACH, COMBINE_SNAP, CombineRead, combine_cover_texel,
    combine_displayed_word, combine_other_texel, combine_own_color, combine_ray_offset,
    combine_read_own, combine_region_position, combine_snap,
};
pub use rects::{ScreenRect, displaced_bounds, merge_rects, screen_rect};

/// One texel of a LOD buffer (mirror of WGSL `LodSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSample {
    /// Color.
    pub color: Vec4,
    /// Instance id, 0 for n-instances.
    pub id: u32,
    /// Clip depth (for the newer sample: reprojected into the older buffer's space).
    pub depth: f32,
}

/// Depth convention (`LODKIT_REVERSE_Z` in the shaders).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthConvention {
    /// 0 near, 1 far.
    #[default]
    Standard,
    /// 1 near, 0 far.
    Reversed,
}

/// Whether clip depth `a` is strictly closer than `b`.
pub fn depth_closer(a: f32, b: f32, convention: DepthConvention) -> bool {
    match convention {
        DepthConvention::Standard => a < b,
        DepthConvention::Reversed => a > b,
    }
}

/// The combined color: both ids 0 -> newer; ids differ -> closer (tie: newer); same id -> average.
///
/// ```
/// # use lodkit::combine::*;
/// # use glam::Vec4;
/// let s = |c: f32, id, depth| LodSample { color: Vec4::splat(c), id, depth };
/// assert_eq!(combine_samples(s(1.0, 0, 0.5), s(0.0, 0, 0.1), DepthConvention::Standard), Vec4::splat(1.0));
/// assert_eq!(combine_samples(s(1.0, 0, 0.5), s(0.0, 7, 0.1), DepthConvention::Standard), Vec4::splat(0.0));
/// assert_eq!(combine_samples(s(1.0, 7, 0.5), s(0.0, 7, 0.1), DepthConvention::Standard), Vec4::splat(0.5));
/// ```
pub fn combine_samples(newer: LodSample, older: LodSample, convention: DepthConvention) -> Vec4 {
    if newer.id == 0 && older.id == 0 {
        return newer.color;
    }
    if newer.id == older.id {
        return 0.5 * (newer.color + older.color);
    }
    if depth_closer(older.depth, newer.depth, convention) {
        older.color
    } else {
        newer.color
    }
}

/// [`combine_samples`] with display-time visibility: when exactly one sample is shown in the
/// frame being displayed, its color; when both or neither are, [`combine_samples`] (neither: the
/// fragments are shown rather than a hole).
///
/// ```
/// # use lodkit::combine::*;
/// # use glam::Vec4;
/// let s = |c: f32, id, depth| LodSample { color: Vec4::splat(c), id, depth };
/// let std = DepthConvention::Standard;
/// assert_eq!(combine_shown(s(1.0, 7, 0.1), false, s(0.0, 0, 0.9), true, std), Vec4::ZERO);
/// assert_eq!(combine_shown(s(1.0, 7, 0.1), false, s(0.0, 7, 0.9), false, std), Vec4::splat(0.5));
/// ```
pub fn combine_shown(
    newer: LodSample,
    newer_shown: bool,
    older: LodSample,
    older_shown: bool,
    convention: DepthConvention,
) -> Vec4 {
    match (newer_shown, older_shown) {
        (true, false) => newer.color,
        (false, true) => older.color,
        _ => combine_samples(newer, older, convention),
    }
}

/// A LOD buffer read back to the CPU.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LodImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Colors, row-major, top row first.
    pub colors: Vec<Vec4>,
    /// Instance ids.
    pub ids: Vec<u32>,
    /// Clip depths.
    pub depths: Vec<f32>,
    /// Display-time flags (`LOD_BUFFER_SHOWN_NOW`, `LOD_BUFFER_SHOWN_NEXT`); empty: shown in
    /// both frames.
    pub flags: Vec<u32>,
    /// Object motion of each texel in texture-space uv
    /// ([`lod_buffer_motion`](crate::lod_buffer::lod_buffer_motion)), read from the newer
    /// buffer; empty: nothing moved by itself.
    pub motion: Vec<Vec2>,
}

impl LodImage {
    /// The texel at pixel index `p`.
    pub fn sample(&self, p: usize) -> LodSample {
        LodSample {
            color: self.colors[p],
            id: self.ids[p],
            depth: self.depths[p],
        }
    }

    /// The object motion at pixel index `p` (zero without motion).
    pub fn motion_at(&self, p: usize) -> Vec2 {
        self.motion.get(p).copied().unwrap_or(Vec2::ZERO)
    }

    /// The id word at pixel index `p` as the shader reads it (id with the flags).
    pub fn word(&self, p: usize) -> u32 {
        let flags = self.flags.get(p).copied().unwrap_or(3);
        crate::lod_buffer::lod_buffer_word(self.ids[p], flags)
    }

    /// Whether the texel at pixel index `p` is shown in the frame `flag` names (always for
    /// n-instances and without flags).
    pub fn shown(&self, p: usize, flag: u32) -> bool {
        self.ids[p] == 0 || self.flags.get(p).is_none_or(|f| f & flag != 0)
    }
}

/// Where a combined pixel came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelSource {
    /// The newer buffer (both n-instances, or the newer fragment was closer).
    Newer,
    /// The older buffer (its fragment was closer).
    Older,
    /// The average of both (two LODs of one t-instance).
    Average,
    /// The newer buffer, because the pixel reprojects outside the older one.
    OutsideOlder,
}

/// One pixel of the CPU reference of the combine pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CombinedPixel {
    /// The combined color.
    pub color: Vec4,
    /// Which rule produced it.
    pub source: PixelSource,
    /// Whether the reprojected position lies within 1e-3 texel of a texel edge, where a GPU may
    /// round to the neighbouring texel.
    pub on_texel_edge: bool,
    /// Whether the older texel came from [`combine_search_texel`]: the moved read and its side
    /// texels held another object than the newer pixel's t-instance, the pixel moved, and the
    /// search found the t-instance.
    pub searched: bool,
}

/// The texel of a `size` texture at texture-space `uv` (clamped to the texture).
pub fn combine_texel(uv: Vec2, size: UVec2) -> UVec2 {
    let inside = uv.clamp(Vec2::ZERO, Vec2::ONE);
    (inside * size.as_vec2())
        .as_uvec2()
        .min(size.saturating_sub(UVec2::ONE))
}

/// Texture-space center of pixel `pixel` of a `size` target.
pub fn combine_uv(pixel: UVec2, size: UVec2) -> Vec2 {
    (pixel.as_vec2() + 0.5) / size.as_vec2()
}

/// Where in the older buffer (texture-space uv) the combine reads for the newer pixel `pixel`
/// with clip depth `newer_depth`: where the point of the pixel's ray at the older depth
/// `first_depth` (found at the first estimate) reprojects, or the first estimate where that
/// leaves the view; both moved by the object motion `motion` (texture-space uv).
pub fn combine_older_uv(
    pixel: UVec2,
    size: UVec2,
    newer_depth: f32,
    first_depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
) -> Vec2 {
    use crate::reproject::{in_viewport, reproject_base, reproject_from_base, reproject_refine};
    let base = reproject_base(combine_uv(pixel, size), new_to_old);
    let first = reproject_from_base(base, newer_depth, new_to_old).truncate() + motion;
    let refined = reproject_refine(base, newer_depth, first_depth, new_to_old).truncate() + motion;
    if in_viewport(refined) { refined } else { first }
}

/// The older buffer's texel at [`combine_older_uv`].
pub fn combine_older_texel(
    pixel: UVec2,
    size: UVec2,
    newer_depth: f32,
    first_depth: f32,
    new_to_old: &Mat4,
    motion: Vec2,
) -> UVec2 {
    let uv = combine_older_uv(pixel, size, newer_depth, first_depth, new_to_old, motion);
    combine_texel(uv, size)
}

/// The texel next to the one holding texture-space `uv` along `axis` (0 x, 1 y), on the side
/// `uv` lies off that texel's center; the texel itself within 1/1000 texel of the center on that
/// axis or where the neighbour would leave the texture.
///
/// ```
/// # use lodkit::combine::combine_side_texel;
/// # use glam::{UVec2, Vec2};
/// let size = UVec2::new(4, 4);
/// // uv (0.3, 0.6) is texel (1, 2), left of its center on x and right of it on y.
/// assert_eq!(combine_side_texel(Vec2::new(0.3, 0.6), size, 0), UVec2::new(0, 2));
/// assert_eq!(combine_side_texel(Vec2::new(0.3, 0.6), size, 1), UVec2::new(1, 1));
/// assert_eq!(combine_side_texel(Vec2::new(0.375, 0.6), size, 0), UVec2::new(1, 2));
/// ```
pub fn combine_side_texel(uv: Vec2, size: UVec2, axis: usize) -> UVec2 {
    let texel = combine_texel(uv, size);
    let offset = uv[axis] * size[axis] as f32 - (texel[axis] as f32 + 0.5);
    let mut side = texel;
    if offset > 1e-3 && texel[axis] + 1 < size[axis] {
        side[axis] = texel[axis] + 1;
    } else if offset < -1e-3 && texel[axis] > 0 {
        side[axis] = texel[axis] - 1;
    }
    side
}

/// The older texel to read for a newer sample of instance `id`: `nearest` (the texel holding
/// the read position) unless `id` is a t-instance's and `nearest` holds another id; then the
/// first of its side texels `x`, `y` ([`combine_side_texel`]) and the diagonal `(x.x, y.y)` that
/// holds `id`, if any. `ids` are the instance ids at nearest, x, y and the diagonal.
///
/// ```
/// # use lodkit::combine::combine_match_texel;
/// # use glam::{UVec2, UVec4};
/// let (n, x, y) = (UVec2::new(1, 1), UVec2::new(2, 1), UVec2::new(1, 0));
/// assert_eq!(combine_match_texel(7, UVec4::new(0, 0, 0, 7), n, x, y), UVec2::new(2, 0));
/// assert_eq!(combine_match_texel(7, UVec4::new(0, 0, 7, 7), n, x, y), y);
/// assert_eq!(combine_match_texel(7, UVec4::new(3, 0, 0, 0), n, x, y), n);
/// assert_eq!(combine_match_texel(0, UVec4::new(3, 0, 0, 0), n, x, y), n);
/// ```
pub fn combine_match_texel(id: u32, ids: UVec4, nearest: UVec2, x: UVec2, y: UVec2) -> UVec2 {
    if id == 0 || ids.x == id {
        nearest
    } else if ids.y == id {
        x
    } else if ids.z == id {
        y
    } else if ids.w == id {
        UVec2::new(x.x, y.y)
    } else {
        nearest
    }
}

/// The `k`-th (0..8) texel of the 3x3 block around `center`: the center, then left, right, up,
/// down, then the corners (top left, top right, bottom left, bottom right); clamped to a `size`
/// texture.
///
/// ```
/// # use lodkit::combine::combine_ring_texel;
/// # use glam::UVec2;
/// let (c, size) = (UVec2::new(3, 3), UVec2::new(8, 8));
/// let ring: Vec<_> = (0..9).map(|k| combine_ring_texel(c, size, k)).collect();
/// assert_eq!(ring[0], c);
/// assert_eq!((ring[1], ring[4]), (UVec2::new(2, 3), UVec2::new(3, 4)));
/// assert_eq!((ring[5], ring[8]), (UVec2::new(2, 2), UVec2::new(4, 4)));
/// assert_eq!(combine_ring_texel(UVec2::ZERO, size, 5), UVec2::ZERO);
/// let far = UVec2::splat(u32::MAX); // clamped, no overflow
/// assert_eq!(combine_ring_texel(far, far, 2), UVec2::splat(u32::MAX - 1));
/// ```
pub fn combine_ring_texel(center: UVec2, size: UVec2, k: u32) -> UVec2 {
    let offset = if k >= 5 {
        glam::IVec2::new(((k - 5) % 2) as i32 * 2 - 1, ((k - 5) / 2) as i32 * 2 - 1)
    } else if k >= 1 {
        let sign = ((k - 1) % 2) as i32 * 2 - 1;
        if k <= 2 {
            glam::IVec2::new(sign, 0)
        } else {
            glam::IVec2::new(0, sign)
        }
    } else {
        glam::IVec2::ZERO
    };
    // In i64: no overflow whatever the center.
    let max = size.max(UVec2::ONE).as_i64vec2() - glam::I64Vec2::ONE;
    (center.as_i64vec2() + offset.as_i64vec2())
        .clamp(glam::I64Vec2::ZERO, max)
        .as_uvec2()
}

/// The first texel of the 3x3 block around `center` ([`combine_ring_texel`] order) where
/// `older` holds instance `id`; `fallback` if none does (the Rust twin of
/// `combine_search_texel`, which reads the older id texture). Where the LODs of an animated
/// t-instance move differently, the combine searches the older LOD there, around where the
/// camera alone puts the pixel.
pub fn combine_search_texel(older: &LodImage, id: u32, center: UVec2, fallback: UVec2) -> UVec2 {
    let size = UVec2::new(older.width, older.height);
    (0..9)
        .map(|k| combine_ring_texel(center, size, k))
        .find(|t| {
            let i = u64::from(t.y) * u64::from(older.width) + u64::from(t.x);
            usize::try_from(i).is_ok_and(|i| older.ids.get(i) == Some(&id))
        })
        .unwrap_or(fallback)
}

/// The object motion of the surface at texture-space `uv` with clip depth `depth` from an
/// engine's motion vector (uv now minus uv in the previous frame, camera motion included): where
/// the surface was minus where the camera's reprojection puts it.
///
/// ```
/// # use lodkit::combine::combine_object_motion;
/// # use glam::{Mat4, Vec2};
/// // A still camera: the whole motion vector is the object's, pointing back in time.
/// let m = combine_object_motion(Vec2::splat(0.5), 0.3, &Mat4::IDENTITY, Vec2::new(0.25, 0.0));
/// assert_eq!(m, Vec2::new(-0.25, 0.0));
/// ```
pub fn combine_object_motion(uv: Vec2, depth: f32, new_to_old: &Mat4, motion_vector: Vec2) -> Vec2 {
    uv - motion_vector - crate::reproject::reproject(uv, depth, new_to_old).truncate()
}

/// The combined color from the fetched texels: the newer color and id word, `old` = the newer
/// pixel reprojected with its depth, the older color, id word and depth at
/// [`combine_older_texel`]. Outside the older view the newer color, else [`combine_shown`].
pub fn combine_texels(
    newer_color: Vec4,
    newer_word: u32,
    old: Vec3,
    older_color: Vec4,
    older_word: u32,
    older_depth: f32,
    convention: DepthConvention,
) -> Vec4 {
    use crate::lod_buffer::*;
    if !crate::reproject::in_viewport(old.truncate()) {
        return newer_color;
    }
    let newer = LodSample {
        color: newer_color,
        id: lod_buffer_id(newer_word),
        depth: old.z,
    };
    let older = LodSample {
        color: older_color,
        id: lod_buffer_id(older_word),
        depth: older_depth,
    };
    let newer_shown = lod_buffer_shown(newer_word, LOD_BUFFER_SHOWN_NOW);
    let older_shown = lod_buffer_shown(older_word, LOD_BUFFER_SHOWN_NEXT);
    combine_shown(newer, newer_shown, older, older_shown, convention)
}

/// The whole per-pixel combine at `pixel` (the Rust twin of `combine_at`, with the buffers read
/// back as [`LodImage`]s; the newer image's motion is not used). `None` when the images differ
/// in size or lack texels, or `pixel` lies outside them.
///
/// ```
/// # use lodkit::combine::*;
/// # use glam::{Mat4, UVec2, Vec4};
/// let image = |c: f32| LodImage { width: 1, height: 1, colors: vec![Vec4::splat(c)], ids: vec![0],
///     depths: vec![0.5], ..Default::default() };
/// let m = Mat4::IDENTITY; // the same camera: the pixel maps to itself
/// let std = DepthConvention::Standard;
/// assert_eq!(combine_at(&image(1.0), &image(0.0), UVec2::ZERO, &m, std), Some(Vec4::ONE));
/// assert_eq!(combine_at(&image(1.0), &image(0.0), UVec2::new(1, 0), &m, std), None);
/// ```
pub fn combine_at(
    newer: &LodImage,
    older: &LodImage,
    pixel: UVec2,
    new_to_old: &Mat4,
    convention: DepthConvention,
) -> Option<Vec4> {
    combine_at_moved(newer, older, pixel, new_to_old, Vec2::ZERO, convention)
}

/// [`combine_at`] for a pixel whose surface moved by itself: the older buffer is read `motion`
/// (texture-space uv) away from where the camera's reprojection puts it, and where that read and
/// its side texels miss the newer pixel's t-instance, [`combine_search_texel`] around where the
/// camera alone puts it (the Rust twin of `combine_at_moved`).
pub fn combine_at_moved(
    newer: &LodImage,
    older: &LodImage,
    pixel: UVec2,
    new_to_old: &Mat4,
    motion: Vec2,
    convention: DepthConvention,
) -> Option<Vec4> {
    let inside = pixel.x < newer.width && pixel.y < newer.height;
    (inside && images_fit(newer, older))
        .then(|| combine_rule_pixel(newer, older, pixel, new_to_old, motion, convention).color)
}

/// Whether two LOD images have the same, non-zero size and complete texel arrays.
fn images_fit(newer: &LodImage, older: &LodImage) -> bool {
    let n = newer.width as usize * newer.height as usize;
    let complete = |i: &LodImage| {
        i.colors.len() == n
            && i.ids.len() == n
            && i.depths.len() == n
            && (i.flags.is_empty() || i.flags.len() == n)
            && (i.motion.is_empty() || i.motion.len() == n)
    };
    let same_size = (newer.width, newer.height) == (older.width, older.height);
    n > 0 && same_size && complete(newer) && complete(older)
}

/// [`combine_at`] with the rule it applied and whether a GPU may read another texel.
fn combine_rule_pixel(
    newer: &LodImage,
    older: &LodImage,
    pixel: UVec2,
    new_to_old: &Mat4,
    motion: Vec2,
    convention: DepthConvention,
) -> CombinedPixel {
    use crate::lod_buffer::{LOD_BUFFER_SHOWN_NEXT, LOD_BUFFER_SHOWN_NOW};
    let size = UVec2::new(newer.width, newer.height);
    let index = |t: UVec2| (t.y * newer.width + t.x) as usize;
    let p = index(pixel);
    let depth = newer.depths[p];
    let old = crate::reproject::reproject(combine_uv(pixel, size), depth, new_to_old);
    if !crate::reproject::in_viewport(old.truncate()) {
        return CombinedPixel {
            color: newer.colors[p],
            source: PixelSource::OutsideOlder,
            on_texel_edge: false,
            searched: false,
        };
    }
    let first = combine_texel(old.truncate() + motion, size);
    let first_depth = older.depths[index(first)];
    let at = combine_older_uv(pixel, size, depth, first_depth, new_to_old, motion);
    let nearest = combine_texel(at, size);
    let (x, y) = (
        combine_side_texel(at, size, 0),
        combine_side_texel(at, size, 1),
    );
    let id_at = |t: UVec2| older.ids[index(t)];
    let ids = UVec4::new(
        id_at(nearest),
        id_at(x),
        id_at(y),
        id_at(UVec2::new(x.x, y.y)),
    );
    let id = newer.ids[p];
    let mut texel = combine_match_texel(id, ids, nearest, x, y);
    let search = id != 0 && id_at(texel) != id && motion != Vec2::ZERO;
    let matched = texel;
    if search {
        texel = combine_search_texel(older, id, combine_texel(old.truncate(), size), texel);
    }
    // The texel the search found holds the id, the one it started from does not.
    let searched = texel != matched;
    let o = index(texel);
    let color = combine_texels(
        newer.colors[p],
        newer.word(p),
        old,
        older.colors[o],
        older.word(o),
        older.depths[o],
        convention,
    );
    // A reprojected position within 1e-3 texel of a texel edge may round the other way on a GPU.
    let near_edge = |uv: Vec2| {
        let f = uv * size.as_vec2();
        let frac = f - f.floor();
        frac.min_element() < 1e-3 || frac.max_element() > 1.0 - 1e-3
    };
    let base = crate::reproject::reproject_base(combine_uv(pixel, size), new_to_old);
    let refined = crate::reproject::reproject_refine(base, depth, first_depth, new_to_old);
    // Off the center by about 1/1000 texel, a GPU may pick another side texel.
    let near_center = |uv: Vec2| {
        let f = uv * size.as_vec2();
        let off = (f - f.floor() - 0.5).abs();
        (off - Vec2::splat(1e-3)).abs().min_element() < 1e-4
    };
    let on_texel_edge = near_edge(old.truncate() + motion)
        || near_edge(refined.truncate() + motion)
        || near_center(at)
        || (search && near_edge(old.truncate()));
    let (n, o) = (newer.sample(p), older.sample(o));
    let (n_shown, o_shown) = (
        newer.shown(p, LOD_BUFFER_SHOWN_NOW),
        older.shown(index(texel), LOD_BUFFER_SHOWN_NEXT),
    );
    let source = if n_shown != o_shown {
        if n_shown {
            PixelSource::Newer
        } else {
            PixelSource::Older
        }
    } else if n.id == 0 && o.id == 0 {
        PixelSource::Newer
    } else if n.id == o.id {
        PixelSource::Average
    } else if depth_closer(o.depth, old.z, convention) {
        PixelSource::Older
    } else {
        PixelSource::Newer
    };
    CombinedPixel {
        color,
        source,
        on_texel_edge,
        searched,
    }
}

/// The combine pass on the CPU: [`combine_at_moved`] at every pixel with the newer image's
/// motion there, and the rule applied. Both images must have the same, non-zero size and
/// complete texel arrays; otherwise the result is empty.
pub fn combine_images(
    newer: &LodImage,
    older: &LodImage,
    new_to_old: &Mat4,
    convention: DepthConvention,
) -> Vec<CombinedPixel> {
    if !images_fit(newer, older) {
        return Vec::new();
    }
    let n = newer.width * newer.height;
    (0..n)
        .map(|p| {
            let pixel = UVec2::new(p % newer.width, p / newer.width);
            let motion = newer.motion_at(p as usize);
            combine_rule_pixel(newer, older, pixel, new_to_old, motion, convention)
        })
        .collect()
}
