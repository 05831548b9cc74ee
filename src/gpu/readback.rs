//! Copying textures and buffers back to the CPU (tests, examples, reports).

use std::sync::{Arc, Mutex, PoisonError};

use super::error::{buffer_size, has_usage};
use super::{GpuContext, GpuError};

/// Reads an RGBA8 (or BGRA8, returned as stored) 2D texture into tightly packed rows.
/// The texture needs `COPY_SRC` usage.
pub fn read_texture_rgba8(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<u8>, GpuError> {
    read_texture(gpu, texture, 4)
}

/// Reads layer 0 of a 2D texture of `bytes_per_pixel` bytes per texel into tightly packed rows.
/// The texture needs `COPY_SRC` usage and an uncompressed format of that texel size whose whole
/// texel can be copied (not a combined depth/stencil format).
pub fn read_texture(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    bytes_per_pixel: u32,
) -> Result<Vec<u8>, GpuError> {
    const CALL: &str = "readback::read_texture";
    let format = texture.format();
    let texel = format
        .block_copy_size(None)
        .filter(|_| format.block_dimensions() == (1, 1));
    let Some(texel) = texel else {
        return Err(GpuError::UnsupportedFormat {
            call: CALL,
            parameter: "texture",
            format,
            reason: "its texels cannot be copied to a buffer as a whole".into(),
        });
    };
    if texel != bytes_per_pixel {
        return Err(GpuError::Mismatch {
            call: CALL,
            parameter: "bytes_per_pixel",
            found: bytes_per_pixel.to_string(),
            expected: format!("a texel of {format:?} has {texel} bytes"),
        });
    }
    let usage = texture.usage();
    let copy_src = usage.contains(wgpu::TextureUsages::COPY_SRC);
    has_usage(CALL, "texture usage", usage, copy_src, "COPY_SRC")?;
    let (w, h) = (texture.width(), texture.height());
    let row = u64::from(w) * u64::from(bytes_per_pixel);
    let align = u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let padded = row.div_ceil(align) * align;
    buffer_size(gpu, CALL, "texture size", padded * u64::from(h))?;
    let bytes = gpu.guarded(CALL, || {
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lodkit readback"),
            size: padded * u64::from(h),
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
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        gpu.queue.submit([encoder.finish()]);
        map_read(gpu, &buffer)
    })?;
    Ok(bytes
        .chunks(padded as usize)
        .flat_map(|r| &r[..row as usize])
        .copied()
        .collect())
}

/// Maps a `MAP_READ` buffer, waits, and returns its contents.
pub fn map_read(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    const CALL: &str = "readback::map_read";
    let usage = buffer.usage();
    let map_read = usage.contains(wgpu::BufferUsages::MAP_READ);
    has_usage(CALL, "buffer usage", usage, map_read, "MAP_READ")?;
    if buffer.size() == 0 {
        return Ok(Vec::new());
    }
    let status = Arc::new(Mutex::new(None));
    let slice = buffer.slice(..);
    gpu.guarded(CALL, || {
        let status = Arc::clone(&status);
        slice.map_async(wgpu::MapMode::Read, move |result| {
            *status.lock().unwrap_or_else(PoisonError::into_inner) = Some(result);
        });
        Ok(())
    })?;
    gpu.wait_idle()?;
    let mapped = status.lock().unwrap_or_else(PoisonError::into_inner).take();
    let bytes = match mapped {
        Some(Ok(())) => slice
            .get_mapped_range()
            .map(|view| view.to_vec())
            .map_err(|e| e.to_string()),
        Some(Err(e)) => Err(e.to_string()),
        None => Err("the buffer was not mapped after the device went idle".into()),
    }
    .map_err(|reason| GpuError::Readback { call: CALL, reason });
    if bytes.is_ok() {
        buffer.unmap();
    }
    bytes
}

/// Submits `encoder` with a copy of `size` bytes of `buffer` (which needs `COPY_SRC`) appended
/// and returns them.
pub fn read_buffer(
    gpu: &GpuContext,
    mut encoder: wgpu::CommandEncoder,
    buffer: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, GpuError> {
    const CALL: &str = "readback::read_buffer";
    if size > buffer.size() || !size.is_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT) {
        return Err(GpuError::Mismatch {
            call: CALL,
            parameter: "size",
            found: size.to_string(),
            expected: format!(
                "it must be a multiple of {} and at most the buffer's {} bytes",
                wgpu::COPY_BUFFER_ALIGNMENT,
                buffer.size()
            ),
        });
    }
    let usage = buffer.usage();
    let copy_src = usage.contains(wgpu::BufferUsages::COPY_SRC);
    has_usage(CALL, "buffer usage", usage, copy_src, "COPY_SRC")?;
    gpu.guarded(CALL, || {
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lodkit readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        gpu.queue.submit([encoder.finish()]);
        map_read(gpu, &staging)
    })
}
