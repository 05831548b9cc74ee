//! The LOD buffer texel (Rust twins of `lodkit::lod_buffer`): color at location 0, and at
//! location 1 an `Rg32Uint` texel (id word, depth bits). The id word holds the instance id in
//! bits 0..29 (exact up to 2^30 - 1) and the display-time flags in bits 30 (shown in the frame
//! rendered) and 31 (shown in the next frame). 12 bytes per pixel with RGBA8 color.

/// Format of the id/depth target.
#[cfg(feature = "wgpu")]
pub const ID_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;

/// Bytes per pixel of one LOD buffer with an RGBA8 color target.
pub const BYTES_PER_PIXEL: u32 = 12;

/// Bits of the id word that hold the instance id.
pub const LOD_BUFFER_ID_MASK: u32 = 0x3fff_ffff;

/// Largest instance id a LOD buffer holds exactly (2^30 - 1).
pub const LOD_BUFFER_MAX_ID: u32 = LOD_BUFFER_ID_MASK;

/// Flag: shown in the frame the buffer is rendered for.
pub const LOD_BUFFER_SHOWN_NOW: u32 = 1;

/// Flag: shown in the next frame, when the buffer is the older one.
pub const LOD_BUFFER_SHOWN_NEXT: u32 = 2;

/// The id/depth texel the shader writes for a fragment shown in both frames.
///
/// ```
/// # use lodkit::lod_buffer::*;
/// let t = lod_buffer_id_depth(70_000, 0.25);
/// assert_eq!((lod_buffer_id(t), lod_buffer_depth(t)), (70_000, 0.25));
/// ```
pub fn lod_buffer_id_depth(instance_id: u32, depth: f32) -> [u32; 2] {
    lod_buffer_id_depth_flags(
        instance_id,
        depth,
        LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT,
    )
}

/// The id/depth texel with display-time `flags` (bits above the two flags and id bits above 29
/// are dropped).
///
/// ```
/// # use lodkit::lod_buffer::*;
/// let t = lod_buffer_id_depth_flags(LOD_BUFFER_MAX_ID, 0.5, LOD_BUFFER_SHOWN_NEXT);
/// assert_eq!((lod_buffer_id(t), lod_buffer_flags(t)), (LOD_BUFFER_MAX_ID, LOD_BUFFER_SHOWN_NEXT));
/// assert!(!lod_buffer_shown(t, LOD_BUFFER_SHOWN_NOW) && lod_buffer_shown(t, LOD_BUFFER_SHOWN_NEXT));
/// ```
pub fn lod_buffer_id_depth_flags(instance_id: u32, depth: f32, flags: u32) -> [u32; 2] {
    [
        (instance_id & LOD_BUFFER_ID_MASK) | ((flags & 3) << 30),
        depth.to_bits(),
    ]
}

/// What `lod_buffer_output` writes: the color and the id/depth texel (shown in both frames).
pub fn lod_buffer_output(color: [f32; 4], instance_id: u32, depth: f32) -> ([f32; 4], [u32; 2]) {
    (color, lod_buffer_id_depth(instance_id, depth))
}

/// What `lod_buffer_output_flags` writes.
pub fn lod_buffer_output_flags(
    color: [f32; 4],
    instance_id: u32,
    depth: f32,
    flags: u32,
) -> ([f32; 4], [u32; 2]) {
    (color, lod_buffer_id_depth_flags(instance_id, depth, flags))
}

/// Instance id of an id/depth texel.
pub fn lod_buffer_id(id_depth: [u32; 2]) -> u32 {
    id_depth[0] & LOD_BUFFER_ID_MASK
}

/// Display-time flags of an id/depth texel.
pub fn lod_buffer_flags(id_depth: [u32; 2]) -> u32 {
    id_depth[0] >> 30
}

/// Whether a texel is shown in the frame `flag` names: always for n-instances (id 0).
pub fn lod_buffer_shown(id_depth: [u32; 2], flag: u32) -> bool {
    lod_buffer_id(id_depth) == 0 || lod_buffer_flags(id_depth) & flag != 0
}

/// Clip depth of an id/depth texel.
pub fn lod_buffer_depth(id_depth: [u32; 2]) -> f32 {
    f32::from_bits(id_depth[1])
}
