//! LOD levels made on the fly: [`AutoLod`] on an entity that already has `Mesh3d` and
//! `MeshMaterial3d<StandardMaterial>` (or of a material of the app's own with a
//! [`FrameSequentialMaterialPlugin`](crate::frame_sequential::FrameSequentialMaterialPlugin)) builds its mesh's LOD chain ([`MeshLodChain`]: levels from
//! meshoptimizer, each with a bound of its distance from the mesh, and switch distances that keep
//! the shown level within a pixel error) in the background, and turns the entity into a [`FrameSequentialGroup`] when it is ready.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use lodkit_bevy::auto_lod::AutoLod;
//!
//! fn give_lod(mut commands: Commands, trees: Query<Entity, With<Mesh3d>>) {
//!     for tree in &trees {
//!         commands.entity(tree).insert(AutoLod::default()); // 1 pixel at 1080p, 60°
//!     }
//! }
//! ```
//!
//! On native platforms the chain is built on a thread of lodkit's own, at the lowest priority
//! (Linux and Android: nice 19), as many builds at once as the machine has cores less one (at
//! least one), the others queued: Bevy's task pools run their tasks on the main thread where Bevy is built without its
//! `multi_threaded` feature, and a chain of a large mesh takes most of a second. On the web it
//! runs on Bevy's `AsyncComputeTaskPool`. Measured on a 2-core machine whose CPU also renders
//! (lavapipe), release build, `cargo run --release --example scale -- --auto-lod 4` in this
//! crate (one 65,536-triangle sphere shared by 4 entities; two runs): median frame 47.4 / 48.7
//! ms before, 48.2 / 50.7 ms over the 46 / 44 frames the build took, slowest 56.4 / 66.6 ms
//! (the build shares the two cores with the renderer); at normal priority the frames in between
//! took about 60 ms, and built on the task pool without `multi_threaded` one frame took 809 ms.
//! On a machine with a core to spare, the build leaves the frame alone.
//!
//! One chain is built per mesh (and descriptor), shared by every entity that shows that mesh:
//! the levels are the same `Handle<Mesh>`s. The main thread only clones the mesh for the build
//! and adds the finished levels to `Assets<Mesh>`; the simplification and its error bound run on
//! the build's thread. Every vertex attribute is carried to the levels, joints and weights
//! included, so a skinned mesh stays skinned (the group's drawers take its `SkinnedMesh`). A mesh the chain
//! cannot take (not a triangle list, its data gone to the render world, no positions) is named
//! in a warning and the entity is left as it is. The entity stops drawing its own mesh the frame
//! its group starts: where Bevy compiles pipelines in the background, the level material's
//! pipeline for that mesh layout may not be ready yet, and the object is missing for those
//! frames (a group of the same layout drawn earlier has compiled it).

use bevy::platform::collections::HashMap;
use bevy::prelude::*;
#[cfg(target_arch = "wasm32")]
use bevy::tasks::{AsyncComputeTaskPool, Task, futures::check_ready};
use lodkit::select::LodGroup;

use crate::frame_sequential::level_material::LevelMaterialTakers;
use crate::frame_sequential::levels::{
    FrameSequentialGroup, FrameSequentialSystems, LodLevel, LodLevels,
};
use crate::lod_chain::{LodChainDescriptor, MeshLodChain, MeshLodChainError, PixelErrorCamera};

/// Gives an entity with `Mesh3d` and `MeshMaterial3d<StandardMaterial>` (or of a type with a
/// [`FrameSequentialMaterialPlugin`](crate::frame_sequential::FrameSequentialMaterialPlugin)) LOD
/// levels built from its mesh in the background (see the [module](self) docs).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct AutoLod {
    /// How the chain is built. Its `camera` sets the pixel error the switch distances keep
    /// (default 1 pixel on a 1080-pixel-high, 60° viewport) and must name the hysteresis the
    /// camera selects with (default 0.5, [`FrameSequentialLod`](crate::FrameSequentialLod)'s).
    pub descriptor: LodChainDescriptor,
}

impl Default for AutoLod {
    fn default() -> Self {
        Self {
            descriptor: LodChainDescriptor {
                camera: PixelErrorCamera {
                    hysteresis: 0.5,
                    ..default()
                },
                ..default()
            },
        }
    }
}

impl AutoLod {
    /// The default chain, switching where a level stays within `pixel_error` pixels.
    pub fn pixel_error(pixel_error: f32) -> Self {
        let mut lod = Self::default();
        lod.descriptor.camera.pixel_error = pixel_error;
        lod
    }
}

