//! Unit tests of the selection system on a bare `World`.

use bevy::ecs::system::RunSystemOnce;

use super::*;
use crate::frame_sequential::{DITHER_TAG_ID, LodLevel};
use lodkit::select::{LodGroup, LodState};
use std::f32::consts::FRAC_PI_2;

/// A world with a camera (with `msaa`) and one two-level group at distance 1, its levels
/// spawned.
fn world_with_group(msaa: Msaa) -> (World, Entity) {
    let mut world = World::new();
    world.init_resource::<Time>();
    world.init_resource::<Assets<Mesh>>();
    world.init_resource::<Assets<FrameSequentialMaterial>>();
    world.init_resource::<Scheduler>();
    world.init_resource::<FrameSequentialStats>();
    world.init_resource::<Surfaces>();
    world.init_resource::<DerivedMaterials>();
    let mut camera = Camera::default();
    // P[1][1] = 1: lodkit::select's distance is the distance itself.
    camera.computed.clip_from_view = Mat4::from_cols_array(
        &glam::camera::rh::proj::directx::perspective_infinite_reverse(FRAC_PI_2, 1.0, 0.1)
            .to_cols_array(),
    );
    world.spawn((
        camera,
        GlobalTransform::IDENTITY,
        FrameSequentialLod::default(),
        msaa,
    ));
    let level = || {
        LodLevel::new(
            Handle::default(),
            Handle::<FrameSequentialMaterial>::default(),
        )
    };
    let group = world
        .spawn((
            LodLevels(vec![level(), level()]),
            FrameSequentialGroup::new(LodGroup::from_distances(&[0.0, 4.0]).unwrap()),
            GlobalTransform::from_translation(Vec3::new(0.0, 0.0, -1.0)),
        ))
        .id();
    world
        .run_system_once(super::super::drawer::spawn_levels)
        .unwrap();
    (world, group)
}

/// Runs the selection with the group at distance `z`: (frame kept, groups in transition, the
/// group's transition).
fn frame(world: &mut World, group: Entity, z: f32) -> (bool, usize, Option<(u8, u8)>) {
    *world.get_mut::<GlobalTransform>(group).unwrap() =
        GlobalTransform::from_translation(Vec3::new(0.0, 0.0, -z));
    world.run_system_once(update).unwrap();
    let stats = world.resource::<FrameSequentialStats>().clone();
    let levels = world.get::<FrameSequentialLevels>(group).unwrap();
    (stats.frame_kept, stats.in_transition, levels.transition)
}

/// A transition begins only after a frame the render world kept: the frame the selection
/// enters the band after idle frames is kept, with nothing in transition yet, and the
/// transition begins the frame after. Idle frames are not kept (no copies).
#[test]
fn a_transition_begins_after_a_kept_frame() {
    let (mut world, group) = world_with_group(Msaa::Off);
    assert_eq!(frame(&mut world, group, 1.0), (false, 0, None), "idle");
    assert_eq!(frame(&mut world, group, 1.0), (false, 0, None), "idle");
    assert_eq!(
        frame(&mut world, group, 4.1),
        (true, 0, None),
        "kept, not begun"
    );
    assert_eq!(
        frame(&mut world, group, 4.1),
        (true, 1, Some((0, 1))),
        "begun"
    );
    assert_eq!(world.resource::<FrameSequentialStats>().frames_kept, 2);
}

