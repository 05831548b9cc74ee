//! Geometry-aware framebuffer LOD on a Bevy camera (Yang, Sander & Lawrence 2008).
//!
//! An expensive screen-space effect (fog, ambient occlusion, ...) runs at 1/r of the camera's
//! resolution; lodkit's bilateral upsample (eq. 1) rebuilds it at full resolution from Bevy's
//! depth and normal prepass, so it does not bleed across depth edges the way a bilinear upsample
//! does, and the result is composited into the camera's HDR main texture before tonemapping.
//! lodkit's framerate controller can choose r every frame from the measured frame time.
//!
//! The effect is an asset type of yours, as a Bevy material is: its fields are the effect's
//! bindings (derive `AsBindGroup`: uniforms, textures, samplers), [`FramebufferLodEffect`] names
//! its fragment shader, [`FramebufferLodEffectPlugin`] prepares it, and the camera holds a
//! [`FramebufferLodEffectHandle`] to one (which adds [`FramebufferLod`]):
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy::render::render_resource::AsBindGroup;
//! use bevy::shader::ShaderRef;
//! use lodkit_bevy::prelude::*;
//!
//! #[derive(Asset, TypePath, AsBindGroup, Clone)]
//! struct Fog {
//!     #[uniform(0)]
//!     density: f32,
//!     #[texture(1)]
//!     #[sampler(2)]
//!     noise: Handle<Image>,
//! }
//!
//! impl FramebufferLodEffect for Fog {
//!     fn fragment_shader() -> ShaderRef {
//!         "shaders/fog.wesl".into()
//!     }
//! }
//!
//! fn setup(mut commands: Commands, assets: Res<AssetServer>, mut fogs: ResMut<Assets<Fog>>) {
//!     let fog = fogs.add(Fog { density: 0.05, noise: assets.load("textures/noise.png") });
//!     commands.spawn((
//!         Camera3d::default(),
//!         Msaa::Off, // the prepass is read per pixel
//!         FramebufferLodEffectHandle(fog),
//!         FramebufferLod {
//!             resolution: FramebufferLodResolution::Adaptive(FramerateTarget::default()),
//!             ..default()
//!         },
//!     ));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, FramebufferLodEffectPlugin::<Fog>::default()))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```
//!
//! The shader is a WESL fragment shader run with Bevy's fullscreen vertex shader. It imports
//! `lodkit_bevy::framebuffer_lod` (group 0: the view, the prepass, `effect_sample`,
//! `effect_output`), may import any `lodkit::` module, and declares the effect's own bindings in
//! group [`FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX`], which WESL spells
//! `constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP` (as materials use `MATERIAL_BIND_GROUP`):
//!
//! ```wgsl
//! import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput;
//! import lodkit::gbuffer::GBufferOutput;
//! import lodkit_bevy::framebuffer_lod::{effect_sample, effect_output};
//!
//! @group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(0) var<uniform> density: f32;
//! @group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(1) var noise: texture_2d<f32>;
//! @group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(2) var noise_sampler: sampler;
//!
//! @fragment
//! fn fragment(in: FullscreenVertexOutput) -> GBufferOutput {
//!     let s = effect_sample(in.position);
//!     let n = textureSampleLevel(noise, noise_sampler, s.world_position.xz * 0.1, 0.0).r;
//!     let transmittance = exp(-density * n * s.view_depth);
//!     // premultiplied: the fog's light, and how much of the scene it hides
//!     return effect_output(vec4(vec3(0.6, 0.7, 0.8) * (1.0 - transmittance), 1.0 - transmittance), s);
//! }
//! ```

mod controller;
mod effect;
mod render;
mod timer;

use std::time::Duration;

use bevy::asset::embedded_asset;
use bevy::camera::Hdr;
use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass};
use bevy::prelude::*;
use bevy::render::extract_component::{ExtractComponentPlugin, UniformComponentPlugin};
use bevy::render::{RenderApp, renderer::RenderDevice};

pub use controller::FramebufferLodState;
pub use effect::{
    FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX, FramebufferLodEffect, FramebufferLodEffectHandle,
    FramebufferLodEffectPlugin,
};
pub use render::{EFFECT_PASS, UPSAMPLE_PASS};

use render::FramebufferLodUniform;

use crate::LodkitShadersPlugin;

