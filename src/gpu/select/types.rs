//! The host-side mirrors of the selection pass's structs and the descriptions a
//! [`GpuLodSelector`](super::GpuLodSelector) is built and driven with.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::select::{LodCamera, LodGroup, LodSettings, SELECT_MAX_LEVELS, SelectGroupData};

/// Rust mirror of `SelectInstance` in `passes/select.wgsl` (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLodInstance {
    /// Bounding-sphere center: the point distances are measured to.
    pub center: [f32; 3],
    /// Bounding-sphere radius (frustum culling).
    pub radius: f32,
    /// Largest world-scale component.
    pub max_scale: f32,
    /// Index of its group; past the table's end it selects nothing.
    pub group: u32,
    /// Padding.
    pub pad: [u32; 2],
}

impl GpuLodInstance {
    /// An instance at `center` with bounding radius `radius`, scale `max_scale`, in `group`.
    pub fn new(center: Vec3, radius: f32, max_scale: f32, group: u32) -> Self {
        Self {
            center: center.to_array(),
            radius,
            max_scale,
            group,
            pad: [0; 2],
        }
    }
}

/// Rust mirror of `SelectGroup` in `lodkit::select` (160 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLodGroup {
    /// (distance, band lo, band hi, 0) per level.
    pub levels: [[f32; 4]; SELECT_MAX_LEVELS],
    /// Levels in use.
    pub level_count: u32,
    /// Max draw distance (`f32::MAX` for none: no infinity reaches the shader).
    pub max_distance: f32,
    /// max_distance - hysteresis.
    pub fade_from: f32,
    /// Hysteresis.
    pub hysteresis: f32,
    /// First (group, level) slot of the group.
    pub first_slot: u32,
    /// Padding.
    pub pad: [u32; 3],
}

impl GpuLodGroup {
    /// The group `data` says (`LodGroup::select_data`), its levels' lists starting at the
    /// (group, level) slot `first_slot`.
    pub fn new(data: &SelectGroupData, first_slot: u32) -> Self {
        Self {
            levels: data.levels,
            level_count: data.level_count,
            max_distance: data.max_distance,
            fade_from: data.fade_from,
            hysteresis: data.hysteresis,
            first_slot,
            pad: [0; 3],
        }
    }
}

/// Rust mirror of `SelectCamera` in `passes/select.wgsl` (144 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuSelectCamera {
    /// Inward frustum planes.
    pub planes: [[f32; 4]; 6],
    /// Camera position.
    pub position: [f32; 3],
    /// Bias / |P\[1\]\[1\]|.
    pub factor: f32,
    /// `SELECT_DISTANCE_*`.
    pub distance_kind: u32,
    /// Transition mode (0 hard, 1 distance, 2 time).
    pub mode: u32,
    /// dt / duration.
    pub step: f32,
    /// Frame index.
    pub frame: u32,
    /// Instances to select, in all chunks.
    pub instance_count: u32,
    /// Groups in the table.
    pub group_count: u32,
    /// 1: frame-sequential routing.
    pub frame_sequential: u32,
    /// 1: frustum culling.
    pub cull: u32,
}

/// Rust mirror of `SelectChunk` in `passes/select.wgsl` (16 bytes): the instances one dispatch
/// selects.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuSelectChunk {
    /// Index of the chunk's first instance (what its list entries add to their local index).
    pub first_instance: u32,
    /// Instances in the chunk.
    pub count: u32,
    /// Index of the chunk's first `DrawIndexedIndirectArgs` in the draws buffer.
    pub draw_base: u32,
    /// Padding.
    pub pad: u32,
}

/// Rust mirror of `SelectEntry` in `passes/select.wgsl`: one instance in a (group, level) list.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuSelectEntry {
    /// Index of the instance.
    pub instance: u32,
    /// Bit 0 incoming level, bit 1 in transition, bit 2 frame-sequential phase.
    pub flags: u32,
    /// Transition progress (0 without one).
    pub transition: f32,
    /// Screen-door alpha of this level (negative: inverted pattern).
    pub alpha: f32,
}

/// What one level of a group draws: the indexed range of its mesh in the engine's buffers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelMesh {
    /// Indices per instance.
    pub index_count: u32,
    /// First index in the index buffer.
    pub first_index: u32,
    /// Added to each index.
    pub base_vertex: i32,
}

/// How to build a [`GpuLodSelector`](super::GpuLodSelector).
#[derive(Clone, Copy, Debug, Default)]
pub struct GpuLodSelectorDescriptor<'a> {
    /// The groups, at most [`SELECT_MAX_LEVELS`] levels each.
    pub groups: &'a [LodGroup],
    /// Bias, hysteresis and transition mode.
    pub settings: LodSettings,
    /// Per group, the mesh of each level (written into the indirect arguments); a group left out
    /// gets zeros (fill them in the engine's own copy, or read only the counts).
    pub meshes: &'a [&'a [LevelMesh]],
}

/// One camera's frame: what the dispatch reads besides the instances.
#[derive(Clone, Copy, Debug)]
pub struct GpuSelectFrame {
    /// The camera LOD is selected for (position, projection, bias).
    pub camera: LodCamera,
    /// World-to-clip matrix to cull against (wgpu depth \[0, 1\]); `None`: no culling.
    pub view_proj: Option<Mat4>,
    /// Frame time in seconds (time-driven transitions).
    pub dt: f32,
    /// Frame index: its parity sets the frame-sequential phase of a transition that begins.
    pub frame: u32,
    /// List an instance in transition only under the level this frame draws
    /// (frame-sequential interpolation); otherwise under both.
    pub frame_sequential: bool,
}

impl GpuSelectFrame {
    /// A frame of `camera` with no culling, dt 0, frame 0, both levels listed.
    pub fn new(camera: LodCamera) -> Self {
        Self {
            camera,
            view_proj: None,
            dt: 0.0,
            frame: 0,
            frame_sequential: false,
        }
    }
}

/// Where one (group, level) list of one chunk of instances lives in a view's buffers.
///
/// Instances are split into chunks when one storage binding cannot hold them all (see
/// [`GpuLodSelector::chunk_count`](super::GpuLodSelector::chunk_count)); most scenes have one
/// chunk, and then there is one range per (group, level) slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlotRange {
    /// The chunk of instances whose list this is: bind
    /// [`GpuLodSelector::entries_buffer`](super::GpuLodSelector::entries_buffer)`(view, chunk)`.
    pub chunk: u32,
    /// The (group, level) slot: group g's level k is slot `first_slot(g) + k`, in group order.
    pub slot: u32,
    /// Byte offset of its `DrawIndexedIndirectArgs` in
    /// [`GpuLodSelector::draws_buffer`](super::GpuLodSelector::draws_buffer).
    pub draw_offset: u64,
    /// Byte offset of its first entry in its chunk's entries buffer (aligned for a dynamic
    /// storage offset).
    pub entries_offset: u64,
    /// Entries it can hold (the group's instance count in the chunk).
    pub capacity: u32,
}