/// A multisampled camera gets no combine: no frame is kept, no scheduler transition begins,
/// the render world gets no view; in the band the group draws both levels through the
/// complementary screen-door dither, its alphas following the selection, and past the band the
/// coarse level alone.
#[test]
fn a_multisampled_camera_blends_with_the_dither() {
    let (mut world, group) = world_with_group(Msaa::Sample4);
    assert_eq!(frame(&mut world, group, 1.0), (false, 0, None), "idle");
    let drawn = |world: &World| {
        let levels = world.get::<FrameSequentialLevels>(group).unwrap();
        [Some(levels.entity), levels.dither_entity].map(|e| {
            let e = e?;
            let visible = world.get::<Visibility>(e).unwrap() != Visibility::Hidden;
            let (id, alpha, ..) = decode_tag(world.get::<MeshTag>(e).unwrap().value);
            visible.then_some((id, alpha))
        })
    };
    // The first frame in the band spawns the second drawer, which Bevy draws from the next
    // frame: the outgoing level is drawn whole meanwhile, not dithered against nothing.
    assert_eq!(
        frame(&mut world, group, 3.9),
        (false, 0, None),
        "in the band"
    );
    let [Some(outgoing), Some(incoming)] = drawn(&world) else {
        panic!("the second drawer is spawned: {:?}", drawn(&world));
    };
    assert_eq!(outgoing, (0, -1.0), "whole");
    assert_eq!(incoming.0, DITHER_TAG_ID);
    let mut last_alpha = incoming.1;
    for z in [4.05, 4.2] {
        assert_eq!(frame(&mut world, group, z), (false, 0, None), "in the band");
        let [Some(outgoing), Some(incoming)] = drawn(&world) else {
            panic!("both levels are drawn in the band: {:?}", drawn(&world));
        };
        assert_eq!((outgoing.0, incoming.0), (DITHER_TAG_ID, DITHER_TAG_ID));
        // -(1 - t) and +t: complementary to the tag's steps, t growing with the distance.
        assert!(
            outgoing.1 < 0.0 && incoming.1 > 0.0,
            "{outgoing:?} {incoming:?}"
        );
        assert!((incoming.1 - outgoing.1 - 1.0).abs() <= 1.0 / 1023.0 + 1e-6);
        assert!(incoming.1 > last_alpha, "{} after {last_alpha}", incoming.1);
        last_alpha = incoming.1;
    }
    assert_eq!(
        frame(&mut world, group, 9.0),
        (false, 0, None),
        "past the band"
    );
    let levels = world.get::<FrameSequentialLevels>(group).unwrap();
    assert_eq!(levels.drawn, 1, "the coarse level is drawn");
    // Tag 0 (an n-instance, drawn whole; its tau field decodes to -1).
    assert_eq!(drawn(&world), [Some((0, -1.0)), None], "one level, whole");
    let mut views = world.query::<&FrameSequentialView>();
    assert_eq!(views.iter(&world).count(), 0, "the render world got a view");
}

/// Gives the world's camera Bevy's depth prepass.
fn give_camera_a_depth_prepass(world: &mut World) {
    let camera = world
        .query_filtered::<Entity, With<FrameSequentialLod>>()
        .single(world)
        .unwrap();
    world
        .entity_mut(camera)
        .insert(bevy::core_pipeline::prepass::DepthPrepass);
}

/// With MSAA and a prepass, levels in `StandardMaterial`s (whose prepass drops the dither's
/// pixels too) blend with the dither as without a prepass: both levels drawn in the band.
#[test]
fn a_multisampled_camera_with_a_prepass_blends_with_the_dither() {
    let (mut world, group) = world_with_group(Msaa::Sample4);
    give_camera_a_depth_prepass(&mut world);
    assert_eq!(frame(&mut world, group, 1.0), (false, 0, None), "idle");
    for z in [3.9, 4.05, 4.2] {
        assert_eq!(frame(&mut world, group, z), (false, 0, None), "in the band");
        let levels = world.get::<FrameSequentialLevels>(group).unwrap();
        let second = levels
            .dither_entity
            .unwrap_or_else(|| panic!("the second drawer at {z}"));
        assert_ne!(world.get::<Visibility>(second), Some(&Visibility::Hidden));
    }
    frame(&mut world, group, 9.0);
    assert_eq!(world.get::<FrameSequentialLevels>(group).unwrap().drawn, 1);
}

