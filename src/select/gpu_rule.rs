//! What the GPU form of the rule (`lodkit::select`) reads, computed on the host from the CPU
//! types: a group's levels and hysteresis bands, the distance kind and factor of a camera, the
//! transition mode and step, the packed state and the frustum planes. Pure math, no wgpu.

use glam::{Mat4, Vec4};

use super::{LodCamera, LodGroup, LodSettings, LodState, TransitionMode, is_orthographic};

/// Levels a group can have on the GPU (`SELECT_MAX_LEVELS` of `lodkit::select`).
pub const SELECT_MAX_LEVELS: usize = 8;
/// `select_distance` kind: a zero bias, every distance is 0 (LOD0).
pub const SELECT_DISTANCE_ZERO: u32 = 0;
/// `select_distance` kind: perspective camera, distance x factor / scale.
pub const SELECT_DISTANCE_PERSPECTIVE: u32 = 1;
/// `select_distance` kind: orthographic camera, factor / scale.
pub const SELECT_DISTANCE_ORTHOGRAPHIC: u32 = 2;
/// `select_distance` kind: an infinite bias, every distance is [`SELECT_FAR`] (the last level).
pub const SELECT_DISTANCE_INFINITE: u32 = 3;
/// The GPU rule's +inf, 1e38 (WGSL has no infinite constant): a NaN distance and an infinite
/// bias select as this, which gives the levels +inf gives; a max distance above it counts as
/// none on the GPU.
pub const SELECT_FAR: f32 = 1e38;

/// The `select_distance` kind and factor (camera bias x global bias / |P\[1\]\[1\]|) of a camera
/// under `settings`: the same distance [`select_batch`](super::select_batch) computes.
///
/// ```
/// # use lodkit::select::*;
/// # use glam::Vec3;
/// let p = glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 100.0);
/// let cam = LodCamera::new(Vec3::ZERO, p).with_bias(2.0);
/// let (kind, factor) = distance_kind(&cam, &LodSettings::default());
/// assert_eq!(kind, SELECT_DISTANCE_PERSPECTIVE);
/// assert!((factor - 2.0).abs() < 1e-6);
/// ```
pub fn distance_kind(camera: &LodCamera, settings: &LodSettings) -> (u32, f32) {
    let bias = if camera.bias == 0.0 || settings.bias == 0.0 {
        0.0
    } else {
        camera.bias * settings.bias
    };
    let p11 = camera.projection.y_axis.y.abs();
    if bias == 0.0 {
        (SELECT_DISTANCE_ZERO, 0.0)
    } else if bias == f32::INFINITY {
        (SELECT_DISTANCE_INFINITE, f32::INFINITY)
    } else if is_orthographic(&camera.projection) {
        (SELECT_DISTANCE_ORTHOGRAPHIC, bias / p11)
    } else {
        (SELECT_DISTANCE_PERSPECTIVE, bias / p11)
    }
}

/// Inward frustum planes of a world-to-clip matrix with clip z in \[0, w\] (wgpu, standard or
/// reversed depth): left, right, bottom, top, near, far; xyz is a unit normal. A plane that
/// constrains nothing (the far plane of an infinite projection) comes out as (0, 0, 0, 1).
pub fn frustum_planes(view_proj: &Mat4) -> [Vec4; 6] {
    let m = view_proj.transpose();
    let (r0, r1, r2, r3) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(|p| {
        let len = p.truncate().length();
        if len > 0.0 {
            p / len
        } else {
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        }
    })
}

/// A group as `lodkit::select::SelectGroup` holds it (without its draw slot).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectGroupData {
    /// Level i: (distance, band lo, band hi, 0); the band of level 0 is unused.
    pub levels: [[f32; 4]; SELECT_MAX_LEVELS],
    /// Levels in use.
    pub level_count: u32,
    /// Max draw distance; `f32::MAX` for none (above [`SELECT_FAR`], which the GPU rule reads as
    /// none: a shader is never given an infinity, which WGSL promises nothing for).
    pub max_distance: f32,
    /// max_distance - hysteresis.
    pub fade_from: f32,
    /// Hysteresis (>= 0).
    pub hysteresis: f32,
}

impl LodGroup {
    /// The group as the GPU module reads it, with the bands of `hysteresis` computed exactly as
    /// [`LodGroup::select`] does; `None` with more than [`SELECT_MAX_LEVELS`] levels.
    pub fn select_data(&self, hysteresis: f32) -> Option<SelectGroupData> {
        let levels = self.levels();
        if levels.len() > SELECT_MAX_LEVELS {
            return None;
        }
        let h = hysteresis.max(0.0);
        let bands = self.bands(h);
        let mut table = [[0.0; 4]; SELECT_MAX_LEVELS];
        for (i, (level, band)) in levels.iter().zip(&bands).enumerate() {
            let (lo, hi) = if i == 0 { (0.0, 0.0) } else { *band };
            table[i] = [level.distance, lo, hi, 0.0];
        }
        let max = self.max_distance().unwrap_or(f32::MAX);
        Some(SelectGroupData {
            levels: table,
            level_count: levels.len() as u32,
            max_distance: max,
            fade_from: max - h,
            hysteresis: h,
        })
    }
}

impl LodSettings {
    /// The `lodkit::select` transition mode (SELECT_HARD 0, _DISTANCE 1, _TIME 2) and the step a
    /// frame of `dt` seconds adds to a timed transition (dt / seconds; 0 for dt <= 0 or NaN).
    pub fn select_mode(&self, dt: f32) -> (u32, f32) {
        match self.transition {
            TransitionMode::Hard => (0, 0.0),
            TransitionMode::Distance => (1, 0.0),
            TransitionMode::Time { seconds } => {
                let dt = if dt > 0.0 { dt } else { 0.0 };
                let step = if dt > 0.0 && seconds > 0.0 {
                    dt / seconds
                } else {
                    0.0
                };
                (2, step)
            }
        }
    }
}

impl LodState {
    /// The state as `lodkit::select::SelectState` packs it: level | target << 8 (255 for no
    /// history), the phase bits clear.
    ///
    /// ```
    /// # use lodkit::select::LodState;
    /// assert_eq!(LodState::NEW.packed(), 0xffff);
    /// assert_eq!(LodState::from_packed(0x0201, 0.5).packed(), 0x0201);
    /// ```
    pub fn packed(&self) -> u32 {
        self.level as u32 | (self.target as u32) << 8
    }

    /// Progress of a timed transition.
    pub fn progress(&self) -> f32 {
        self.progress
    }

    /// The state of a packed word (low 16 bits; the phase bits are ignored) and a progress.
    pub fn from_packed(packed: u32, progress: f32) -> Self {
        Self {
            level: (packed & 0xff) as u8,
            target: ((packed >> 8) & 0xff) as u8,
            progress,
        }
    }
}
