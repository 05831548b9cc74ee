//! The part of the example to copy into a Bevy 0.19 application: lodkit's shader modules as
//! `Shader` assets, a material that draws one LOD level through lodkit's complementary
//! screen-door pattern, and applying a `lodkit::select::LodSelection` to a group's entities.

use bevy::asset::uuid_handle;
use bevy::prelude::*;
use bevy::reflect::TypePath;
use bevy::render::render_resource::{AsBindGroup, ShaderType};
use bevy::shader::ShaderRef;
use lodkit::select::LodSelection;
use lodkit::shaders::{Language, ModuleKind};

/// The material's fragment shader, under a fixed handle (embedded, so no asset folder is needed).
const LOD_DITHER_SHADER: Handle<Shader> = uuid_handle!("6f0c1c52-93a4-4d7e-9a51-2b7e0d3c5a10");

/// Registers every lodkit WGSL module, and this example's material shader, as `Shader` assets.
///
/// Register all modules, not just the one you import: they import each other, and Bevy reports
/// a missing module only as a pipeline that never becomes ready.
pub struct LodkitShadersPlugin;

/// Strong handles that keep lodkit's modules loaded for the app's lifetime.
#[derive(Resource)]
pub struct LodkitShaders(
    #[expect(
        dead_code,
        reason = "held, never read: dropping the handles unloads the modules"
    )]
    Vec<Handle<Shader>>,
);

impl Plugin for LodkitShadersPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        // `from_wgsl` reads `#define_import_path lodkit::<topic>` from the source: that is the
        // name `#import` resolves, whatever the asset path.
        let modules: Vec<Handle<Shader>> = lodkit::shaders::modules()
            .iter()
            .filter(|m| m.language == Language::Wgsl && m.kind == ModuleKind::Module)
            .map(|m| shaders.add(Shader::from_wgsl(m.source, m.path)))
            .collect();
        let source = include_str!("../assets/shaders/lod_dither.wgsl");
        shaders
            .insert(
                &LOD_DITHER_SHADER,
                Shader::from_wgsl(source, "shaders/lod_dither.wgsl"),
            )
            .expect("UUID handles never fail to insert");
        app.insert_resource(LodkitShaders(modules));
    }
}

/// One level of a LOD group, drawn through lodkit's screen-door pattern.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
pub struct LodDitherMaterial {
    #[uniform(0)]
    pub params: LodDitherParams,
}

/// The material's uniform (`LodDitherParams` in lod_dither.wgsl).
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
