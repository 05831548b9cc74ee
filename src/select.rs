//! LOD selection in the style of DigitalRune: view-normalized distance, LOD bias, LOD groups with
//! an optional max draw distance, a stateful hysteresis band per camera, and transitions driven by
//! distance (across the band) or by time (a fixed duration after the switch decision).
//!
//! Pure math, no wgpu. The batch API ([`select_batch`]) is what a renderer calls once per frame per
//! camera; [`LodGroup::select`] is the same rule for one instance.

mod batch;
pub mod config;
mod gpu_rule;
mod group;

pub use batch::{InstanceBatch, select_batch};
pub use gpu_rule::{
    SELECT_DISTANCE_INFINITE, SELECT_DISTANCE_ORTHOGRAPHIC, SELECT_DISTANCE_PERSPECTIVE,
    SELECT_DISTANCE_ZERO, SELECT_FAR, SELECT_MAX_LEVELS, SelectGroupData, distance_kind,
    frustum_planes,
};
pub use group::{LodGroup, LodLevel, LodSelection, LodSettings, LodState, TransitionMode};

use glam::{Mat4, Vec3};

/// What is wrong with a LOD description.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LodError {
    /// A group with no levels.
    #[error("a LOD group needs at least one level")]
    NoLevels,
    /// More levels than a selection can name.
    #[error("a LOD group has at most 255 levels, this one has {0}")]
    TooManyLevels(usize),
    /// A level distance that is negative, NaN or infinite.
    #[error("level {index}: distance {distance} must be finite and >= 0")]
    BadDistance {
        /// Index of the level as given.
        index: usize,
        /// The distance.
        distance: f32,
    },
    /// A max draw distance that is not positive.
    #[error("max distance {0} must be > 0 (leave it out for no limit)")]
    BadMaxDistance(f32),
    /// A hysteresis that is negative or not finite.
    #[error("hysteresis {0} must be finite and >= 0")]
    BadHysteresis(f32),
    /// A LOD bias that is negative or NaN.
    #[error("LOD bias {0} must be >= 0 (0 forces LOD0, +inf the last LOD)")]
    BadBias(f32),
    /// A transition duration that is not positive and finite.
    #[error("transition duration {0} s must be finite and > 0")]
    BadDuration(f32),
    /// Batch slices of different lengths.
    #[error("batch slices differ in length: {what} has {got}, positions has {want}")]
    LengthMismatch {
        /// Which slice.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length of `positions`.
        want: usize,
    },
}

/// Whether `projection` is orthographic (its last row is (0, 0, 0, 1)).
///
/// ```
/// # use lodkit::select::is_orthographic;
/// use glam::camera::rh::proj::directx::{orthographic, perspective};
/// assert!(is_orthographic(&orthographic(-1.0, 1.0, -1.0, 1.0, 0.1, 10.0)));
/// assert!(!is_orthographic(&perspective(1.0, 1.0, 0.1, 10.0)));
/// ```
pub fn is_orthographic(projection: &Mat4) -> bool {
    projection.x_axis.w == 0.0 && projection.y_axis.w == 0.0 && projection.z_axis.w == 0.0
}

/// Distance used for LOD selection that does not change with the camera's field of view.
///
/// Perspective: `distance / |projection.y_axis.y|` (so a wider field of view, which makes objects
/// smaller on screen, gives a larger distance). Orthographic: `1 / |projection.y_axis.y|`, half the
/// view height, whatever the distance: the distance at which a 90° perspective camera shows the
/// object at the same size. Either is divided by `max_scale`, the largest world-scale component
/// of the object (so a model scaled x2 selects as if it were half as far).
///
/// Documented edge cases: a negative `max_scale` counts by its magnitude; a zero one gives +inf
/// (NaN at distance 0); NaN in, NaN out. Selection treats NaN as +inf: the last level, hidden only
/// beyond a group's max distance.
///
/// ```
/// # use lodkit::select::view_normalized_distance;
/// let p = glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 100.0);
/// assert!((view_normalized_distance(10.0, &p, 1.0) - 10.0).abs() < 1e-5);
/// // 60 degrees: tan(30°) = 0.577, so the same object selects as if at 5.77.
/// let narrow = glam::camera::rh::proj::directx::perspective(60f32.to_radians(), 1.0, 0.1, 100.0);
/// assert!((view_normalized_distance(10.0, &narrow, 1.0) - 5.7735).abs() < 1e-3);
/// assert!((view_normalized_distance(10.0, &p, 2.0) - 5.0).abs() < 1e-5);
/// ```
pub fn view_normalized_distance(distance: f32, projection: &Mat4, max_scale: f32) -> f32 {
    let p11 = projection.y_axis.y.abs();
    let d = if is_orthographic(projection) {
        1.0 / p11
    } else {
        distance / p11
    };
    d / max_scale.abs()
}