/// Without MSAA a group with a blending level takes the dither, but on a camera with a prepass
/// its other levels' prepass is Bevy's (it would write their depth whole): it switches at once.
#[test]
fn a_blending_level_on_a_camera_with_a_prepass_and_no_msaa_switches_at_once() {
    let (mut world, group) = world_with_group(Msaa::Off);
    give_camera_a_depth_prepass(&mut world);
    let blending =
        world
            .resource_mut::<Assets<FrameSequentialMaterial>>()
            .add(FrameSequentialMaterial {
                base: StandardMaterial {
                    alpha_mode: AlphaMode::Blend,
                    ..default()
                },
                extension: default(),
            });
    world.get_mut::<LodLevels>(group).unwrap().0[1] = LodLevel::new(Handle::default(), blending);
    world
        .run_system_once(super::super::drawer::spawn_levels)
        .unwrap();
    assert_eq!(frame(&mut world, group, 1.0), (false, 0, None), "idle");
    for z in [3.9, 4.05, 4.2] {
        frame(&mut world, group, z);
        let levels = world.get::<FrameSequentialLevels>(group).unwrap();
        assert_eq!(levels.dither_entity, None, "one level at {z}");
    }
    frame(&mut world, group, 9.0);
    assert_eq!(world.get::<FrameSequentialLevels>(group).unwrap().drawn, 1);
}

/// A group whose levels change while it is in transition gives its t-instance id and slot
/// back to the scheduler, and its old drawer goes.
#[test]
fn changed_levels_release_the_groups_transition() {
    let mut world = World::new();
    world.init_resource::<DerivedMaterials>();
    let mut scheduler = TransitionScheduler::new();
    let key = scheduler.insert(0);
    scheduler
        .begin_transition(key, 1, Drive::Time { seconds: 1.0 })
        .unwrap();
    assert_eq!(scheduler.live_ids().len(), 1);
    let level = || {
        LodLevel::new(
            Handle::default(),
            Handle::<FrameSequentialMaterial>::default(),
        )
    };
    let drawer = world.spawn_empty().id();
    let dither_entity = world.spawn_empty().id();
    let group = world
        .spawn((
            LodLevels(vec![level(), level()]),
            FrameSequentialLevels {
                entity: drawer,
                dither_entity: Some(dither_entity),
                drawn: 0,
                selection: None,
                transition: Some((0, 1)),
                key: Some(key),
                state: LodState::NEW,
                previous_model: None,
                bounds: None,
            },
        ))
        .id();
    world.insert_resource(Scheduler(scheduler, vec![(group, key)]));
    world
        .run_system_once(super::super::drawer::spawn_levels)
        .unwrap();
    let Scheduler(scheduler, keys) = world.resource::<Scheduler>();
    assert!(
        scheduler.live_ids().is_empty(),
        "the t-instance id is still taken"
    );
    assert!(keys.is_empty());
    assert!(
        world.get_entity(drawer).is_err(),
        "the old drawer is still there"
    );
    let levels = world.get::<FrameSequentialLevels>(group).unwrap();
    assert_eq!((levels.key, levels.transition), (None, None));
}

/// With the pattern on the screen, the combine shows the older level at this frame's threshold
/// for it, complementary to the level drawn now, also when the transition's progress jumps
/// (last frame's tau_next, a prediction, would miss: pixels with both levels or neither).
#[test]
fn the_older_level_is_shown_at_this_frames_threshold() {
    let (mut world, group) = world_with_group(Msaa::Off);
    let mut cameras = world.query::<&mut FrameSequentialLod>();
    cameras.single_mut(&mut world).unwrap().schedule =
        lodkit::frame_sequential::Schedule::Complementary;
    // The band is 3.75..4.25: progress 0.1, 0.1 (begun), 0.2, then 0.7 (predicted 0.3).
    for z in [1.0, 3.8, 3.8, 3.85, 4.1] {
        frame(&mut world, group, z);
    }
    let levels = world.get::<FrameSequentialLevels>(group).unwrap();
    let (id, drawn_tau, ..) = decode_tag(world.get::<MeshTag>(levels.entity).unwrap().value);
    let mut views = world.query::<&FrameSequentialView>();
    let view = views.single(&world).unwrap();
    let &(older_id, older_tau) = view
        .older_tau
        .iter()
        .find(|&&(i, _)| i == id)
        .expect("the older level's tau");
    assert_eq!(older_id, id);
    // Complementary: one level shows v <= p (tau p), the other the rest (tau -(1 - p)).
    assert!(
        drawn_tau * older_tau < 0.0 && (drawn_tau.abs() + older_tau.abs() - 1.0).abs() < 2e-3,
        "drawn at {drawn_tau}, older shown at {older_tau}"
    );
    let progress = drawn_tau.max(older_tau);
    assert!((progress - 0.7).abs() < 2e-3, "progress {progress}");
}
