//! `lodkit::select` on the GPU (WGSL, its WESL form and the GLSL twin) against the Rust twin
//! `LodGroup::select`, one selection per case: walks of distances through every group, mode and
//! band (out, back, a stop inside the band and a turn), each step's state fed in and read out.

use lodkit::select::{
    LodGroup, LodSelection, LodSettings, LodState, SelectGroupData, TransitionMode,
    select_sphere_visible, select_update_phase,
};

use crate::harness::{Probe, Word, accuracy, run_glsl, run_wgsl, twin_mismatch, words};

/// Input words per case: the group (36), distance, mode, step, packed state, progress, frame.
const INPUTS: usize = 42;
/// Output words per case: current, next, transition, fade, visible, packed state, progress.
const OUTPUTS: usize = 7;

const WGSL_BODY: &str = "var g: SelectGroup;
    for (var i = 0u; i < 8u; i++) {
        g.levels[i] = vec4<f32>(inp_f(4u * i), inp_f(4u * i + 1u), inp_f(4u * i + 2u), inp_f(4u * i + 3u));
    }
    g.level_count = inp_u(32u);
    g.max_distance = inp_f(33u);
    g.fade_from = inp_f(34u);
    g.hysteresis = inp_f(35u);
    let o = select_level(inp_f(36u), g, inp_u(37u), inp_f(38u), SelectState(inp_u(39u), inp_f(40u)));
    let s = select_update_phase(o.state, o.selection, inp_u(41u));
    out_u(0u, o.selection.current);
    out_u(1u, o.selection.next);
    out_f(2u, o.selection.transition);
    out_f(3u, o.selection.fade);
    out_u(4u, u32(o.selection.visible));
    out_u(5u, s.packed);
    out_f(6u, s.progress);";

const GLSL_BODY: &str = "LodkitSelectGroup g;
    for (uint i = 0u; i < 8u; i++) {
        g.levels[i] = vec4(inp_f(4u * i), inp_f(4u * i + 1u), inp_f(4u * i + 2u), inp_f(4u * i + 3u));
    }
    g.level_count = inp_u(32u);
    g.max_distance = inp_f(33u);
    g.fade_from = inp_f(34u);
    g.hysteresis = inp_f(35u);
    LodkitSelectOutcome o = lodkit_select_level(inp_f(36u), g, inp_u(37u), inp_f(38u), LodkitSelectState(inp_u(39u), inp_f(40u)));
    LodkitSelectState s = lodkit_select_update_phase(o.state, o.selection, inp_u(41u));
    out_u(0u, o.selection.current);
    out_u(1u, o.selection.next);
    out_f(2u, o.selection.transition);
    out_f(3u, o.selection.fade);
    out_u(4u, o.selection.visible ? 1u : 0u);
    out_u(5u, s.packed);
    out_f(6u, s.progress);";

/// One case: inputs and what the Rust twin gives.
struct Case {
    inputs: Vec<u32>,
    want: [u32; OUTPUTS],
}

fn group_words(data: &SelectGroupData) -> Vec<u32> {
    let mut w: Vec<u32> = data.levels.iter().flatten().map(|v| v.to_bits()).collect();
    w.extend([
        data.level_count,
        data.max_distance.to_bits(),
        data.fade_from.to_bits(),
        data.hysteresis.to_bits(),
    ]);
    w
}

fn output_words(sel: &LodSelection, packed: u32, progress: f32) -> [u32; OUTPUTS] {
    [
        sel.current as u32,
        sel.next.map_or(u32::MAX, u32::from),
        sel.transition.to_bits(),
        sel.fade.to_bits(),
        sel.visible as u32,
        packed,
        progress.to_bits(),
    ]
}

