//! The bind group layout of group 0 that the effect pass and the upsample pass share
//! (`lodkit_bevy::framebuffer_lod` in framebuffer_lod.wesl), and the settings uniform in it.

use bevy::prelude::*;
use bevy::render::globals::GlobalsUniform;
use bevy::render::render_resource::binding_types::{texture_2d, texture_depth_2d, uniform_buffer};
use bevy::render::render_resource::*;
use bevy::render::view::ViewUniform;

/// The settings the shaders read (`FramebufferLodSettings` in framebuffer_lod.wesl).
#[derive(Component, ShaderType, Clone, Copy, Debug)]
pub struct FramebufferLodUniform {
    pub(super) low_size: Vec2,
    pub(super) full_size: Vec2,
    pub(super) origin: Vec2,
    pub(super) factor: f32,
    pub(super) depth_sigma: f32,
    pub(super) normal_sigma: f32,
    pub(super) sky_depth: f32,
}

/// The bindings `lodkit_bevy::framebuffer_lod` declares in group 0: view, globals, depth and
/// normal prepass, settings.
pub(super) fn common_entries() -> [BindGroupLayoutEntryBuilder; 5] {
    [
        uniform_buffer::<ViewUniform>(true),
        uniform_buffer::<GlobalsUniform>(false),
        texture_depth_2d(),
        texture_2d(TextureSampleType::Float { filterable: true }),
        uniform_buffer::<FramebufferLodUniform>(true),
    ]
}

/// Group 0 of the effect pass (the effect's own bindings are group 1).
pub(super) fn effect_view_layout() -> BindGroupLayoutDescriptor {
    let [a, b, c, d, e] = common_entries();
    BindGroupLayoutDescriptor::new(
        "lodkit_framebuffer_lod_effect",
        &BindGroupLayoutEntries::sequential(ShaderStages::FRAGMENT, (a, b, c, d, e)),
    )
}
