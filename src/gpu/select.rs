//! GPU-driven LOD selection: [`GpuLodSelector`] runs `passes/select.wgsl` (the rule of
//! `lodkit::select`, the same as [`select_batch`](crate::select::select_batch)) once per camera
//! per frame, keeps each instance's selection state in a GPU buffer, and leaves per-(group, level)
//! instance lists and their `DrawIndexedIndirectArgs` for the draws: no readback in the frame loop.
//!
//! Buffers are sized when instances are set and grow (to the next power of two) when more come;
//! the group table is fixed at creation. Each (group, level) list starts at an offset aligned to
//! `min_storage_buffer_offset_alignment`, so a draw binds its list at that offset (its own bind
//! group, or a dynamic offset) and leaves `first_instance` at 0: one `draw_indexed_indirect` per
//! list, which works on every backend with indirect execution, OpenGL included (no
//! `MULTI_DRAW_INDIRECT` or `INDIRECT_FIRST_INSTANCE` needed). `examples/gpu_select.rs` draws
//! 102,400 instances this way.
//!
//! ```no_run
//! # use lodkit::gpu::{GpuContext, GpuOptions};
//! # use lodkit::gpu::select::*;
//! # use lodkit::select::*;
//! # fn main() -> Result<(), lodkit::gpu::GpuError> {
//! let gpu = GpuContext::new_headless(&GpuOptions::default())?;
//! let groups = [LodGroup::from_distances(&[0.0, 20.0, 60.0]).unwrap()];
//! let mut selector = GpuLodSelector::new(&gpu, &GpuLodSelectorDescriptor {
//!     groups: &groups,
//!     settings: LodSettings { hysteresis: 4.0, ..Default::default() },
//!     ..Default::default() // no meshes: read the counts only
//! })?;
//! selector.set_instances(&gpu, &[GpuLodInstance::new(glam::Vec3::ZERO, 1.0, 1.0, 0)])?;
//! let view = selector.add_view(&gpu)?;
//! let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 500.0);
//! let mut encoder = gpu.device.create_command_encoder(&Default::default());
//! selector.record(&gpu, &mut encoder, view, &GpuSelectFrame::new(LodCamera::new(glam::Vec3::Z * 5.0, proj)))?;
//! gpu.queue.submit([encoder.finish()]);
//! # Ok(()) }
//! ```

mod chunks;
mod types;
mod views;

pub use types::{
    GpuLodGroup, GpuLodInstance, GpuLodSelectorDescriptor, GpuSelectCamera, GpuSelectChunk,
    GpuSelectEntry, GpuSelectFrame, LevelMesh, SlotRange,
};

use chunks::{Chunk, ENTRY_BYTES, INSTANCE_BYTES};

use super::GpuContext;
use super::GpuError;
use super::checks::buffer_size;
use crate::select::{LodSettings, distance_kind};

/// A view's selection read back (tests and debugging): per instance its state (packed word,
/// progress bits), per (group, level) slot its list, the chunks' lists joined.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelectReadback {
    /// (level | target << 8 | phase << 16 | in transition << 17, progress as f32 bits).
    pub states: Vec<[u32; 2]>,
    /// The entries of each (group, level) list, in slot order.
    pub lists: Vec<Vec<GpuSelectEntry>>,
}

/// The buffers of one chunk of instances shared by every view.
struct ChunkBuffers {
    plan: Chunk,
    instances: wgpu::Buffer,
    slot_first: wgpu::Buffer,
    info: wgpu::Buffer,
}

/// One camera's buffers.
struct View {
    camera: wgpu::Buffer,
    draws: wgpu::Buffer,
    /// Per chunk: states, entries and the bind group of its dispatch.
    chunks: Vec<ViewChunk>,
}

