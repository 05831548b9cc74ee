//! A [`GpuLodSelector`]'s views: each camera's buffers and bind groups, made when a view is
//! added or the instances change, and read back for tests and debugging.

use super::chunks::{DRAW_BYTES, ENTRY_BYTES, STATE_BYTES};
use super::{
    GpuLodSelector, GpuSelectCamera, GpuSelectEntry, SelectReadback, View, ViewChunk, ViewId,
    create,
};
use crate::gpu::checks::buffer_size;
use crate::gpu::{GpuContext, GpuError};

impl GpuLodSelector {
    pub(super) fn make_view(&self, gpu: &GpuContext, call: &'static str) -> Result<View, GpuError> {
        let rw = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let draw_bytes = (self.slots.len().max(1) as u64) * DRAW_BYTES;
        let draws = create(
            gpu,
            call,
            draw_bytes,
            rw | wgpu::BufferUsages::INDIRECT,
            "lodkit select draws",
        )?;
        let camera = crate::gpu::resources::uniform_buffer(
            gpu,
            std::mem::size_of::<GpuSelectCamera>(),
            "lodkit select camera",
        )?;
        let mut chunks = Vec::with_capacity(self.chunks.len());
        for chunk in &self.chunks {
            let n = chunk.plan.count.max(1) as usize;
            buffer_size(gpu, call, "states", n as u64 * STATE_BYTES)?;
            let new_states = vec![[crate::select::LodState::NEW.packed(), 0u32]; n];
            let states = crate::gpu::resources::buffer_with_data(
                gpu,
                bytemuck::cast_slice(&new_states),
                rw,
                "lodkit select states",
            )?;
            let entries = create(
                gpu,
                call,
                chunk.plan.entry_bytes,
                rw,
                "lodkit select entries",
            )?;
            let buffers = [
                &camera,
                &self.group_buffer,
                &chunk.instances,
                &chunk.slot_first,
                &states,
                &draws,
                &entries,
                &chunk.info,
            ];
            let bind_group = gpu.guarded(call, || {
                Ok(crate::gpu::resources::buffers_bind_group(
                    &gpu.device,
                    &self.pipeline.get_bind_group_layout(0),
                    &buffers,
                    "lodkit select",
                ))
            })?;
            chunks.push(ViewChunk {
                states,
                entries,
                bind_group,
            });
        }
        Ok(View {
            camera,
            draws,
            chunks,
        })
    }

    /// Reads a view's states and lists back (tests and debugging, not the frame loop): the
    /// states (packed word, progress) of every instance, and each slot's entries over all chunks.
    pub fn read_back(&self, gpu: &GpuContext, view: ViewId) -> Result<SelectReadback, GpuError> {
        const CALL: &str = "GpuLodSelector::read_back";
        let v = self.view(CALL, view)?;
        let read = |buffer: &wgpu::Buffer, size: u64| {
            let encoder = gpu.device.create_command_encoder(&Default::default());
            crate::gpu::readback::read_buffer(gpu, encoder, buffer, size)
        };
        let draws: Vec<u32> = bytemuck::pod_collect_to_vec(&read(&v.draws, v.draws.size())?);
        let mut states = Vec::with_capacity(self.instance_count as usize);
        let mut lists = vec![Vec::new(); self.slot_meshes.len()];
        for (chunk, vc) in self.chunks.iter().zip(&v.chunks) {
            if chunk.plan.count == 0 {
                continue;
            }
            let bytes = read(&vc.states, u64::from(chunk.plan.count) * STATE_BYTES)?;
            states.extend(bytemuck::pod_collect_to_vec::<u8, [u32; 2]>(&bytes));
            let entries: Vec<GpuSelectEntry> =
                bytemuck::pod_collect_to_vec(&read(&vc.entries, vc.entries.size())?);
            for range in &chunk.plan.slots {
                let first = (range.entries_offset / ENTRY_BYTES) as usize;
                let d = (range.draw_offset / DRAW_BYTES) as usize;
                let n = (draws[d * 5 + 1] as usize).min(range.capacity as usize);
                lists[range.slot as usize].extend_from_slice(&entries[first..first + n]);
            }
        }
        Ok(SelectReadback { states, lists })
    }
}
