//! The impostor as the last level of a lodkit frame-sequential LOD group: the tree's mesh (its
//! own `StandardMaterial`) and its impostor (`LevelMaterial::custom`, through
//! `FrameSequentialMaterialPlugin::<ImpostorMaterial>`), switching at the camera's distance
//! while the LOD bias ramps across it, held to the mesh alone and the impostor alone seen from
//! the same camera (`measure::Figures`: pop, flicker, see-through and ghost pixel-frames).

use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass};
use bevy::prelude::*;
use lodkit::select::{LodGroup, TransitionMode};
use lodkit_bevy::frame_sequential::{
    FrameSequentialGroup, FrameSequentialLevels, FrameSequentialLod, LevelMaterial, LodLevel,
    LodLevels,
};
use lodkit_bevy::impostor::ImpostorMaterial;

use crate::crossfade::{References, Shot};
use crate::headless::{finish_readback, start_readback, step};
use crate::{BACKGROUND, FOV, SIZE};

/// Frames of the run: the LOD bias ramps from 0.8 to 1.25 over them, across the switch.
const FRAMES: usize = 56;

/// How a run draws the group.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Run {
    /// lodkit's default, smooth.
    Smooth,
    /// Switching at once (`TransitionMode::Hard`).
    Hard,
    /// Smooth, on a camera with Bevy's depth and normal prepass and under a light that casts
    /// shadows: the card must draw nothing in either.
    Prepass,
}

/// Runs the group from the shot's camera (`Msaa::Off`), the mesh from `tree`'s components and
/// the card from `impostor`'s, as `run` says; returns the figures and the levels drawn, as
/// JSON.
pub fn frame_sequential_group(
    app: &mut App,
    shot: &Shot,
    [tree, impostor]: [Entity; 2],
    references: &References,
    run: Run,
) -> Result<serde_json::Value, (u8, String)> {
    let world = app.world_mut();
    let tree = world.entity(tree);
    let (Some(tree_mesh), Some(tree_material)) = (
        tree.get::<Mesh3d>().map(|m| m.0.clone()),
        tree.get::<MeshMaterial3d<StandardMaterial>>()
            .map(|m| m.0.clone()),
    ) else {
        return Err((1, "the tree entity has no mesh and material".into()));
    };
    let impostor = world.entity(impostor);
    let (Some(card), Some(impostor_material)) = (
        impostor.get::<Mesh3d>().map(|m| m.0.clone()),
        impostor
            .get::<MeshMaterial3d<ImpostorMaterial>>()
            .map(|m| m.0.clone()),
    ) else {
        return Err((1, "the impostor entity has no card and material".into()));
    };
    // The group's distance is view-normalized: the world distance to its origin over the
    // projection's y scale.
    let p11 = 1.0 / (FOV.to_radians() * 0.5).tan();
    let switch = shot.eye.length() / p11;
    let group = LodGroup::from_distances(&[0.0, switch]).map_err(|e| (1, e.to_string()))?;
    let entity = world
        .spawn((
            LodLevels(vec![
                LodLevel::new(tree_mesh, tree_material),
                LodLevel::new(card, LevelMaterial::custom(impostor_material)),
            ]),
            FrameSequentialGroup::new(group),
        ))
        .id();
    let mut lod = FrameSequentialLod::default();
    lod.settings.bias = 0.8;
    if run == Run::Hard {
        lod.settings.transition = TransitionMode::Hard;
    }
    let camera = world.spawn((shot.camera(), lod)).id();
    let mut spawned = vec![camera, entity];
    if run == Run::Prepass {
        world
            .entity_mut(camera)
            .insert((DepthPrepass, NormalPrepass));
        let light = world.spawn((
            DirectionalLight {
                shadow_maps_enabled: true,
                ..default()
            },
            Transform::from_xyz(-2.0, 6.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        spawned.push(light.id());
    }
    for _ in 0..3 {
        step(app);
    }
    let readback = start_readback(app.world_mut(), &shot.target);
    let mut drawn = Vec::new();
    for f in 0..FRAMES {
        if let Some(mut lod) = app.world_mut().get_mut::<FrameSequentialLod>(camera) {
            lod.settings.bias = 0.8 + 0.45 * f as f32 / (FRAMES - 1) as f32;
        }
        step(app);
        let world = app.world();
        if let Some(levels) = world.get::<FrameSequentialLevels>(entity)
            && !drawn.contains(&levels.drawn)
        {
            drawn.push(levels.drawn);
        }
    }
    let frames =
        finish_readback(app, readback, &spawned, FRAMES, (SIZE, SIZE)).map_err(|e| (1, e))?;
    let fine = vec![references.mesh.clone(); FRAMES];
    let coarse = vec![references.impostor.clone(); FRAMES];
    let figures = crate::measure::Figures::of(
        &frames,
        [&fine[..], &coarse[..]],
        [&fine[..], &coarse[..]],
        [&fine[..], &coarse[..]],
        BACKGROUND,
    )
    .map_err(|e| (1, e.to_string()))?;
    println!(
        "frame-sequential group, mesh -> impostor{}: {}; levels drawn {drawn:?}",
        match run {
            Run::Smooth => "",
            Run::Hard => ", switching at once",
            Run::Prepass => ", with a depth and normal prepass and shadows",
        },
        figures.line()
    );
    let mut json = figures.json();
    json["drawn"] = serde_json::json!(drawn);
    Ok(json)
}
