//! Octahedral impostors, the last level of a LOD chain: Rust twins of `lodkit::impostor` (the
//! octahedral and hemi-octahedral maps, the frames around a view and their weights, the ray and
//! frame geometry), the atlas layout a bake writes and a draw reads, the CPU steps of a bake
//! (padding frames, mipmaps) and the switch distance with a pixel bound.
//!
//! Space: the object's bounding sphere normalized to the unit sphere, y up (`q = (p - centre) /
//! radius`). Frame `(i, j)` of an `n x n` grid sits at column `i`, row `j` of the atlas and saw
//! the object orthographically from [`impostor_frame_dir`]`((i, j), n, hemi)` over the square
//! `[-1, 1]²` of its plane; its uv is `(dot(q, right), -dot(q, up)) * 0.5 + 0.5` and its stored
//! depth `dot(q, dir) * 0.5 + 0.5`. docs/impostors.md has the whole picture.

mod atlas;
mod bound;
mod gltf;
mod sample;

/// The key of a glTF node's `extras` under which `lodkit lod --impostor` writes an impostor
/// level's layout (docs/impostors.md), and by which a loader knows the node for an impostor's
/// card.
pub const IMPOSTOR_GLTF_EXTRAS_KEY: &str = "lodkit_impostor";

pub use atlas::{
    ImpostorAtlas, ImpostorImage, dilate_frames, mip_chain, preserve_coverage, srgba8,
};
#[cfg(feature = "lod_chain")]
pub use bound::{ImpostorPlacement, impostor_placement, impostor_switch_distance};
pub use bound::{impostor_angle, impostor_error};
pub use gltf::ImpostorGltfExtras;
pub use sample::{ImpostorSample, impostor_sample, impostor_sample_frame, impostor_sample_level};

use glam::{Mat3, UVec2, Vec2, Vec3};

/// How an impostor's directions are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ImpostorShape {
    /// The whole sphere of directions (objects seen from below as well: floating, flying).
    Full,
    /// The upper hemisphere (objects standing on the ground); a view from below the horizon
    /// uses the horizon's frames.
    Hemi,
}

impl ImpostorShape {
    /// Whether this is [`ImpostorShape::Hemi`] (the shaders' `hemi` argument).
    pub fn is_hemi(self) -> bool {
        self == Self::Hemi
    }
}

/// The layout of an impostor atlas: what a bake writes and a draw needs besides the textures.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ImpostorLayout {
    /// Frames per side (>= 2): the atlas holds `frames x frames` pictures.
    pub frames: u32,
    /// Texels per side of one frame (a power of two, so every mip level keeps whole frames).
    pub frame_size: u32,
    /// Full sphere or upper hemisphere of directions.
    pub shape: ImpostorShape,
    /// The bounding sphere's centre (object space): the card's centre.
    pub center: [f32; 3],
    /// The bounding sphere's radius (object space, > 0): half the side of a frame's square.
    pub radius: f32,
}

/// A layout an atlas cannot have.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImpostorError {
    /// A field of [`ImpostorLayout`] (or of a bake's descriptor) out of its range.
    #[error("impostor {field} is {value}: {expected}")]
    BadLayout {
        /// The field.
        field: &'static str,
        /// Its value, as written.
        value: String,
        /// What it must be.
        expected: &'static str,
    },
    /// An atlas image whose size is not the layout's.
    #[error(
        "impostor {atlas} atlas is {width} x {height} texels: the layout needs {expected} x {expected}"
    )]
    ImageSize {
        /// `color` or `normal_depth`.
        atlas: &'static str,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// The layout's [`ImpostorLayout::atlas_size`].
        expected: u32,
    },
}

impl ImpostorLayout {
    /// Checks the fields: `frames` in 2..=64, `frame_size` a power of two in 4..=1024, the atlas
    /// at most 16384 texels a side, a finite centre and a finite radius > 0.
    pub fn validate(&self) -> Result<(), ImpostorError> {
        let bad = |field, value: String, expected| {
            Err(ImpostorError::BadLayout {
                field,
                value,
                expected,
            })
        };
        if !(2..=64).contains(&self.frames) {
            return bad("frames", self.frames.to_string(), "2 to 64 frames per side");
        }
        if !(self.frame_size.is_power_of_two() && (4..=1024).contains(&self.frame_size)) {
            return bad(
                "frame_size",
                self.frame_size.to_string(),
                "a power of two from 4 to 1024 texels",
            );
        }
        if self.atlas_size() > 16384 {
            return bad(
                "frames x frame_size",
                self.atlas_size().to_string(),
                "an atlas of at most 16384 texels a side",
            );
        }
        if !self.center.iter().all(|c| c.is_finite()) {
            return bad("center", format!("{:?}", self.center), "finite");
        }
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return bad("radius", self.radius.to_string(), "finite and > 0");
        }
        Ok(())
    }

    /// Texels per side of the atlas: `frames x frame_size`.
    pub fn atlas_size(&self) -> u32 {
        self.frames * self.frame_size
    }

    /// Normalized object space of object-space point `p`: `(p - centre) / radius`.
    pub fn normalize(&self, p: Vec3) -> Vec3 {
        (p - Vec3::from(self.center)) / self.radius
    }
}

