//! The outline of an alpha-tested card's coverage: where `lodkit::alpha_mask`'s test keeps a
//! fragment of a card (a billboard impostor, a foliage card), as segments whose winding number
//! is not 0 exactly there, like a closed mesh's silhouette.

use glam::{Mat4, Vec2, Vec4};
use thiserror::Error;

use super::{Segment, SilhouetteError, to_pixels};
use crate::alpha_mask::AlphaMask;

/// Why a mask has no outline.
#[derive(Clone, Copy, Debug, Error, PartialEq)]
pub enum MaskOutlineError {
    /// The rect is zero (`rect.x == 0`): no alpha test, so the card's own triangles cover.
    #[error("the alpha rect {rect:?} maps no mask (rect.x is 0): the card has no alpha test")]
    NoMask {
        /// The rect given.
        rect: [f32; 4],
    },
    /// The mask's texels do not fill its `size * size` square.
    #[error("the mask is {size}x{size} but holds {texels} texels")]
    TexelCount {
        /// Its width and height.
        size: u32,
        /// How many texels it holds.
        texels: usize,
    },
}

/// The coverage of an alpha-tested card: a mesh in its z = 0 plane that covers the whole
/// rectangle its alpha rect maps onto the mask (as `Mesh::card` and `alpha_mask_rect` of the
/// same corners do), drawn without face culling, whose fragment at object-space `p` is kept
/// where [`alpha_mask_keep`](crate::alpha_mask::alpha_mask_keep) says. That region of the plane
/// is the union of the mask's covered texels (>= 0.5); its boundary, each edge oriented with
/// the covered texel on the same side and collinear runs merged, projected, has a winding number
/// ([`winding`](super::winding)) other than 0 exactly where the card's alpha test keeps the
/// fragment at a pixel center. Built once per mask and rect; [`silhouette`](Self::silhouette)
/// then projects its edges.
///
/// ```
/// # use lodkit::alpha_mask::{AlphaMask, alpha_mask_rect};
/// # use lodkit::silhouette::{MaskOutline, winding};
/// # use glam::{Mat4, Vec2};
/// // Top-left texel of a 2x2 mask, on the card from (-1, -1) to (1, 1).
/// let mask = AlphaMask { size: 2, texels: vec![1.0, 0.0, 0.0, 0.0] };
/// let outline = MaskOutline::new(&mask, alpha_mask_rect(Vec2::splat(-1.0), Vec2::ONE)).unwrap();
/// // Seen head-on (clip = object xy) on a 4x4 target: the top-left 2x2 pixels.
/// let segments = outline.silhouette(Mat4::IDENTITY, (4, 4)).unwrap();
/// assert_ne!(winding(&segments, Vec2::new(0.5, 0.5)), 0);
/// assert_ne!(winding(&segments, Vec2::new(1.5, 1.5)), 0);
/// assert_eq!(winding(&segments, Vec2::new(2.5, 0.5)), 0);
/// assert_eq!(winding(&segments, Vec2::new(0.5, 2.5)), 0);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaskOutline {
    /// Object-space (x, y) of each edge's ends, in the card's z = 0 plane.
    edges: Vec<[Vec2; 2]>,
}

impl MaskOutline {
    /// The outline of `mask`'s covered texels, mapped onto the card's plane through `rect`
    /// ([`alpha_mask_rect`](crate::alpha_mask::alpha_mask_rect)).
    pub fn new(mask: &AlphaMask, rect: Vec4) -> Result<Self, MaskOutlineError> {
        if rect.x == 0.0 || rect.y == 0.0 {
            return Err(MaskOutlineError::NoMask {
                rect: rect.to_array(),
            });
        }
        let n = mask.size as usize;
        if mask.texels.len() != n * n {
            return Err(MaskOutlineError::TexelCount {
                size: mask.size,
                texels: mask.texels.len(),
            });
        }
        let kept = |x: isize, y: isize| {
            (0..n as isize).contains(&x)
                && (0..n as isize).contains(&y)
                && mask.texels[y as usize * n + x as usize] >= 0.5
        };
        // A texel-grid point (texels, v down) on the card: uv = p.xy * rect.xy + rect.zw.
        let point = |i: usize, j: usize| {
            let uv = Vec2::new(i as f32, j as f32) / n as f32;
            (uv - Vec2::new(rect.z, rect.w)) / Vec2::new(rect.x, rect.y)
        };
        let mut edges = Vec::new();
        // Along each grid line, a run of texel edges with the covered texel on the same side
        // (`side`: +1 one way, -1 the other, 0 none or both) is one edge, oriented by that side.
        let mut runs = |side: &dyn Fn(usize, usize) -> i8, end: &dyn Fn(usize, usize) -> Vec2| {
            for line in 0..=n {
                let mut k = 0;
                while k < n {
                    let s = side(line, k);
                    let start = k;
                    while k < n && side(line, k) == s {
                        k += 1;
                    }
                    let (a, b) = (end(line, start), end(line, k));
                    match s {
                        1 => edges.push([a, b]),
                        -1 => edges.push([b, a]),
                        _ => {}
                    }
                }
            }
        };
        let side =
            |after: bool, before: bool| i8::from(after && !before) - i8::from(before && !after);
        // Row lines j (v = j / n): +1 where the texel below, (x, j), is covered and the one
        // above not (the edge runs +x); every covered texel's boundary then runs the same way
        // round it (+x along its top, +v down its right side, -x, -v).
        runs(
            &|j, x| {
                side(
                    kept(x as isize, j as isize),
                    kept(x as isize, j as isize - 1),
                )
            },
            &|j, x| point(x, j),
        );
        // Column lines i: +1 where the texel left of it, (i - 1, y), is covered and the one
        // right of it not (the edge runs +v).
        runs(
            &|i, y| {
                side(
                    kept(i as isize - 1, y as isize),
                    kept(i as isize, y as isize),
                )
            },
            &|i, y| point(i, y),
        );
        Ok(Self { edges })
    }

    /// How many edges the outline has (collinear runs merged).
    pub fn edges(&self) -> usize {
        self.edges.len()
    }

    /// The outline under `clip_from_local` (a camera's clip_from_world times the card's
    /// world_from_local; NDC x and y in [-1, 1], y up) on a target of `size` pixels, as
    /// [`Surface::silhouette`](super::Surface::silhouette) gives a mesh's (seen edge-on, its
    /// segments enclose nothing, as the rasterizer draws nothing). An edge end at or behind the
    /// camera plane: [`SilhouetteError::BehindCamera`].
    pub fn silhouette(
        &self,
        clip_from_local: Mat4,
        size: (u32, u32),
    ) -> Result<Vec<Segment>, SilhouetteError> {
        let project = |p: Vec2| to_pixels(clip_from_local, p.extend(0.0), size);
        self.edges
            .iter()
            .map(|[a, b]| match (project(*a), project(*b)) {
                (Some(a), Some(b)) => Ok([a.x, a.y, b.x, b.y]),
                _ => Err(SilhouetteError::BehindCamera),
            })
            .collect()
    }
}

#[cfg(test)]
#[path = "mask_tests.rs"]
mod tests;
