//! Unit tests of the level materials: derived, followed, drawn.

use bevy::asset::AssetPlugin;

use crate::frame_sequential::level_material::*;
use crate::frame_sequential::levels::LodLevel;
use crate::frame_sequential::material::FrameSequentialExtension;

/// A material of an app's own (its shader is not compiled here).
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
struct Plain {
    #[uniform(0)]
    color: LinearRgba,
    alpha_mode: AlphaMode,
}

impl Material for Plain {
    fn alpha_mode(&self) -> AlphaMode {
        self.alpha_mode
    }
}

/// An app with the assets and the systems, as the plugins schedule them (no renderer).
fn app() -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default()))
        .init_asset::<Image>()
        .init_asset::<Mesh>()
        .init_asset::<StandardMaterial>()
        .init_asset::<FrameSequentialMaterial>()
        .init_asset::<Plain>()
        .init_asset::<FrameSequentialLevel<Plain>>();
    add_level_material::<StandardMaterial, FrameSequentialExtension>(&mut app);
    add_level_material::<Plain, FrameSequentialBindings>(&mut app);
    app.configure_sets(PostUpdate, DeriveMaterials.before(ApplyDrawerMaterials));
    app
}

fn derived<B: Material, E: MaterialExtension>(
    app: &App,
    material: LevelMaterial,
) -> Option<ExtendedMaterial<B, E>> {
    let handle = app
        .world()
        .resource::<DerivedMaterials>()
        .resolve(&material)?
        .try_typed::<ExtendedMaterial<B, E>>()
        .ok()?;
    let materials = app.world().resource::<Assets<ExtendedMaterial<B, E>>>();
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
        app.world().resource::<DerivedMaterials>().derived.len(),
        1,
        "one derived material for one StandardMaterial"
    );
    let material: FrameSequentialMaterial =
        derived(&app, standard.clone().into()).expect("derived at once");
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
    let material: FrameSequentialMaterial = derived(&app, standard.into()).unwrap();
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
    let none: Option<FrameSequentialMaterial> = derived(&app, standard.clone().into());
    assert!(none.is_none(), "nothing to derive yet");
    app.world_mut()
        .resource_mut::<Assets<StandardMaterial>>()
        .insert(standard.id(), StandardMaterial::from(Color::WHITE))
        .unwrap();
    app.update();
    app.update();
    let material: FrameSequentialMaterial =
        derived(&app, standard.clone().into()).expect("derived once it arrived");
    assert_eq!(material.base.base_color, Color::WHITE);
    // A mask: the combine takes it, with its alpha test.
    let level = LevelMaterial::Standard(standard.clone());
    {
        let mut masks = app.world_mut().resource_mut::<Assets<StandardMaterial>>();
        let mut leaf = masks.get_mut(&standard).unwrap();
        leaf.alpha_mode = AlphaMode::Mask(0.3);
        leaf.base_color = Color::srgba(1.0, 1.0, 1.0, 0.8);
    }
    app.update();
    app.update();
    let empty = Assets::<FrameSequentialMaterial>::default();
    let looks = app
        .world()
        .resource::<DerivedMaterials>()
        .looks(&level, &empty);
    let test = looks.as_ref().and_then(|l| l.alpha_test.clone());
    assert!(!looks.as_ref().is_some_and(|l| l.blends), "{looks:?}");
    assert_eq!(
        test.map(|t| (t.cutoff, t.base_alpha)),
        Some((0.3, 0.8)),
        "{looks:?}"
    );
}