/// What became of an [`AutoLod`] entity (inserted by the plugin).
#[derive(Component, Clone, Debug, PartialEq)]
pub enum AutoLodStatus {
    /// Its chain is being built.
    Building,
    /// It is a LOD group now, with this many levels.
    Ready(usize),
    /// The chain could not be built: why (also logged); the entity is drawn as before.
    Failed(String),
}

/// What a chain's build gives.
type Built = Result<MeshLodChain, MeshLodChainError>;

/// A chain's build, off the main thread.
enum Build {
    /// On a thread of lodkit's own (native): Bevy's task pools run their tasks on the main
    /// thread where Bevy is built without its `multi_threaded` feature, and a chain of a large
    /// mesh takes most of a second. None once joined.
    #[cfg(not(target_arch = "wasm32"))]
    Thread(Option<std::thread::JoinHandle<Built>>),
    /// On Bevy's `AsyncComputeTaskPool` (the web, where no thread can be started).
    #[cfg(target_arch = "wasm32")]
    Task(Task<Built>),
    /// Built on the main thread, where no thread could be started. None once taken.
    #[cfg(not(target_arch = "wasm32"))]
    Done(Option<Built>),
}

impl Build {
    /// Starts building the chain of `mesh`.
    fn start(mesh: Mesh, descriptor: LodChainDescriptor) -> Self {
        let job = move || MeshLodChain::build(&mesh, &descriptor);
        #[cfg(not(target_arch = "wasm32"))]
        {
            let shared = std::sync::Arc::new(std::sync::Mutex::new(Some(job)));
            let on_thread = shared.clone();
            let thread = std::thread::Builder::new()
                .name("lodkit AutoLod".into())
                .spawn(move || {
                    lowest_priority();
                    let job = on_thread.lock().ok().and_then(|mut j| j.take());
                    job.map_or(Err(MeshLodChainError::Panicked), |job| job())
                });
            match thread {
                Ok(handle) => Self::Thread(Some(handle)),
                Err(_) => {
                    let job = shared.lock().ok().and_then(|mut j| j.take());
                    Self::Done(Some(
                        job.map_or(Err(MeshLodChainError::Panicked), |job| job()),
                    ))
                }
            }
        }
        #[cfg(target_arch = "wasm32")]
        {
            Self::Task(AsyncComputeTaskPool::get().spawn(async move { job() }))
        }
    }

    /// The chain, once built (a build that panicked is [`MeshLodChainError::Panicked`]).
    fn poll(&mut self) -> Option<Built> {
        match self {
            #[cfg(not(target_arch = "wasm32"))]
            Self::Thread(handle) => {
                if !handle.as_ref()?.is_finished() {
                    return None;
                }
                let joined = handle.take()?.join();
                Some(joined.unwrap_or(Err(MeshLodChainError::Panicked)))
            }
            #[cfg(target_arch = "wasm32")]
            Self::Task(task) => check_ready(task),
            #[cfg(not(target_arch = "wasm32"))]
            Self::Done(built) => built.take(),
        }
    }
}

/// Gives the calling thread the lowest scheduling priority where the platform lets a thread
/// have its own (Linux and Android: nice 19, which `setpriority` sets per thread there); a
/// build then takes the cores the frame leaves idle instead of slowing the frame. Elsewhere the
/// thread keeps the default priority.
#[cfg(not(target_arch = "wasm32"))]
fn lowest_priority() {
    #[cfg(any(target_os = "linux", target_os = "android"))]
    // SAFETY: setpriority reads no memory of ours; with `who` 0 Linux applies it to the
    // calling thread. A refusal leaves the priority as it was, which is harmless.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, 19);
    }
}

/// A chain shared by the entities showing one mesh with one descriptor.
enum Chain {
    /// Being built (None: queued until fewer builds run than [`max_builds`]); the entities
    /// waiting for it.
    Building(Option<Build>, Vec<Entity>),
    /// Built: the coarser levels (level 0 is each entity's own mesh) and the group.
    Ready(Vec<Handle<Mesh>>, LodGroup),
    /// Refused, with the reason.
    Failed(String),
}

/// The chains by mesh, one per descriptor; a mesh's chains go when the mesh does.
#[derive(Resource, Default)]
struct Chains(HashMap<AssetId<Mesh>, Vec<(LodChainDescriptor, Chain)>>);

impl Chains {
    /// How many builds run now.
    fn running(&self) -> usize {
        let slots = self.0.values().flatten();
        slots
            .filter(|(_, c)| matches!(c, Chain::Building(Some(_), _)))
            .count()
    }
}

/// The most chains built at once: one core is left to the frame (the main thread and the
/// renderer); at least one.
fn max_builds() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1).max(1))
}

pub(crate) fn build(app: &mut App) {
    app.init_resource::<Chains>()
        .init_resource::<LevelMaterialTakers>()
        .add_systems(
            PostUpdate,
            (start_chains, finish_chains)
                .chain()
                .before(FrameSequentialSystems),
        );
}

