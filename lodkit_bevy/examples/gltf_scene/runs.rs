//! The loaded scene and one run over it: a camera of its own (Bevy's default MSAA unless
//! [`Scene::msaa`] says otherwise, nothing else changed), the scene's LOD groups drawn by lodkit, by Bevy's `VisibilityRange` crossfade
//! from the same levels, or as one level alone (the references), every frame read back.

use std::path::Path;

use bevy::camera::visibility::VisibilityRange;
use bevy::prelude::*;
use lodkit_bevy::frame_sequential::{
    FrameSequentialDefaultCamera, FrameSequentialGroup, FrameSequentialLevels, FrameSequentialLod,
    FrameSequentialLodPlugin, LevelMaterial, LodLevels,
};

use lodkit_bevy::impostor::ImpostorMaterial;

use crate::frames::Frame;
use crate::headless::{
    build_app_with_assets, finish_readback, harness_camera, render_target, start_readback, step,
};

pub const WIDTH: u32 = 320;
/// The height `lodkit lod` made the committed file's switch distances for.
pub const HEIGHT: u32 = 180;
/// The clear colour: a key colour no object of a real asset comes near, so that "shows the
/// background" (within `frames::BACKGROUND_TOLERANCE`) means a hole. A dark grey one was within
/// the tolerance of the dark rubber of Bevy's FlightHelmet: a pixel whose shade moved by one
/// level counted as a hole, or as an object where no level is.
pub const BACKGROUND: Color = Color::srgb_u8(255, 0, 255);
/// Updates at the first pose before a run is recorded (materials and view resources ready).
const WARMUP_UPDATES: usize = 3;

/// A failure with its exit code.
pub struct Failure(pub u8, pub String);

/// How a run draws the scene's LOD groups (nodes without levels are drawn as loaded in every
/// run).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// Each group's level k alone (its last where it has fewer), as a plain Bevy mesh (or
    /// impostor), up to where the group is hidden: the references.
    Level(usize),
    /// Bevy's own `VisibilityRange` crossfade over the group's levels, at its distances and
    /// with the same band.
    BevyCrossfade,
    /// lodkit's frame-sequential LOD: the groups the plugin made of the file, as they are.
    FrameSequential,
}

/// A level's material as a plain entity draws it: a mesh level's `StandardMaterial`, or an
/// impostor level's `ImpostorMaterial`.
#[derive(Clone)]
pub enum LevelDraw {
    Standard(Handle<StandardMaterial>),
    Impostor(Handle<ImpostorMaterial>),
}

impl LevelDraw {
    fn insert(&self, entity: &mut EntityWorldMut) {
        match self {
            Self::Standard(m) => entity.insert(MeshMaterial3d(m.clone())),
            Self::Impostor(m) => entity.insert(MeshMaterial3d(m.clone())),
        };
    }
}

/// A LOD group the plugin made of the file.
pub struct Group {
    pub entity: Entity,
    pub name: String,
    /// Mesh and material of each level.
    pub levels: Vec<(Handle<Mesh>, LevelDraw)>,
    /// View-normalized switch distances (the first is 0).
    pub distances: Vec<f32>,
    pub max_distance: Option<f32>,
    pub transform: Transform,
    /// Largest axis scale (lodkit divides world distances by it).
    pub scale: f32,
}

impl Group {
    /// Bevy's visibility range of level `k`: the band of lodkit's hysteresis `h` around each
    /// switch, in world units (view-normalized distance times |P11| and the scale).
    fn range(&self, k: usize, h: f32) -> VisibilityRange {
        let world = |d: f32| (d - h / 2.0) * p11() * self.scale..(d + h / 2.0) * p11() * self.scale;
        let next = self.distances.get(k + 1).copied().or(self.max_distance);
        VisibilityRange {
            start_margin: if k == 0 {
                0.0..0.0
            } else {
                world(self.distances[k])
            },
            end_margin: next.map_or(f32::MAX..f32::MAX, world),
            use_aabb: false,
        }
    }
}

