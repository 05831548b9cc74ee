//! lodkit's WGSL modules as Bevy `Shader` assets.

use bevy::prelude::*;
use lodkit::shaders::{Language, ModuleKind};

/// Registers every lodkit WGSL module (naga_oil form) as a `Shader` asset, so any shader can
/// `#import lodkit::<topic>::<item>`.
///
/// All modules are registered, not only those you import: they import each other, and Bevy
/// reports a missing module only as a pipeline that never becomes ready.
pub struct LodkitShadersPlugin;

/// Strong handles that keep lodkit's modules loaded for the app's lifetime.
#[derive(Resource)]
pub struct LodkitShaders(pub Vec<Handle<Shader>>);

impl Plugin for LodkitShadersPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        // `from_wgsl` reads `#define_import_path lodkit::<topic>` from the source: that is the
        // name `#import` resolves, whatever the asset path.
        let modules = lodkit::shaders::modules()
            .iter()
            .filter(|m| m.language == Language::Wgsl && m.kind == ModuleKind::Module)
            .map(|m| shaders.add(Shader::from_wgsl(m.source, m.path)))
            .collect();
        app.insert_resource(LodkitShaders(modules));
    }
}
