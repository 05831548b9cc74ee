// lodkit::select — LOD selection per instance on the GPU, stateful (DigitalRune's rule:
// view-normalized distance, LOD bias, hysteresis band, max draw distance with fade-out; distance-
// or time-driven transitions). Rust twin: lodkit::select::LodGroup::select / select_batch.
//
// A group's levels and hysteresis bands come precomputed from the host (lodkit::gpu::select
// writes them from a LodGroup, so both sides compare the same floats). The per-instance state
// (settled level, target level, progress of a timed transition, frame-sequential phase) lives in a
// storage buffer per camera and is read and written once per frame; the state a new instance
// starts with is SELECT_STATE_NEW. Every function is pure: a compute pass (passes/select.wgsl,
// or an engine's own culling shader) loads a group, a state and an instance and calls them.
//
// Exports:
//   SELECT_MAX_LEVELS: u32   levels a group can have on the GPU (8)
//   SELECT_NONE: u32   `next` of a selection without a transition
//   SELECT_HARD, SELECT_DISTANCE, SELECT_TIME: u32   transition modes
//   SELECT_STATE_NEW: u32   packed word of a state with no history
//   SELECT_FAR: f32   1e38, the rule's +inf
//   SelectGroup   levels (x distance, y/z hysteresis band below the level), count, max distance
//   SelectState   packed level | target << 8 | phase << 16 | blending << 17, and progress
//   Selection     current, next, transition, fade, visible (LodSelection)
//   select_distance(center, camera_position, factor, max_scale, kind) -> f32   the distance
//       the rule compares: view-normalized and biased (kind: SELECT_DISTANCE_*)
//   SelectOutcome   what select_level returns: the selection and the state to store
//   select_level(distance, group, mode, step, state) -> SelectOutcome   the rule
//   select_update_phase(state, selection, frame) -> SelectState   frame-sequential phase: the
//       parity of the frame a transition began (kept while it runs)
//   select_draws_next(state, frame) -> bool   frame-sequential: whether this frame draws the
//       incoming level (else the outgoing)
//   select_screen_door_alpha(selection, incoming) -> f32   -(1 - t) x fade for the current
//       level, t x fade for the next (negative = inverted pattern), fade without a transition
//   select_sphere_visible(center, radius, planes) -> bool   bounding sphere against 6 planes
// Shader defs: none.
#define_import_path lodkit::select

/// Levels a group can have on the GPU.
const SELECT_MAX_LEVELS: u32 = 8u;
/// `Selection::next` when there is no transition.
const SELECT_NONE: u32 = 0xffffffffu;
/// Transition mode: switch at the band edges, no blend.
const SELECT_HARD: u32 = 0u;
/// Transition mode: blend across the hysteresis band.
const SELECT_DISTANCE: u32 = 1u;
/// Transition mode: switch at the band edges, then blend by `step` per frame.
const SELECT_TIME: u32 = 2u;
/// Packed state word with no history (level and target 255): the first selection takes the
/// level for the distance.
const SELECT_STATE_NEW: u32 = 0xffffu;
/// `select_distance` kind: a zero bias, every distance is 0 (LOD0).
const SELECT_DISTANCE_ZERO: u32 = 0u;
/// `select_distance` kind: perspective camera, distance x factor / scale.
const SELECT_DISTANCE_PERSPECTIVE: u32 = 1u;
/// `select_distance` kind: orthographic camera, factor / scale whatever the distance.
const SELECT_DISTANCE_ORTHOGRAPHIC: u32 = 2u;
/// `select_distance` kind: an infinite bias, every distance is SELECT_FAR (the last level).
const SELECT_DISTANCE_INFINITE: u32 = 3u;
/// What the rule uses for +inf, 1e38 (WGSL has no infinite constant): a NaN distance and an
/// infinite bias select as this, which gives the levels +inf gives; a max distance above it
/// counts as none.
const SELECT_FAR: f32 = 1e38;

/// One LOD group as the GPU selects it (160 bytes; Rust mirror lodkit::gpu::select::GpuLodGroup).
struct SelectGroup {
    /// Level i: x its distance, y and z the hysteresis band (lo, hi) around the boundary between
    /// levels i - 1 and i (unused for level 0), w unused. Sorted by distance.
    levels: array<vec4<f32>, 8>,
    /// Levels in use, 1 ..= SELECT_MAX_LEVELS.
    level_count: u32,
    /// Max draw distance; above SELECT_FAR for none (the host writes 3.4e38: no infinity).
    max_distance: f32,
    /// max_distance - hysteresis: where the fade-out begins.
    fade_from: f32,
    /// Hysteresis band width h (>= 0).
    hysteresis: f32,
    /// First (group, level) draw slot of the group: level k draws through slot first_slot + k.
    first_slot: u32,
    pad_a: u32,
    pad_b: u32,
    pad_c: u32,
}

