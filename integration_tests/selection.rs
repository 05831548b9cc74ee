//! LOD selection: the DigitalRune rules on hand-derived cases, and properties over random input.

use glam::{Mat4, Vec3};
use lodkit::select::config::{ConfigError, LodConfig};
use lodkit::select::*;
use proptest::prelude::*;

fn settings(h: f32, transition: TransitionMode) -> LodSettings {
    LodSettings {
        hysteresis: h,
        transition,
        ..Default::default()
    }
}

#[test]
fn hysteresis_switches_at_105_and_back_at_95() {
    // The DigitalRune example: LOD distance 100, hysteresis 10.
    let g = LodGroup::from_distances(&[0.0, 100.0]).unwrap();
    let s = settings(10.0, TransitionMode::Hard);
    let mut state = LodState::NEW;
    let walk_out: Vec<u8> = [90.0, 99.0, 101.0, 104.9, 105.0, 110.0]
        .iter()
        .map(|&d| g.select(d, &s, 0.0, &mut state).current)
        .collect();
    assert_eq!(walk_out, [0, 0, 0, 0, 1, 1]);
    let walk_in: Vec<u8> = [104.0, 99.0, 95.0, 94.99, 90.0]
        .iter()
        .map(|&d| g.select(d, &s, 0.0, &mut state).current)
        .collect();
    assert_eq!(walk_in, [1, 1, 1, 0, 0]);
}

#[test]
fn distance_transition_runs_across_the_band_and_is_the_same_both_ways() {
    let g = LodGroup::from_distances(&[0.0, 100.0]).unwrap();
    let s = settings(10.0, TransitionMode::Distance);
    let mut out_state = LodState::NEW;
    let mut back_state = LodState::NEW;
    g.select(120.0, &s, 0.0, &mut back_state);
    for d in [96.0f32, 97.5, 100.0, 102.5, 104.0] {
        let a = g.select(d, &s, 0.0, &mut out_state);
        assert_eq!((a.current, a.next), (0, Some(1)), "going out at {d}");
        let want = (d - 95.0) / 10.0;
        assert!((a.transition - want).abs() < 1e-6, "{d}: {}", a.transition);
    }
    for d in [104.0f32, 102.5, 100.0, 97.5, 96.0] {
        let b = g.select(d, &s, 0.0, &mut back_state);
        assert_eq!((b.current, b.next), (1, Some(0)), "coming back at {d}");
        // Weight of level 1 is the same at the same distance whichever way we came.
        let weight_of_1 = 1.0 - b.transition;
        assert!((weight_of_1 - (d - 95.0) / 10.0).abs() < 1e-6);
    }
}

#[test]
fn time_transition_runs_for_its_duration_and_turns_back_smoothly() {
    let g = LodGroup::from_distances(&[0.0, 100.0]).unwrap();
    let s = settings(10.0, TransitionMode::Time { seconds: 0.5 });
    let mut st = LodState::NEW;
    assert_eq!(g.select(50.0, &s, 0.1, &mut st).next, None);
    // Crossing 105 starts the switch; standing still it still completes (no freeze).
    let a = g.select(106.0, &s, 0.1, &mut st);
    assert_eq!((a.current, a.next), (0, Some(1)));
    assert!((a.transition - 0.2).abs() < 1e-6);
    let b = g.select(106.0, &s, 0.1, &mut st);
    assert!((b.transition - 0.4).abs() < 1e-6);
    // Turn back below 95 mid-way: the same blend runs backwards from where it was (level 1 had
    // weight 0.4; reversed, level 0 has 0.6, and this frame's 0.2 of progress makes it 0.8).
    let c = g.select(90.0, &s, 0.1, &mut st);
    assert_eq!((c.current, c.next), (1, Some(0)));
    assert!((c.transition - 0.8).abs() < 1e-5, "{}", c.transition);
    for _ in 0..3 {
        g.select(90.0, &s, 0.1, &mut st);
    }
    let d = g.select(90.0, &s, 0.1, &mut st);
    assert_eq!((d.current, d.next), (0, None));
}