/// Starts (or joins) the chain of each new [`AutoLod`] entity whose mesh is loaded.
fn start_chains(
    mut commands: Commands,
    mut chains: ResMut<Chains>,
    mut events: MessageReader<AssetEvent<Mesh>>,
    meshes: Res<Assets<Mesh>>,
    entities: Query<(Entity, &AutoLod, &Mesh3d), Without<AutoLodStatus>>,
) {
    for event in events.read() {
        if let AssetEvent::Removed { id } | AssetEvent::Unused { id } = event {
            chains.0.remove(id);
        }
    }
    // Queued chains start as builds finish.
    let mut free = max_builds().saturating_sub(chains.running());
    for (id, slots) in chains.0.iter_mut() {
        for (descriptor, chain) in slots.iter_mut() {
            if let (Chain::Building(build @ None, _), Some(data)) = (chain, meshes.get(*id))
                && free > 0
            {
                *build = Some(Build::start(data.clone(), *descriptor));
                free -= 1;
            }
        }
    }
    for (entity, lod, mesh) in &entities {
        let Some(data) = meshes.get(&mesh.0) else {
            continue; // not loaded yet
        };
        let slots = chains.0.entry(mesh.0.id()).or_default();
        let slot = match slots.iter_mut().position(|(d, _)| *d == lod.descriptor) {
            Some(i) => &mut slots[i].1,
            None => {
                let build = (free > 0).then(|| Build::start(data.clone(), lod.descriptor));
                free = free.saturating_sub(1);
                slots.push((lod.descriptor, Chain::Building(build, Vec::new())));
                &mut slots.last_mut().expect("pushed").1
            }
        };
        match slot {
            Chain::Building(_, waiting) => {
                waiting.push(entity);
                commands.entity(entity).insert(AutoLodStatus::Building);
            }
            Chain::Ready(levels, group) => {
                convert(&mut commands, entity, levels, group);
            }
            Chain::Failed(why) => {
                commands
                    .entity(entity)
                    .insert(AutoLodStatus::Failed(why.clone()));
            }
        }
    }
}

/// Turns the entities waiting for each finished chain into groups.
fn finish_chains(
    mut commands: Commands,
    mut chains: ResMut<Chains>,
    mut meshes: ResMut<Assets<Mesh>>,
) {
    for slots in chains.0.values_mut() {
        for (descriptor, slot) in slots.iter_mut() {
            let Chain::Building(build, waiting) = slot else {
                continue;
            };
            let Some(result) = build.as_mut().and_then(Build::poll) else {
                continue;
            };
            let waiting = std::mem::take(waiting);
            let built = result.and_then(|chain| Ok((chain.lod_group(&descriptor.camera)?, chain)));
            *slot = match built {
                Ok((group, chain)) => {
                    let coarser: Vec<Handle<Mesh>> = chain.meshes()[1..]
                        .iter()
                        .map(|m| meshes.add(m.clone()))
                        .collect();
                    for &entity in &waiting {
                        convert(&mut commands, entity, &coarser, &group);
                    }
                    Chain::Ready(coarser, group)
                }
                Err(e) => {
                    let why = e.to_string();
                    for &entity in &waiting {
                        warn!("AutoLod on {entity}: no LOD levels: {why}");
                        if let Ok(mut e) = commands.get_entity(entity) {
                            e.insert(AutoLodStatus::Failed(why.clone()));
                        }
                    }
                    Chain::Failed(why)
                }
            };
        }
    }
}

/// Makes `entity` a group of its own mesh and the `coarser` levels, each drawn with its own
/// material.
fn convert(commands: &mut Commands, entity: Entity, coarser: &[Handle<Mesh>], group: &LodGroup) {
    let coarser = coarser.to_vec();
    let group = group.clone();
    commands.queue(move |world: &mut World| {
        let Ok(mut e) = world.get_entity_mut(entity) else {
            return;
        };
        let Some(mesh) = e.get::<Mesh3d>().map(|m| m.0.clone()) else {
            let why = "the entity lost its Mesh3d".to_owned();
            warn!("AutoLod on {entity}: no LOD levels: {why}");
            e.insert(AutoLodStatus::Failed(why));
            return;
        };
        let material = e.resource_scope(|e, takers: Mut<LevelMaterialTakers>| takers.take(e));
        let Some(material) = material else {
            let why = "the entity has no material a level can use: a MeshMaterial3d of \
                       StandardMaterial or of a type with a FrameSequentialMaterialPlugin"
                .to_owned();
            warn!("AutoLod on {entity}: no LOD levels: {why}");
            e.insert(AutoLodStatus::Failed(why));
            return;
        };
        let levels: Vec<LodLevel> = std::iter::once(mesh)
            .chain(coarser)
            .map(|mesh| LodLevel::new(mesh, material.clone()))
            .collect();
        let count = levels.len();
        e.remove::<Mesh3d>().insert((
            LodLevels(levels),
            FrameSequentialGroup::new(group),
            AutoLodStatus::Ready(count),
        ));
    });
}

