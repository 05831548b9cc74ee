// passes/select — GPU-driven LOD selection for one camera: per instance, the level(s) by
// lodkit's rule with the state kept in a buffer (lodkit::select), bounding-sphere frustum
// culling, and compaction into per-(group, level) instance lists whose counts are the
// instance_count of indexed indirect draws (DrawIndexedIndirectArgs). One dispatch per chunk of
// instances per camera per frame: a chunk is as many instances as one storage binding holds
// with their states and lists (the host splits them; most scenes have one). Workgroups of 64
// on a 2-D grid, so a chunk may hold more than max_compute_workgroups_per_dimension x 64
// instances; the host resets the counts before the dispatches (a buffer copy).
//
// Every instance's state is updated whether or not it is in the frustum, so a timed transition
// runs on out of view and the state equals select_batch's. An instance in transition is listed
// under both levels (screen-door, unpopping) or, with camera.frame_sequential set, only under the
// level this frame draws.
//
// Entry points:
//   select_main   @compute @workgroup_size(64)
//   push(slot, entry)   helper: appends an entry to a slot's list (atomic count, then the write)
// Bindings (group 0): 0 `camera: SelectCamera` (uniform), 1 `groups: array<SelectGroup>`,
//   2 `instances: array<SelectInstance>` (the chunk's), 3 `slot_first: array<u32>` (first entry
//   of each slot's list in the chunk's entries), 4 `states: array<SelectState>` (read_write, the
//   chunk's), 5 `draws: array<atomic<u32>>` (5 words per (chunk, slot): DrawIndexedIndirectArgs;
//   word 1 counted here), 6 `entries: array<SelectEntry>` (read_write, the chunk's), 7 `chunk:
//   SelectChunk` (uniform).
// Shader defs: none.
#import lodkit::select::{SelectGroup, SelectState, SELECT_NONE, select_distance, select_level, select_update_phase, select_draws_next, select_screen_door_alpha, select_sphere_visible}

/// Per-camera data (Rust mirror lodkit::gpu::select::GpuSelectCamera).
struct SelectCamera {
    /// Inward frustum planes (unit xyz normal, w offset): left, right, bottom, top, near, far.
    planes: array<vec4<f32>, 6>,
    position: vec3<f32>,
    /// camera bias x global bias / |P[1][1]|.
    factor: f32,
    /// SELECT_DISTANCE_* of lodkit::select.
    distance_kind: u32,
    /// SELECT_HARD / SELECT_DISTANCE / SELECT_TIME.
    mode: u32,
    /// dt / duration of a timed transition (0 for dt <= 0).
    step: f32,
    /// Frame index (its parity sets the frame-sequential phase).
    frame: u32,
    instance_count: u32,
    group_count: u32,
    /// 1: list an instance in transition only under the level this frame draws.
    frame_sequential: u32,
    /// 1: cull against the planes; 0: every visible instance is drawn.
    cull: u32,
}

/// The instances one dispatch selects (Rust mirror lodkit::gpu::select::GpuSelectChunk).
struct SelectChunk {
    /// Index of the chunk's first instance: list entries hold first_instance + local index.
    first_instance: u32,
    /// Instances in the chunk.
    count: u32,
    /// The chunk's first (chunk, slot) in `draws`.
    draw_base: u32,
    pad: u32,
}

/// One instance (32 bytes; Rust mirror lodkit::gpu::select::GpuLodInstance).
struct SelectInstance {
    /// Bounding-sphere center: the point distances are measured to.
    center: vec3<f32>,
    radius: f32,
    /// Largest world-scale component.
    max_scale: f32,
    /// Index into `groups`; past its end the instance selects nothing.
    group: u32,
    pad_a: u32,
    pad_b: u32,
}

/// One entry of a (group, level) list: what the draw of that level needs for this instance.
struct SelectEntry {
    /// Index of the instance.
    instance: u32,
    /// Bit 0: this is the incoming level of a transition; bit 1: the instance is in transition;
    /// bit 2: frame-sequential phase (parity of the frame the transition began).
    flags: u32,
    /// Progress of the transition (unpopping t, frame-sequential tau from it); 0 without one.
    transition: f32,
    /// Screen-door alpha of this level (negative: inverted pattern).
    alpha: f32,
}

@group(0) @binding(0) var<uniform> camera: SelectCamera;
@group(0) @binding(1) var<storage, read> groups: array<SelectGroup>;
@group(0) @binding(2) var<storage, read> instances: array<SelectInstance>;
@group(0) @binding(3) var<storage, read> slot_first: array<u32>;
@group(0) @binding(4) var<storage, read_write> states: array<SelectState>;
@group(0) @binding(5) var<storage, read_write> draws: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> entries: array<SelectEntry>;
@group(0) @binding(7) var<uniform> chunk: SelectChunk;

/// Appends `entry` to the chunk's list of `slot`.
fn push(slot: u32, entry: SelectEntry) {
    let k = atomicAdd(&draws[(chunk.draw_base + slot) * 5u + 1u], 1u);
    entries[slot_first[slot] + k] = entry;
}

/// Selects for one instance, writes its state and lists it under the level(s) it draws.
@compute @workgroup_size(64)
fn select_main(
    @builtin(workgroup_id) workgroup: vec3<u32>,
    @builtin(num_workgroups) grid: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    // The chunk's instance of this invocation: workgroups run row by row over a 2-D grid.
    let i = (workgroup.y * grid.x + workgroup.x) * 64u + local;
    if (i >= chunk.count) {
        return;
    }
    let inst = instances[i];
    if (inst.group >= camera.group_count) {
        return;
    }
    let group = groups[inst.group];
    let d = select_distance(inst.center, camera.position, camera.factor, inst.max_scale, camera.distance_kind);
    let outcome = select_level(d, group, camera.mode, camera.step, states[i]);
    let sel = outcome.selection;
    let state = select_update_phase(outcome.state, sel, camera.frame);
    states[i] = state;
    if (!sel.visible) {
        return;
    }
    if (camera.cull != 0u && !select_sphere_visible(inst.center, inst.radius, camera.planes)) {
        return;
    }
    let phase = (state.packed >> 14u) & 4u;
    if (sel.next == SELECT_NONE) {
        push(group.first_slot + sel.current, SelectEntry(chunk.first_instance + i, 0u, 0.0, sel.fade));
        return;
    }
    let draws_next = select_draws_next(state, camera.frame);
    if (camera.frame_sequential == 0u || !draws_next) {
        let alpha = select_screen_door_alpha(sel, false);
        push(group.first_slot + sel.current, SelectEntry(chunk.first_instance + i, 2u | phase, sel.transition, alpha));
    }
    if (camera.frame_sequential == 0u || draws_next) {
        let alpha = select_screen_door_alpha(sel, true);
        push(group.first_slot + sel.next, SelectEntry(chunk.first_instance + i, 3u | phase, sel.transition, alpha));
    }
}
