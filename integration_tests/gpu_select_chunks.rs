//! `GpuLodSelector` past one binding and one dispatch row: instances split into chunks (each
//! fitting `max_storage_buffer_binding_size` with its states and lists) and dispatched on a 2-D
//! grid (past `max_compute_workgroups_per_dimension` x 64). Cheaply on a device whose limits are
//! lowered to make ~10^4 instances need both, and once at full size: more than 4,194,240
//! instances (65535 x 64, one 1-D dispatch on lavapipe and on an H200) against `select_batch`.

use glam::Vec3;
use lodkit::gpu::select::{
    GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectEntry, GpuSelectFrame,
    SelectReadback,
};
use lodkit::gpu::{GpuContext, GpuOptions};
use lodkit::select::{
    InstanceBatch, LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode,
    distance_kind, select_batch, select_distance, select_screen_door_alpha, select_update_phase,
};

use crate::gpu_select_path::{entry_tolerance, lists_match, near_threshold};
use crate::harness::{float_matches, say, strict, test_name};

fn groups() -> Vec<LodGroup> {
    vec![
        LodGroup::from_distances(&[0.0, 20.0, 50.0]).unwrap(),
        LodGroup::from_distances(&[0.0, 10.0, 30.0, 70.0, 120.0])
            .unwrap()
            .with_max_distance(200.0)
            .unwrap(),
    ]
}

/// `n` instances on a grid in front of the camera, spread over both groups and one group past
/// the table; whole-number coordinates keep every distance clear of the thresholds' roundings.
fn instances(n: usize) -> Vec<GpuLodInstance> {
    (0..n)
        .map(|i| {
            let side = 2048;
            let (x, z) = ((i % side) as f32, (i / side) as f32);
            let center = Vec3::new(x * 0.25 - 256.0, 0.0, -(z * 0.25) - 1.0);
            let group = match i % 7 {
                6 => 5, // past the table: selects nothing
                k => (k % 2) as u32,
            };
            GpuLodInstance::new(center, 0.5, 1.0 + (i % 3) as f32 * 0.5, group)
        })
        .collect()
}

/// Runs `frames` frames of distance-driven selection on the GPU and on the CPU and holds them
/// equal as the path test does (`gpu_select_path`: states word for word, lists as sets with
/// the derived tolerances, where a rounding of the distance decides accepted and counted).
/// Returns the readback of the last frame.
fn select_and_compare(gpu: &GpuContext, insts: &[GpuLodInstance], frames: u32) -> SelectReadback {
    let groups = groups();
    let settings = LodSettings {
        hysteresis: 4.0,
        transition: TransitionMode::Distance,
        ..Default::default()
    };
    let mut selector = GpuLodSelector::new(
        gpu,
        &GpuLodSelectorDescriptor {
            groups: &groups,
            settings,
            meshes: &[],
        },
    )
    .unwrap();
    selector.set_instances(gpu, insts).unwrap();
    let view = selector.add_view(gpu).unwrap();
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.5, 0.1, 1000.0);
    let positions: Vec<Vec3> = insts.iter().map(|i| Vec3::from_array(i.center)).collect();
    let scales: Vec<f32> = insts.iter().map(|i| i.max_scale).collect();
    let ids: Vec<u32> = insts.iter().map(|i| i.group).collect();
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &scales,
        groups: &ids,
    };
    let mut states = vec![LodState::NEW; insts.len()];
    let mut out = vec![LodSelection::default(); insts.len()];
    let mut phases = vec![LodState::NEW.packed(); insts.len()];
    let mut last = SelectReadback::default();
    for frame in 0..frames {
        let cam = LodCamera::new(Vec3::new(0.0, 2.0, 10.0 - 7.0 * frame as f32), proj);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let desc = GpuSelectFrame {
            frame,
            ..GpuSelectFrame::new(cam)
        };
        selector.record(gpu, &mut encoder, view, &desc).unwrap();
        gpu.queue.submit([encoder.finish()]);
        let got = selector.read_back(gpu, view).unwrap();
        select_batch(
            &cam,
            &settings,
            &groups,
            &batch,
            0.016,
            &mut states,
            &mut out,
        )
        .unwrap();
        assert_eq!(got.states.len(), insts.len(), "frame {frame}: states");
        let (kind, factor) = distance_kind(&cam, &settings);
        let distance =
            |i: usize| select_distance(positions[i], cam.position, factor, scales[i], kind);
        let near = |i: usize| {
            groups
                .get(ids[i] as usize)
                .is_some_and(|g| near_threshold(g, settings.hysteresis, distance(i)))
        };
        // States word for word, but where a rounding of the distance decides (see the path test).
        let mut accepted = 0;
        for (i, (g, s)) in got.states.iter().zip(states.iter_mut()).enumerate() {
            let progress = f32::from_bits(g[1]);
            if g[0] & 0xffff != s.packed() || !float_matches(progress, s.progress(), 0.0) {
                assert!(
                    near(i),
                    "frame {frame}: state of {i}: GPU {g:x?} vs CPU {s:?}"
                );
                *s = LodState::from_packed(g[0] & 0xffff, progress);
                accepted += 1;
            }
        }
        // The CPU's lists, slot by slot (group 0 has slots 0..3, group 1 slots 3..8); an entry
        // in transition carries the phase bit its state keeps (the parity of the frame its
        // transition began).
        let mut want = vec![Vec::new(); 8];
        for (i, sel) in out.iter().enumerate() {
            phases[i] =
                select_update_phase(phases[i] & 0xffff_0000 | states[i].packed(), sel, frame);
            let g = ids[i] as usize;
            if g >= groups.len() || !sel.visible {
                continue;
            }
            let first = if g == 0 { 0 } else { 3 };
            let phase = (phases[i] >> 14) & 4;
            let entry = |flags, alpha| GpuSelectEntry {
                instance: i as u32,
                flags,
                transition: sel.transition,
                alpha,
            };
            match sel.next {
                None => want[first + usize::from(sel.current)].push(entry(0, sel.fade)),
                Some(next) => {
                    want[first + usize::from(sel.current)]
                        .push(entry(2 | phase, select_screen_door_alpha(sel, false)));
                    want[first + usize::from(next)]
                        .push(entry(3 | phase, select_screen_door_alpha(sel, true)));
                }
            }
        }
        let tolerance = |i: usize| {
            let g = &groups[ids[i] as usize];
            entry_tolerance(
                g,
                settings.hysteresis,
                distance(i),
                &out[i],
                settings.transition,
            )
        };
        accepted += lists_match(&got.lists, &want, near, tolerance)
            .unwrap_or_else(|e| panic!("frame {frame}: {e}"));
        assert!(
            accepted <= insts.len() / 10_000 + 4,
            "frame {frame}: {accepted} instances decided by rounding"
        );
        last = got;
    }
    say(&format!(
        "{} instances in {} chunk(s): {} listed, {} in transition on the last frame",
        insts.len(),
        selector.chunk_count(),
        last.lists.iter().map(Vec::len).sum::<usize>(),
        out.iter().filter(|s| s.next.is_some()).count()
    ));
    assert!(
        out.iter().any(|s| s.next.is_some()),
        "the camera path puts instances in transition"
    );
    last
}