/// |P[1][1]| of Bevy's default perspective (vertical field of view π/4).
pub fn p11() -> f32 {
    1.0 / std::f32::consts::FRAC_PI_8.tan()
}

/// What one run recorded.
pub struct Run {
    pub frames: Vec<Frame>,
    /// Per group (in [`Scene::groups`] order): the levels lodkit drew, in the order first drawn.
    pub drawn: Vec<Vec<u8>>,
}

pub struct Scene {
    app: App,
    target: Handle<Image>,
    pub groups: Vec<Group>,
    /// Meshes the file gave no levels (drawn as loaded).
    pub plain_meshes: usize,
    /// The sphere around the scene: (centre, radius).
    pub sphere: (Vec3, f32),
    /// Every run's camera's MSAA (Bevy's default, `Sample4`, unless set).
    pub msaa: Msaa,
}

impl Scene {
    /// Loads scene 0 of `file` (in folder `assets`) with Bevy's glTF loader, in an app whose
    /// only lodkit code is the plugin.
    pub fn load(assets: &Path, file: &str) -> Result<Self, Failure> {
        let mut app = build_app_with_assets(Some(assets), |app| {
            app.add_plugins(FrameSequentialLodPlugin);
        });
        let world = app.world_mut();
        let target = render_target(world, WIDTH, HEIGHT);
        world.spawn((
            DirectionalLight {
                illuminance: 6000.0,
                ..default()
            },
            Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        if !crate::gltf_scene::load_scene(&mut app, file) {
            return Err(Failure(1, format!("{file} did not load")));
        }
        let world = app.world_mut();
        let mut groups = Vec::new();
        let mut query = world.query::<(
            Entity,
            &FrameSequentialGroup,
            &LodLevels,
            &GlobalTransform,
            Option<&Name>,
            Option<&ChildOf>,
        )>();
        for (entity, group, levels, transform, name, parent) in query.iter(world) {
            let name = name
                .or_else(|| parent.and_then(|p| world.get::<Name>(p.parent())))
                .map_or_else(|| format!("{entity}"), |n| n.as_str().to_owned());
            let levels = levels
                .0
                .iter()
                .map(|level| match &level.material {
                    LevelMaterial::Standard(material) => {
                        Ok((level.mesh.clone(), LevelDraw::Standard(material.clone())))
                    }
                    LevelMaterial::Custom { handle, .. } => handle
                        .clone()
                        .try_typed::<ImpostorMaterial>()
                        .map(|m| (level.mesh.clone(), LevelDraw::Impostor(m)))
                        .map_err(|_| Failure(1, format!("{name}: a level of another material"))),
                    _ => Err(Failure(
                        1,
                        format!("{name}: a level without a StandardMaterial"),
                    )),
                })
                .collect::<Result<_, _>>()?;
            let transform = transform.compute_transform();
            groups.push(Group {
                entity,
                name,
                levels,
                distances: group.group.levels().iter().map(|l| l.distance).collect(),
                max_distance: group.group.max_distance(),
                scale: transform.scale.abs().max_element(),
                transform,
            });
        }
        groups.sort_by(|a, b| a.name.cmp(&b.name));
        let plain_meshes = world
            .query_filtered::<(), With<MeshMaterial3d<StandardMaterial>>>()
            .iter(world)
            .count();
        let Some(sphere) = crate::gltf_scene::scene_sphere(world) else {
            return Err(Failure(1, format!("{file} has no mesh")));
        };
        Ok(Self {
            app,
            target,
            groups,
            plain_meshes,
            sphere,
            msaa: Msaa::default(),
        })
    }

    /// The world distance from the scene's centre past which every group shows its last level:
    /// each group's last switch (the far edge of its band) plus its distance from the centre.
    pub fn farthest_switch(&self) -> f32 {
        let h = FrameSequentialLod::default().settings.hysteresis;
        self.groups
            .iter()
            .filter_map(|g| {
                let last = g.distances.iter().skip(1).last()?;
                let off = g.transform.translation.distance(self.sphere.0);
                Some((last + h / 2.0) * p11() * g.scale + off)
            })
            .fold(2.0 * self.sphere.1, f32::max)
    }

    /// Runs `technique` with the camera at `poses`, one per frame.
    pub fn run(&mut self, technique: Technique, poses: &[Transform]) -> Result<Run, Failure> {
        let world = self.app.world_mut();
        // An app's camera: Bevy's default MSAA (Sample4) unless the scene says otherwise; no
        // tonemapping or deband dither, so the background is the clear colour exactly.
        let camera = world.spawn((
            harness_camera(&self.target, BACKGROUND, poses[0]),
            self.msaa,
        ));
        let camera = camera.id();
        // The app's camera has no lodkit component: with groups about and no camera selecting,
        // the plugin gives it `FrameSequentialLod::default()`. The other runs' cameras are the
        // harness's and must stay as they are (no Hdr).
        world.insert_resource(FrameSequentialDefaultCamera(
            technique == Technique::FrameSequential,
        ));
        let h = FrameSequentialLod::default().settings.hysteresis;
        let mut copies = Vec::new();
        for group in &self.groups {
            let shown = technique == Technique::FrameSequential;
            *world.get_mut::<Visibility>(group.entity).expect("a group") = if shown {
                Visibility::Inherited
            } else {
                Visibility::Hidden
            };
            let last = group.levels.len() - 1;
            let levels: Vec<usize> = match technique {
                Technique::Level(k) => vec![k.min(last)],
                Technique::BevyCrossfade => (0..=last).collect(),
                Technique::FrameSequential => Vec::new(),
            };
            for k in levels {
                let (mesh, material) = group.levels[k].clone();
                let mut copy = world.spawn((Mesh3d(mesh), group.transform));
                material.insert(&mut copy);
                if technique == Technique::BevyCrossfade {
                    copy.insert(group.range(k, h));
                } else if let Some(max) = group.max_distance {
                    // A reference level shows until the group is hidden (a hard cut): a
                    // primitive whose object's impostor another group draws is hidden there.
                    let max = max * p11() * group.scale;
                    copy.insert(VisibilityRange {
                        start_margin: 0.0..0.0,
                        end_margin: max..max,
                        use_aabb: false,
                    });
                }
                copies.push(copy.id());
            }
        }
        for _ in 0..WARMUP_UPDATES {
            step(&mut self.app);
        }
        let readback = start_readback(self.app.world_mut(), &self.target);
        let selecting = self.app.world().get::<FrameSequentialLod>(camera).is_some();
        if selecting != (technique == Technique::FrameSequential) {
            return Err(Failure(
                1,
                format!("{technique:?}: the camera selects: {selecting}"),
            ));
        }
        let mut drawn = vec![Vec::new(); self.groups.len()];
        for pose in poses {
            *self
                .app
                .world_mut()
                .get_mut::<Transform>(camera)
                .expect("camera") = *pose;
            step(&mut self.app);
            let world = self.app.world();
            for (group, seen) in self.groups.iter().zip(&mut drawn) {
                if let Some(levels) = world.get::<FrameSequentialLevels>(group.entity)
                    && technique == Technique::FrameSequential
                    && !seen.contains(&levels.drawn)
                {
                    seen.push(levels.drawn);
                }
            }
        }
        let entities: Vec<Entity> = std::iter::once(camera).chain(copies).collect();
        let frames = finish_readback(
            &mut self.app,
            readback,
            &entities,
            poses.len(),
            (WIDTH, HEIGHT),
        )
        .map_err(|e| Failure(1, e))?;
        Ok(Run { frames, drawn })
    }
}
