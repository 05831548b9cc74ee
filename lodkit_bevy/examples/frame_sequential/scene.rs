//! The scene both techniques render: three LOD groups (large and near, small and far, one that
//! moves), two levels each (a fine warm sphere, a coarse cool one), a light, and the camera
//! paths: still with a LOD bias that sweeps every group through its band, and moving back and
//! sideways at bias 1 so every group crosses its band.

use std::ops::Range;

use bevy::camera::visibility::VisibilityRange;
use bevy::prelude::*;
use lodkit::select::LodGroup;
use lodkit_bevy::frame_sequential::{
    FrameSequentialExtension, FrameSequentialGroup, FrameSequentialMaterial, LodLevel, LodLevels,
};

/// Frames of a run.
pub const FRAMES: usize = 72;
/// Width of the transition band in world units (the same for every group: lodkit's hysteresis
/// is one setting per camera).
pub const BAND: f32 = 2.0;
/// |P[1][1]| of Bevy's default perspective (vertical field of view pi/4): lodkit selects on
/// distance / |P[1][1]|, Bevy's visibility ranges on the distance itself.
pub fn p11() -> f32 {
    1.0 / (std::f32::consts::FRAC_PI_8).tan()
}

/// One LOD group of the scene.
pub struct GroupSpec {
    /// Where it stands at frame 0.
    pub position: Vec3,
    /// Sphere radius.
    pub radius: f32,
    /// The switch distance (world units, the middle of the band).
    pub distance: f32,
    /// Sideways motion: amplitude (world units) of x = position.x + a sin(0.12 frame).
    pub sway: f32,
    /// Colors of the fine and the coarse level.
    pub colors: [Color; 2],
}

/// The three groups.
pub fn groups() -> [GroupSpec; 3] {
    [
        GroupSpec {
            position: Vec3::new(-1.3, 0.0, 0.0),
            radius: 1.0,
            distance: 7.1,
            sway: 0.0,
            colors: [Color::srgb(0.95, 0.55, 0.20), Color::srgb(0.20, 0.65, 0.85)],
        },
        GroupSpec {
            position: Vec3::new(1.6, 0.6, -6.0),
            radius: 0.35,
            distance: 13.0,
            sway: 0.0,
            colors: [Color::srgb(0.90, 0.80, 0.25), Color::srgb(0.35, 0.45, 0.90)],
        },
        GroupSpec {
            position: Vec3::new(1.0, -0.6, -1.5),
            radius: 0.6,
            distance: 8.5,
            sway: 0.5,
            colors: [Color::srgb(0.85, 0.35, 0.45), Color::srgb(0.30, 0.80, 0.55)],
        },
    ]
}

/// Where group `spec` stands at `frame`.
pub fn group_position(spec: &GroupSpec, frame: usize) -> Vec3 {
    spec.position + Vec3::X * spec.sway * (0.12 * frame as f32).sin()
}

/// Camera pose and LOD bias of a run at `frame`.
pub fn camera_at(moving: bool, frame: usize) -> (Transform, f32) {
    let s = frame as f32 / (FRAMES - 1) as f32;
    let (eye, bias) = if moving {
        (Vec3::new(-0.5 + s, 0.3, 5.0 + 4.5 * s), 1.0)
    } else {
        (Vec3::new(-0.5, 0.3, 5.0), 1.0 + 0.75 * s)
    };
    let target = Vec3::new(0.0, 0.0, -1.0);
    (
        Transform::from_translation(eye).looking_at(target, Vec3::Y),
        bias,
    )
}

/// Bevy's visibility ranges of a group's two levels under LOD `bias` (distances divided by it).
pub fn bevy_ranges(spec: &GroupSpec, bias: f32) -> [VisibilityRange; 2] {
    let band: Range<f32> = (spec.distance - BAND / 2.0) / bias..(spec.distance + BAND / 2.0) / bias;
    [
        VisibilityRange {
            start_margin: 0.0..0.0,
            end_margin: band.clone(),
            use_aabb: false,
        },
        VisibilityRange {
            start_margin: band,
            end_margin: f32::MAX..f32::MAX,
            use_aabb: false,
        },
    ]
}

/// Whether a group at `distance` (world units, from the camera) is inside its band under `bias`.
pub fn in_band(spec: &GroupSpec, distance: f32, bias: f32) -> bool {
    (distance * bias - spec.distance).abs() < BAND / 2.0
}

/// How a run draws the groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// Level `0` or `1` alone, Bevy's StandardMaterial: the references.
    Reference(usize),
    /// lodkit's frame-sequential LOD.
    FrameSequential,
    /// Bevy's own `VisibilityRange` crossfade (dithered), StandardMaterial.
    BevyCrossfade,
}

/// The meshes of a group's two levels.
fn level_meshes(spec: &GroupSpec, meshes: &mut Assets<Mesh>) -> [Handle<Mesh>; 2] {
    [
        meshes.add(Sphere::new(spec.radius).mesh().uv(48, 24)),
        meshes.add(Sphere::new(spec.radius).mesh().uv(9, 6)),
    ]
}

fn standard(color: Color) -> StandardMaterial {
    StandardMaterial {
        base_color: color,
        perceptual_roughness: 0.6,
        ..default()
    }
}

/// Spawns the groups for `technique`; returns each group's root entity (whose `Transform` the
/// run moves) and, for Bevy's crossfade, the level entities holding the visibility ranges.
pub fn spawn_groups(world: &mut World, technique: Technique) -> Vec<(Entity, Vec<Entity>)> {
    groups()
        .iter()
        .map(|spec| {
            let meshes = level_meshes(spec, &mut world.resource_mut::<Assets<Mesh>>());
            let transform = Transform::from_translation(spec.position);
            match technique {
                Technique::FrameSequential => {
                    let levels = (0..2)
                        .map(|i| {
                            let material = world
                                .resource_mut::<Assets<FrameSequentialMaterial>>()
                                .add(FrameSequentialMaterial {
                                    base: standard(spec.colors[i]),
                                    extension: FrameSequentialExtension::default(),
                                });
                            LodLevel::new(meshes[i].clone(), material)
                        })
                        .collect();
                    let group = LodGroup::from_distances(&[0.0, spec.distance / p11()])
                        .expect("increasing distances");
                    let root = world
                        .spawn((
                            LodLevels(levels),
                            FrameSequentialGroup::new(group),
                            transform,
                        ))
                        .id();
                    (root, Vec::new())
                }
                Technique::Reference(level) => {
                    let material = world
                        .resource_mut::<Assets<StandardMaterial>>()
                        .add(standard(spec.colors[level]));
                    let root = world
                        .spawn((
                            Mesh3d(meshes[level].clone()),
                            MeshMaterial3d(material),
                            transform,
                        ))
                        .id();
                    (root, Vec::new())
                }
                Technique::BevyCrossfade => {
                    let root = world.spawn((transform, Visibility::default())).id();
                    let ranges = bevy_ranges(spec, 1.0);
                    let children = (0..2)
                        .map(|i| {
                            let material = world
                                .resource_mut::<Assets<StandardMaterial>>()
                                .add(standard(spec.colors[i]));
                            world
                                .spawn((
                                    Mesh3d(meshes[i].clone()),
                                    MeshMaterial3d(material),
                                    ranges[i].clone(),
                                    Transform::IDENTITY,
                                    ChildOf(root),
                                ))
                                .id()
                        })
                        .collect();
                    (root, children)
                }
            }
        })
        .collect()
}
