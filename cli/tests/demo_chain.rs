//! The demo's generated LOD group (scene `chain`): where its transitions stand.

use crate::support::say;

/// Every object of the `chain` scene stands where its transition's coarser level deviates from
/// the original by at most the reference camera's pixel error, and by more than half of it:
/// `projected_error` (the bound's closed form) at the object's distance from the eye, scaled
/// with the object.
#[test]
fn chain_scene_stands_each_transition_at_its_switch_distance() {
    use lodkit::lod_chain::projected_error;
    use lodkit_cli::demo::fixtures::scene::Shape;
    use lodkit_cli::demo::fixtures::{
        chain_scene::scene,
        lod_chain::{CAMERA, chain},
    };
    let scene = scene();
    let radius = chain().bounding_sphere().radius;
    let eye = glam::Vec3::from(scene.camera.eye);
    let mut seen = 0;
    for o in scene.objects.iter().filter(|o| o.transition) {
        let Shape::Chain { level } = o.coarse else {
            panic!("{:?}", o.coarse)
        };
        let error = chain().levels()[level as usize].error();
        let s = o.scale[0];
        // The sphere's centre in the world (the model is translate x uniform scale).
        let centre =
            glam::Vec3::from(o.position) + glam::Vec3::from(chain().bounding_sphere().center) * s;
        let pixels = projected_error(
            error * s,
            radius * s,
            f64::from(eye.distance(centre)),
            &CAMERA,
        );
        say(&format!(
            "demo figure chain level {level}: {pixels:.3} px at its switch distance"
        ));
        assert!(
            pixels <= f64::from(CAMERA.pixel_error) * 1.001,
            "level {level}: {pixels} px"
        );
        assert!(
            pixels >= 0.5 * f64::from(CAMERA.pixel_error),
            "level {level}: {pixels} px"
        );
        seen += 1;
    }
    assert_eq!(seen, lodkit_cli::demo::fixtures::lod_chain::levels() - 1);
}

/// The report's picture of the levels shows each level as a sphere: in every panel the shaded
/// pixels cover about the disc of its silhouette (radius 0.48 of the panel for the bounding
/// sphere, so between 0.94 / 1.06 of that for the bumps: 0.55-0.72 of the panel).
#[test]
fn chain_picture_shows_every_level() {
    use lodkit_cli::demo::{fixtures::lod_chain::levels, measures::lod_chain::levels_picture};
    let size = 64;
    let picture = levels_picture(size);
    assert_eq!(picture.dimensions(), (size * levels() as u32, size));
    for k in 0..levels() as u32 {
        let mut covered = 0;
        for y in 0..size {
            for x in 0..size {
                if picture.get_pixel(k * size + x, y).0 != [255, 255, 255, 255] {
                    covered += 1;
                }
            }
        }
        let share = f64::from(covered) / f64::from(size * size);
        say(&format!(
            "demo figure chain picture level {k}: {share:.3} of the panel"
        ));
        assert!((0.5..0.75).contains(&share), "level {k}: {share}");
    }
}
