//! The combination rule of two LOD buffers (Scherzer & Wimmer 2008, sec. 3.4): Rust twins of
//! `lodkit::combine`.

use glam::Vec4;

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
}

/// The combine pass on the CPU: every pixel of `newer` reprojected into `older` through
/// `new_to_old` and combined with [`combine_shown`] (the newer texel shown if flagged for now, the
/// older if flagged for next), as `passes/combine.wgsl` does. Both images
/// must have the same, non-zero size and complete texel arrays; otherwise the result is empty.
pub fn combine_images(
    newer: &LodImage,
    older: &LodImage,
    new_to_old: &glam::Mat4,
    convention: DepthConvention,
) -> Vec<CombinedPixel> {
    use glam::Vec2;
    let n = (newer.width * newer.height) as usize;
    let complete = |i: &LodImage| i.colors.len() == n && i.ids.len() == n && i.depths.len() == n;
    let same_size = (newer.width, newer.height) == (older.width, older.height);
    if n == 0 || !same_size || !complete(newer) || !complete(older) {
        return Vec::new();
    }
    let size = Vec2::new(newer.width as f32, newer.height as f32);
    (0..newer.colors.len())
        .map(|p| {
            let mut n = newer.sample(p);
            let (x, y) = (
                (p as u32 % newer.width) as f32,
                (p as u32 / newer.width) as f32,
            );
            let uv = (Vec2::new(x, y) + 0.5) / size;
            let base = crate::reproject::reproject_base(uv, new_to_old);
            let old = crate::reproject::reproject_from_base(base, n.depth, new_to_old);
            if !crate::reproject::in_viewport(old.truncate()) {
                return CombinedPixel {
                    color: n.color,
                    source: PixelSource::OutsideOlder,
                    on_texel_edge: false,
                };
            }
            let last = glam::UVec2::new(newer.width - 1, newer.height - 1);
            let texel = |uv: Vec2| (uv * size).as_uvec2().min(last);
            let near_edge = |uv: Vec2| {
                let f = uv * size;
                let frac = f - f.floor();
                frac.min_element() < 1e-3 || frac.max_element() > 1.0 - 1e-3
            };
            let first = texel(old.truncate());
            let first_depth = older.depths[(first.y * newer.width + first.x) as usize];
            let refined =
                crate::reproject::reproject_refine(base, n.depth, first_depth, new_to_old);
            let (op, on_texel_edge) = if crate::reproject::in_viewport(refined.truncate()) {
                (
                    texel(refined.truncate()),
                    near_edge(old.truncate()) || near_edge(refined.truncate()),
                )
            } else {
                (first, near_edge(old.truncate()))
            };
            let o = older.sample((op.y * newer.width + op.x) as usize);
            n.depth = old.z;
            use crate::lod_buffer::{LOD_BUFFER_SHOWN_NEXT, LOD_BUFFER_SHOWN_NOW};
            let (n_shown, o_shown) = (
                newer.shown(p, LOD_BUFFER_SHOWN_NOW),
                older.shown((op.y * newer.width + op.x) as usize, LOD_BUFFER_SHOWN_NEXT),
            );
            let color = combine_shown(n, n_shown, o, o_shown, convention);
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
            } else if depth_closer(o.depth, n.depth, convention) {
                PixelSource::Older
            } else {
                PixelSource::Newer
            };
            CombinedPixel {
                color,
                source,
                on_texel_edge,
            }
        })
        .collect()
}