/// `distance` times `bias` (camera bias x global bias). A bias of 0 gives 0 (LOD0) even for an
/// infinite distance; +inf gives +inf (the last LOD) even for distance 0.
///
/// ```
/// # use lodkit::select::biased_distance;
/// assert_eq!(biased_distance(40.0, 0.5), 20.0);
/// assert_eq!(biased_distance(f32::INFINITY, 0.0), 0.0);
/// assert_eq!(biased_distance(0.0, f32::INFINITY), f32::INFINITY);
/// ```
pub fn biased_distance(distance: f32, bias: f32) -> f32 {
    if bias == 0.0 {
        0.0
    } else if bias == f32::INFINITY {
        f32::INFINITY
    } else {
        distance * bias
    }
}

/// The camera LOD is selected for. Shadow and reflection passes select with the main camera's
/// `LodCamera`, not their own, so an object casts the shadow of the LOD that is on screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodCamera {
    /// World-space position of the camera.
    pub position: Vec3,
    /// Its projection (only `y_axis.y` and whether it is orthographic matter).
    pub projection: Mat4,
    /// Camera LOD bias, multiplied with the global bias (default 1).
    pub bias: f32,
}

impl LodCamera {
    /// A camera at `position` with `projection` and bias 1.
    pub fn new(position: Vec3, projection: Mat4) -> Self {
        Self {
            position,
            projection,
            bias: 1.0,
        }
    }

    /// The camera of a view matrix (world to view) and a projection.
    ///
    /// ```
    /// # use lodkit::select::LodCamera;
    /// # use glam::{Mat4, Vec3};
    /// let view = glam::camera::rh::view::look_at_mat4(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y);
    /// let cam = LodCamera::from_view(&view, Mat4::IDENTITY);
    /// assert!(cam.position.distance(Vec3::new(1.0, 2.0, 3.0)) < 1e-5);
    /// ```
    pub fn from_view(view: &Mat4, projection: Mat4) -> Self {
        Self::new(view.inverse().w_axis.truncate(), projection)
    }

    /// The same camera with another bias.
    pub fn with_bias(self, bias: f32) -> Self {
        Self { bias, ..self }
    }

    /// View-normalized, biased distance of an object at `position` with largest world-scale
    /// component `max_scale`, under the extra `global_bias`. A zero bias (either one) gives 0.
    ///
    /// ```
    /// # use lodkit::select::LodCamera;
    /// # use glam::Vec3;
    /// let p = glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 100.0);
    /// let cam = LodCamera::new(Vec3::ZERO, p).with_bias(2.0);
    /// assert!((cam.lod_distance(Vec3::new(0.0, 0.0, -10.0), 1.0, 0.5) - 10.0).abs() < 1e-4);
    /// assert_eq!(cam.lod_distance(Vec3::new(0.0, 0.0, -10.0), 1.0, 0.0), 0.0);
    /// ```
    pub fn lod_distance(&self, position: Vec3, max_scale: f32, global_bias: f32) -> f32 {
        let d = view_normalized_distance(
            position.distance(self.position),
            &self.projection,
            max_scale,
        );
        let bias = if self.bias == 0.0 || global_bias == 0.0 {
            0.0
        } else {
            self.bias * global_bias
        };
        biased_distance(d, bias)
    }
}

