//! Alpha-mask levels (the alpha_mask example run on the GPU, its report read here): a ball with
//! holes and a bunch of leaf cards, `StandardMaterial`s with `AlphaMode::Mask`, through
//! frame-sequential LOD's combine (`Msaa::Off`) and its screen-door dither (Bevy's default MSAA),
//! without and with Bevy's depth and motion-vector prepass.

mod support;

/// The combine knows a masked level's coverage from its alpha test: no background shown on a
/// leaf, nothing drawn between leaves (0 ghost pixel-frames; without the older-level depth
/// pass's alpha test the combine drew the older level over its holes: 7,975 ghost pixel-frames
/// and flicker 5.4 on lavapipe), each pixel changed one way only (flicker 1 within 10 %), and a
/// pop at most a quarter of switching at once (measured on lavapipe: 0.126 combine, 0.086
/// dither without and with the prepass, against 0.643: 0.20x and 0.13x). The hard switch's pop is there for the metric to
/// see one (at least 0.4). No wgpu validation error is logged.
#[test]
fn alpha_mask_levels_transition_with_their_exact_coverage() {
    let Some(r) = support::example_report("alpha_mask") else {
        return;
    };
    let hard = r["hard_switch"]["pop"].as_f64().unwrap();
    assert!(hard >= 0.4, "the hard switch pops: {r}");
    for name in ["frame_sequential", "dither", "dither_prepass"] {
        let drawn = serde_json::json!([[0, 1], [0, 1]]);
        support::assert_smooth_transition(name, &r[name], drawn, hard, 0.25);
    }
    let combined = r["frame_sequential"]["frames_in_transition"]
        .as_u64()
        .unwrap();
    assert!(combined > 0, "the combine ran: {r}");
}
