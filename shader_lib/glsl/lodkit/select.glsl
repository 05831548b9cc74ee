// lodkit::select — LOD selection per instance on the GPU, stateful (DigitalRune's rule:
// view-normalized distance, LOD bias, hysteresis band, max draw distance with fade-out; distance-
// or time-driven transitions). Rust twin: lodkit::select::LodGroup::select / select_batch.
//
// GLSL twin of shader_lib/wgsl/lodkit/select.wgsl; same semantics, `lodkit_` prefix (constants
// `LODKIT_` prefix).
//
// Exports:
//   LODKIT_SELECT_MAX_LEVELS, LODKIT_SELECT_NONE, LODKIT_SELECT_HARD / _DISTANCE / _TIME,
//   LODKIT_SELECT_STATE_NEW, LODKIT_SELECT_DISTANCE_ZERO / _PERSPECTIVE / _ORTHOGRAPHIC / _INFINITE,
//   LODKIT_SELECT_FAR
//   LodkitSelectGroup, LodkitSelectState, LodkitSelection, LodkitSelectOutcome   (the WGSL structs)
//   lodkit_select_distance(center, camera_position, factor, max_scale, kind) -> float
//   lodkit_select_level(distance, group, mode, step, state) -> LodkitSelectOutcome
//   lodkit_select_update_phase(state, selection, frame) -> LodkitSelectState
//   lodkit_select_draws_next(state, frame) -> bool
//   lodkit_select_screen_door_alpha(selection, incoming) -> float
//   lodkit_select_sphere_visible(center, radius, planes) -> bool
// Shader defs: none.
#ifndef LODKIT_SELECT_GLSL
#define LODKIT_SELECT_GLSL

/// Levels a group can have on the GPU.
const uint LODKIT_SELECT_MAX_LEVELS = 8u;
/// `next` of a selection without a transition.
const uint LODKIT_SELECT_NONE = 0xffffffffu;
/// Transition modes.
const uint LODKIT_SELECT_HARD = 0u;
const uint LODKIT_SELECT_DISTANCE = 1u;
const uint LODKIT_SELECT_TIME = 2u;
/// Packed state word with no history.
const uint LODKIT_SELECT_STATE_NEW = 0xffffu;
/// lodkit_select_distance kinds.
const uint LODKIT_SELECT_DISTANCE_ZERO = 0u;
const uint LODKIT_SELECT_DISTANCE_PERSPECTIVE = 1u;
const uint LODKIT_SELECT_DISTANCE_ORTHOGRAPHIC = 2u;
const uint LODKIT_SELECT_DISTANCE_INFINITE = 3u;
/// 1e38, the rule's +inf (SELECT_FAR of the WGSL module).
const float LODKIT_SELECT_FAR = 1e38;

/// One LOD group (std430 layout as SelectGroup: 160 bytes).
struct LodkitSelectGroup {
    vec4 levels[8];
    uint level_count;
    float max_distance;
    float fade_from;
    float hysteresis;
    uint first_slot;
    uint pad_a;
    uint pad_b;
    uint pad_c;
};

/// Persistent selection state of one instance for one camera.
struct LodkitSelectState {
    uint packed;
    float progress;
};

/// What to draw this frame for one instance.
struct LodkitSelection {
    uint current;
    uint next;
    float transition;
    float fade;
    bool visible;
};

/// What lodkit_select_level returns: the selection and the state to store.
struct LodkitSelectOutcome {
    LodkitSelection selection;
    LodkitSelectState state;
};

/// View-normalized, biased distance (see the WGSL module).
float lodkit_select_distance(vec3 center, vec3 camera_position, float factor, float max_scale, uint kind) {
    if (kind == LODKIT_SELECT_DISTANCE_ZERO) {
        return 0.0;
    }
    if (kind == LODKIT_SELECT_DISTANCE_INFINITE) {
        return LODKIT_SELECT_FAR;
    }
    if (kind == LODKIT_SELECT_DISTANCE_ORTHOGRAPHIC) {
        return factor / abs(max_scale);
    }
    vec3 v = center - camera_position;
    float len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return len * factor / abs(max_scale);
}

