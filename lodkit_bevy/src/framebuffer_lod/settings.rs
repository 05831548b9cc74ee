//! Framebuffer LOD's settings (the components and types an app sets), the state the controller
//! keeps per camera, and what the render world extracts: the leaf every other file of the
//! plugin reads, importing none of them.

use std::time::Duration;

use bevy::camera::Hdr;
use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass};
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use lodkit::bilateral::RangeSigmas;
use lodkit::framebuffer_lod::RlsController;

/// Format of the low-resolution color and geometry targets (lodkit::gbuffer's geometry layout).
pub(super) const LOW_FORMAT: TextureFormat = TextureFormat::Rgba16Float;

/// What the render device offers framebuffer LOD (inserted by [`FramebufferLodPlugin`](super::FramebufferLodPlugin) once the
/// renderer exists).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct FramebufferLodCapabilities {
    /// Timestamp queries inside command encoders: [`FrameTimeSource::Auto`] measures the camera's
    /// GPU time with them.
    pub gpu_timestamps: bool,
}

/// Framebuffer LOD on a 3D camera: its effect (a [`FramebufferLodEffectHandle`](super::FramebufferLodEffectHandle) on the same
/// camera) runs at 1/r resolution and is upsampled with lodkit's bilateral filter from the
/// camera's depth and normal prepass. Without an effect nothing is drawn.
///
/// Requires (and adds) [`DepthPrepass`], [`NormalPrepass`] and [`Hdr`]; the camera must also
/// have `Msaa::Off` (the effect pass is skipped with an error otherwise). Only meshes drawn in the
/// prepass (opaque and alpha-masked, with prepass-enabled materials) give the upsample its edges.
/// The effect covers the camera's main-pass viewport and writes nothing outside it: its
/// `Camera::viewport` (split screen: each camera its own r), or the whole target; with a
/// `MainPassResolutionOverride` in the render world, the override's size at the viewport's
/// corner, where Bevy's prepass and main pass drew. When the render target (or the viewport)
/// is resized, the low-resolution targets are reallocated in the same frame.
#[derive(Component, Clone, Debug, Default, Reflect)]
#[reflect(Component, Default, Clone)]
#[require(DepthPrepass, NormalPrepass, Hdr, FramebufferLodState)]
pub struct FramebufferLod {
    /// How the upsampled effect is combined with the scene.
    pub composite: FramebufferLodComposite,
    /// How the low-resolution effect is brought to full resolution.
    pub upsample: FramebufferLodUpsample,
    /// How r is chosen.
    pub resolution: FramebufferLodResolution,
}

/// How the upsampled effect is combined with the camera's image (before tonemapping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Reflect)]
#[reflect(Default, Clone, PartialEq)]
pub enum FramebufferLodComposite {
    /// `scene * (1 - a) + rgb`: the effect returns premultiplied color and coverage (fog:
    /// in-scattered light and 1 - transmittance). The whole effect is resized.
    #[default]
    Over,
    /// `scene * rgb`: the effect returns a factor (ambient occlusion, a shadow term). Only that
    /// smooth factor is resized and the scene keeps its full-resolution detail: the paper's
    /// fine-grained resizing (sec. 2.3).
    Modulate,
}

/// How the low-resolution effect is brought to full resolution.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Default, Clone, PartialEq)]
pub enum FramebufferLodUpsample {
    /// lodkit's geometry-aware upsample (eq. 1): a 2x2 tent times Gaussians on the depth and
    /// normal differences between the pixel and each low-resolution sample.
    /// The fields are those of lodkit's `RangeSigmas` (`lodkit::bilateral`), which lodkit's own
    /// upsample pass takes: one set of names, units and defaults.
    Bilateral {
        /// Depth sigma as a fraction of the pixel's view depth
        /// (`lodkit::bilateral::bilateral_relative_sigma`; default 0.05: samples 5 % nearer or
        /// farther weigh e^-1/2). Relative, so distant slanted surfaces stay smooth.
        depth: f32,
        /// Sigma on the foreshortened normal distance (lodkit::normal_distance; default 0.5).
        normal: f32,
    },
    /// Plain bilinear upsampling (the same pass with sigmas that turn the range terms off,
    /// `lodkit::bilateral::BILATERAL_SIGMA_OFF`): what a renderer does
    /// without geometry awareness; here for comparison.
    Bilinear,
}

impl Default for FramebufferLodUpsample {
    /// lodkit's defaults (`RangeSigmas::default()`).
    fn default() -> Self {
        let RangeSigmas { depth, normal } = RangeSigmas::default();
        Self::Bilateral { depth, normal }
    }
}

impl FramebufferLodUpsample {
    /// The sigmas the upsample pass uses ([`RangeSigmas::OFF`] for bilinear).
    pub fn sigmas(&self) -> RangeSigmas {
        match *self {
            Self::Bilateral { depth, normal } => RangeSigmas { depth, normal },
            Self::Bilinear => RangeSigmas::OFF,
        }
    }
}

/// Largest resize factor a camera accepts (fixed or adaptive).
pub const MAX_FACTOR: f32 = 16.0;