#[test]
fn max_distance_fades_then_hides() {
    let g = LodGroup::from_distances(&[0.0, 50.0])
        .unwrap()
        .with_max_distance(200.0)
        .unwrap();
    let s = settings(10.0, TransitionMode::Distance);
    let mut st = LodState::NEW;
    assert_eq!(g.select(150.0, &s, 0.0, &mut st).fade, 1.0);
    let near = g.select(195.0, &s, 0.0, &mut st);
    assert!((near.fade - 0.5).abs() < 1e-6 && near.visible);
    let gone = g.select(200.0, &s, 0.0, &mut st);
    assert!(!gone.visible);
}

#[test]
fn bias_zero_forces_lod0_and_infinity_the_last() {
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0);
    let groups = [LodGroup::from_distances(&[0.0, 10.0, 20.0]).unwrap()];
    let positions = [Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 0.0, -1000.0)];
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &[1.0, 1.0],
        groups: &[0, 0],
    };
    for (bias, want) in [(0.0, [0, 0]), (f32::INFINITY, [2, 2])] {
        let camera = LodCamera::new(Vec3::ZERO, proj).with_bias(bias);
        let mut states = [LodState::NEW; 2];
        let mut out = [LodSelection::default(); 2];
        select_batch(
            &camera,
            &LodSettings::default(),
            &groups,
            &batch,
            0.0,
            &mut states,
            &mut out,
        )
        .unwrap();
        assert_eq!(out.map(|s| s.current), want, "bias {bias}");
    }
}

#[test]
fn orthographic_cameras_select_by_view_height() {
    let ortho = glam::camera::rh::proj::directx::orthographic(-20.0, 20.0, -20.0, 20.0, 0.1, 100.0);
    // Half the view height is 20: a 90-degree perspective camera shows an object that size at 20.
    assert!((view_normalized_distance(3.0, &ortho, 1.0) - 20.0).abs() < 1e-5);
    assert!((view_normalized_distance(99.0, &ortho, 1.0) - 20.0).abs() < 1e-5);
}

#[test]
fn lod_camera_is_the_main_camera_for_shadow_passes() {
    // A shadow pass selects with the main camera's LodCamera: the same result as the main pass.
    let main = LodCamera::new(
        Vec3::ZERO,
        glam::camera::rh::proj::directx::perspective(1.2, 1.0, 0.1, 100.0),
    );
    let d_main = main.lod_distance(Vec3::new(0.0, 0.0, -30.0), 1.0, 1.0);
    let light = LodCamera::new(Vec3::new(0.0, 100.0, 0.0), Mat4::IDENTITY);
    assert_ne!(
        d_main,
        light.lod_distance(Vec3::new(0.0, 0.0, -30.0), 1.0, 1.0)
    );
}

#[test]
fn batch_reports_length_mismatch_and_bad_group_ids() {
    let camera = LodCamera::new(Vec3::ZERO, Mat4::IDENTITY);
    let groups = [LodGroup::from_distances(&[0.0]).unwrap()];
    let positions = [Vec3::ZERO; 2];
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &[1.0],
        groups: &[0, 0],
    };
    let err = select_batch(
        &camera,
        &LodSettings::default(),
        &groups,
        &batch,
        0.0,
        &mut [LodState::NEW; 2],
        &mut [LodSelection::default(); 2],
    );
    assert!(
        matches!(
            err,
            Err(LodError::LengthMismatch {
                what: "max_scales",
                ..
            })
        ),
        "{err:?}"
    );
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &[1.0; 2],
        groups: &[0, 7],
    };
    let mut out = [LodSelection::default(); 2];
    select_batch(
        &camera,
        &LodSettings::default(),
        &groups,
        &batch,
        0.0,
        &mut [LodState::NEW; 2],
        &mut out,
    )
    .unwrap();
    assert!(out[0].visible && !out[1].visible);
}

