//! Copying textures and buffers back to the CPU (tests, examples, reports).

use super::GpuContext;

/// Reads an RGBA8 (or BGRA8, returned as stored) 2D texture into tightly packed rows.
/// The texture needs `COPY_SRC` usage.
pub fn read_texture_rgba8(gpu: &GpuContext, texture: &wgpu::Texture) -> Vec<u8> {
    read_texture(gpu, texture, 4)
}

/// Reads a 2D texture of `bytes_per_pixel` bytes per texel into tightly packed rows.
pub fn read_texture(gpu: &GpuContext, texture: &wgpu::Texture, bytes_per_pixel: u32) -> Vec<u8> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * bytes_per_pixel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("lodkit readback"),
        size: u64::from(padded) * u64::from(h),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = map_read(gpu, &buffer);
    bytes
        .chunks(padded as usize)
        .flat_map(|r| &r[..row as usize])
        .copied()
        .collect()
}

/// Maps a `MAP_READ` buffer, waits, and returns its contents.
pub fn map_read(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<u8> {
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    gpu.wait_idle();
    let bytes = match slice.get_mapped_range() {
        Ok(view) => view.to_vec(),
        Err(_) => Vec::new(),
    };
    buffer.unmap();
    bytes
}

/// Submits `encoder` with a copy of `size` bytes of `buffer` (which needs `COPY_SRC`) appended
/// and returns them.
pub fn read_buffer(
    gpu: &GpuContext,
    mut encoder: wgpu::CommandEncoder,
    buffer: &wgpu::Buffer,
    size: u64,
) -> Vec<u8> {
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("lodkit readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    map_read(gpu, &staging)
}
