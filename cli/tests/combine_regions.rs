//! The combine pass works only inside the screen rectangles of the objects in transition; a
//! pixel of such an object outside them shows the newer buffer alone. The rectangles must take
//! the whole reach of an animated object, not its rest pose.

use lodkit_cli::demo::fixtures::render::{Coverage, Technique};
use lodkit_cli::demo::fixtures::scene::DemoScene;

#[test]
fn the_combine_rectangles_hold_every_pixel_of_the_swaying_tree() {
    use lodkit::frame_sequential::Schedule;
    use lodkit::visibility::{VisibilityPattern, VisibilitySpace};
    use lodkit_cli::demo::fixtures::render::{Background, RunSpec, SceneRenderer};
    let gpu = lodkit_test_gpu!();
    // The field scene at the docs' size, every object swaying as far as a scene may (1 object
    // unit at the top): its reach leaves the rest-pose rectangles and their 2 px margin. With
    // the rest-pose bounds 136,159 pixels of objects in transition fell outside the rectangles
    // over the two runs; with `displaced_bounds` none does. (The built-in field's own sway
    // stays inside either way: its crown is widest at the base, where the sway is smallest.)
    let mut scene = DemoScene::built_in()
        .into_iter()
        .find(|s| s.name == "field")
        .expect("the field scene");
    for o in &mut scene.objects {
        o.sway = 1.0;
    }
    let renderer = SceneRenderer::new(gpu, &scene, (320, 180), 24).unwrap();
    for (coverage, moving) in [
        Coverage::Estimated,
        Coverage::Silhouettes,
        Coverage::DepthPass,
    ]
    .into_iter()
    .flat_map(|c| [(c, false), (c, true)])
    {
        let technique = Technique::FrameSequential(
            VisibilityPattern::BlueNoise,
            Schedule::Complementary,
            VisibilitySpace::Screen,
            coverage,
        );
        let spec = RunSpec {
            technique,
            moving,
            transition: true,
            hold_level: 0,
            background: Background::Scene,
        };
        renderer
            .run(gpu, spec, &|_| false, &mut |_, _| {}, None)
            .unwrap();
    }
    assert_eq!(renderer.take_outside_rects(), 0);
}
