//! The part of the example to copy into a Bevy 0.20 application: a material that draws one LOD
//! level through lodkit's complementary screen-door pattern (its shader imports
//! `lodkit::screen_door`, registered by `lodkit_bevy::LodkitShadersPlugin`), and applying a
//! `lodkit::select::LodSelection` to a group's entities.

use bevy::asset::uuid_handle;
use bevy::prelude::*;
use bevy::reflect::TypePath;
use bevy::render::render_resource::{AsBindGroup, ShaderType};
use bevy::shader::ShaderRef;
use lodkit::select::LodSelection;

/// The material's fragment shader, under a fixed handle (embedded, so no asset folder is needed).
const LOD_DITHER_SHADER: Handle<Shader> = uuid_handle!("6f0c1c52-93a4-4d7e-9a51-2b7e0d3c5a10");

/// Registers this example's material shader under its fixed handle (lodkit's modules it imports
/// come from `lodkit_bevy::LodkitShadersPlugin`).
pub struct LodDitherShaderPlugin;

impl Plugin for LodDitherShaderPlugin {
    fn build(&self, app: &mut App) {
        let source = include_str!("lod_dither.wesl");
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(
                &LOD_DITHER_SHADER,
                Shader::from_wesl(source, "shaders/lod_dither.wesl"),
            )
            .expect("UUID handles never fail to insert");
    }
}

/// One level of a LOD group, drawn through lodkit's screen-door pattern.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
pub struct LodDitherMaterial {
    #[uniform(0)]
    pub params: LodDitherParams,
}

/// The material's uniform (`LodDitherParams` in lod_dither.wesl).
#[derive(ShaderType, Clone, Copy, Debug)]
pub struct LodDitherParams {
    /// Linear RGB of the level.
    pub color: Vec4,
    /// Signed screen-door alpha from `LodSelection::screen_door_alphas()`: -(1 - t) for the
    /// outgoing level (inverted pattern), +t for the incoming one, 1 when settled.
    pub alpha: f32,
}

impl Material for LodDitherMaterial {
    fn fragment_shader() -> ShaderRef {
        LOD_DITHER_SHADER.into()
    }
    // This scene has no prepass and no shadow maps. An engine that has them must give those
    // passes the same discard, or depth and shadows keep both levels whole during a transition.
    fn enable_prepass() -> bool {
        false
    }
    fn enable_shadows() -> bool {
        false
    }
}

/// The entity and material of one LOD level.
pub struct LevelEntity {
    pub entity: Entity,
    pub material: Handle<LodDitherMaterial>,
}

/// Shows the levels `alpha_of` gives an alpha (with that alpha) and hides the others.
pub fn show_levels(
    world: &mut World,
    levels: &[LevelEntity],
    alpha_of: impl Fn(usize) -> Option<f32>,
) {
    for (i, level) in levels.iter().enumerate() {
        let alpha = alpha_of(i);
        if let Some(mut visibility) = world.get_mut::<Visibility>(level.entity) {
            *visibility = if alpha.is_some() {
                Visibility::Visible
            } else {
                Visibility::Hidden
            };
        }
        if let Some(alpha) = alpha {
            let mut materials = world.resource_mut::<Assets<LodDitherMaterial>>();
            if let Some(mut material) = materials.get_mut(&level.material) {
                material.params.alpha = alpha;
            }
        }
    }
}

/// Applies a selection: the current level with the first alpha, the next one (if any) with the
/// second, everything else hidden.
pub fn apply_selection(world: &mut World, levels: &[LevelEntity], selection: &LodSelection) {
    let (current, next) = selection.screen_door_alphas();
    show_levels(world, levels, |i| {
        if !selection.visible {
            None
        } else if i == usize::from(selection.current) {
            Some(current)
        } else if selection.next.map(usize::from) == Some(i) {
            next
        } else {
            None
        }
    });
}