/// One chunk's buffers of one camera.
struct ViewChunk {
    states: wgpu::Buffer,
    entries: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// Selects LODs on the GPU for a fixed table of groups, for any number of views (cameras).
pub struct GpuLodSelector {
    settings: LodSettings,
    groups: Vec<GpuLodGroup>,
    slot_meshes: Vec<LevelMesh>,
    pipeline: wgpu::ComputePipeline,
    group_buffer: wgpu::Buffer,
    chunks: Vec<ChunkBuffers>,
    template: Option<wgpu::Buffer>,
    slots: Vec<SlotRange>,
    instance_count: u32,
    views: Vec<View>,
}

/// Handle of a view (camera) of a [`GpuLodSelector`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewId(usize);

const WORKGROUP: u32 = 64;
/// Storage buffers `passes/select.wgsl` binds.
const STORAGE_BINDINGS: u32 = 6;

/// The pass needs compute shaders, storage buffers and indirect draws.
fn check_capabilities(gpu: &GpuContext, call: &'static str) -> Result<(), GpuError> {
    let flags = gpu.capabilities().downlevel;
    for (flag, name) in [
        (wgpu::DownlevelFlags::COMPUTE_SHADERS, "COMPUTE_SHADERS"),
        (
            wgpu::DownlevelFlags::INDIRECT_EXECUTION,
            "INDIRECT_EXECUTION",
        ),
    ] {
        if !flags.contains(flag) {
            return Err(GpuError::MissingCapability {
                call,
                capability: name,
                fallback: "select on the CPU with lodkit::select::select_batch",
            });
        }
    }
    let limits = gpu.device.limits();
    if limits.max_storage_buffers_per_shader_stage < STORAGE_BINDINGS {
        return Err(GpuError::TooLarge {
            call,
            parameter: "storage buffers of passes/select.wgsl",
            value: STORAGE_BINDINGS.into(),
            limit: "max_storage_buffers_per_shader_stage",
            max: limits.max_storage_buffers_per_shader_stage.into(),
        });
    }
    Ok(())
}

/// What one binding (and one buffer) of the device holds at most, in bytes.
fn binding_bytes(gpu: &GpuContext) -> u64 {
    let limits = gpu.device.limits();
    limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
}

/// A refused instance: what is wrong with it.
fn check_instance(i: usize, inst: &GpuLodInstance) -> Result<(), GpuError> {
    let finite = inst.center.iter().all(|c| c.is_finite())
        && inst.radius.is_finite()
        && inst.max_scale.is_finite();
    if !finite || inst.max_scale == 0.0 || inst.radius < 0.0 {
        return Err(GpuError::Invalid {
            call: "GpuLodSelector::set_instances",
            parameter: "instances",
            value: format!(
                "instance {i}: center {:?}, radius {}, max_scale {}",
                inst.center, inst.radius, inst.max_scale
            ),
            rule: "must have a finite center, a finite radius >= 0 and a finite, nonzero \
                   max_scale (a shader is given no infinity or NaN, and a zero scale would \
                   divide by zero)",
        });
    }
    Ok(())
}

impl GpuLodSelector {
    /// Builds the pipeline and the group table. Errors: a group with more than
    /// [`SELECT_MAX_LEVELS`](crate::select::SELECT_MAX_LEVELS) levels, invalid settings, more meshes than levels, a device without
    /// compute shaders or indirect execution ([`GpuError::MissingCapability`]).
    pub fn new(gpu: &GpuContext, desc: &GpuLodSelectorDescriptor) -> Result<Self, GpuError> {
        const CALL: &str = "GpuLodSelector::new";
        check_capabilities(gpu, CALL)?;
        desc.settings.validate().map_err(|e| GpuError::Invalid {
            call: CALL,
            parameter: "settings",
            value: e.to_string(),
            rule: "must be valid LodSettings",
        })?;
        if desc.meshes.len() > desc.groups.len() {
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "meshes",
                found: format!("{} groups of meshes", desc.meshes.len()),
                expected: format!("at most one per group ({})", desc.groups.len()),
            });
        }
        let mut groups = Vec::with_capacity(desc.groups.len().max(1));
        let mut slot_meshes = Vec::new();
        for (g, group) in desc.groups.iter().enumerate() {
            let data =
                group
                    .select_data(desc.settings.hysteresis)
                    .ok_or_else(|| GpuError::Invalid {
                        call: CALL,
                        parameter: "groups",
                        value: format!("group {g} with {} levels", group.levels().len()),
                        rule: "has more levels than the GPU selects (SELECT_MAX_LEVELS = 8)",
                    })?;
            let meshes = desc.meshes.get(g).copied().unwrap_or(&[]);
            if meshes.len() > group.levels().len() {
                return Err(GpuError::Mismatch {
                    call: CALL,
                    parameter: "meshes",
                    found: format!("{} meshes for group {g}", meshes.len()),
                    expected: format!("at most its {} levels", group.levels().len()),
                });
            }
            groups.push(GpuLodGroup::new(&data, slot_meshes.len() as u32));
            for level in 0..group.levels().len() {
                slot_meshes.push(meshes.get(level).copied().unwrap_or_default());
            }
        }
        let table: &[u8] = if groups.is_empty() {
            &[0; std::mem::size_of::<GpuLodGroup>()]
        } else {
            bytemuck::cast_slice(&groups)
        };
        let group_buffer = super::resources::buffer_with_data(
            gpu,
            table,
            wgpu::BufferUsages::STORAGE,
            "lodkit select groups",
        )?;
        let module = gpu.pass_module("select", &[])?;
        let pipeline = gpu.guarded(CALL, || {
            Ok(gpu
                .device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("lodkit select"),
                    layout: None,
                    module: &module,
                    entry_point: Some("select_main"),
                    compilation_options: Default::default(),
                    cache: None,
                }))
        })?;
        let mut selector = Self {
            settings: desc.settings,
            groups,
            slot_meshes,
            pipeline,
            group_buffer,
            chunks: Vec::new(),
            template: None,
            slots: Vec::new(),
            instance_count: 0,
            views: Vec::new(),
        };
        selector.set_instances(gpu, &[])?;
        Ok(selector)
    }

    /// Uploads the instances and lays out the lists (each (group, level) list holds as many
    /// entries as its group has instances). Every view's state starts over (no history).
    ///
    /// Instances that one storage binding cannot hold with their states and lists
    /// (`max_storage_buffer_binding_size`, `max_buffer_size`) are split into chunks, each
    /// selected by a dispatch of its own, each list with one range per chunk
    /// ([`chunk_count`](Self::chunk_count), [`slots`](Self::slots)); so one selector takes as
    /// many instances as the device's memory holds. Errors: an instance with a NaN or infinite
    /// center, radius or scale, or a zero scale ([`GpuError::Invalid`]); more than `u32::MAX`
    /// instances, or a binding too small for one instance's lists ([`GpuError::TooLarge`]);
    /// buffers the device cannot allocate ([`GpuError::OutOfMemory`] and the like).
    pub fn set_instances(
        &mut self,
        gpu: &GpuContext,
        instances: &[GpuLodInstance],
    ) -> Result<(), GpuError> {
        const CALL: &str = "GpuLodSelector::set_instances";
        let count = u32::try_from(instances.len()).map_err(|_| GpuError::TooLarge {
            call: CALL,
            parameter: "instances",
            value: instances.len() as u64,
            limit: "u32::MAX (instance indices are 32-bit)",
            max: u64::from(u32::MAX),
        })?;
        for (i, inst) in instances.iter().enumerate() {
            check_instance(i, inst)?;
        }
        let limits = gpu.device.limits();
        let align = u64::from(limits.min_storage_buffer_offset_alignment);
        let max = binding_bytes(gpu);
        let max_count =
            chunks::grid_capacity(WORKGROUP, limits.max_compute_workgroups_per_dimension);
        let slot_count = self.slot_meshes.len() as u32;
        let plans = chunks::plan(instances, &self.groups, slot_count, align, (max, max_count))
            .map_err(|e| GpuError::TooLarge {
                call: CALL,
                parameter: "one instance's entry in every list of its group (bytes)",
                value: e.needed,
                limit: "max_storage_buffer_binding_size",
                max,
            })?;
        let mut buffers = Vec::with_capacity(plans.len());
        for plan in plans {
            let range = plan.first as usize..(plan.first + plan.count) as usize;
            let bytes: &[u8] = bytemuck::cast_slice(&instances[range]);
            let instance_buffer = create(
                gpu,
                CALL,
                (bytes.len() as u64).max(INSTANCE_BYTES),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                "lodkit select instances",
            )?;
            gpu.guarded(CALL, || {
                gpu.queue.write_buffer(&instance_buffer, 0, bytes);
                Ok(())
            })?;
            let firsts: Vec<u32> = plan
                .slots
                .iter()
                .map(|s| (s.entries_offset / ENTRY_BYTES) as u32)
                .chain(std::iter::once(0)) // a group-less table still binds a word
                .collect();
            let slot_first = super::resources::buffer_with_data(
                gpu,
                bytemuck::cast_slice(&firsts),
                wgpu::BufferUsages::STORAGE,
                "lodkit select slots",
            )?;
            let info = GpuSelectChunk {
                first_instance: plan.first,
                count: plan.count,
                draw_base: buffers.len() as u32 * slot_count,
                pad: 0,
            };
            let info = super::resources::buffer_with_data(
                gpu,
                bytemuck::bytes_of(&info),
                wgpu::BufferUsages::UNIFORM,
                "lodkit select chunk",
            )?;
            buffers.push(ChunkBuffers {
                plan,
                instances: instance_buffer,
                slot_first,
                info,
            });
        }
        let template: Vec<u32> = (0..buffers.len())
            .flat_map(|_| self.slot_meshes.iter())
            .flat_map(|m| [m.index_count, 0, m.first_index, m.base_vertex as u32, 0])
            .collect();
        self.template = if template.is_empty() {
            None
        } else {
            Some(super::resources::buffer_with_data(
                gpu,
                bytemuck::cast_slice(&template),
                wgpu::BufferUsages::COPY_SRC,
                "lodkit select draw template",
            )?)
        };
        self.slots = buffers.iter().flat_map(|c| c.plan.slots.clone()).collect();
        self.chunks = buffers;
        self.instance_count = count;
        for v in 0..self.views.len() {
            self.views[v] = self.make_view(gpu, CALL)?;
        }
        Ok(())
    }

    /// Adds a view (a camera with its own states and lists) and returns its handle.
    pub fn add_view(&mut self, gpu: &GpuContext) -> Result<ViewId, GpuError> {
        let view = self.make_view(gpu, "GpuLodSelector::add_view")?;
        self.views.push(view);
        Ok(ViewId(self.views.len() - 1))
    }

    /// Records one view's selection for `frame` into `encoder`: the camera upload, the reset of
    /// the counts (a copy of the draw template) and one dispatch per chunk. Nothing is read back.
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        view: ViewId,
        frame: &GpuSelectFrame,
    ) -> Result<(), GpuError> {
        const CALL: &str = "GpuLodSelector::record";
        let v = self.view(CALL, view)?;
        let camera = &frame.camera;
        if camera.bias.is_nan() || camera.bias < 0.0 {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "frame.camera.bias",
                value: camera.bias.to_string(),
                rule: "must be >= 0",
            });
        }
        let (kind, factor) = distance_kind(camera, &self.settings);
        let (mode, step) = self.settings.select_mode(frame.dt);
        let planes = frame
            .view_proj
            .map(|m| crate::select::frustum_planes(&m).map(|p| p.to_array()))
            .unwrap_or([[0.0, 0.0, 0.0, 1.0]; 6]);
        let uniform = GpuSelectCamera {
            planes,
            position: camera.position.to_array(),
            // An infinite bias is its own distance kind, which reads no factor: the shader is
            // given 0 rather than an infinity.
            factor: if factor.is_finite() { factor } else { 0.0 },
            distance_kind: kind,
            mode,
            step,
            frame: frame.frame,
            instance_count: self.instance_count,
            group_count: self.groups.len() as u32,
            frame_sequential: frame.frame_sequential as u32,
            cull: frame.view_proj.is_some() as u32,
        };
        let max_dim = gpu.device.limits().max_compute_workgroups_per_dimension;
        gpu.recording(CALL, || {
            gpu.queue
                .write_buffer(&v.camera, 0, bytemuck::bytes_of(&uniform));
            if let Some(template) = &self.template {
                encoder.copy_buffer_to_buffer(
                    template,
                    0,
                    &v.draws,
                    0,
                    template.size().min(v.draws.size()),
                );
            }
            if self.instance_count > 0 {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("lodkit select"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                for (chunk, vc) in self.chunks.iter().zip(&v.chunks) {
                    if chunk.plan.count == 0 {
                        continue;
                    }
                    let (x, y) = chunks::grid(chunk.plan.count, WORKGROUP, max_dim);
                    pass.set_bind_group(0, &vc.bind_group, &[]);
                    pass.dispatch_workgroups(x, y, 1);
                }
            }
            Ok(())
        })
    }

    fn view(&self, call: &'static str, view: ViewId) -> Result<&View, GpuError> {
        self.views.get(view.0).ok_or_else(|| GpuError::Mismatch {
            call,
            parameter: "view",
            found: format!("view {}", view.0),
            expected: format!(
                "one of the {} views added to this selector",
                self.views.len()
            ),
        })
    }

    /// Every list: per chunk, the (group, level) slots in order (group by group, level by
    /// level). With one chunk, one range per slot.
    pub fn slots(&self) -> &[SlotRange] {
        &self.slots
    }

    /// The range of `level` of `group` in `chunk`, if all three exist.
    pub fn slot(&self, group: usize, level: usize, chunk: u32) -> Option<SlotRange> {
        let g = self.groups.get(group)?;
        if level >= g.level_count as usize {
            return None;
        }
        let plan = &self.chunks.get(chunk as usize)?.plan;
        plan.slots.get(g.first_slot as usize + level).copied()
    }

    /// How many chunks the instances are split into (1 unless one storage binding cannot hold
    /// them; see [`set_instances`](Self::set_instances)).
    pub fn chunk_count(&self) -> u32 {
        self.chunks.len() as u32
    }

    /// The view's indirect arguments: one `DrawIndexedIndirectArgs` (20 bytes) per list (per
    /// chunk and slot), whose `instance_count` the last dispatch wrote. Draw a list with
    /// `draw_indexed_indirect(buffer, range.draw_offset)`.
    pub fn draws_buffer(&self, view: ViewId) -> Option<&wgpu::Buffer> {
        Some(&self.views.get(view.0)?.draws)
    }

    /// The view's list entries ([`GpuSelectEntry`]) of `chunk`; bind a list at
    /// `range.entries_offset` (a dynamic storage offset) so that `instance_index` indexes it.
    pub fn entries_buffer(&self, view: ViewId, chunk: u32) -> Option<&wgpu::Buffer> {
        Some(&self.views.get(view.0)?.chunks.get(chunk as usize)?.entries)
    }

    /// The view's states of `chunk`'s instances (8 bytes per instance: packed level | target <<
    /// 8 | phase bits, progress), from the chunk's first instance on.
    pub fn states_buffer(&self, view: ViewId, chunk: u32) -> Option<&wgpu::Buffer> {
        Some(&self.views.get(view.0)?.chunks.get(chunk as usize)?.states)
    }

    /// Instances set.
    pub fn instance_count(&self) -> u32 {
        self.instance_count
    }
}

fn create(
    gpu: &GpuContext,
    call: &'static str,
    size: u64,
    usage: wgpu::BufferUsages,
    label: &'static str,
) -> Result<wgpu::Buffer, GpuError> {
    buffer_size(gpu, call, label, size)?;
    gpu.guarded(call, || {
        Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.div_ceil(4) * 4,
            usage,
            mapped_at_creation: false,
        }))
    })
}
