//! The main-world side: every frame, each camera's resize factor from its settings and, for
//! [`FramebufferLodResolution::Adaptive`], from lodkit's controller and the measured frame time.

use std::time::Duration;

use bevy::prelude::*;
use lodkit::framebuffer_lod::{ResizeController, ResizeLimits, RlsController, clamp_factor};

use super::settings::{
    FrameTimeSource, FramebufferLod, FramebufferLodCapabilities, FramebufferLodFrameTimes,
    FramebufferLodResolution, FramebufferLodState, FramerateTarget, MAX_FACTOR,
};
use super::timer::GpuFrameTimes;

/// The limits of `target` made valid: r_max in [1, MAX_FACTOR], a finite non-negative step.
fn limits(target: &FramerateTarget) -> ResizeLimits {
    let r_max = clamp_factor(target.max_factor, MAX_FACTOR);
    let max_step = if target.max_step.is_finite() {
        target.max_step.max(0.0)
    } else {
        0.2
    };
    ResizeLimits { r_max, max_step }
}

/// Updates every camera's [`FramebufferLodState`] (system in `Last`).
pub(super) fn update_resolution(
    time: Res<Time<Real>>,
    capabilities: Option<Res<FramebufferLodCapabilities>>,
    gpu_times: Res<GpuFrameTimes>,
    mut cameras: Query<(
        Entity,
        &FramebufferLod,
        &mut FramebufferLodState,
        Option<&mut FramebufferLodFrameTimes>,
    )>,
) {
    let timestamps = capabilities.is_some_and(|c| c.gpu_timestamps);
    let mut measured = gpu_times.take();
    for (entity, settings, mut state, provided) in &mut cameras {
        let state = &mut *state;
        let target = match settings.resolution {
            FramebufferLodResolution::Fixed(_) => None,
            FramebufferLodResolution::Adaptive(target) => Some(target),
        };
        let source = match target.map_or(FrameTimeSource::Auto, |t| t.source) {
            FrameTimeSource::Auto | FrameTimeSource::GpuTimestamps if timestamps => {
                FrameTimeSource::GpuTimestamps
            }
            FrameTimeSource::Provided => FrameTimeSource::Provided,
            _ => FrameTimeSource::WallClock,
        };
        state.gpu_timed = source == FrameTimeSource::GpuTimestamps;
        // What the frames rendered so far measured, with the r each was rendered at.
        let samples = match source {
            FrameTimeSource::GpuTimestamps => measured.remove(&entity).unwrap_or_default(),
            FrameTimeSource::Provided => provided
                .map(|mut p| std::mem::take(&mut p.0))
                .unwrap_or_default()
                .into_iter()
                // An r outside [1, MAX_FACTOR] was not rendered here, and a zero time measured
                // nothing: neither is learned from.
                .filter(|(r, t)| (1.0..=MAX_FACTOR).contains(r) && !t.is_zero())
                .map(|(r, t)| (r, t.as_secs_f32()))
                .collect(),
            _ => {
                let dt = time.delta_secs();
                if dt > 0.0 {
                    vec![(state.factor, dt)]
                } else {
                    Vec::new()
                }
            }
        };
        if let Some(&(r, seconds)) = samples.last() {
            state.frame_time = Duration::try_from_secs_f32(seconds).ok();
            state.measured_factor = r;
            state.measured_with = Some(source);
        }
        let Some(target) = target else {
            if let FramebufferLodResolution::Fixed(r) = settings.resolution {
                state.factor = clamp_factor(r, MAX_FACTOR);
            }
            state.controller = None;
            state.estimates = None;
            continue;
        };
        // A new or changed target starts a new controller, from the current r.
        let limits = limits(&target);
        if state.controller.as_ref().is_none_or(|(t, _)| *t != target) {
            let controller = RlsController::new(target.frame_time.as_secs_f32(), limits)
                .starting_at(state.factor);
            state.controller = Some((target, controller));
        }
        let Some((_, controller)) = &mut state.controller else {
            continue;
        };
        let state_recent = &mut state.recent;
        // Late GPU measurements can arrive two at once: learn from each, move r once. Each is
        // given as the median of it and the two before it, so that one frame's hitch (a driver
        // stall, a shader compile) is not taken for a workload change.
        let before = controller.r();
        for sample in samples {
            state_recent.rotate_left(1);
            state_recent[2] = sample;
            let mut window = *state_recent;
            window.sort_by(|a, b| a.1.total_cmp(&b.1));
            let (r, seconds) = window[1];
            controller.observe(r, seconds);
        }
        let factor = limits.apply(before, controller.r());
        *controller = controller.starting_at(factor);
        state.factor = factor;
        state.estimates = Some(controller.estimates());
    }
}