/// How the resize factor r (the effect renders at 1/r of the camera's width and height) is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Default, Clone, PartialEq)]
pub enum FramebufferLodResolution {
    /// A fixed r, clamped to [1, [`MAX_FACTOR`]].
    Fixed(f32),
    /// lodkit's framerate controller (`lodkit::framebuffer_lod::RlsController`) picks r every
    /// frame so that the measured frame time meets a target.
    Adaptive(FramerateTarget),
}

impl Default for FramebufferLodResolution {
    fn default() -> Self {
        Self::Fixed(2.0)
    }
}

/// The framerate controller's target and limits.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Default, Clone, PartialEq)]
pub struct FramerateTarget {
    /// Frame time to hold (default 1/60 s).
    pub frame_time: Duration,
    /// Largest r (default 4, at most [`MAX_FACTOR`]); the smallest is 1.
    pub max_factor: f32,
    /// Largest change of r from one frame to the next (default 0.2, the paper's).
    pub max_step: f32,
    /// What is measured.
    pub source: FrameTimeSource,
}

impl Default for FramerateTarget {
    fn default() -> Self {
        Self {
            frame_time: Duration::from_secs_f64(1.0 / 60.0),
            max_factor: 4.0,
            max_step: 0.2,
            source: FrameTimeSource::Auto,
        }
    }
}

/// Where the controller's frame time comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Reflect)]
#[reflect(Default, Clone, PartialEq)]
pub enum FrameTimeSource {
    /// GPU timestamps where the device has them ([`FramebufferLodCapabilities`]), else wall time.
    #[default]
    Auto,
    /// The camera's GPU time, from timestamp queries written before its prepass and after its
    /// last post-process pass. Arrives a frame or two late; each measurement is credited to the
    /// r it was rendered at. Falls back to wall time without timestamp support.
    GpuTimestamps,
    /// Real time between frames (`Time<Real>`): everything the frame costs, CPU included.
    WallClock,
    /// The app's own measurements: each frame the controller takes what the app pushed into the
    /// camera's [`FramebufferLodFrameTimes`] (an engine's profiler, a frame-time model in a
    /// test). Push before
    /// [`FramebufferLodSystems::Control`](super::FramebufferLodSystems::Control) in `Last`.
    Provided,
}

/// Frame times the app measured itself, for [`FrameTimeSource::Provided`]: each entry is the r
/// a frame was rendered at (the [`FramebufferLodState::factor`] of the frame, read before the
/// controller changes it) and the time that frame took. The controller drains it every frame;
/// with another source it is left alone. Entries with an r outside [1, [`MAX_FACTOR`]] or a
/// zero time are dropped.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct FramebufferLodFrameTimes(pub Vec<(f32, Duration)>);

/// What framebuffer LOD is doing on a camera (added with [`FramebufferLod`], updated every frame
/// in `Last`; read it, don't write it).
#[derive(Component, Clone, Debug)]
pub struct FramebufferLodState {
    /// The resize factor r the next frame renders the effect at.
    pub factor: f32,
    /// The camera's last measured frame time (`None` before the first measurement): its GPU time
    /// where the device has timestamp queries (unless the target asks for
    /// [`FrameTimeSource::WallClock`]), else the real time between frames. With an adaptive
    /// resolution this is what the controller was given.
    pub frame_time: Option<Duration>,
    /// The r that frame time was rendered at.
    pub measured_factor: f32,
    /// Where that frame time came from: [`FrameTimeSource::GpuTimestamps`],
    /// [`FrameTimeSource::WallClock`] or [`FrameTimeSource::Provided`].
    pub measured_with: Option<FrameTimeSource>,
    /// The controller's estimates (K, C) of eq. 3, t = K / r^2 + C, in seconds (adaptive only).
    pub estimates: Option<(f32, f32)>,
    /// Whether the render world writes timestamps for this camera.
    pub(super) gpu_timed: bool,
    pub(super) controller: Option<(FramerateTarget, RlsController)>,
    /// The last three (r, seconds) measurements (NaN before there are three).
    pub(super) recent: [(f32, f32); 3],
}

impl Default for FramebufferLodState {
    fn default() -> Self {
        Self {
            factor: 1.0,
            frame_time: None,
            measured_factor: 1.0,
            measured_with: None,
            estimates: None,
            gpu_timed: false,
            controller: None,
            recent: [(f32::NAN, f32::NAN); 3],
        }
    }
}

/// What the render world keeps of a camera's [`FramebufferLod`].
#[derive(Component, Clone, Debug)]
pub struct ExtractedFramebufferLod {
    pub(super) composite: FramebufferLodComposite,
    /// r this frame.
    pub(super) factor: f32,
    /// Whether the camera's GPU time is measured (adaptive r on GPU timestamps).
    pub(super) gpu_timed: bool,
    /// The low-resolution viewport this frame: ceil(main-pass viewport / r).
    pub(super) low_size: UVec2,
    /// The camera's main-pass viewport in its render target: top-left corner and size.
    pub(super) origin: UVec2,
    pub(super) full_size: UVec2,
}
