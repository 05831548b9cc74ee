//! The LOD buffer texel (Rust twins of `lodkit::lod_buffer`): color at location 0, at location 1
//! an `R32Uint` id word, and each buffer's own depth attachment. The id word holds the instance
//! id in bits 0..29 (exact up to 2^30 - 1) and the display-time flags in bits 30 (shown in the
//! frame rendered) and 31 (shown in the next frame). 8 bytes per pixel beyond the depth
//! attachment with RGBA8 color. Objects that move by themselves also write their object motion
//! ([`lod_buffer_motion`]) into one `MOTION_FORMAT` (`Rg16Float`) target for the frame (4 bytes
//! per pixel, shared by both buffers), cleared to 0.

use glam::{Vec2, Vec4};

/// Format of the id target (location 1).
#[cfg(feature = "wgpu")]
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// Format of the object motion target (location 2), one for the frame.
#[cfg(feature = "wgpu")]
pub const MOTION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;

/// Bytes per pixel of one LOD buffer with an RGBA8 color target, beyond its depth attachment.
pub const BYTES_PER_PIXEL: u32 = 8;

/// Bits of the id word that hold the instance id.
pub const LOD_BUFFER_ID_MASK: u32 = 0x3fff_ffff;

/// Largest instance id a LOD buffer holds exactly (2^30 - 1).
pub const LOD_BUFFER_MAX_ID: u32 = LOD_BUFFER_ID_MASK;

/// Flag: shown in the frame the buffer is rendered for.
pub const LOD_BUFFER_SHOWN_NOW: u32 = 1;

/// Flag: shown in the next frame, when the buffer is the older one.
pub const LOD_BUFFER_SHOWN_NEXT: u32 = 2;

/// The id word of `instance_id` (bits above 29 dropped) with display-time `flags` (bits above
/// the two flags dropped).
///
/// ```
/// # use lodkit::lod_buffer::*;
/// let w = lod_buffer_word(LOD_BUFFER_MAX_ID, LOD_BUFFER_SHOWN_NEXT);
/// assert_eq!((lod_buffer_id(w), lod_buffer_flags(w)), (LOD_BUFFER_MAX_ID, LOD_BUFFER_SHOWN_NEXT));
/// assert!(!lod_buffer_shown(w, LOD_BUFFER_SHOWN_NOW) && lod_buffer_shown(w, LOD_BUFFER_SHOWN_NEXT));
/// assert!(lod_buffer_shown(lod_buffer_word(0, 0), LOD_BUFFER_SHOWN_NOW));
/// ```
pub fn lod_buffer_word(instance_id: u32, flags: u32) -> u32 {
    (instance_id & LOD_BUFFER_ID_MASK) | ((flags & 3) << 30)
}

/// What `lod_buffer_output_flags` writes: the color and the id word.
pub fn lod_buffer_output_flags(color: [f32; 4], instance_id: u32, flags: u32) -> ([f32; 4], u32) {
    (color, lod_buffer_word(instance_id, flags))
}

/// What `lod_buffer_output` writes: the color and the id word, shown in both frames (`depth`
/// is kept by the depth attachment, not in the targets).
pub fn lod_buffer_output(color: [f32; 4], instance_id: u32, _depth: f32) -> ([f32; 4], u32) {
    let both = LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT;
    lod_buffer_output_flags(color, instance_id, both)
}

/// Instance id of an id word.
pub fn lod_buffer_id(word: u32) -> u32 {
    word & LOD_BUFFER_ID_MASK
}

/// Display-time flags of an id word.
pub fn lod_buffer_flags(word: u32) -> u32 {
    word >> 30
}

/// Whether a texel is shown in the frame `flag` names: always for n-instances (id 0).
pub fn lod_buffer_shown(word: u32, flag: u32) -> bool {
    lod_buffer_id(word) == 0 || lod_buffer_flags(word) & flag != 0
}

/// What `lod_buffer_output_motion` writes: the color, the id word and the object motion.
pub fn lod_buffer_output_motion(
    color: [f32; 4],
    instance_id: u32,
    flags: u32,
    motion: Vec2,
) -> ([f32; 4], u32, Vec2) {
    (color, lod_buffer_word(instance_id, flags), motion)
}

/// Object motion of a fragment in texture-space uv: `then_clip` (its surface point in the
/// previous frame) minus `now_clip` (the point now), both in the previous frame's clip space;
/// zero when either has w <= 0.
///
/// ```
/// # use lodkit::lod_buffer::lod_buffer_motion;
/// # use glam::{Vec2, Vec4};
/// // The point was an eighth of the view right of and below where it is now.
/// let m = lod_buffer_motion(Vec4::new(0.5, 0.0, 0.5, 2.0), Vec4::new(0.0, 0.5, 0.5, 2.0));
/// assert_eq!(m, Vec2::new(0.125, 0.125));
/// assert_eq!(lod_buffer_motion(Vec4::new(1.0, 0.0, 0.5, -1.0), Vec4::W), Vec2::ZERO);
/// ```
pub fn lod_buffer_motion(then_clip: Vec4, now_clip: Vec4) -> Vec2 {
    if then_clip.w <= 0.0 || now_clip.w <= 0.0 {
        return Vec2::ZERO;
    }
    let ndc = |c: Vec4| c.truncate().truncate() / c.w;
    (ndc(then_clip) - ndc(now_clip)) * Vec2::new(0.5, -0.5)
}