#[test]
fn odd_inputs_have_documented_results() {
    let g = LodGroup::from_distances(&[0.0, 10.0, 10.0, 20.0]).unwrap();
    let s = LodSettings::default();
    let mut st = LodState::NEW;
    assert_eq!(
        g.select(f32::NAN, &s, 0.0, &mut st).current,
        3,
        "NaN counts as +inf"
    );
    let mut st = LodState::NEW;
    assert_eq!(
        g.select(-5.0, &s, 0.0, &mut st).current,
        0,
        "negative counts as 0"
    );
    let mut st = LodState::NEW;
    assert_eq!(
        g.select(15.0, &s, 0.0, &mut st).current,
        2,
        "of equal distances, the later wins"
    );
    assert_eq!(LodGroup::new([]), Err(LodError::NoLevels));
    assert!(matches!(
        LodGroup::from_distances(&[0.0, f32::NAN]),
        Err(LodError::BadDistance { index: 1, .. })
    ));
    assert!(LodSettings { bias: -1.0, ..s }.validate().is_err());
}

const CONFIG: &str = r#"
LodConfig(
    bias: 1.5,
    hysteresis: 10.0,
    transition: Time(seconds: 0.4),
    groups: {
        "tree": (
            levels: [(distance: 40.0, mesh: "tree_lod1"), (distance: 0.0, mesh: "tree_lod0")],
            max_distance: Some(300.0),
        ),
        "rock": (levels: [(distance: 0.0)]),
    },
)
"#;

#[test]
fn config_loads_from_ron() {
    let config = LodConfig::from_ron(CONFIG).unwrap();
    let s = config.settings().unwrap();
    assert_eq!(
        (s.bias, s.hysteresis, s.transition),
        (1.5, 10.0, TransitionMode::Time { seconds: 0.4 })
    );
    let groups = config.groups().unwrap();
    assert_eq!(groups[1].0, "tree");
    assert_eq!(
        groups[1].1.levels()[0].mesh,
        "tree_lod0",
        "levels sorted by distance"
    );
    assert_eq!(groups[1].1.max_distance(), Some(300.0));
}

#[test]
fn bad_ron_names_line_column_and_field() {
    let typo = CONFIG.replace("max_distance", "max_distnace");
    match LodConfig::from_ron(&typo).unwrap_err() {
        ConfigError::Ron {
            line,
            column,
            field,
            message,
        } => {
            assert_eq!(line, 9, "{message}");
            assert!(column > 1);
            assert_eq!(field.as_deref(), Some("max_distnace"));
            assert!(message.contains("max_distnace"), "{message}");
        }
        other => panic!("{other}"),
    }
    let negative = CONFIG.replace("distance: 40.0", "distance: -4.0");
    let err = LodConfig::from_ron(&negative).unwrap_err();
    assert_eq!(
        err.to_string(),
        "groups[\"tree\"].levels[0].distance: level 0: distance -4 must be finite and >= 0"
    );
    let missing = "LodConfig(bias: 1.0)";
    match LodConfig::from_ron(missing).unwrap_err() {
        ConfigError::Ron { field, .. } => assert_eq!(field.as_deref(), Some("groups")),
        other => panic!("{other}"),
    }
    let bad_duration = CONFIG.replace("seconds: 0.4", "seconds: 0.0");
    assert!(
        LodConfig::from_ron(&bad_duration)
            .unwrap_err()
            .to_string()
            .starts_with("transition:")
    );
}

fn arb_group() -> impl Strategy<Value = LodGroup> {
    prop::collection::vec(0.0f32..500.0, 1..6).prop_map(|mut d| {
        d[0] = 0.0;
        LodGroup::from_distances(&d).unwrap()
    })
}