/// +1 or -1 by the sign of each component; +1 for either zero (a zero's sign is not read).
pub fn impostor_sign(v: Vec2) -> Vec2 {
    Vec2::new(
        if v.x >= 0.0 { 1.0 } else { -1.0 },
        if v.y >= 0.0 { 1.0 } else { -1.0 },
    )
}

/// Unit direction `d` on the octahedron unfolded into `[-1, 1]²`: the upper half (y >= 0) is
/// the diamond `|e.x| + |e.y| <= 1` around +y, the lower half folded into the corners.
///
/// ```
/// # use lodkit::impostor::{impostor_octa_decode, impostor_octa_encode};
/// # use glam::{Vec2, Vec3};
/// assert_eq!(impostor_octa_encode(Vec3::Y), Vec2::ZERO);
/// assert_eq!(impostor_octa_encode(Vec3::X), Vec2::X);
/// assert_eq!(impostor_octa_encode(-Vec3::Y).abs(), Vec2::ONE); // a corner
/// let d = Vec3::new(0.3, -0.5, 0.7).normalize();
/// assert!((impostor_octa_decode(impostor_octa_encode(d)) - d).length() < 1e-6);
/// ```
pub fn impostor_octa_encode(d: Vec3) -> Vec2 {
    let p = Vec2::new(d.x, d.z) / (d.x.abs() + d.y.abs() + d.z.abs());
    if d.y >= 0.0 {
        return p;
    }
    (Vec2::ONE - Vec2::new(p.y, p.x).abs()) * impostor_sign(p)
}

/// Inverse of [`impostor_octa_encode`]: the unit direction at `e` in `[-1, 1]²`.
pub fn impostor_octa_decode(e: Vec2) -> Vec3 {
    let y = 1.0 - e.x.abs() - e.y.abs();
    let xz = if y < 0.0 {
        (Vec2::ONE - Vec2::new(e.y, e.x).abs()) * impostor_sign(e)
    } else {
        e
    };
    Vec3::new(xz.x, y, xz.y).normalize()
}

/// Unit direction `d` of the upper hemisphere (y clamped to >= 0) on `[-1, 1]²`: the diamond of
/// the octahedron's upper half turned by 45 degrees to fill the square. A view from below the
/// horizon maps onto the rim; one from straight below (no horizontal part) to the corner
/// (1, 1), the horizon's +x.
///
/// ```
/// # use lodkit::impostor::{impostor_hemi_decode, impostor_hemi_encode};
/// # use glam::{Vec2, Vec3};
/// assert_eq!(impostor_hemi_encode(Vec3::Y), Vec2::ZERO);
/// assert_eq!(impostor_hemi_encode(Vec3::X), Vec2::ONE);
/// let d = Vec3::new(-0.2, 0.4, 0.6).normalize();
/// assert!((impostor_hemi_decode(impostor_hemi_encode(d)) - d).length() < 1e-6);
/// ```
pub fn impostor_hemi_encode(d: Vec3) -> Vec2 {
    if d.x.abs() + d.z.abs() == 0.0 && d.y < 0.0 {
        return Vec2::ONE;
    }
    let p = Vec2::new(d.x, d.z) / (d.x.abs() + d.y.max(0.0) + d.z.abs()).max(1e-30);
    Vec2::new(p.x + p.y, p.x - p.y)
}

/// Inverse of [`impostor_hemi_encode`]: the unit direction (y >= 0) at `e` in `[-1, 1]²`.
pub fn impostor_hemi_decode(e: Vec2) -> Vec3 {
    let p = Vec2::new(e.x + e.y, e.x - e.y) * 0.5;
    Vec3::new(p.x, 1.0 - p.x.abs() - p.y.abs(), p.y).normalize()
}

/// [`impostor_hemi_encode`] when `hemi`, else [`impostor_octa_encode`].
pub fn impostor_encode(d: Vec3, hemi: bool) -> Vec2 {
    if hemi {
        impostor_hemi_encode(d)
    } else {
        impostor_octa_encode(d)
    }
}

/// [`impostor_hemi_decode`] when `hemi`, else [`impostor_octa_decode`].
pub fn impostor_decode(e: Vec2, hemi: bool) -> Vec3 {
    if hemi {
        impostor_hemi_decode(e)
    } else {
        impostor_octa_decode(e)
    }
}

/// The direction (from the centre toward the camera) frame `frame` of an `n x n` grid (`n < 2`
/// is taken as 2) was baked from: the grid spans `[-1, 1]²` corner to corner, frame (0, 0) at
/// (-1, -1).
pub fn impostor_frame_dir(frame: UVec2, n: u32, hemi: bool) -> Vec3 {
    let e = frame.as_vec2() * (2.0 / (n.max(2) - 1) as f32) - 1.0;
    impostor_decode(e, hemi)
}

