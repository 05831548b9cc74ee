//! The [`FrameSequentialMaterial`] the plugin derives from a level's plain [`StandardMaterial`]
//! handle (what a glTF scene or an app already spawns; [`LevelMaterial::Standard`]), kept in step
//! with it.

use bevy::platform::collections::HashMap;
use bevy::prelude::*;

use super::levels::{LevelMaterial, LodLevels};
use super::material::{FrameSequentialExtension, FrameSequentialMaterial};

/// The [`FrameSequentialMaterial`] derived from each [`StandardMaterial`] a level names.
#[derive(Resource, Default)]
pub(super) struct DerivedMaterials(
    HashMap<AssetId<StandardMaterial>, Handle<FrameSequentialMaterial>>,
);

impl DerivedMaterials {
    /// The material a level is drawn with (None: derived, but its `StandardMaterial` is not
    /// loaded yet, or not derived at all).
    pub(super) fn resolve(
        &self,
        material: &LevelMaterial,
    ) -> Option<Handle<FrameSequentialMaterial>> {
        match material {
            LevelMaterial::FrameSequential(handle) => Some(handle.clone()),
            LevelMaterial::Standard(handle) => self.0.get(&handle.id()).cloned(),
        }
    }
}

/// Whether `mode` blends the fragment with what lies behind it.
pub(super) fn blends(mode: AlphaMode) -> bool {
    !matches!(mode, AlphaMode::Opaque | AlphaMode::Mask(_))
}

/// `standard` as the frame-sequential material of a level.
fn derive(standard: &StandardMaterial) -> FrameSequentialMaterial {
    FrameSequentialMaterial {
        base: standard.clone(),
        extension: FrameSequentialExtension::default(),
    }
}

/// Derives a material for every `StandardMaterial` a new or changed [`LodLevels`] names, copies
/// each changed one into its derived material, and forgets those the app dropped.
pub(super) fn sync_derived_materials(
    mut derived: ResMut<DerivedMaterials>,
    mut events: MessageReader<AssetEvent<StandardMaterial>>,
    standards: Res<Assets<StandardMaterial>>,
    mut materials: ResMut<Assets<FrameSequentialMaterial>>,
    groups: Query<&LodLevels, Changed<LodLevels>>,
) {
    for levels in &groups {
        for level in &levels.0 {
            let LevelMaterial::Standard(handle) = &level.material else {
                continue;
            };
            if derived.0.contains_key(&handle.id()) {
                continue;
            }
            // Not loaded yet: its `LoadedWithDependencies` (or `Added`) event derives it.
            if let Some(standard) = standards.get(handle) {
                let material = materials.add(derive(standard));
                derived.0.insert(handle.id(), material);
            } else {
                derived.0.insert(handle.id(), materials.reserve_handle());
            }
        }
    }
    for event in events.read() {
        match *event {
            AssetEvent::Added { id }
            | AssetEvent::Modified { id }
            | AssetEvent::LoadedWithDependencies { id } => {
                if let (Some(handle), Some(standard)) = (derived.0.get(&id), standards.get(id)) {
                    // A reserved handle gets its asset, a derived one the change.
                    let _ = materials.insert(handle.id(), derive(standard));
                }
            }
            AssetEvent::Removed { id } | AssetEvent::Unused { id } => {
                derived.0.remove(&id);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use bevy::asset::AssetPlugin;

    use super::*;
    use crate::frame_sequential::LodLevel;

    /// An app with the assets and the system, as the plugin schedules it (no renderer).
    fn app() -> App {
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, AssetPlugin::default()))
            .init_asset::<Image>()
            .init_asset::<Mesh>()
            .init_asset::<StandardMaterial>()
            .init_asset::<FrameSequentialMaterial>()
            .init_resource::<DerivedMaterials>()
            .add_systems(PostUpdate, sync_derived_materials);
        app
    }

    fn derived(app: &App, standard: &Handle<StandardMaterial>) -> Option<FrameSequentialMaterial> {
        let handle = app
            .world()
            .resource::<DerivedMaterials>()
            .resolve(&standard.clone().into())?;
        let materials = app.world().resource::<Assets<FrameSequentialMaterial>>();
        materials.get(&handle).cloned()
    }

    #[test]
    fn a_standard_material_is_derived_once_shared_and_followed() {
        let mut app = app();
        let texture = app.world().resource::<Assets<Image>>().reserve_handle();
        let standard = app
            .world_mut()
            .resource_mut::<Assets<StandardMaterial>>()
            .add(StandardMaterial {
                base_color: Color::srgb(0.8, 0.5, 0.2),
                base_color_texture: Some(texture.clone()),
                ..default()
            });
        let level = || LodLevel::new(Handle::default(), standard.clone());
        app.world_mut().spawn(LodLevels(vec![level(), level()]));
        app.world_mut().spawn(LodLevels(vec![level()]));
        app.update();
        assert_eq!(
            app.world().resource::<DerivedMaterials>().0.len(),
            1,
            "one derived material for one StandardMaterial"
        );
        let material = derived(&app, &standard).expect("derived at once");
        assert_eq!(material.base.base_color, Color::srgb(0.8, 0.5, 0.2));
        assert_eq!(
            material.base.base_color_texture,
            Some(texture),
            "the texture is the same handle"
        );
        // The app edits its material: the level follows (the asset event arrives after the
        // frame that made the change).
        app.world_mut()
            .resource_mut::<Assets<StandardMaterial>>()
            .get_mut(&standard)
            .unwrap()
            .base_color = Color::srgb(0.1, 0.9, 0.3);
        app.update();
        app.update();
        let material = derived(&app, &standard).unwrap();
        assert_eq!(material.base.base_color, Color::srgb(0.1, 0.9, 0.3));
    }

    #[test]
    fn a_material_not_yet_loaded_is_derived_when_it_arrives() {
        let mut app = app();
        let standard = app
            .world()
            .resource::<Assets<StandardMaterial>>()
            .reserve_handle();
        app.world_mut().spawn(LodLevels(vec![LodLevel::new(
            Handle::default(),
            standard.clone(),
        )]));
        app.update();
        assert!(derived(&app, &standard).is_none(), "nothing to derive yet");
        app.world_mut()
            .resource_mut::<Assets<StandardMaterial>>()
            .insert(standard.id(), StandardMaterial::from(Color::WHITE))
            .unwrap();
        app.update();
        app.update();
        let material = derived(&app, &standard).expect("derived once it arrived");
        assert_eq!(material.base.base_color, Color::WHITE);
    }

    #[test]
    fn blending_modes_are_told_apart() {
        assert!(!blends(AlphaMode::Opaque));
        assert!(!blends(AlphaMode::Mask(0.5)));
        for mode in [
            AlphaMode::Blend,
            AlphaMode::Premultiplied,
            AlphaMode::Add,
            AlphaMode::Multiply,
            AlphaMode::AlphaToCoverage,
        ] {
            assert!(blends(mode), "{mode:?}");
        }
    }
}
