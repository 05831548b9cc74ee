//! The LOD buffer texel (Rust twins of `lodkit::lod_buffer`): color at location 0, and at
//! location 1 an `Rg32Uint` texel (instance id, depth bits). 12 bytes per pixel with RGBA8 color.

/// Format of the id/depth target.
#[cfg(feature = "wgpu")]
pub const ID_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;

/// Bytes per pixel of one LOD buffer with an RGBA8 color target.
pub const BYTES_PER_PIXEL: u32 = 12;

/// The id/depth texel the shader writes: (instance id, depth bits).
///
/// ```
/// # use lodkit::lod_buffer::*;
/// let t = lod_buffer_id_depth(70_000, 0.25);
/// assert_eq!((lod_buffer_id(t), lod_buffer_depth(t)), (70_000, 0.25));
/// ```
pub fn lod_buffer_id_depth(instance_id: u32, depth: f32) -> [u32; 2] {
    [instance_id, depth.to_bits()]
}

/// What `lod_buffer_output` writes: the color and the id/depth texel.
pub fn lod_buffer_output(color: [f32; 4], instance_id: u32, depth: f32) -> ([f32; 4], [u32; 2]) {
    (color, lod_buffer_id_depth(instance_id, depth))
}

/// Instance id of an id/depth texel.
pub fn lod_buffer_id(id_depth: [u32; 2]) -> u32 {
    id_depth[0]
}

/// Clip depth of an id/depth texel.
pub fn lod_buffer_depth(id_depth: [u32; 2]) -> f32 {
    f32::from_bits(id_depth[1])
}
