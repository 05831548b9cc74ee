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
//!     meshes: &[],
//! })?;
//! selector.set_instances(&gpu, &[GpuLodInstance::new(glam::Vec3::ZERO, 1.0, 1.0, 0)])?;
//! let view = selector.add_view(&gpu)?;
//! let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 500.0);
//! let mut encoder = gpu.device.create_command_encoder(&Default::default());
//! selector.record(&gpu, &mut encoder, view, &GpuSelectFrame::new(LodCamera::new(glam::Vec3::Z * 5.0, proj)))?;
//! gpu.queue.submit([encoder.finish()]);
//! # Ok(()) }
//! ```

mod types;

pub use types::{
    GpuLodGroup, GpuLodInstance, GpuLodSelectorDescriptor, GpuSelectCamera, GpuSelectEntry,
    GpuSelectFrame, LevelMesh, SlotRange,
};

use super::GpuContext;
use super::error::{GpuError, buffer_size};
use crate::select::{LodSettings, distance_kind};

/// A view's selection read back (tests and debugging): per instance its state (packed word,
/// progress bits), per slot its list.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelectReadback {
    /// (level | target << 8 | phase << 16 | in transition << 17, progress as f32 bits).
    pub states: Vec<[u32; 2]>,
    /// The entries of each (group, level) list, in slot order.
    pub lists: Vec<Vec<GpuSelectEntry>>,
}

/// One camera's buffers.
struct View {
    camera: wgpu::Buffer,
    states: wgpu::Buffer,
    draws: wgpu::Buffer,
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
    instances: Option<wgpu::Buffer>,
    slot_first: Option<wgpu::Buffer>,
    template: Option<wgpu::Buffer>,
    slots: Vec<SlotRange>,
    instance_count: u32,
    capacity: u32,
    entry_capacity: u64,
    views: Vec<View>,
}

/// Handle of a view (camera) of a [`GpuLodSelector`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewId(usize);

const WORKGROUP: u32 = 64;
const ENTRY_BYTES: u64 = std::mem::size_of::<GpuSelectEntry>() as u64;
const DRAW_BYTES: u64 = 20;

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
    if limits.max_storage_buffers_per_shader_stage < 6 {
        return Err(GpuError::TooLarge {
            call,
            parameter: "storage buffers of passes/select.wgsl",
            value: 6,
            limit: "max_storage_buffers_per_shader_stage",
            max: limits.max_storage_buffers_per_shader_stage.into(),
        });
    }
    Ok(())
}

