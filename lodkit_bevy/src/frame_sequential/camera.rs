//! The camera that selects when the app names none: LOD groups need a camera with
//! [`FrameSequentialLod`] to choose their levels, and an app that only added the plugin and
//! loaded a glTF file with levels has none.

use bevy::camera::RenderTarget;
use bevy::log::info_once;
use bevy::prelude::*;

use super::FrameSequentialLod;
use super::levels::FrameSequentialGroup;

/// Whether the plugin gives a camera [`FrameSequentialLod::default()`] while LOD groups exist
/// and no camera has the component (default: it does). The camera chosen is an active
/// `Camera3d` that draws to a window (the app's main camera, not one drawing a texture such as
/// a minimap's; any active `Camera3d` where none draws to a window), the lowest `Camera::order`
/// first, then the lowest entity index; the component (and the [`Hdr`] it requires) is
/// inserted on it, so the app sees and may edit it. Without a camera that selects,
/// the groups draw nothing. Set `FrameSequentialDefaultCamera(false)` for an app that gives its
/// camera the component itself, later or only at times.
///
/// [`Hdr`]: bevy::camera::Hdr
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSequentialDefaultCamera(pub bool);

impl Default for FrameSequentialDefaultCamera {
    fn default() -> Self {
        Self(true)
    }
}

/// Gives the app's main camera ([`FrameSequentialDefaultCamera`] says which)
/// [`FrameSequentialLod::default()`] when groups exist and no
/// camera has the component (and the app has not said no).
pub(super) fn default_camera(
    mut commands: Commands,
    enabled: Res<FrameSequentialDefaultCamera>,
    selecting: Query<(), With<FrameSequentialLod>>,
    groups: Query<(), With<FrameSequentialGroup>>,
    cameras: Query<(Entity, &Camera, Option<&RenderTarget>), With<Camera3d>>,
) {
    if !enabled.0 || !selecting.is_empty() || groups.is_empty() {
        return;
    }
    // A camera without a RenderTarget draws to the primary window (Bevy's default target).
    let to_window =
        |target: Option<&RenderTarget>| target.is_none_or(|t| matches!(t, RenderTarget::Window(_)));
    let chosen = cameras
        .iter()
        .filter(|(_, camera, _)| camera.is_active)
        .min_by_key(|(entity, camera, target)| (!to_window(*target), camera.order, entity.index()));
    if let Some((entity, ..)) = chosen {
        info_once!(
            "no camera has FrameSequentialLod: camera {entity} selects the LOD groups' levels with \
             FrameSequentialLod::default() (FrameSequentialDefaultCamera(false) turns this off)"
        );
        commands
            .entity(entity)
            .insert(FrameSequentialLod::default());
    }
}

#[cfg(test)]
mod tests {
    use bevy::ecs::system::RunSystemOnce;
    use lodkit::select::LodGroup;

    use super::*;

    fn world(enabled: bool) -> (World, [Entity; 4]) {
        let mut world = World::new();
        world.insert_resource(FrameSequentialDefaultCamera(enabled));
        let camera = |order: isize, is_active: bool| {
            (
                Camera3d::default(),
                Camera {
                    order,
                    is_active,
                    ..default()
                },
            )
        };
        let cameras = [
            world.spawn(camera(1, true)).id(),
            world.spawn(camera(0, true)).id(),
            world.spawn(camera(-1, false)).id(),
            // Drawn first, into a texture (a minimap's): not the app's main camera.
            world
                .spawn((camera(-2, true), RenderTarget::None { size: UVec2::ONE }))
                .id(),
        ];
        (world, cameras)
    }

    fn selecting(world: &World, cameras: [Entity; 4]) -> [bool; 4] {
        cameras.map(|c| world.get::<FrameSequentialLod>(c).is_some())
    }

    fn group() -> FrameSequentialGroup {
        FrameSequentialGroup::new(LodGroup::from_distances(&[0.0, 4.0]).unwrap())
    }

    #[test]
    fn the_first_active_camera_selects_while_groups_exist_and_none_does() {
        let (mut world, cameras) = world(true);
        world.run_system_once(default_camera).unwrap();
        assert_eq!(selecting(&world, cameras), [false; 4], "no group yet");
        world.spawn(group());
        world.run_system_once(default_camera).unwrap();
        assert_eq!(selecting(&world, cameras), [false, true, false, false]);
        // One camera selecting is enough: none more is given the component.
        world.entity_mut(cameras[1]).remove::<FrameSequentialLod>();
        world
            .entity_mut(cameras[0])
            .insert(FrameSequentialLod::default());
        world.run_system_once(default_camera).unwrap();
        assert_eq!(selecting(&world, cameras), [true, false, false, false]);
    }

    #[test]
    fn an_app_that_says_no_keeps_its_cameras_as_they_are() {
        let (mut world, cameras) = world(false);
        world.spawn(group());
        world.run_system_once(default_camera).unwrap();
        assert_eq!(selecting(&world, cameras), [false; 4]);
    }

    #[test]
    fn with_no_camera_drawing_to_a_window_one_drawing_a_texture_selects() {
        let (mut world, cameras) = world(true);
        for c in &cameras[..3] {
            world.entity_mut(*c).despawn();
        }
        world.spawn(group());
        world.run_system_once(default_camera).unwrap();
        assert!(world.get::<FrameSequentialLod>(cameras[3]).is_some());
    }
}
