//! The child entities that draw a LOD group: one shows the level drawn this frame, the other
//! the incoming level while the group is drawn through the screen-door dither.

use bevy::camera::visibility::NoFrustumCulling;
use bevy::log::warn_once;
use bevy::mesh::MeshTag;
use bevy::mesh::skinning::SkinnedMesh;
use bevy::prelude::*;
use lodkit::frame_sequential::{InstanceKey, TransitionScheduler};
use lodkit::select::{LodSelection, LodState};

use super::level_material::{DerivedMaterials, DrawerMaterial};
use super::levels::LodLevels;
use super::rects::Bounds;

/// lodkit's transition scheduler for the app's frame-sequential camera, and the key of each
/// group in it (released when the group goes away).
#[derive(Resource, Default)]
pub(super) struct Scheduler(
    pub(super) TransitionScheduler,
    pub(super) Vec<(Entity, InstanceKey)>,
);

/// What the plugin keeps of a [`FrameSequentialGroup`](super::FrameSequentialGroup) (inserted by the plugin).
#[derive(Component, Clone, Debug)]
pub struct FrameSequentialLevels {
    /// The child entity that draws the group: the plugin gives it the mesh and material of the
    /// level drawn each frame. One entity, not one per level, so Bevy's motion vectors follow
    /// the group from frame to frame (an entity that was hidden last frame gets none).
    pub entity: Entity,
    /// The second drawing child: the incoming level while the group is drawn through the
    /// screen-door dither (MSAA, a blending material), else hidden; spawned the first time the
    /// group is dithered, so groups that never are cost one entity, not two.
    pub dither_entity: Option<Entity>,
    /// The level drawn this frame.
    pub drawn: u8,
    /// lodkit's selection this frame.
    pub selection: Option<LodSelection>,
    /// The transition under way: (from, to).
    pub transition: Option<(u8, u8)>,
    pub(super) key: Option<InstanceKey>,
    pub(super) state: LodState,
    /// The group's model matrix last frame (where the older buffer holds it).
    pub(super) previous_model: Option<Mat4>,
    pub(super) bounds: Option<Bounds>,
}

/// Groups whose levels are new or changed, with their drawers and skin.
type NewLevels<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static LodLevels,
        Option<&'static FrameSequentialLevels>,
        Option<&'static SkinnedMesh>,
    ),
    Changed<LodLevels>,
>;

/// Spawns the drawing child of every new or changed [`LodLevels`]. A changed group starts over:
/// its old drawer goes, and so do its transition slot and t-instance id in the scheduler.
pub(super) fn spawn_levels(
    mut commands: Commands,
    mut scheduler: ResMut<Scheduler>,
    derived: Res<DerivedMaterials>,
    groups: NewLevels,
) {
    let Scheduler(scheduler, keys) = &mut *scheduler;
    for (group, levels, old, skin) in &groups {
        if let Some(old) = old {
            commands.entity(old.entity).despawn();
            if let Some(dither) = old.dither_entity {
                commands.entity(dither).despawn();
            }
            if let Some(key) = old.key {
                let _ = scheduler.remove(key);
            }
            keys.retain(|&(g, _)| g != group);
            commands.entity(group).remove::<FrameSequentialLevels>();
        }
        if levels.0.len() > 256 {
            warn_once!("a LOD group has more than 256 levels: the rest are ignored");
        }
        if let Some(name) = levels
            .0
            .iter()
            .find_map(|l| derived.unregistered(&l.material))
        {
            warn!(
                "LOD group {group}: a level's material is a {name}, which no \
                 FrameSequentialMaterialPlugin::<{name}> derives a level material from: that \
                 level is not drawn (add the plugin)"
            );
        }
        let Some(first) = levels.0.first() else {
            warn_once!("a LOD group has no levels: nothing is drawn");
            continue;
        };
        // The material is set each frame, once a StandardMaterial's derived one is there.
        let entity = spawn_drawer(&mut commands, group, first.mesh.clone(), skin);
        commands.entity(group).insert(FrameSequentialLevels {
            entity,
            dither_entity: None,
            drawn: 0,
            selection: None,
            transition: None,
            key: None,
            state: LodState::NEW,
            previous_model: None,
            bounds: None,
        });
    }
}

/// A hidden drawing child of `group` (showing `mesh` once made visible), with the group's skin.
pub(super) fn spawn_drawer(
    commands: &mut Commands,
    group: Entity,
    mesh: Handle<Mesh>,
    skin: Option<&SkinnedMesh>,
) -> Entity {
    let mut drawer = commands.spawn((
        Mesh3d(mesh),
        DrawerMaterial::default(),
        MeshTag::new(0),
        Transform::IDENTITY,
        Visibility::Hidden,
        ChildOf(group),
    ));
    // A skinned group (a glTF primitive with a skin) is drawn with its joints; its box moves
    // with them, so the drawers are not culled by the rest pose's.
    if let Some(skin) = skin {
        drawer.insert((skin.clone(), NoFrustumCulling));
    }
    drawer.id()
}

/// What a drawer shows for `draw` (level, tag) of `levels`: None where nothing, or a level whose
/// material is not there yet.
pub(super) fn drawn(
    draw: Option<(u8, u32)>,
    levels: &LodLevels,
    derived: &DerivedMaterials,
) -> Option<(Handle<Mesh>, UntypedHandle, u32)> {
    let (lod, tag) = draw?;
    let level = levels.0.get(usize::from(lod)).or(levels.0.last())?;
    Some((level.mesh.clone(), derived.resolve(&level.material)?, tag))
}

pub(super) type DrawerQuery<'w, 's> = Query<
    'w,
    's,
    (
        &'static mut Visibility,
        &'static mut MeshTag,
        &'static mut Mesh3d,
        &'static mut DrawerMaterial,
    ),
>;

/// Shows level `draw.0` of `levels` with tag `draw.1` through `drawer`, or hides it (None, or
/// a level whose material is not there yet).
pub(super) fn show(
    drawers: &mut DrawerQuery,
    drawer: Entity,
    draw: Option<(u8, u32)>,
    levels: &LodLevels,
    derived: &DerivedMaterials,
) {
    let Ok((mut visibility, mut mesh_tag, mut mesh, mut material)) = drawers.get_mut(drawer) else {
        return;
    };
    let Some((level_mesh, handle, tag)) = drawn(draw, levels, derived) else {
        visibility.set_if_neq(Visibility::Hidden);
        return;
    };
    visibility.set_if_neq(Visibility::Inherited);
    mesh_tag.set_if_neq(MeshTag::new(tag));
    if mesh.0 != level_mesh {
        mesh.0 = level_mesh;
    }
    if material.0.as_ref() != Some(&handle) {
        material.0 = Some(handle);
    }
}
