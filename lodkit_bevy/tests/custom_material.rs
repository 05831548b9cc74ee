//! A material of the app's own as the levels' material (the custom_material example run on the
//! GPU, its report read here): `Stripes`, with its own WESL shader and one call to
//! `lod_level_color`, through frame-sequential LOD's combine (`Msaa::Off`) and its screen-door
//! dither (Bevy's default MSAA), without and with Bevy's depth and motion-vector prepass.

mod support;

/// Every route takes every ball through both levels with no background shown and nothing drawn
/// where no level is, change each pixel one way only (flicker 1 against the fine level, within
/// 10 %), and pop at most a quarter of switching at once (measured on lavapipe: 0.054, 0.052
/// and, with the prepass, 0.052 against 0.345: 0.16x, 0.15x and 0.15x; `Stripes` has no prepass shader
/// of its own, and without the dither's discard in Bevy's default prepass, a throwaway edit,
/// the prepass run showed the background in 79,882 pixel-frames, pop 0.20); the combine ran (frames with a group in transition). The
/// hard switch's pop is there for the metric to see one (a third of the picture's change in one
/// frame, one ball of three; at least 0.2). No wgpu validation error is logged.
#[test]
fn a_material_of_the_apps_own_transitions_without_a_pop() {
    let Some(r) = support::example_report("custom_material") else {
        return;
    };
    let hard = r["hard_switch"]["pop"].as_f64().unwrap();
    assert!(hard >= 0.2, "the hard switch pops: {r}");
    for name in ["frame_sequential", "dither", "dither_prepass"] {
        let drawn = serde_json::json!([[0, 1], [0, 1], [0, 1]]);
        support::assert_smooth_transition(name, &r[name], drawn, hard, 0.25);
    }
    let combined = r["frame_sequential"]["frames_in_transition"]
        .as_u64()
        .unwrap();
    assert!(combined > 0, "the combine ran: {r}");
}