/// The frame's axes as columns (right, up, dir): up follows +y, except at the poles (x = z = 0,
/// where the maps put exact zeros), whose up is -z (from above) or +z (from below).
pub fn impostor_frame_basis(dir: Vec3) -> Mat3 {
    let reference = if dir.x.abs() + dir.z.abs() < 1e-6 {
        Vec3::new(0.0, 0.0, if dir.y > 0.0 { -1.0 } else { 1.0 })
    } else {
        Vec3::Y
    };
    let right = reference.cross(dir).normalize();
    Mat3::from_cols(right, dir.cross(right), dir)
}

/// The three frames around a view direction and their barycentric weights (sum 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorBlend {
    /// The frames, atlas column and row.
    pub frames: [UVec2; 3],
    /// Their weights.
    pub weights: Vec3,
}

/// The frames of an `n x n` grid (`n < 2` is taken as 2) to blend for unit view direction `view` (object
/// space, from the centre toward the eye), with their barycentric weights in the grid triangle
/// that holds it: each cell is split along its anti-diagonal.
///
/// ```
/// # use lodkit::impostor::{impostor_blend, impostor_frame_dir};
/// # use glam::{UVec2, Vec3};
/// // Straight from above, on a 5 x 5 full-sphere grid: the centre frame alone.
/// let b = impostor_blend(Vec3::Y, 5, false);
/// assert_eq!(b.frames[0], UVec2::new(2, 2));
/// assert_eq!(b.weights, Vec3::X);
/// assert!((impostor_frame_dir(b.frames[0], 5, false) - Vec3::Y).length() < 1e-6);
/// ```
pub fn impostor_blend(view: Vec3, n: u32, hemi: bool) -> ImpostorBlend {
    let last = (n.max(2) - 1) as f32;
    let g = (impostor_encode(view, hemi) * 0.5 + 0.5).clamp(Vec2::ZERO, Vec2::ONE) * last;
    let cell = g.floor().min(Vec2::splat(last - 1.0));
    let f = g - cell;
    let c = cell.as_uvec2();
    if f.x + f.y <= 1.0 {
        ImpostorBlend {
            frames: [c, c + UVec2::X, c + UVec2::Y],
            weights: Vec3::new(1.0 - f.x - f.y, f.x, f.y),
        }
    } else {
        ImpostorBlend {
            frames: [c + UVec2::ONE, c + UVec2::X, c + UVec2::Y],
            weights: Vec3::new(f.x + f.y - 1.0, 1.0 - f.y, 1.0 - f.x),
        }
    }
}

/// The point of the ray `origin + t ray` (normalized object space) at `height` above the plane
/// of frame direction `dir` (`dot(q, dir) = height`). A ray that does not run against `dir` (a
/// frame seen edge-on or from behind, which a blend never picks) is taken as just doing so.
pub fn impostor_ray_at_height(origin: Vec3, ray: Vec3, dir: Vec3, height: f32) -> Vec3 {
    let t = (height - origin.dot(dir)) / ray.dot(dir).min(-1e-4);
    origin + t * ray
}

/// The uv of normalized object-space point `q` in the frame with axes `basis` (row 0 at the
/// top; `[0, 1]²` is the frame's square `[-1, 1]²`).
pub fn impostor_frame_uv(basis: &Mat3, q: Vec3) -> Vec2 {
    Vec2::new(q.dot(basis.x_axis), -q.dot(basis.y_axis)) * 0.5 + 0.5
}

/// The atlas uv of frame uv `uv` in frame `frame` of an `n x n` atlas, uv clamped to `[0, 1]`.
pub fn impostor_atlas_uv(frame: UVec2, n: u32, uv: Vec2) -> Vec2 {
    (frame.as_vec2() + uv.clamp(Vec2::ZERO, Vec2::ONE)) / n as f32
}

/// How far inside its frame (frame uv) a sample at mip `level` of an atlas whose frames are
/// `texels` texels wide stays: half a texel of the coarsest mip trilinear filtering reads there
/// (`2^ceil(level)` texels of mip 0), so bilinear filtering takes no texel of a neighbouring
/// frame; at most 0.5, the frame's centre.
///
/// ```
/// # use lodkit::impostor::impostor_frame_inset;
/// assert_eq!(impostor_frame_inset(64.0, 0.0), 0.5 / 64.0);
/// assert_eq!(impostor_frame_inset(64.0, 2.3), 4.0 / 64.0); // mips 2 and 3: a texel of mip 3
/// assert_eq!(impostor_frame_inset(4.0, 5.0), 0.5);
/// ```
pub fn impostor_frame_inset(texels: f32, level: f32) -> f32 {
    (0.5 * level.max(0.0).ceil().exp2() / texels).min(0.5)
}

/// The height `[-1, 1]` above a frame's plane of a stored depth in `[0, 1]`.
pub fn impostor_depth_height(depth: f32) -> f32 {
    depth * 2.0 - 1.0
}

/// The impostor's alpha test: keep the fragment when the blended coverage is at least 0.5.
pub fn impostor_keep(alpha: f32) -> bool {
    alpha >= 0.5
}

#[cfg(test)]
mod tests;
