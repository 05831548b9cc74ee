//! A glTF scene loaded by Bevy's own loader, and the sphere around what it shows, for the
//! examples' camera walks.

use bevy::camera::primitives::Aabb;
use bevy::prelude::*;

/// Spawns scene 0 of `file` (from the app's asset folder) and runs updates until it is spawned
/// and what the plugins make of it is made; false when it did not load within 600 updates.
pub fn load_scene(app: &mut App, file: &str) -> bool {
    let world = app.world_mut();
    let scene = world
        .resource::<AssetServer>()
        .load(GltfAssetLabel::Scene(0).from_asset(file.to_owned()));
    world.spawn(WorldAssetRoot(scene));
    for _ in 0..600 {
        crate::headless::step(app);
        let world = app.world_mut();
        let spawned = world
            .query_filtered::<Entity, With<WorldAssetRoot>>()
            .iter(world)
            .any(|root| world.get::<Children>(root).is_some_and(|c| !c.is_empty()));
        if spawned {
            // The groups made and their transforms propagated.
            crate::headless::step(app);
            crate::headless::step(app);
            return true;
        }
    }
    false
}

/// The sphere around every box in the scene (`Aabb`s, kept by LOD groups too): (centre,
/// radius); None for an empty scene.
pub fn scene_sphere(world: &mut World) -> Option<(Vec3, f32)> {
    let spheres: Vec<(Vec3, f32)> = world
        .query::<(&Aabb, &GlobalTransform)>()
        .iter(world)
        .map(|(aabb, transform)| {
            let scale = transform
                .to_scale_rotation_translation()
                .0
                .abs()
                .max_element();
            let centre = transform.transform_point(Vec3::from(aabb.center));
            (centre, Vec3::from(aabb.half_extents).length() * scale)
        })
        .collect();
    let (lo, hi) = spheres
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &(c, r)| {
            (lo.min(c - r), hi.max(c + r))
        });
    let centre = 0.5 * (lo + hi);
    let radius = spheres
        .iter()
        .map(|&(c, r)| c.distance(centre) + r)
        .fold(0.0f32, f32::max);
    (radius.is_finite() && radius > 0.0).then_some((centre, radius))
}
