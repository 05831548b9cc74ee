//! The demo's alpha-tested billboard impostor: the mask baked from the tree, and impostor
//! scenes read from RON.

use lodkit_cli::demo::fixtures::scene::DemoScene;

use crate::support::say;

#[test]
fn a_baked_impostor_mask_is_its_trees_silhouette() {
    use lodkit::alpha_mask::alpha_mask_keep;
    use lodkit_cli::demo::fixtures::impostor::{MASK_SIZE, bake};
    use lodkit_cli::demo::fixtures::scene::Shape;
    use lodkit_scenes::mesh::MeshRenderer;
    let gpu = lodkit_test_gpu!();
    let renderer = MeshRenderer::new(gpu, false).unwrap();
    let impostor = Shape::Impostor { puffs: 7, rings: 8 };
    let mask = bake(gpu, &renderer, impostor).unwrap().unwrap();
    assert_eq!(mask.texels.len(), (MASK_SIZE * MASK_SIZE) as usize);
    assert!(bake(gpu, &renderer, Shape::Cube).unwrap().is_none());
    // Independent check: a point of the tree's front extent is covered when a ray along -z
    // through it hits the trunk box (x, z within 0.12 of 0, y from -1 to -0.2), and not where it
    // misses the tree's bounding box; the top corners of the card are empty.
    let rect = impostor.alpha_rect();
    let (min, max) = impostor.card_rect();
    let keep = |x: f32, y: f32| alpha_mask_keep(&mask, glam::Vec3::new(x, y, 0.0), rect);
    assert!(keep(0.0, -0.7) && keep(0.05, -0.5), "the trunk is covered");
    assert!(!keep(min.x + 0.01, max.y - 0.01) && !keep(max.x - 0.01, max.y - 0.01));
    assert!(
        !keep(min.x + 0.01, min.y + 0.01),
        "beside the trunk's foot is empty"
    );
    let covered = mask.texels.iter().filter(|&&t| t >= 0.5).count();
    let share = covered as f32 / mask.texels.len() as f32;
    assert!(
        (0.3..0.9).contains(&share),
        "the silhouette covers {share:.2} of the card"
    );
    say(&format!("impostor mask: {share:.2} of the card covered"));
}

#[test]
fn an_impostor_scene_reads_from_ron() {
    use lodkit_cli::demo::fixtures::scene::Shape;
    let text = "(name: \"card\", camera: (eye: (0.0, 1.0, 6.0), target: (0.0, 0.0, 0.0), \
        moving_eye: (1.0, 1.0, 5.0)), objects: [(fine: Tree(puffs: 5, rings: 6), \
        coarse: Impostor(puffs: 5, rings: 6), fine_color: (0.2, 0.6, 0.2), \
        coarse_color: (0.2, 0.5, 0.3), position: (0.0, 0.0, 0.0))])";
    let scene = DemoScene::from_ron(text, "card.ron").unwrap();
    assert_eq!(
        scene.objects[0].coarse,
        Shape::Impostor { puffs: 5, rings: 6 }
    );
    assert_eq!(scene.objects[0].coarse.mesh().triangles(), 2);
    let bad = text.replace("Impostor(puffs: 5", "Impostor(puffs: 50");
    let err = DemoScene::from_ron(&bad, "card.ron")
        .unwrap_err()
        .to_string();
    assert!(err.contains("objects[0].coarse: puffs = 50"), "{err}");
}

#[test]
fn a_scene_with_two_kinds_of_impostor_is_refused() {
    use lodkit_cli::demo::fixtures::scene::Shape;
    let mut scene = DemoScene::field();
    assert_eq!(scene.check(), Ok(()));
    let last = scene.objects.len() - 1;
    scene.objects[last].coarse = Shape::Impostor { puffs: 3, rings: 4 };
    let err = scene.check().unwrap_err();
    assert!(err.contains("kinds of Impostor"), "{err}");
}

#[test]
fn an_octahedral_scene_reads_from_ron_and_its_objects_stay_uniform_and_still() {
    use lodkit_cli::demo::fixtures::scene::Shape;
    let text = "(name: \"octa\", camera: (eye: (0.0, 1.0, 6.0), target: (0.0, 0.0, 0.0), \
        moving_eye: (1.0, 1.0, 5.0)), objects: [(fine: Tree(puffs: 5, rings: 6), \
        coarse: Octahedral(puffs: 5, rings: 6), fine_color: (0.2, 0.6, 0.2), \
        coarse_color: (0.2, 0.5, 0.3), position: (0.0, 0.0, 0.0), scale: (0.8, 0.8, 0.8))])";
    let scene = DemoScene::from_ron(text, "octa.ron").unwrap();
    let coarse = scene.objects[0].coarse;
    assert_eq!(coarse, Shape::Octahedral { puffs: 5, rings: 6 });
    assert_eq!(coarse.triangles(), 2, "a card");
    assert_eq!(
        coarse.octahedral_of(),
        Some(Shape::Tree { puffs: 5, rings: 6 })
    );
    let refused = |from: &str, to: &str, wanted: &str| {
        let bad = text.replace(from, to);
        let err = DemoScene::from_ron(&bad, "octa.ron")
            .unwrap_err()
            .to_string();
        assert!(err.contains(wanted), "{err}");
    };
    refused(
        "scale: (0.8, 0.8, 0.8)",
        "scale: (0.8, 1.6, 0.8)",
        "objects[0].scale = [0.8, 1.6, 0.8] must be uniform",
    );
    refused(
        "scale: (0.8, 0.8, 0.8)",
        "scale: (0.8, 0.8, 0.8), sway: 0.1",
        "objects[0].sway = 0.1 must be 0",
    );
    refused(
        "Octahedral(puffs: 5",
        "Octahedral(puffs: 40",
        "objects[0].coarse: puffs = 40",
    );
    let mut two = scene.clone();
    let mut other = two.objects[0].clone();
    other.coarse = Shape::Octahedral { puffs: 3, rings: 6 };
    two.objects.push(other);
    let err = two.check().unwrap_err();
    assert!(err.contains("kinds of Octahedral"), "{err}");
}