/// The persistent part of one instance's selection for one camera.
struct SelectState {
    /// Bits 0-7 the settled level, 8-15 the target level (255 = no history), bit 16 the parity of
    /// the frame the running transition began, bit 17 set while a transition runs.
    packed: u32,
    /// Progress of a time-driven transition, in [0, 1).
    progress: f32,
}

/// What select_level returns: the selection and the state to store for the next frame.
struct SelectOutcome {
    /// What to draw this frame.
    selection: Selection,
    /// The state to store for the next frame.
    state: SelectState,
}

/// What to draw this frame for one instance (LodSelection).
struct Selection {
    /// The level shown (the outgoing one during a transition).
    current: u32,
    /// The level blended in, or SELECT_NONE.
    next: u32,
    /// Progress from current to next in [0, 1]; 0 without a transition.
    transition: f32,
    /// Fade near the max draw distance: (max - d) / h inside the last h, else 1.
    fade: f32,
    /// False beyond the max draw distance.
    visible: bool,
}

/// View-normalized, biased distance of an instance at `center` with largest world-scale
/// component `max_scale`: `distance(center, camera_position) * factor / |max_scale|` for a
/// perspective camera, `factor / |max_scale|` for an orthographic one, where
/// `factor = camera bias x global bias / |P[1][1]|` (LodCamera::lod_distance).
fn select_distance(center: vec3<f32>, camera_position: vec3<f32>, factor: f32, max_scale: f32, kind: u32) -> f32 {
    if (kind == SELECT_DISTANCE_ZERO) {
        return 0.0;
    }
    if (kind == SELECT_DISTANCE_INFINITE) {
        return SELECT_FAR;
    }
    if (kind == SELECT_DISTANCE_ORTHOGRAPHIC) {
        return factor / abs(max_scale);
    }
    let v = center - camera_position;
    let len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return len * factor / abs(max_scale);
}