/// Walks through every group in every mode: out across each band, a stop inside a band, a turn
/// back, out again past the max distance, then back to 0.
fn cases() -> Vec<Case> {
    let groups = [
        LodGroup::from_distances(&[0.0, 100.0]).unwrap(),
        LodGroup::from_distances(&[0.0, 10.0, 14.0, 40.0, 90.0])
            .unwrap()
            .with_max_distance(150.0)
            .unwrap(),
        LodGroup::from_distances(&[0.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 80.0]).unwrap(),
    ];
    let modes = [
        TransitionMode::Hard,
        TransitionMode::Distance,
        TransitionMode::Time { seconds: 0.3 },
    ];
    let mut walk: Vec<f32> = (0..=80).map(|k| k as f32 * 2.0).collect(); // out to 160
    walk.extend([
        103.0, 103.0, 103.0, 97.0, 96.0, 104.0, 94.0, 94.0, 106.0, 99.9,
    ]);
    walk.extend([41.5, 41.5, 38.0, 38.5, 42.5, 12.0, 11.9, 12.1, 13.0, 9.0]);
    walk.extend((0..=80).rev().map(|k| k as f32 * 2.0 + 0.37)); // back in
    walk.extend([f32::NAN, -3.0, f32::INFINITY, 0.0]);
    let mut out = Vec::new();
    for group in &groups {
        for mode in modes {
            let settings = LodSettings {
                hysteresis: 6.0,
                transition: mode,
                ..Default::default()
            };
            let data = group.select_data(settings.hysteresis).unwrap();
            let mode_words = settings.select_mode(0.05);
            let mut state = LodState::NEW;
            let mut packed = state.packed();
            for (frame, &d) in walk.iter().enumerate() {
                let mut inputs = group_words(&data);
                inputs.extend([
                    d.to_bits(),
                    mode_words.0,
                    mode_words.1.to_bits(),
                    packed,
                    state.progress().to_bits(),
                    frame as u32,
                ]);
                let sel = group.select(d, &settings, 0.05, &mut state);
                packed =
                    select_update_phase(packed & 0xffff_0000 | state.packed(), &sel, frame as u32);
                out.push(Case {
                    inputs,
                    want: output_words(&sel, packed, state.progress()),
                });
            }
        }
    }
    out
}

/// Compares GPU words with the twin's: levels and state word for word; the progress (sums of
/// the same step, clamped: correctly rounded on both sides) equal as a float, +0 and -0 alike;
/// the transition `(d - lo) / (hi - lo)` and fade `(max - d) / h`, whose subtractions round alike
/// on both sides and whose division may be 2.5 ULP off on the GPU (0.5 on the CPU), within 3 ULP
/// of a value in [0, 1]. A NaN or infinite distance gets no promise from WGSL (it need not keep
/// either): there only a selection that indexes nothing out of range is asked for.
fn check(got: &[u32], cases: &[Case], what: &str) {
    assert_eq!(got.len(), cases.len() * OUTPUTS, "{what}: result count");
    let kinds = [
        Word::Exact,
        Word::Exact,
        Word::Float((accuracy::DIV + accuracy::CORRECTLY_ROUNDED) * accuracy::ULP),
        Word::Float((accuracy::DIV + accuracy::CORRECTLY_ROUNDED) * accuracy::ULP),
        Word::Exact,
        Word::Exact,
        Word::Float(0.0),
    ];
    for (k, (g, c)) in got.chunks(OUTPUTS).zip(cases).enumerate() {
        let d = f32::from_bits(c.inputs[36]);
        if !d.is_finite() {
            let levels = c.inputs[32];
            let (current, next, packed) = (g[0], g[1], g[5]);
            let in_range = |l: u32| l < levels;
            assert!(
                in_range(current) && (next == u32::MAX || in_range(next)),
                "{what}: case {k} (distance {d}): levels {current}, {next:#x} of {levels}"
            );
            let (level, target) = (packed & 0xff, (packed >> 8) & 0xff);
            assert!(
                (in_range(level) || level == 0xff) && (in_range(target) || target == 0xff),
                "{what}: case {k} (distance {d}): state {packed:#x} of {levels} levels"
            );
            continue;
        }
        if let Some(problem) = twin_mismatch(g, &c.want, &kinds) {
            panic!("{what}: case {k} (distance {d}): {problem}");
        }
    }
}

fn probe(header: &'static str, body: &'static str) -> Probe<'static> {
    Probe {
        header,
        body,
        inputs: INPUTS,
        outputs: OUTPUTS,
        texture: None,
        rgba: &[],
        urgba: &[],
    }
}

#[test]
fn select_level_wgsl_and_wesl_match_rust_twin() {
    let gpu = lodkit_test_gpu!(device);
    let cases = cases();
    let inputs: Vec<u32> = cases.iter().flat_map(|c| c.inputs.clone()).collect();
    let p = probe(
        "#import lodkit::select::{SelectGroup, SelectState, select_level, select_update_phase}",
        WGSL_BODY,
    );
    check(&run_wgsl(gpu, &p, &inputs), &cases, "WGSL select_level");
}