impl GpuLodSelector {
    /// Builds the pipeline and the group table. Errors: a group with more than
    /// [`SELECT_MAX_LEVELS`] levels, invalid settings, more meshes than levels, a device without
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
            groups.push(GpuLodGroup {
                levels: data.levels,
                level_count: data.level_count,
                max_distance: data.max_distance,
                fade_from: data.fade_from,
                hysteresis: data.hysteresis,
                first_slot: slot_meshes.len() as u32,
                pad: [0; 3],
            });
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
        Ok(Self {
            settings: desc.settings,
            groups,
            slot_meshes,
            pipeline,
            group_buffer,
            instances: None,
            slot_first: None,
            template: None,
            slots: Vec::new(),
            instance_count: 0,
            capacity: 0,
            entry_capacity: 0,
            views: Vec::new(),
        })
    }

    /// Uploads the instances and lays out the lists (each (group, level) list holds as many
    /// entries as its group has instances). Every view's state starts over (no history). Buffers
    /// grow to the next power of two when they are too small, and are kept otherwise. Errors: more
    /// instances than one dispatch covers, or buffers larger than the device allows.
    pub fn set_instances(
        &mut self,
        gpu: &GpuContext,
        instances: &[GpuLodInstance],
    ) -> Result<(), GpuError> {
        const CALL: &str = "GpuLodSelector::set_instances";
        let limits = gpu.device.limits();
        let max = u64::from(limits.max_compute_workgroups_per_dimension) * u64::from(WORKGROUP);
        if instances.len() as u64 > max {
            return Err(GpuError::TooLarge {
                call: CALL,
                parameter: "instances",
                value: instances.len() as u64,
                limit: "max_compute_workgroups_per_dimension x 64",
                max,
            });
        }
        let align = u64::from(limits.min_storage_buffer_offset_alignment).max(ENTRY_BYTES);
        let mut per_group = vec![0u32; self.groups.len()];
        for inst in instances {
            if let Some(c) = per_group.get_mut(inst.group as usize) {
                *c += 1;
            }
        }
        let mut slots = Vec::with_capacity(self.slot_meshes.len());
        let mut entries = 0u64;
        for (g, group) in self.groups.iter().enumerate() {
            for level in 0..group.level_count {
                slots.push(SlotRange {
                    draw_offset: u64::from(group.first_slot + level) * DRAW_BYTES,
                    entries_offset: entries,
                    capacity: per_group[g],
                });
                entries += (u64::from(per_group[g]) * ENTRY_BYTES).div_ceil(align) * align;
            }
        }
        let entry_bytes = entries.max(ENTRY_BYTES);
        let binding_max = limits.max_storage_buffer_binding_size;
        if entry_bytes > binding_max {
            return Err(GpuError::TooLarge {
                call: CALL,
                parameter: "instance lists (bytes)",
                value: entry_bytes,
                limit: "max_storage_buffer_binding_size",
                max: binding_max,
            });
        }
        buffer_size(gpu, CALL, "instance lists", entry_bytes)?;
        let count = instances.len() as u32;
        let grow = count > self.capacity || entry_bytes > self.entry_capacity;
        if grow {
            self.capacity = count.max(1).next_power_of_two().max(self.capacity);
            self.entry_capacity = entry_bytes.next_power_of_two().max(self.entry_capacity);
            if self.entry_capacity > binding_max {
                self.entry_capacity = entry_bytes;
            }
        }
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let inst_bytes = u64::from(self.capacity) * std::mem::size_of::<GpuLodInstance>() as u64;
        buffer_size(gpu, CALL, "instances", inst_bytes)?;
        if grow || self.instances.is_none() {
            self.instances = Some(create(
                gpu,
                CALL,
                inst_bytes,
                storage,
                "lodkit select instances",
            )?);
        }
        let template: Vec<u32> = self
            .slot_meshes
            .iter()
            .flat_map(|m| [m.index_count, 0, m.first_index, m.base_vertex as u32, 0])
            .collect();
        let firsts: Vec<u32> = slots
            .iter()
            .map(|s| (s.entries_offset / ENTRY_BYTES) as u32)
            .collect();
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        self.template = Some(super::resources::buffer_with_data(
            gpu,
            bytemuck::cast_slice(&template),
            usage,
            "lodkit select draw template",
        )?);
        self.slot_first = Some(super::resources::buffer_with_data(
            gpu,
            bytemuck::cast_slice(&firsts),
            wgpu::BufferUsages::STORAGE,
            "lodkit select slots",
        )?);
        let buffer = self.instances.as_ref().expect("created above");
        gpu.guarded(CALL, || {
            gpu.queue
                .write_buffer(buffer, 0, bytemuck::cast_slice(instances));
            Ok(())
        })?;
        self.slots = slots;
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

    fn make_view(&self, gpu: &GpuContext, call: &'static str) -> Result<View, GpuError> {
        let capacity = u64::from(self.capacity.max(1));
        let states_bytes = capacity * 8;
        buffer_size(gpu, call, "states", states_bytes)?;
        let new_states = vec![[crate::select::LodState::NEW.packed(), 0u32]; capacity as usize];
        let rw = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let states = super::resources::buffer_with_data(
            gpu,
            bytemuck::cast_slice(&new_states),
            rw,
            "lodkit select states",
        )?;
        let draw_bytes = (self.slot_meshes.len().max(1) as u64) * DRAW_BYTES;
        let draws = create(
            gpu,
            call,
            draw_bytes,
            rw | wgpu::BufferUsages::INDIRECT,
            "lodkit select draws",
        )?;
        let entries = create(
            gpu,
            call,
            self.entry_capacity.max(ENTRY_BYTES),
            rw,
            "lodkit select entries",
        )?;
        let camera = super::resources::uniform_buffer(
            gpu,
            std::mem::size_of::<GpuSelectCamera>(),
            "lodkit select camera",
        )?;
        let dummy;
        let (instances, slot_first) = match (&self.instances, &self.slot_first) {
            (Some(i), Some(s)) => (i, s),
            _ => {
                dummy = create(
                    gpu,
                    call,
                    64,
                    wgpu::BufferUsages::STORAGE,
                    "lodkit select empty",
                )?;
                (&dummy, &dummy)
            }
        };
        let buffers = [
            &camera,
            &self.group_buffer,
            instances,
            slot_first,
            &states,
            &draws,
            &entries,
        ];
        let bind_group = gpu.guarded(call, || {
            let entries: Vec<wgpu::BindGroupEntry> = buffers
                .iter()
                .enumerate()
                .map(|(k, b)| wgpu::BindGroupEntry {
                    binding: k as u32,
                    resource: b.as_entire_binding(),
                })
                .collect();
            Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("lodkit select"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &entries,
            }))
        })?;
        Ok(View {
            camera,
            states,
            draws,
            entries,
            bind_group,
        })
    }

    /// Records one view's selection for `frame` into `encoder`: the camera upload, the reset of
    /// the counts (a copy of the draw template) and one dispatch. Nothing is read back.
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
            factor,
            distance_kind: kind,
            mode,
            step,
            frame: frame.frame,
            instance_count: self.instance_count,
            group_count: self.groups.len() as u32,
            frame_sequential: frame.frame_sequential as u32,
            cull: frame.view_proj.is_some() as u32,
        };
        gpu.guarded(CALL, || {
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
                pass.set_bind_group(0, &v.bind_group, &[]);
                pass.dispatch_workgroups(self.instance_count.div_ceil(WORKGROUP), 1, 1);
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

    /// The (group, level) lists in slot order (group by group, level by level).
    pub fn slots(&self) -> &[SlotRange] {
        &self.slots
    }

    /// The slot of `level` of `group`, if both exist.
    pub fn slot(&self, group: usize, level: usize) -> Option<SlotRange> {
        let g = self.groups.get(group)?;
        if level >= g.level_count as usize {
            return None;
        }
        self.slots.get(g.first_slot as usize + level).copied()
    }

    /// The view's indirect arguments: one `DrawIndexedIndirectArgs` (20 bytes) per slot, whose
    /// `instance_count` the last dispatch wrote. Draw slot s with
    /// `draw_indexed_indirect(buffer, slot.draw_offset)`.
    pub fn draws_buffer(&self, view: ViewId) -> Option<&wgpu::Buffer> {
        Some(&self.views.get(view.0)?.draws)
    }

    /// The view's lists of [`GpuSelectEntry`]; bind slot s at `slot.entries_offset` (a dynamic
    /// storage offset) so that `instance_index` indexes its list.
    pub fn entries_buffer(&self, view: ViewId) -> Option<&wgpu::Buffer> {
        Some(&self.views.get(view.0)?.entries)
    }

    /// The view's state buffer (8 bytes per instance: packed level | target << 8 | phase bits,
    /// progress).
    pub fn states_buffer(&self, view: ViewId) -> Option<&wgpu::Buffer> {
        Some(&self.views.get(view.0)?.states)
    }

    /// Instances set.
    pub fn instance_count(&self) -> u32 {
        self.instance_count
    }

    /// Reads a view's states and lists back (tests and debugging, not the frame loop): the
    /// states (packed word, progress) of every instance, and each slot's entries.
    pub fn read_back(&self, gpu: &GpuContext, view: ViewId) -> Result<SelectReadback, GpuError> {
        const CALL: &str = "GpuLodSelector::read_back";
        let v = self.view(CALL, view)?;
        let read = |buffer: &wgpu::Buffer, size: u64| {
            let encoder = gpu.device.create_command_encoder(&Default::default());
            super::readback::read_buffer(gpu, encoder, buffer, size)
        };
        let states_bytes = read(&v.states, u64::from(self.instance_count.max(1)) * 8)?;
        let mut states: Vec<[u32; 2]> = bytemuck::pod_collect_to_vec(&states_bytes);
        states.truncate(self.instance_count as usize);
        let draws: Vec<u32> = bytemuck::pod_collect_to_vec(&read(&v.draws, v.draws.size())?);
        let entries: Vec<GpuSelectEntry> =
            bytemuck::pod_collect_to_vec(&read(&v.entries, v.entries.size())?);
        let lists = self
            .slots
            .iter()
            .enumerate()
            .map(|(s, slot)| {
                let first = (slot.entries_offset / ENTRY_BYTES) as usize;
                let n = (draws[s * 5 + 1] as usize).min(slot.capacity as usize);
                entries[first..first + n].to_vec()
            })
            .collect();
        Ok(SelectReadback { states, lists })
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