/// A material of the app's own is derived and followed as a StandardMaterial is; its alpha
/// mode says whether it blends; a drawer showing it gets its `MeshMaterial3d` of the
/// derived type and loses the other type's.
#[test]
fn a_custom_material_is_derived_followed_and_drawn() {
    let mut app = app();
    let plain = app.world_mut().resource_mut::<Assets<Plain>>().add(Plain {
        color: LinearRgba::RED,
        alpha_mode: AlphaMode::Opaque,
    });
    let standard = app
        .world_mut()
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial::default());
    let custom = LevelMaterial::custom(plain.clone());
    assert!(matches!(custom, LevelMaterial::Custom { .. }));
    assert_eq!(
        LevelMaterial::custom(standard.clone()),
        LevelMaterial::Standard(standard.clone()),
        "a StandardMaterial handle stays Standard"
    );
    let made = Handle::<FrameSequentialMaterial>::default();
    assert_eq!(
        LevelMaterial::custom(made.clone()),
        LevelMaterial::FrameSequential(made),
        "a FrameSequentialMaterial handle is drawn as it is"
    );
    app.world_mut().spawn(LodLevels(vec![
        LodLevel::new(Handle::default(), custom.clone()),
        LodLevel::new(Handle::default(), standard.clone()),
    ]));
    app.update();
    let material: FrameSequentialLevel<Plain> =
        derived(&app, custom.clone()).expect("derived at once");
    assert_eq!(material.base.color, LinearRgba::RED);
    let empty = Assets::<FrameSequentialMaterial>::default();
    let looks = |app: &App| {
        app.world()
            .resource::<DerivedMaterials>()
            .looks(&custom, &empty)
            .expect("loaded")
    };
    assert_eq!(
        looks(&app),
        Looks {
            blends: false,
            // No prepass shader of its own: Bevy's default, which lodkit's replaces.
            prepass_dithers: true,
            cull_mode: Some(Face::Back),
            alpha_test: None,
        }
    );
    app.world_mut()
        .resource_mut::<Assets<Plain>>()
        .get_mut(&plain)
        .unwrap()
        .alpha_mode = AlphaMode::Blend;
    app.update();
    app.update();
    assert!(looks(&app).blends, "a change of alpha mode is followed");
    assert!(
        looks(&app).prepass_dithers,
        "a blending material has no prepass"
    );
    app.world_mut()
        .resource_mut::<Assets<Plain>>()
        .get_mut(&plain)
        .unwrap()
        .alpha_mode = AlphaMode::Mask(0.5);
    app.update();
    app.update();
    let masked = looks(&app);
    assert!(
        masked.blends && masked.alpha_test.is_none(),
        "a mask lodkit cannot repeat is dithered: {masked:?}"
    );

    // A drawer: the custom material, then the standard one, then hidden.
    let resolve =
        |app: &App, m: &LevelMaterial| app.world().resource::<DerivedMaterials>().resolve(m);
    let (first, second) = (
        resolve(&app, &custom),
        resolve(&app, &LevelMaterial::Standard(standard)),
    );
    let drawer = app.world_mut().spawn(DrawerMaterial(first.clone())).id();
    app.update();
    let has = |app: &App| {
        (
            app.world()
                .get::<MeshMaterial3d<FrameSequentialLevel<Plain>>>(drawer)
                .map(|m| m.0.clone().untyped()),
            app.world()
                .get::<MeshMaterial3d<FrameSequentialMaterial>>(drawer)
                .map(|m| m.0.clone().untyped()),
        )
    };
    assert_eq!(has(&app), (first.clone(), None));
    app.world_mut().get_mut::<DrawerMaterial>(drawer).unwrap().0 = second.clone();
    app.update();
    assert_eq!(
        has(&app),
        (None, second),
        "one material component at a time"
    );
}

#[test]
fn a_material_without_its_plugin_is_named() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default()))
        .init_asset::<Plain>();
    let derived = DerivedMaterials::default();
    let plain = app.world_mut().resource_mut::<Assets<Plain>>().add(Plain {
        color: LinearRgba::RED,
        alpha_mode: AlphaMode::Opaque,
    });
    let name = derived.unregistered(&LevelMaterial::custom(plain));
    assert!(name.is_some_and(|n| n.ends_with("Plain")), "{name:?}");
}

/// A material with a prepass shader of its own (its shader is not compiled here).
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
struct OwnPrepass {
    alpha_mode: AlphaMode,
}

impl Material for OwnPrepass {
    fn prepass_fragment_shader() -> bevy::shader::ShaderRef {
        "own_prepass.wesl".into()
    }

    fn alpha_mode(&self) -> AlphaMode {
        self.alpha_mode
    }
}

/// A material whose prepass is its own draws a dithered level whole there (its groups switch at
/// once on a camera with MSAA and a prepass); one without a prepass shader, or one that blends
/// (not in the prepass), does not.
#[test]
fn a_prepass_of_the_materials_own_is_told_apart() {
    let own = |alpha_mode| OwnPrepass { alpha_mode };
    assert!(!looks_of(&own(AlphaMode::Opaque)).prepass_dithers);
    assert!(!looks_of(&own(AlphaMode::Mask(0.5))).prepass_dithers);
    // A blending material is not in the prepass, whatever its prepass shader.
    assert!(looks_of(&own(AlphaMode::Blend)).prepass_dithers);
    let plain = |alpha_mode| Plain {
        color: LinearRgba::RED,
        alpha_mode,
    };
    assert!(looks_of(&plain(AlphaMode::Opaque)).prepass_dithers);
    assert!(looks_of(&plain(AlphaMode::Blend)).prepass_dithers);
    assert!(looks_of(&plain(AlphaMode::Mask(0.5))).prepass_dithers);
    assert!(looks_of(&StandardMaterial::default()).prepass_dithers);
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
