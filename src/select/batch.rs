//! Selection over slices of instances: what a renderer calls once per frame per camera.

use glam::Vec3;

use super::{LodCamera, LodError, LodGroup, LodSelection, LodSettings, LodState, is_orthographic};

/// Instances as parallel slices (structure of arrays), all of the same length.
#[derive(Clone, Copy, Debug)]
pub struct InstanceBatch<'a> {
    /// World-space positions (the point distances are measured to, usually the bounds center).
    pub positions: &'a [Vec3],
    /// Largest world-scale component of each instance.
    pub max_scales: &'a [f32],
    /// Index into the `groups` slice for each instance; an index past its end selects nothing
    /// (the instance is reported hidden).
    pub groups: &'a [u32],
}

/// Product of two biases where 0 wins over +inf (0 forces LOD0).
fn combine_bias(a: f32, b: f32) -> f32 {
    if a == 0.0 || b == 0.0 { 0.0 } else { a * b }
}

/// Selects a level for every instance of `batch` as seen from `camera`, writing `out[i]` and
/// updating `states[i]` (one state per instance for this camera; start with [`LodState::NEW`]).
/// `dt` is the frame time in seconds (used by time-driven transitions).
///
/// Errors only when the slices differ in length or the settings are invalid; nothing panics on
/// odd values (see [`LodGroup::select`] for NaN and negative distances).
///
/// ```
/// # use lodkit::select::*;
/// # use glam::{Mat4, Vec3};
/// let proj = glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 1000.0);
/// let camera = LodCamera::new(Vec3::ZERO, proj);
/// let groups = [LodGroup::from_distances(&[0.0, 10.0, 50.0]).unwrap()];
/// let positions = [Vec3::new(0.0, 0.0, -5.0), Vec3::new(0.0, 0.0, -20.0), Vec3::new(0.0, 0.0, -80.0)];
/// let batch = InstanceBatch { positions: &positions, max_scales: &[1.0; 3], groups: &[0; 3] };
/// let mut states = [LodState::NEW; 3];
/// let mut out = [LodSelection::default(); 3];
/// select_batch(&camera, &LodSettings::default(), &groups, &batch, 0.016, &mut states, &mut out).unwrap();
/// assert_eq!(out.map(|s| s.current), [0, 1, 2]);
/// ```
pub fn select_batch(
    camera: &LodCamera,
    settings: &LodSettings,
    groups: &[LodGroup],
    batch: &InstanceBatch,
    dt: f32,
    states: &mut [LodState],
    out: &mut [LodSelection],
) -> Result<(), LodError> {
    settings.validate()?;
    if camera.bias.is_nan() || camera.bias < 0.0 {
        return Err(LodError::BadBias(camera.bias));
    }
    let n = batch.positions.len();
    for (what, got) in [
        ("max_scales", batch.max_scales.len()),
        ("groups", batch.groups.len()),
        ("states", states.len()),
        ("out", out.len()),
    ] {
        if got != n {
            return Err(LodError::LengthMismatch { what, got, want: n });
        }
    }
    let bias = combine_bias(camera.bias, settings.bias);
    let p11 = camera.projection.y_axis.y.abs();
    let ortho = is_orthographic(&camera.projection);
    let dt = if dt > 0.0 { dt } else { 0.0 };
    let bands: Vec<Vec<(f32, f32)>> = groups
        .iter()
        .map(|g| g.bands(settings.hysteresis))
        .collect();
    // distance x factor / scale, with the bias folded into the factor; a zero bias is LOD0 even
    // for infinite distances (0 x inf would be NaN).
    let factor = bias / p11;
    let instances = batch
        .positions
        .iter()
        .zip(batch.max_scales)
        .zip(batch.groups)
        .zip(states.iter_mut())
        .zip(out.iter_mut());
    for ((((position, scale), &group_id), state), out) in instances {
        let (Some(group), Some(bands)) =
            (groups.get(group_id as usize), bands.get(group_id as usize))
        else {
            *out = LodSelection {
                visible: false,
                fade: 0.0,
                ..LodSelection::default()
            };
            continue;
        };
        let d = if bias == 0.0 {
            0.0
        } else if ortho {
            factor / scale.abs()
        } else {
            position.distance(camera.position) * factor / scale.abs()
        };
        *out = group.select_banded(d, settings, dt, state, |b| bands[b]);
    }
    Ok(())
}

impl Default for LodSelection {
    /// Level 0, no transition, fully visible.
    fn default() -> Self {
        Self {
            current: 0,
            next: None,
            transition: 0.0,
            fade: 1.0,
            visible: true,
        }
    }
}