/// The selection rule (LodGroup::select): the selection and the state to store.
LodkitSelectOutcome lodkit_select_level(float distance, LodkitSelectGroup group, uint mode, float step, LodkitSelectState state) {
    // NaN counts as LODKIT_SELECT_FAR (found from its bits), negative as 0.
    float d = max(distance, 0.0);
    if ((floatBitsToUint(distance) & 0x7fffffffu) > 0x7f800000u) {
        d = LODKIT_SELECT_FAR;
    }
    uint n = min(group.level_count, LODKIT_SELECT_MAX_LEVELS);
    if (group.max_distance <= LODKIT_SELECT_FAR && d >= group.max_distance) {
        return LodkitSelectOutcome(LodkitSelection(n - 1u, LODKIT_SELECT_NONE, 0.0, 0.0, false), LodkitSelectState(LODKIT_SELECT_STATE_NEW, 0.0));
    }
    uint level = state.packed & 0xffu;
    uint target_level = (state.packed >> 8u) & 0xffu;
    float progress = state.progress;
    if (level < n && target_level == level && d < group.fade_from) {
        vec2 above = vec2(LODKIT_SELECT_FAR, LODKIT_SELECT_FAR);
        if (level + 1u < n) {
            above = group.levels[level + 1u].yz;
        }
        vec2 below = vec2(-LODKIT_SELECT_FAR, -LODKIT_SELECT_FAR);
        if (level > 0u) {
            below = group.levels[level].yz;
        }
        float from_d = mode == LODKIT_SELECT_HARD ? below.x : below.y;
        float to_d = mode == LODKIT_SELECT_HARD ? above.y : above.x;
        if (d >= from_d && d < to_d) {
            return LodkitSelectOutcome(LodkitSelection(level, LODKIT_SELECT_NONE, 0.0, 1.0, true), state);
        }
    }
    float margin = group.max_distance - d;
    float fade = 1.0;
    if (margin < group.hysteresis) {
        fade = margin / group.hysteresis;
    }
    if (level >= n) {
        level = 0u;
        for (uint i = 1u; i < LODKIT_SELECT_MAX_LEVELS; i++) {
            if (i >= n || group.levels[i].x > d) {
                break;
            }
            level = i;
        }
        target_level = level;
        progress = 0.0;
    }
    uint desired = target_level;
    for (uint k = 0u; k < LODKIT_SELECT_MAX_LEVELS; k++) {
        if (!(desired + 1u < n && d >= group.levels[desired + 1u].yz.y)) {
            break;
        }
        desired += 1u;
    }
    for (uint k = 0u; k < LODKIT_SELECT_MAX_LEVELS; k++) {
        if (!(desired > 0u && d < group.levels[desired].yz.x)) {
            break;
        }
        desired -= 1u;
    }
    LodkitSelection sel = LodkitSelection(desired, LODKIT_SELECT_NONE, 0.0, fade, true);
    if (mode != LODKIT_SELECT_TIME) {
        level = desired;
        target_level = desired;
        if (mode == LODKIT_SELECT_DISTANCE) {
            bool done = false;
            if (level + 1u < n) {
                vec2 b = group.levels[level + 1u].yz;
                if (b.y > b.x && d >= b.x) {
                    sel.next = level + 1u;
                    sel.transition = clamp((d - b.x) / (b.y - b.x), 0.0, 1.0);
                    done = true;
                }
            }
            if (!done && level > 0u) {
                vec2 b = group.levels[level].yz;
                if (b.y > b.x && d < b.y) {
                    sel.next = level - 1u;
                    sel.transition = clamp((b.y - d) / (b.y - b.x), 0.0, 1.0);
                }
            }
        }
    } else {
        if (target_level != level) {
            if (desired == level) {
                level = target_level;
                target_level = desired;
                progress = 1.0 - progress;
            } else if (desired != target_level) {
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
    uint packed = (state.packed & 0xffff0000u) | (level & 0xffu) | ((target_level & 0xffu) << 8u);
    return LodkitSelectOutcome(sel, LodkitSelectState(packed, progress));
}

/// `state` with the frame-sequential phase (bit 16) and the in-transition bit (17) kept.
LodkitSelectState lodkit_select_update_phase(LodkitSelectState state, LodkitSelection selection, uint frame) {
    bool blending = selection.next != LODKIT_SELECT_NONE;
    bool was = (state.packed & 0x20000u) != 0u;
    uint packed = state.packed & 0xffffu;
    if (blending) {
        uint phase = was ? ((state.packed >> 16u) & 1u) : (frame & 1u);
        packed = packed | (phase << 16u) | 0x20000u;
    }
    return LodkitSelectState(packed, state.progress);
}

/// Frame-sequential: whether this frame draws the incoming level.
bool lodkit_select_draws_next(LodkitSelectState state, uint frame) {
    return (frame & 1u) != ((state.packed >> 16u) & 1u);
}

/// Screen-door alpha of the current (incoming false) or next level.
float lodkit_select_screen_door_alpha(LodkitSelection selection, bool incoming) {
    if (selection.next == LODKIT_SELECT_NONE) {
        return selection.fade;
    }
    if (incoming) {
        return selection.transition * selection.fade;
    }
    return -(1.0 - selection.transition) * selection.fade;
}

/// Whether a bounding sphere is at least partly inside the six inward planes.
bool lodkit_select_sphere_visible(vec3 center, float radius, vec4 planes[6]) {
    bool inside = true;
    for (uint i = 0u; i < 6u; i++) {
        vec4 p = planes[i];
        if (p.x * center.x + p.y * center.y + p.z * center.z + p.w < -radius) {
            inside = false;
        }
    }
    return inside;
}

#endif // LODKIT_SELECT_GLSL
