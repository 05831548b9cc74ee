//! [`DrawUniforms`]: per-draw uniform data of a renderer in one buffer.

use bytemuck::Pod;

use super::uniform_buffer;
use crate::gpu::checks::buffer_size;
use crate::gpu::{GpuContext, GpuError};

/// Per-draw uniforms in one buffer, one aligned slot per draw, bound with a dynamic offset.
#[derive(Debug)]
pub struct DrawUniforms {
    buffer: wgpu::Buffer,
    stride: u64,
    item_size: u64,
    capacity: usize,
}

impl DrawUniforms {
    /// Room for `capacity` items of `item_size` bytes each.
    pub fn new(
        gpu: &GpuContext,
        item_size: usize,
        capacity: usize,
        label: &str,
    ) -> Result<Self, GpuError> {
        let limits = gpu.device.limits();
        let max_binding = limits.max_uniform_buffer_binding_size;
        if item_size as u64 > max_binding {
            return Err(GpuError::TooLarge {
                call: "DrawUniforms::new",
                parameter: "item_size",
                value: item_size as u64,
                limit: "max_uniform_buffer_binding_size",
                max: max_binding,
            });
        }
        let align = u64::from(limits.min_uniform_buffer_offset_alignment.max(1));
        let stride = (item_size as u64).div_ceil(align).max(1) * align;
        let bytes = stride.saturating_mul(capacity.max(1) as u64);
        buffer_size(gpu, "DrawUniforms::new", "item_size x capacity", bytes)?;
        let buffer = gpu.guarded("DrawUniforms::new", || {
            uniform_buffer(gpu, bytes as usize, label)
        })?;
        Ok(Self {
            buffer,
            stride,
            item_size: item_size as u64,
            capacity,
        })
    }

    /// Most items it holds.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// `Ok` when `count` items fit, else [`GpuError::TooManyDraws`] naming `call`.
    pub fn check_count(&self, call: &'static str, count: usize) -> Result<(), GpuError> {
        if count > self.capacity {
            return Err(GpuError::TooManyDraws {
                call,
                count,
                max: self.capacity,
            });
        }
        Ok(())
    }

    /// Writes `items` and returns how many were written. More than
    /// [`capacity`](Self::capacity) items is [`GpuError::TooManyDraws`] (nothing is written); an
    /// item larger than the item size the buffer was made for is [`GpuError::Mismatch`].
    pub fn write<T: Pod>(&self, gpu: &GpuContext, items: &[T]) -> Result<usize, GpuError> {
        const CALL: &str = "DrawUniforms::write";
        self.check_count(CALL, items.len())?;
        let size = std::mem::size_of::<T>();
        if size as u64 > self.item_size {
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "items",
                found: format!("of {size} bytes each"),
                expected: format!("the buffer was made for items of {} bytes", self.item_size),
            });
        }
        let n = items.len();
        let mut data = vec![0u8; self.stride as usize * n];
        for (item, slot) in items.iter().zip(data.chunks_mut(self.stride as usize)) {
            slot[..size].copy_from_slice(bytemuck::bytes_of(item));
        }
        if !data.is_empty() {
            gpu.recording(CALL, || {
                gpu.queue.write_buffer(&self.buffer, 0, &data);
                Ok(())
            })?;
        }
        Ok(n)
    }

    /// Dynamic offset of item `i`.
    pub fn offset(&self, i: usize) -> u32 {
        (i as u64 * self.stride) as u32
    }

    /// A bind group holding the buffer at `binding` 0 of `layout` (one item wide).
    pub fn bind_group(
        &self,
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
    ) -> Result<wgpu::BindGroup, GpuError> {
        gpu.guarded("DrawUniforms::bind_group", || {
            Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.buffer,
                        offset: 0,
                        size: wgpu::BufferSize::new(self.item_size),
                    }),
                }],
            }))
        })
    }
}
