//! [`RecordedUniform`]: a pass's parameters, written into the command encoder with each recording.

use std::sync::{Mutex, PoisonError};

use bytemuck::Pod;

use crate::gpu::{GpuContext, GpuError};

/// A uniform buffer whose contents travel with each recording: every write is a copy recorded
/// into the encoder (from a `wgpu::util::StagingBelt` chunk) right before the pass that reads
/// it, so any number of recordings in one encoder, with different parameters, each read their
/// own. (A `queue.write_buffer` would land before the whole submission, and every recording
/// would read the last parameters written.) The staging chunks come back for reuse once the
/// encoder is submitted and its work is done: after a few frames nothing more is allocated.
#[derive(Debug)]
pub struct RecordedUniform {
    buffer: wgpu::Buffer,
    belt: Mutex<wgpu::util::StagingBelt>,
    size: u64,
}

impl RecordedUniform {
    /// A uniform of `size` bytes (at least 16), labelled `label`.
    pub fn new(gpu: &GpuContext, size: usize, label: &str) -> Result<Self, GpuError> {
        let size = (size as u64).max(16).div_ceil(16) * 16;
        let buffer = gpu.guarded("RecordedUniform::new", || {
            Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }))
        })?;
        // One recording's parameters per chunk: the belt closes a chunk at each write.
        let belt = wgpu::util::StagingBelt::new(gpu.device.clone(), size.max(256));
        Ok(Self {
            buffer,
            belt: Mutex::new(belt),
            size,
        })
    }

    /// The uniform buffer to bind.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Records into `encoder` the copy of `value` into the buffer, before whatever the caller
    /// records next. A value larger than the buffer is [`GpuError::Mismatch`].
    pub fn write<T: Pod>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        value: &T,
    ) -> Result<(), GpuError> {
        let bytes = bytemuck::bytes_of(value);
        let Some(len) = wgpu::BufferSize::new(self.size) else {
            return Ok(());
        };
        if bytes.len() as u64 > self.size {
            return Err(GpuError::Mismatch {
                call: "RecordedUniform::write",
                parameter: "value",
                found: format!("{} bytes", bytes.len()),
                expected: format!("at most the uniform's {} bytes", self.size),
            });
        }
        let mut padded = vec![0u8; self.size as usize];
        padded[..bytes.len()].copy_from_slice(bytes);
        let mut belt = self.belt.lock().unwrap_or_else(PoisonError::into_inner);
        belt.write_buffer(encoder, &self.buffer, 0, len)
            .copy_from_slice(&padded);
        belt.finish_and_recall_on_submit(encoder);
        Ok(())
    }
}