/// Rust twin of `lodkit::select::select_distance`: the distance the rule compares for an instance
/// at `center` with largest world-scale component `max_scale`, seen from `camera_position`, where
/// `factor` is camera bias x global bias / |P\[1\]\[1\]| and `kind` one of the `SELECT_DISTANCE_*`
/// constants ([`distance_kind`] picks it). Float for float what [`select_batch`] computes.
///
/// ```
/// # use lodkit::select::*;
/// # use glam::Vec3;
/// let d = select_distance(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, 0.5, 2.0, SELECT_DISTANCE_PERSPECTIVE);
/// assert_eq!(d, 2.5);
/// assert_eq!(select_distance(Vec3::ONE, Vec3::ZERO, 1.0, 1.0, SELECT_DISTANCE_ZERO), 0.0);
/// ```
pub fn select_distance(
    center: Vec3,
    camera_position: Vec3,
    factor: f32,
    max_scale: f32,
    kind: u32,
) -> f32 {
    match kind {
        SELECT_DISTANCE_ZERO => 0.0,
        SELECT_DISTANCE_INFINITE => SELECT_FAR,
        SELECT_DISTANCE_ORTHOGRAPHIC => factor / max_scale.abs(),
        _ => center.distance(camera_position) * factor / max_scale.abs(),
    }
}

/// Rust twin of `lodkit::select::select_level`: the selection rule, [`LodGroup::select`] (the
/// GPU form takes `dt / seconds` as its step and the state packed, see [`LodState::packed`]).
pub fn select_level(
    distance: f32,
    group: &LodGroup,
    settings: &LodSettings,
    dt: f32,
    state: &mut LodState,
) -> LodSelection {
    group.select(distance, settings, dt, state)
}

/// Rust twin of `lodkit::select::select_update_phase`: the packed state word after `selection`
/// on frame `frame`. Bit 16 is the parity of the frame a transition began (kept while it runs),
/// bit 17 is set while one runs; the low 16 bits (level, target) are kept.
///
/// ```
/// # use lodkit::select::*;
/// let blend = LodSelection { current: 0, next: Some(1), transition: 0.2, fade: 1.0, visible: true };
/// let w = select_update_phase(0x0000, &blend, 7); // begins on an odd frame
/// assert_eq!(w, 0x30000);
/// assert_eq!(select_update_phase(w, &blend, 8), 0x30000); // the phase is kept
/// assert_eq!(select_update_phase(w, &LodSelection::default(), 9), 0);
/// ```
pub fn select_update_phase(packed: u32, selection: &LodSelection, frame: u32) -> u32 {
    let low = packed & 0xffff;
    if selection.next.is_none() {
        return low;
    }
    let phase = if packed & 0x20000 != 0 {
        (packed >> 16) & 1
    } else {
        frame & 1
    };
    low | (phase << 16) | 0x20000
}

/// Rust twin of `lodkit::select::select_draws_next`: frame-sequential interpolation draws the
/// outgoing level on the frame a transition began and every other frame after, the incoming one
/// between.
///
/// ```
/// # use lodkit::select::select_draws_next;
/// assert!(!select_draws_next(0x30000, 7) && select_draws_next(0x30000, 8));
/// ```
pub fn select_draws_next(packed: u32, frame: u32) -> bool {
    (frame & 1) != ((packed >> 16) & 1)
}

/// Rust twin of `lodkit::select::select_screen_door_alpha`: the screen-door alpha of the current
/// level (`incoming` false) or of the next one ([`LodSelection::screen_door_alphas`]).
///
/// ```
/// # use lodkit::select::*;
/// let s = LodSelection { current: 0, next: Some(1), transition: 0.25, fade: 1.0, visible: true };
/// assert_eq!((select_screen_door_alpha(&s, false), select_screen_door_alpha(&s, true)), (-0.75, 0.25));
/// ```
pub fn select_screen_door_alpha(selection: &LodSelection, incoming: bool) -> f32 {
    let (current, next) = selection.screen_door_alphas();
    if incoming {
        next.unwrap_or(selection.fade)
    } else {
        current
    }
}

/// Rust twin of `lodkit::select::select_sphere_visible`: whether a bounding sphere is at least
/// partly inside six inward planes (unit xyz normal, w offset; [`frustum_planes`] makes them).
///
/// ```
/// # use lodkit::select::*;
/// # use glam::Vec3;
/// let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0);
/// let planes = frustum_planes(&proj);
/// assert!(select_sphere_visible(Vec3::new(0.0, 0.0, -10.0), 1.0, &planes));
/// assert!(!select_sphere_visible(Vec3::new(0.0, 0.0, 10.0), 1.0, &planes)); // behind
/// ```
pub fn select_sphere_visible(center: Vec3, radius: f32, planes: &[glam::Vec4; 6]) -> bool {
    !planes
        .iter()
        .any(|p| p.x * center.x + p.y * center.y + p.z * center.z + p.w < -radius)
}