/// A device with lowered limits: 4 workgroups per dimension (256 invocations in one row) and
/// 64 KiB bindings, so 12,000 instances need several chunks and a 2-D grid in each.
#[test]
fn a_device_with_small_limits_selects_in_chunks_on_a_2d_grid() {
    let gpu = lodkit_test_gpu!(compute);
    let mut limits = gpu.adapter.limits();
    limits.max_compute_workgroups_per_dimension = 4;
    limits.max_storage_buffer_binding_size = 64 << 10;
    let small = match GpuContext::new_headless(&GpuOptions {
        backends: vec![gpu.adapter.get_info().backend.into()],
        limits: Some(limits),
        ..Default::default()
    }) {
        Ok(g) => g,
        Err(e) if !strict() => {
            say(&format!(
                "SKIPPED {}: no device with lowered limits: {e}",
                test_name()
            ));
            return;
        }
        Err(e) => panic!("a device with lowered limits: {e}"),
    };
    let insts = instances(12_000);
    let got = select_and_compare(&small, &insts, 6);
    assert_eq!(got.states.len(), 12_000);
    // The same instances in one chunk on the full device give the same lists.
    let whole = select_and_compare(gpu, &insts, 6);
    let sorted = |r: &SelectReadback| {
        r.lists
            .iter()
            .map(|l| {
                let mut ids: Vec<(u32, u32)> = l.iter().map(|e| (e.instance, e.flags)).collect();
                ids.sort_unstable();
                ids
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(sorted(&got), sorted(&whole), "chunked and whole lists");
    assert_eq!(got.states, whole.states, "chunked and whole states");
}

/// More instances than one 1-D dispatch covers (65535 x 64 = 4,194,240) and than lavapipe's
/// 2^27-byte binding holds (4,194,304 instances of 32 bytes): one selector, against
/// `select_batch`.
#[test]
fn more_instances_than_one_dispatch_row_select_as_select_batch_does() {
    let gpu = lodkit_test_gpu!(compute);
    let insts = instances(4_200_000);
    let got = select_and_compare(gpu, &insts, 2);
    assert_eq!(got.states.len(), 4_200_000);
}