#[test]
fn select_level_glsl_matches_rust_twin() {
    let gpu = lodkit_test_gpu!(device);
    let cases = cases();
    let inputs: Vec<u32> = cases.iter().flat_map(|c| c.inputs.clone()).collect();
    let p = probe("#include \"lodkit/select.glsl\"", GLSL_BODY);
    check(
        &run_glsl(gpu, &p, &inputs),
        &cases,
        "GLSL lodkit_select_level",
    );
}

/// Spheres around the frustum of a camera looking down -z: inside, straddling each plane by a
/// margin, outside.
#[test]
fn select_sphere_visible_matches_rust_twin() {
    let gpu = lodkit_test_gpu!(device);
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.5, 200.0);
    let view = glam::camera::rh::view::look_at_mat4(
        glam::Vec3::new(3.0, 2.0, 10.0),
        glam::Vec3::new(0.0, 0.0, -20.0),
        glam::Vec3::Y,
    );
    let planes = lodkit::select::frustum_planes(&(proj * view));
    let mut spheres = Vec::new();
    for x in -12..=12 {
        for z in [-250.0f32, -199.0, -100.0, -10.0, 9.0, 10.5, 30.0] {
            spheres.push((glam::Vec3::new(x as f32 * 7.3, 1.0, z), 2.5));
        }
    }
    let mut inputs = Vec::new();
    for (c, r) in &spheres {
        inputs.extend(words(&[c.x, c.y, c.z, *r]));
        inputs.extend(words(
            &planes.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>(),
        ));
    }
    let want: Vec<u32> = spheres
        .iter()
        .map(|(c, r)| select_sphere_visible(*c, *r, &planes) as u32)
        .collect();
    assert!(
        want.contains(&0) && want.contains(&1),
        "both outcomes are tested"
    );
    let p = Probe {
        header: "#import lodkit::select::select_sphere_visible",
        body: "var planes: array<vec4<f32>, 6>;
               for (var i = 0u; i < 6u; i++) {
                   planes[i] = vec4<f32>(inp_f(4u + 4u * i), inp_f(5u + 4u * i), inp_f(6u + 4u * i), inp_f(7u + 4u * i));
               }
               let c = vec3<f32>(inp_f(0u), inp_f(1u), inp_f(2u));
               out_u(0u, u32(select_sphere_visible(c, inp_f(3u), planes)));",
        inputs: 28,
        outputs: 1,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    assert_eq!(
        run_wgsl(gpu, &p, &inputs),
        want,
        "WGSL select_sphere_visible"
    );
    let p = Probe {
        header: "#include \"lodkit/select.glsl\"",
        body: "vec4 planes[6];
               for (uint i = 0u; i < 6u; i++) {
                   planes[i] = vec4(inp_f(4u + 4u * i), inp_f(5u + 4u * i), inp_f(6u + 4u * i), inp_f(7u + 4u * i));
               }
               vec3 c = vec3(inp_f(0u), inp_f(1u), inp_f(2u));
               out_u(0u, lodkit_select_sphere_visible(c, inp_f(3u), planes) ? 1u : 0u);",
        ..p
    };
    assert_eq!(
        run_glsl(gpu, &p, &inputs),
        want,
        "GLSL lodkit_select_sphere_visible"
    );
}

