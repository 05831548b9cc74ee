//! The default route's host side: `TransitionScheduler::older` (the level the older buffer
//! holds) and `CoverageLevels::data` (the frame's combine data from levels registered once).

use glam::{Mat4, Vec3};
use lodkit::alpha_mask::{AlphaMask, alpha_mask_rect};
use lodkit::combine_coverage::{
    COMBINE_LEVEL_DEPTH, COMBINE_ROUTE_DEPTH_PASS, COMBINE_ROUTE_SILHOUETTE, CombineData,
    CombineDataDescriptor, CombineObjectData, CoverageError, CoverageFrame, CoverageLevels,
    CoverageRoute, MissingSilhouette, OlderLevel, combine_object,
};
use lodkit::frame_sequential::{Drive, Schedule, TransitionScheduler};
use lodkit::silhouette::{MaskOutline, SilhouetteError, Surface};

/// A unit cube's corners and its 12 triangles, counterclockwise seen from outside.
fn cube() -> Surface {
    let p: Vec<[f32; 3]> = (0..8)
        .map(|i| {
            let c = |bit: u32| if i & bit != 0 { 0.5 } else { -0.5 };
            [c(1), c(2), c(4)]
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let i: Vec<u32> = quads
        .iter()
        .flat_map(|[a, b, c, d]| [*a, *b, *c, *a, *c, *d])
        .collect();
    Surface::new(&p, Some(&i)).expect("a closed cube")
}

/// The level a t-instance drew last frame is what `older` names on the next, over a whole
/// transition of either schedule, with this frame's threshold for the level not drawn now; an
/// n-instance has none. Tried against a throwaway edit that returns this frame's level.
#[test]
fn older_names_the_level_drawn_last_frame() {
    for schedule in [Schedule::Paper, Schedule::Complementary] {
        let mut s = TransitionScheduler::with_schedule(schedule);
        let key = s.insert(2);
        let still = s.insert(0);
        s.advance(0.1);
        assert_eq!(s.older(key), Ok(None));
        let mut last = s.draw(key).unwrap().lod;
        s.begin_transition(key, 3, Drive::Time { seconds: 0.55 })
            .unwrap();
        let mut frames = 0;
        while s.in_transition(key) {
            let older = s.older(key).unwrap().expect("in transition");
            let draw = s.draw(key).unwrap();
            assert_eq!(older.lod, last, "frame {frames}");
            assert_eq!(older.id, draw.id);
            let tau = schedule.threshold(draw.progress, !draw.incoming);
            assert_eq!(older.tau.to_bits(), tau.to_bits(), "frame {frames}");
            assert_eq!(s.older(still), Ok(None));
            last = draw.lod;
            s.advance(0.1);
            frames += 1;
        }
        assert!(frames >= 6, "{frames}");
    }
}

/// A camera 4 units from the origin, looking at it.
fn frame_of<'a>(objects: &'a [OlderLevel<'a>]) -> CoverageFrame<'a> {
    let eye = Vec3::new(1.0, 1.5, 4.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
    let proj = glam::camera::rh::proj::directx::perspective(0.9, 1.5, 0.1, 50.0);
    CoverageFrame {
        clip_from_world: proj * view,
        eye,
        size: (96, 64),
        new_to_old: Mat4::from_translation(Vec3::new(0.01, 0.0, 0.0)),
        objects,
        ..Default::default()
    }
}

fn older(id: u32, level: lodkit::combine_coverage::CoverageLevel, at: Mat4) -> OlderLevel<'static> {
    OlderLevel {
        id,
        level,
        world_from_local: at,
        new_to_old: None,
        older_tau: Some(0.25),
        displace: None,
    }
}

/// `data` lays out exactly what the lower-level calls give when composed by hand (each
/// instance's silhouette with its own eye and winding, `CombineData::new`), a mirrored instance
/// and an instance with its own motion included.
#[test]
fn coverage_data_is_the_silhouettes_laid_out() {
    let mut levels = CoverageLevels::new();
    let box_level = levels.register(cube());
    let models = [
        Mat4::from_translation(Vec3::new(-0.8, 0.0, 0.0)),
        Mat4::from_translation(Vec3::new(0.9, 0.2, -0.5))
            * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
    ];
    let motion = Mat4::from_translation(Vec3::new(0.0, 0.02, 0.0));
    let mut objects = [
        older(3, box_level, models[0]),
        older(9, box_level, models[1]),
    ];
    objects[1].new_to_old = Some(motion);
    let frame = frame_of(&objects);
    let data = levels.data(&frame).unwrap();

    let surface = cube();
    let segments: Vec<_> = models
        .iter()
        .map(|m| {
            let eye = m.inverse().transform_point3(frame.eye);
            let ccw = m.determinant() > 0.0;
            surface
                .silhouette(frame.clip_from_world * *m, eye, frame.size, ccw)
                .unwrap()
        })
        .collect();
    assert!(segments.iter().all(|s| s.len() >= 4), "{segments:?}");
    let by_hand = [
        (3, frame.new_to_old, &segments[0]),
        (9, motion, &segments[1]),
    ]
    .map(|(id, new_to_old, s)| CombineObjectData {
        id,
        new_to_old,
        older_tau: Some(0.25),
        route: CoverageRoute::Silhouette(s),
    });
    let expected = CombineData::new(&CombineDataDescriptor {
        new_to_old: frame.new_to_old,
        height: 64,
        objects: &by_hand,
        ..Default::default()
    })
    .unwrap();
    assert_eq!(data, expected);
    assert_ne!(
        combine_object(&data.texels, 9).flags & COMBINE_ROUTE_SILHOUETTE,
        0
    );
}

/// What the route needs and lacks is an error naming the t-instance: a level not registered,
/// a level reaching behind the camera (unless the frame names another route: the depth pass,
/// whose flag it then sets, or the estimate), a displacement given for a mask card.
#[test]
fn a_missing_silhouette_is_named_not_estimated() {
    let mut levels = CoverageLevels::new();
    let box_level = levels.register(cube());
    let mut other = CoverageLevels::new();
    other.register(cube());
    let stranger = other.register(cube());
    let unknown = [older(5, stranger, Mat4::IDENTITY)];
    assert_eq!(
        levels.data(&frame_of(&unknown)),
        Err(CoverageError::UnknownLevel {
            id: 5,
            level: stranger,
            count: 1
        })
    );
    // Straddling the camera: a corner lies behind it.
    let behind = [older(
        6,
        box_level,
        Mat4::from_translation(Vec3::new(1.6, 1.5, 4.0)),
    )];
    let error = levels.data(&frame_of(&behind)).unwrap_err();
    assert_eq!(
        error,
        CoverageError::NoSilhouette {
            id: 6,
            reason: SilhouetteError::BehindCamera
        }
    );
    assert!(error.to_string().contains("t-instance 6"), "{error}");
    let depth = levels
        .data(&CoverageFrame {
            missing: MissingSilhouette::DepthPass,
            ..frame_of(&behind)
        })
        .unwrap();
    assert_eq!(
        combine_object(&depth.texels, 0).flags & COMBINE_LEVEL_DEPTH,
        COMBINE_LEVEL_DEPTH
    );
    assert_ne!(
        combine_object(&depth.texels, 6).flags & COMBINE_ROUTE_DEPTH_PASS,
        0
    );
    let estimate = levels
        .data(&CoverageFrame {
            missing: MissingSilhouette::Estimate,
            ..frame_of(&behind)
        })
        .unwrap();
    let flags = combine_object(&estimate.texels, 6).flags;
    assert_eq!(
        flags & (COMBINE_ROUTE_DEPTH_PASS | COMBINE_ROUTE_SILHOUETTE),
        0
    );

    let mask = AlphaMask {
        size: 2,
        texels: vec![1.0, 0.0, 1.0, 1.0],
    };
    let rect = alpha_mask_rect(glam::Vec2::splat(-0.5), glam::Vec2::splat(0.5));
    let card = levels.register(MaskOutline::new(&mask, rect).unwrap());
    let sway = |p: Vec3| p + Vec3::X * 0.1;
    let swayed = [OlderLevel {
        displace: Some(&sway),
        ..older(7, card, Mat4::IDENTITY)
    }];
    assert_eq!(
        levels.data(&frame_of(&swayed)),
        Err(CoverageError::DisplacedMask { id: 7 })
    );
    let still = [older(7, card, Mat4::IDENTITY)];
    assert!(levels.data(&frame_of(&still)).is_ok());
}