/// Adds framebuffer LOD to every camera with a [`FramebufferLod`] component and an effect
/// ([`FramebufferLodEffectHandle`]); [`FramebufferLodEffectPlugin`] adds it for you.
///
/// Registers lodkit's shader modules ([`LodkitShadersPlugin`], if not added yet) and the
/// `lodkit_bevy::framebuffer_lod` module effects import, the render passes (scheduled in
/// `Core3d` after the main pass, before the post-processing that precedes tonemapping) and the
/// controller that updates [`FramebufferLodState`] every frame.
pub struct FramebufferLodPlugin;

impl Plugin for FramebufferLodPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<LodkitShadersPlugin>() {
            app.add_plugins(LodkitShadersPlugin);
        }
        crate::shaders::register_library(
            app,
            "framebuffer_lod",
            include_str!("framebuffer_lod.wesl"),
        );
        embedded_asset!(app, "upsample.wesl");
        app.register_type::<FramebufferLod>()
            .add_plugins((
                ExtractComponentPlugin::<FramebufferLod>::default(),
                UniformComponentPlugin::<FramebufferLodUniform>::default(),
            ))
            .init_resource::<timer::GpuFrameTimes>()
            .add_systems(
                Last,
                controller::update_resolution.in_set(FramebufferLodSystems::Control),
            );
        let times = app.world().resource::<timer::GpuFrameTimes>().clone();
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render_app.insert_resource(times);
            render::build(render_app);
        }
    }

    fn finish(&self, app: &mut App) {
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        let features = render_app.world().resource::<RenderDevice>().features();
        let timestamps = timer::supported(features);
        render::finish(render_app);
        app.insert_resource(FramebufferLodCapabilities {
            gpu_timestamps: timestamps,
        });
    }
}

/// What the render device offers framebuffer LOD (inserted by [`FramebufferLodPlugin`] once the
/// renderer exists).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct FramebufferLodCapabilities {
    /// Timestamp queries inside command encoders: [`FrameTimeSource::Auto`] measures the camera's
    /// GPU time with them.
    pub gpu_timestamps: bool,
}

/// Framebuffer LOD on a 3D camera: its effect (a [`FramebufferLodEffectHandle`] on the same
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
    Bilateral {
        /// Depth sigma as a fraction of the pixel's view depth (default 0.05: samples 5 % nearer
        /// or farther weigh e^-1/2). Relative, so distant slanted surfaces stay smooth.
        depth_sigma: f32,
        /// Sigma on the foreshortened normal distance (lodkit::normal_distance; default 0.5).
        normal_sigma: f32,
    },
    /// Plain bilinear upsampling (the same pass with sigmas that turn the range terms off,
    /// `lodkit::bilateral::BILATERAL_SIGMA_OFF`): what a renderer does
    /// without geometry awareness; here for comparison.
    Bilinear,
}

impl Default for FramebufferLodUpsample {
    fn default() -> Self {
        Self::Bilateral {
            depth_sigma: 0.05,
            normal_sigma: 0.5,
        }
    }
}

impl FramebufferLodUpsample {
    /// The (depth, normal) sigmas the upsample pass uses; `BILATERAL_SIGMA_OFF` for bilinear (a
    /// finite value: a shader must not be given an infinity).
    pub fn sigmas(&self) -> (f32, f32) {
        match *self {
            Self::Bilateral {
                depth_sigma,
                normal_sigma,
            } => (depth_sigma, normal_sigma),
            Self::Bilinear => (
                lodkit::bilateral::BILATERAL_SIGMA_OFF,
                lodkit::bilateral::BILATERAL_SIGMA_OFF,
            ),
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
    /// test). Push before [`FramebufferLodSystems::Control`] in `Last`.
    Provided,
}

/// Frame times the app measured itself, for [`FrameTimeSource::Provided`]: each entry is the r
/// a frame was rendered at (the [`FramebufferLodState::factor`] of the frame, read before the
/// controller changes it) and the time that frame took. The controller drains it every frame;
/// with another source it is left alone. Entries with an r outside [1, [`MAX_FACTOR`]] or a
/// zero time are dropped.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct FramebufferLodFrameTimes(pub Vec<(f32, Duration)>);

/// The systems of [`FramebufferLodPlugin`] in the main world.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FramebufferLodSystems {
    /// Updates every camera's [`FramebufferLodState`] from its settings and measurements (in
    /// `Last`).
    Control,
}
