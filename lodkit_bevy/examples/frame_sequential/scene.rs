//! The scene both techniques render: three LOD groups (large and near, small and far, one that
//! moves), two levels each (a fine warm sphere, a coarse cool one), a light, and the camera
//! paths: still with a LOD bias that sweeps every group through its band, and moving back and
//! sideways at bias 1 so every group crosses its band. With `--chain` the moving group's coarse
//! level and its switch distance come from lodkit's LOD chain ([`chain`]): meshoptimizer
//! simplifies the fine sphere, and the distance keeps the coarse level within
//! [`CHAIN_PIXEL_ERROR`] of it.

use std::ops::Range;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

use bevy::camera::visibility::VisibilityRange;
use bevy::prelude::*;
use lodkit::select::LodGroup;
use lodkit_bevy::frame_sequential::{FrameSequentialGroup, LodLevel, LodLevels};
use lodkit_bevy::lod_chain::{LodChainDescriptor, MeshLodChain, PixelErrorCamera};

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

/// Height of the frames the example renders (pixels): the chain's pixel error is on it.
pub const HEIGHT: u32 = 192;

/// Screen-space error (pixels at [`HEIGHT`], Bevy's default field of view) the chain's coarse
/// level may show against the fine sphere: it sets the moving group's switch distance.
pub const CHAIN_PIXEL_ERROR: f32 = 1.0;

static FROM_CHAIN: AtomicBool = AtomicBool::new(false);

/// Builds the moving group's levels and distance with the LOD chain (`--chain`).
pub fn use_chain() {
    FROM_CHAIN.store(true, Ordering::Relaxed);
}

/// The moving group's two levels: its fine sphere and what lodkit's LOD chain simplifies it to
/// (one level at about 20 % of the triangles: at 5 % meshoptimizer's sphere is 0.6 off, its
/// whole radius, and would never be shown), built once.
pub fn chain() -> &'static MeshLodChain {
    static CHAIN: OnceLock<MeshLodChain> = OnceLock::new();
    CHAIN.get_or_init(|| {
        let descriptor = LodChainDescriptor {
            levels: 2,
            ratio: 0.2,
            ..Default::default()
        };
        MeshLodChain::build(&fine_sphere(0.6), &descriptor).expect("a sphere simplifies")
    })
}

/// The camera the chain's switch distance holds its pixel error for: the example's field of
/// view and frame height, and lodkit's hysteresis band (the distance is the band's middle).
pub fn chain_camera() -> PixelErrorCamera {
    PixelErrorCamera {
        fov_y: std::f32::consts::FRAC_PI_4,
        viewport_height: HEIGHT as f32,
        pixel_error: CHAIN_PIXEL_ERROR,
        hysteresis: BAND / p11(),
    }
}

/// The chain's switch distance in world units (the middle of the band).
fn chain_distance() -> f32 {
    let group = chain().lod_group(&chain_camera()).expect("a valid camera");
    group.levels()[1].distance * p11()
}

fn fine_sphere(radius: f32) -> Mesh {
    Sphere::new(radius).mesh().uv(48, 24)
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
    /// Whether the coarse level and the distance come from the LOD chain ([`chain`]).
    pub from_chain: bool,
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
            from_chain: false,
        },
        GroupSpec {
            position: Vec3::new(1.6, 0.6, -6.0),
            radius: 0.35,
            distance: 13.0,
            sway: 0.0,
            colors: [Color::srgb(0.90, 0.80, 0.25), Color::srgb(0.35, 0.45, 0.90)],
            from_chain: false,
        },
        GroupSpec {
            position: Vec3::new(1.0, -0.6, -1.5),
            radius: 0.6,
            distance: if FROM_CHAIN.load(Ordering::Relaxed) {
                chain_distance()
            } else {
                8.5
            },
            sway: 0.5,
            colors: [Color::srgb(0.85, 0.35, 0.45), Color::srgb(0.30, 0.80, 0.55)],
            from_chain: FROM_CHAIN.load(Ordering::Relaxed),
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
    if spec.from_chain {
        let levels = chain().meshes();
        return [meshes.add(levels[0].clone()), meshes.add(levels[1].clone())];
    }
    [
        meshes.add(fine_sphere(spec.radius)),
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
                    // The app's own StandardMaterials, as they are: the plugin derives what
                    // the combine needs.
                    let levels = (0..2)
                        .map(|i| {
                            let material = world
                                .resource_mut::<Assets<StandardMaterial>>()
                                .add(standard(spec.colors[i]));
                            LodLevel::new(meshes[i].clone(), material)
                        })
                        .collect();
                    // The chain's group is the same distance over p11: built by the chain.
                    let group = if spec.from_chain {
                        chain().lod_group(&chain_camera()).expect("a valid camera")
                    } else {
                        LodGroup::from_distances(&[0.0, spec.distance / p11()])
                            .expect("increasing distances")
                    };
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
