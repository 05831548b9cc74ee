//! Copying textures and buffers back to the CPU (tests, examples, reports).

use std::sync::{Arc, Mutex, PoisonError};

use super::checks::{buffer_size, has_usage};
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
    // On a device shared between threads, another thread's poll may be the one running the
    // callback, and still be running it when this poll returns: give it a moment.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
    let mapped = loop {
        let taken = status.lock().unwrap_or_else(PoisonError::into_inner).take();
        if taken.is_some() || std::time::Instant::now() > deadline {
            break taken;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    };
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

/// Reads a `Depth32Float` texture (`COPY_SRC`, and `TEXTURE_BINDING` where the device cannot
/// copy depth to a buffer, as on OpenGL ES) as clip depths, rows top to bottom.
pub fn read_depth32(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<f32>, GpuError> {
    const CALL: &str = "readback::read_depth32";
    let format = texture.format();
    if format != wgpu::TextureFormat::Depth32Float {
        return Err(GpuError::UnsupportedFormat {
            call: CALL,
            parameter: "texture",
            format,
            reason: "read_depth32 reads Depth32Float".into(),
        });
    }
    let copies = wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES;
    let bytes = if gpu.capabilities().downlevel.contains(copies) {
        read_texture(gpu, texture, 4)?
    } else {
        let usage = texture.usage();
        let bound = usage.contains(wgpu::TextureUsages::TEXTURE_BINDING);
        has_usage(CALL, "texture usage", usage, bound, "TEXTURE_BINDING")?;
        let copy = gpu.guarded(CALL, || depth_to_r32uint(gpu, texture))?;
        read_texture(gpu, &copy, 4)?
    };
    Ok(bytes
        .chunks(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// Draws a depth texture's bits into an `R32Uint` texture of its size (for devices that cannot copy
/// depth to a buffer).
fn depth_to_r32uint(gpu: &GpuContext, depth: &wgpu::Texture) -> Result<wgpu::Texture, GpuError> {
    const SOURCE: &str = "@group(0) @binding(0) var depth: texture_2d<f32>;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
}
@fragment fn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<u32> {
    return vec4<u32>(bitcast<u32>(textureLoad(depth, vec2<u32>(p.xy), 0).x), 0u, 0u, 1u);
}";
    let device = &gpu.device;
    let size = (depth.width(), depth.height());
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    // R32Uint holds the depth's bits and renders on every backend (R32Float does not on GL ES).
    let format = wgpu::TextureFormat::R32Uint;
    let target = super::resources::texture_2d(gpu, size, format, usage, "depth copy")?;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("lodkit depth copy"),
        source: wgpu::ShaderSource::Wgsl(SOURCE.into()),
    });
    let float = wgpu::TextureSampleType::Float { filterable: false };
    let entries = [super::resources::texture_entry(0, float)];
    let (group_layout, layout) =
        super::resources::one_group_layout(gpu, &entries, "lodkit depth copy");
    let pipeline =
        super::resources::fullscreen_pipeline_with(gpu, &module, format, Some(&layout), "depth")?;
    let group =
        super::resources::textures_and_uniform(gpu, &group_layout, &[depth], None, "depth")?;
    let view = target.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let clear = wgpu::Color::BLACK;
        let mut pass = super::resources::begin_color_pass(&mut encoder, &view, clear, "depth copy");
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    Ok(target)
}