/// The Rust mirrors of the selection pass's structs have the WGSL sizes and member offsets
/// (naga's layouter on the composed pass).
#[test]
fn rust_mirrors_match_the_select_pass_layout() {
    use lodkit::gpu::select::{GpuLodGroup, GpuLodInstance, GpuSelectCamera, GpuSelectEntry};
    use std::mem::{offset_of, size_of};
    let composed = lodkit::shaders::compose_pass("select", &[]).unwrap();
    let module = &composed.module;
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    /// (WGSL struct, Rust size, (member, Rust offset)).
    type Mirror = (&'static str, usize, Vec<(&'static str, usize)>);
    let mirrors: [Mirror; 4] = [
        (
            "SelectInstance",
            size_of::<GpuLodInstance>(),
            vec![
                ("radius", offset_of!(GpuLodInstance, radius)),
                ("max_scale", offset_of!(GpuLodInstance, max_scale)),
                ("group", offset_of!(GpuLodInstance, group)),
            ],
        ),
        (
            "SelectCamera",
            size_of::<GpuSelectCamera>(),
            vec![
                ("position", offset_of!(GpuSelectCamera, position)),
                ("factor", offset_of!(GpuSelectCamera, factor)),
                ("step", offset_of!(GpuSelectCamera, step)),
                ("cull", offset_of!(GpuSelectCamera, cull)),
            ],
        ),
        (
            "SelectEntry",
            size_of::<GpuSelectEntry>(),
            vec![("alpha", offset_of!(GpuSelectEntry, alpha))],
        ),
        (
            // naga_oil decorates names imported from a module.
            "SelectGroup",
            size_of::<GpuLodGroup>(),
            vec![
                ("level_count", offset_of!(GpuLodGroup, level_count)),
                ("hysteresis", offset_of!(GpuLodGroup, hysteresis)),
                ("first_slot", offset_of!(GpuLodGroup, first_slot)),
            ],
        ),
    ];
    for (name, size, members) in mirrors {
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| {
                t.name
                    .as_deref()
                    .is_some_and(|n| n == name || n.starts_with(&format!("{name}X_naga_oil")))
            })
            .unwrap_or_else(|| panic!("no struct {name} in passes/select.wgsl"));
        assert_eq!(layouter[handle].size as usize, size, "size of {name}");
        let naga::TypeInner::Struct { members: wgsl, .. } = &ty.inner else {
            panic!("{name} is not a struct");
        };
        for (member, offset) in members {
            let m = wgsl
                .iter()
                .find(|m| m.name.as_deref() == Some(member))
                .unwrap_or_else(|| panic!("{name} has no member {member}"));
            assert_eq!(m.offset as usize, offset, "{name}.{member}");
        }
    }
}

/// Bad input to the selector is a typed error naming the parameter, never a panic.
#[test]
fn selector_rejects_bad_groups_meshes_and_views() {
    use lodkit::gpu::GpuError;
    use lodkit::gpu::select::{
        GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectFrame, LevelMesh,
    };
    let gpu = lodkit_test_gpu!(compute);
    let nine = LodGroup::from_distances(&[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]).unwrap();
    let two = LodGroup::from_distances(&[0.0, 10.0]).unwrap();
    let desc = |groups, meshes| GpuLodSelectorDescriptor {
        groups,
        settings: LodSettings::default(),
        meshes,
    };
    let err = GpuLodSelector::new(gpu, &desc(std::slice::from_ref(&nine), &[])).err();
    assert!(
        matches!(err, Some(GpuError::Invalid { parameter: "groups", ref value, .. }) if value.contains("9 levels")),
        "{err:?}"
    );
    let three = [LevelMesh::default(); 3];
    let meshes: [&[LevelMesh]; 1] = [&three];
    let err = GpuLodSelector::new(gpu, &desc(std::slice::from_ref(&two), &meshes)).err();
    assert!(
        matches!(
            err,
            Some(GpuError::Mismatch {
                parameter: "meshes",
                ..
            })
        ),
        "{err:?}"
    );
    let bad = LodSettings {
        hysteresis: -1.0,
        ..Default::default()
    };
    let err = GpuLodSelector::new(
        gpu,
        &GpuLodSelectorDescriptor {
            settings: bad,
            ..desc(std::slice::from_ref(&two), &[])
        },
    )
    .err();
    assert!(
        matches!(
            err,
            Some(GpuError::Invalid {
                parameter: "settings",
                ..
            })
        ),
        "{err:?}"
    );
    let mut a = GpuLodSelector::new(gpu, &desc(std::slice::from_ref(&two), &[])).unwrap();
    let mut b = GpuLodSelector::new(gpu, &desc(std::slice::from_ref(&two), &[])).unwrap();
    b.add_view(gpu).unwrap();
    let foreign = b.add_view(gpu).unwrap();
    a.add_view(gpu).unwrap();
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 10.0);
    let frame = GpuSelectFrame::new(lodkit::select::LodCamera::new(glam::Vec3::ZERO, proj));
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let err = a.record(gpu, &mut encoder, foreign, &frame).err();
    assert!(
        matches!(
            err,
            Some(GpuError::Mismatch {
                parameter: "view",
                ..
            })
        ),
        "{err:?}"
    );
}
