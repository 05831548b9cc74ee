//! lodkit's WESL modules as Bevy `Shader` assets.

use bevy::prelude::*;

/// Registers every lodkit WESL module as a `Shader` asset, so any WESL shader of the app can
/// `import lodkit::<topic>::<item>;` (for example
/// `import lodkit::bilateral::bilateral_upsample_at;`).
///
/// Each module is registered with `Shader::from_wesl(source, "embedded://lodkit/<topic>.wesl")`:
/// Bevy names a module after that path, `lodkit::<topic>`, the path wesl-js and wesl-rs give the
/// same package. Inside the package the modules import each other as `package::<topic>`. Shader
/// defs a module reads (`LODKIT_REVERSE_Z`, `LODKIT_SCREEN_DOOR_BLUE_NOISE`) are WESL conditions:
/// set them as bool shader defs on the pipeline that imports the module.
///
/// All modules are registered, not only those you import: they import each other, and Bevy
/// reports a missing module only as a warning and a pipeline that never becomes ready.
pub struct LodkitShadersPlugin;

/// Strong handles that keep lodkit's modules loaded for the app's lifetime, one per module.
#[derive(Resource)]
pub struct LodkitShaders(pub Vec<Handle<Shader>>);

impl Plugin for LodkitShadersPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        let modules = lodkit::shaders::wesl_modules()
            .filter_map(|m| {
                let path = m.embedded_path.clone()?;
                Some(shaders.add(Shader::from_wesl(m.source, path)))
            })
            .collect();
        app.insert_resource(LodkitShaders(modules));
    }
}

/// The names [`register_library`] has registered in this app.
#[derive(Resource, Default)]
struct Libraries(Vec<&'static str>);

/// Registers a WESL library module of lodkit_bevy's own under `embedded://lodkit_bevy/<name>.wesl`,
/// importable as `lodkit_bevy::<name>`, kept loaded for the app's lifetime; once per app, however
/// many plugins ask for it.
pub(crate) fn register_library(app: &mut App, name: &'static str, source: &'static str) {
    let mut libraries = app.world_mut().get_resource_or_init::<Libraries>();
    if libraries.0.contains(&name) {
        return;
    }
    libraries.0.push(name);
    let handle = app
        .world_mut()
        .resource_mut::<Assets<Shader>>()
        .add(Shader::from_wesl(
            source,
            format!("embedded://lodkit_bevy/{name}.wesl"),
        ));
    app.world_mut()
        .resource_mut::<LodkitShaders>()
        .0
        .push(handle);
}

/// Registers the modules a material's shader imports to draw a level of a frame-sequential LOD
/// group (`lodkit_bevy::frame_sequential_level` and the `lodkit_bevy::frame_sequential` it
/// imports).
pub(crate) fn register_level_libraries(app: &mut App) {
    register_library(
        app,
        "frame_sequential",
        include_str!("frame_sequential/frame_sequential.wesl"),
    );
    register_library(
        app,
        "frame_sequential_level",
        include_str!("frame_sequential/frame_sequential_level.wesl"),
    );
}