proptest! {
    #[test]
    fn selection_is_monotone_in_distance(g in arb_group(), a in 0.0f32..600.0, b in 0.0f32..600.0) {
        let (near, far) = if a <= b { (a, b) } else { (b, a) };
        prop_assert!(g.level_at(near) <= g.level_at(far));
        let s = LodSettings::default();
        let (mut s1, mut s2) = (LodState::NEW, LodState::NEW);
        prop_assert!(g.select(near, &s, 0.0, &mut s1).current <= g.select(far, &s, 0.0, &mut s2).current);
    }

    #[test]
    fn a_still_object_never_toggles(g in arb_group(), d in 0.0f32..600.0, h in 0.0f32..40.0, warm in 0.0f32..600.0) {
        for mode in [TransitionMode::Hard, TransitionMode::Distance] {
            let s = settings(h, mode);
            let mut st = LodState::NEW;
            g.select(warm, &s, 0.016, &mut st); // arrive from anywhere
            let first = g.select(d, &s, 0.016, &mut st);
            for _ in 0..20 {
                prop_assert_eq!(g.select(d, &s, 0.016, &mut st), first);
            }
        }
    }

    #[test]
    fn bias_zero_is_lod0(g in arb_group(), d in 0.0f32..1e6) {
        let mut st = LodState::NEW;
        prop_assert_eq!(g.select(biased_distance(d, 0.0), &LodSettings::default(), 0.0, &mut st).current, 0);
    }

    #[test]
    fn nothing_panics(g in arb_group(), d in any::<f32>(), h in any::<f32>(), dt in any::<f32>()) {
        let s = LodSettings { hysteresis: h, transition: TransitionMode::Time { seconds: 0.3 }, ..Default::default() };
        let mut st = LodState::NEW;
        let sel = g.select(d, &s, dt, &mut st);
        prop_assert!((sel.current as usize) < g.levels().len());
        prop_assert!((0.0..=1.0).contains(&sel.transition));
    }
}

#[test]
fn infinite_distance_without_max_distance_is_the_last_level_and_visible() {
    let g = LodGroup::from_distances(&[0.0, 10.0]).unwrap();
    for d in [f32::INFINITY, f32::NAN] {
        let mut st = LodState::NEW;
        let s = g.select(d, &LodSettings::default(), 0.0, &mut st);
        assert!(s.visible && s.current == 1, "{d}: {s:?}");
    }
    let capped = g.with_max_distance(100.0).unwrap();
    let mut st = LodState::NEW;
    assert!(
        !capped
            .select(f32::INFINITY, &LodSettings::default(), 0.0, &mut st)
            .visible
    );
}

#[test]
fn a_timed_transition_does_not_reverse_inside_the_band() {
    let g = LodGroup::from_distances(&[0.0, 100.0]).unwrap();
    let s = settings(10.0, TransitionMode::Time { seconds: 1.0 });
    let mut st = LodState::NEW;
    g.select(90.0, &s, 0.1, &mut st);
    assert_eq!(
        g.select(106.0, &s, 0.1, &mut st).next,
        Some(1),
        "switch decided at 105"
    );
    // Back inside the band (above 95): the switch goes on.
    for _ in 0..3 {
        let sel = g.select(101.0, &s, 0.1, &mut st);
        assert_eq!(
            (sel.current, sel.next),
            (0, Some(1)),
            "reversed inside the band: {sel:?}"
        );
    }
    // Below 95 it turns back.
    assert_eq!(g.select(94.0, &s, 0.1, &mut st).next, Some(0));
}

#[test]
fn a_negative_camera_bias_is_an_error() {
    let camera = LodCamera::new(Vec3::ZERO, Mat4::IDENTITY).with_bias(-1.0);
    let groups = [LodGroup::from_distances(&[0.0]).unwrap()];
    let batch = InstanceBatch {
        positions: &[Vec3::ZERO],
        max_scales: &[1.0],
        groups: &[0],
    };
    let r = select_batch(
        &camera,
        &LodSettings::default(),
        &groups,
        &batch,
        0.0,
        &mut [LodState::NEW],
        &mut [LodSelection::default()],
    );
    assert_eq!(r, Err(LodError::BadBias(-1.0)));
}
