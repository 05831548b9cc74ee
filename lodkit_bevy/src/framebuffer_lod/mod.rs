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
mod layout;
mod render;
mod settings;
mod timer;

use bevy::asset::embedded_asset;
use bevy::prelude::*;
use bevy::render::extract_component::{ExtractComponentPlugin, UniformComponentPlugin};
use bevy::render::{RenderApp, renderer::RenderDevice};

pub use effect::{
    FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX, FramebufferLodEffect, FramebufferLodEffectHandle,
    FramebufferLodEffectPlugin,
};
pub use render::{EFFECT_PASS, UPSAMPLE_PASS};
pub use settings::{
    FrameTimeSource, FramebufferLod, FramebufferLodCapabilities, FramebufferLodComposite,
    FramebufferLodFrameTimes, FramebufferLodResolution, FramebufferLodState,
    FramebufferLodUpsample, FramerateTarget, MAX_FACTOR,
};

use layout::FramebufferLodUniform;

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

/// The systems of [`FramebufferLodPlugin`] in the main world.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FramebufferLodSystems {
    /// Updates every camera's [`FramebufferLodState`] from its settings and measurements (in
    /// `Last`).
    Control,
}