#[cfg(test)]
mod tests {
    use bevy::asset::{AssetPlugin, RenderAssetUsages};
    use bevy::mesh::PrimitiveTopology;

    use crate::auto_lod::*;

    fn app() -> App {
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, AssetPlugin::default()))
            .init_asset::<Mesh>()
            .init_asset::<Image>()
            .init_asset::<StandardMaterial>();
        build(&mut app);
        app
    }

    /// Updates until no entity is building (the chains run on the task pool).
    fn settle(app: &mut App) {
        for _ in 0..20_000 {
            app.update();
            let world = app.world_mut();
            let building = world
                .query::<&AutoLodStatus>()
                .iter(world)
                .any(|s| *s == AutoLodStatus::Building);
            let waiting = world
                .query_filtered::<(), (With<AutoLod>, Without<AutoLodStatus>)>()
                .iter(world)
                .count();
            if !building && waiting == 0 {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        panic!("the chains never finished");
    }

    #[test]
    fn entities_with_one_mesh_share_one_chain_and_become_groups() {
        let mut app = app();
        let world = app.world_mut();
        let sphere = Sphere::new(1.0).mesh().uv(48, 24);
        let expected = MeshLodChain::build(&sphere, &AutoLod::default().descriptor).unwrap();
        let mesh = world.resource_mut::<Assets<Mesh>>().add(sphere);
        let materials: Vec<_> = [Color::WHITE, Color::BLACK]
            .map(|c| world.resource_mut::<Assets<StandardMaterial>>().add(c))
            .into();
        let entities: Vec<Entity> = materials
            .iter()
            .map(|m| {
                world
                    .spawn((
                        Mesh3d(mesh.clone()),
                        MeshMaterial3d(m.clone()),
                        AutoLod::default(),
                    ))
                    .id()
            })
            .collect();
        settle(&mut app);
        let world = app.world();
        let levels: Vec<&LodLevels> = entities
            .iter()
            .map(|&e| world.get::<LodLevels>(e).expect("a group"))
            .collect();
        let n = expected.meshes().len();
        assert!(n >= 3, "{n} levels");
        for (e, (l, m)) in entities.iter().zip(levels.iter().zip(&materials)) {
            assert_eq!(
                world.get::<AutoLodStatus>(*e),
                Some(&AutoLodStatus::Ready(n))
            );
            assert_eq!(l.0.len(), n);
            assert_eq!(l.0[0].mesh, mesh, "level 0 is the entity's own mesh");
            assert!(l.0.iter().all(|level| level.material == m.clone().into()));
            assert!(world.get::<Mesh3d>(*e).is_none(), "the group draws it now");
        }
        // One chain: the coarser levels are the same assets for both entities.
        for k in 1..n {
            assert_eq!(levels[0].0[k].mesh, levels[1].0[k].mesh);
            let triangles = world
                .resource::<Assets<Mesh>>()
                .get(&levels[0].0[k].mesh)
                .unwrap()
                .indices()
                .unwrap()
                .len()
                / 3;
            assert_eq!(triangles, expected.chain().levels()[k].triangles());
        }
        assert_eq!(
            world.resource::<Assets<Mesh>>().len(),
            n,
            "one copy of each level"
        );
        let group = world.get::<FrameSequentialGroup>(entities[0]).unwrap();
        assert_eq!(
            group.group,
            expected
                .lod_group(&AutoLod::default().descriptor.camera)
                .unwrap()
        );
    }

    #[test]
    fn a_mesh_the_chain_cannot_take_is_named_and_left_as_it_is() {
        let mut app = app();
        let world = app.world_mut();
        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default())
            .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![[0.0f32; 3]; 2]);
        let mesh = world.resource_mut::<Assets<Mesh>>().add(lines);
        let material = world
            .resource_mut::<Assets<StandardMaterial>>()
            .add(Color::WHITE);
        let entity = world
            .spawn((Mesh3d(mesh), MeshMaterial3d(material), AutoLod::default()))
            .id();
        settle(&mut app);
        let status = app.world().get::<AutoLodStatus>(entity).unwrap();
        assert!(
            matches!(status, AutoLodStatus::Failed(why) if why.contains("LineList")),
            "{status:?}"
        );
        assert!(
            app.world().get::<Mesh3d>(entity).is_some(),
            "drawn as before"
        );
        assert!(app.world().get::<LodLevels>(entity).is_none());
    }
}