/// Selects the level(s) to draw for view-normalized, biased distance `distance` in `group`
/// under transition mode `mode` (SELECT_HARD / _DISTANCE / _TIME) from `state`, returning the
/// selection and the state to store; `step` is
/// dt / duration for time-driven transitions (0 when dt is not positive). The same rule, float
/// for float, as LodGroup::select.
fn select_level(distance: f32, group: SelectGroup, mode: u32, step: f32, state: SelectState) -> SelectOutcome {
    // Negative counts as 0. A NaN distance (a NaN position or scale) counts as SELECT_FAR where
    // the GPU keeps the NaN (found from its bits: compilers may fold `d != d`); WGSL promises
    // nothing for NaN or infinity, so the host refuses such instances and this is only a guard.
    var d = max(distance, 0.0);
    if ((bitcast<u32>(distance) & 0x7fffffffu) > 0x7f800000u) {
        d = SELECT_FAR;
    }
    let n = min(group.level_count, SELECT_MAX_LEVELS);
    // A max distance above SELECT_FAR is none.
    if (group.max_distance <= SELECT_FAR && d >= group.max_distance) {
        return SelectOutcome(Selection(n - 1u, SELECT_NONE, 0.0, 0.0, false), SelectState(SELECT_STATE_NEW, 0.0));
    }
    var level = state.packed & 0xffu;
    var target_level = (state.packed >> 8u) & 0xffu;
    var progress = state.progress;
    // Fast path: settled on a level and outside every band around it.
    if (level < n && target_level == level && d < group.fade_from) {
        var above = vec2<f32>(SELECT_FAR, SELECT_FAR);
        if (level + 1u < n) {
            above = group.levels[level + 1u].yz;
        }
        var below = vec2<f32>(-SELECT_FAR, -SELECT_FAR);
        if (level > 0u) {
            below = group.levels[level].yz;
        }
        var lo_edge = below.y;
        var hi_edge = above.x;
        if (mode == SELECT_HARD) {
            lo_edge = below.x;
            hi_edge = above.y;
        }
        if (d >= lo_edge && d < hi_edge) {
            return SelectOutcome(Selection(level, SELECT_NONE, 0.0, 1.0, true), state);
        }
    }
    let margin = group.max_distance - d;
    var fade = 1.0;
    if (margin < group.hysteresis) {
        fade = margin / group.hysteresis;
    }
    if (level >= n) {
        // The level for d with no hysteresis: the last whose distance is <= d.
        level = 0u;
        for (var i = 1u; i < SELECT_MAX_LEVELS; i++) {
            if (i >= n || group.levels[i].x > d) {
                break;
            }
            level = i;
        }
        target_level = level;
        progress = 0.0;
    }
    // Stateful hysteresis, from the level being approached.
    var desired = target_level;
    for (var k = 0u; k < SELECT_MAX_LEVELS; k++) {
        if (!(desired + 1u < n && d >= group.levels[desired + 1u].yz.y)) {
            break;
        }
        desired += 1u;
    }
    for (var k = 0u; k < SELECT_MAX_LEVELS; k++) {
        if (!(desired > 0u && d < group.levels[desired].yz.x)) {
            break;
        }
        desired -= 1u;
    }
    var sel = Selection(desired, SELECT_NONE, 0.0, fade, true);
    if (mode != SELECT_TIME) {
        level = desired;
        target_level = desired;
        if (mode == SELECT_DISTANCE) {
            // Blend toward the neighbour whose band d is in.
            var done = false;
            if (level + 1u < n) {
                let b = group.levels[level + 1u].yz;
                if (b.y > b.x && d >= b.x) {
                    sel.next = level + 1u;
                    sel.transition = clamp((d - b.x) / (b.y - b.x), 0.0, 1.0);
                    done = true;
                }
            }
            if (!done && level > 0u) {
                let b = group.levels[level].yz;
                if (b.y > b.x && d < b.y) {
                    sel.next = level - 1u;
                    sel.transition = clamp((b.y - d) / (b.y - b.x), 0.0, 1.0);
                }
            }
        }
    } else {
        if (target_level != level) {
            if (desired == level) {
                // Turned back: the same blend runs the other way, without a jump.
                level = target_level;
                target_level = desired;
                progress = 1.0 - progress;
            } else if (desired != target_level) {
                // A third level: start over from whichever level dominates now.
                if (progress >= 0.5) {
                    level = target_level;
                }
                target_level = desired;
                progress = 0.0;
            }
        } else if (desired != level) {
            target_level = desired;
            progress = 0.0;
        }
        if (target_level != level) {
            progress = clamp(progress + step, 0.0, 1.0);
            if (progress >= 1.0) {
                level = target_level;
                progress = 0.0;
            }
        }
        sel.current = level;
        if (target_level != level) {
            sel.next = target_level;
            sel.transition = progress;
        }
    }
    let packed = (state.packed & 0xffff0000u) | (level & 0xffu) | ((target_level & 0xffu) << 8u);
    return SelectOutcome(sel, SelectState(packed, progress));
}

/// `state` with the frame-sequential phase kept: when `selection` starts a transition (none ran
/// last frame), bit 16 takes the parity of `frame`; bit 17 records whether one runs now.
fn select_update_phase(state: SelectState, selection: Selection, frame: u32) -> SelectState {
    let blending = selection.next != SELECT_NONE;
    let was = (state.packed & 0x20000u) != 0u;
    var packed = state.packed & 0xffffu;
    if (blending) {
        var phase = frame & 1u;
        if (was) {
            phase = (state.packed >> 16u) & 1u;
        }
        packed = packed | (phase << 16u) | 0x20000u;
    }
    return SelectState(packed, state.progress);
}

/// Frame-sequential interpolation draws one level of a transition per frame: the outgoing on the
/// frame the transition began and every other frame after, the incoming between.
fn select_draws_next(state: SelectState, frame: u32) -> bool {
    return (frame & 1u) != ((state.packed >> 16u) & 1u);
}

/// Screen-door alpha of the current level (`incoming` false) or of the next one (true):
/// -(1 - t) x fade and t x fade; without a transition the current level gets fade.
fn select_screen_door_alpha(selection: Selection, incoming: bool) -> f32 {
    if (selection.next == SELECT_NONE) {
        return selection.fade;
    }
    if (incoming) {
        return selection.transition * selection.fade;
    }
    return -(1.0 - selection.transition) * selection.fade;
}

/// Whether a bounding sphere is at least partly inside the six planes (xyz unit normal pointing
/// inward, w offset): dot(n, center) + w >= -radius for every plane.
fn select_sphere_visible(center: vec3<f32>, radius: f32, planes: array<vec4<f32>, 6>) -> bool {
    var inside = true;
    for (var i = 0u; i < 6u; i++) {
        let p = planes[i];
        if (p.x * center.x + p.y * center.y + p.z * center.z + p.w < -radius) {
            inside = false;
        }
    }
    return inside;
}
