//! `GpuLodSelector` (passes/select.wgsl) against `select_batch` frame by frame: a camera path of
//! 240 frames over 12,000 instances in four groups, in each transition mode; the camera flies
//! in, stops where a ring of instances sits inside a hysteresis band, turns and flies back out
//! while turning (culling). Every frame the GPU state buffer must equal the CPU states word for
//! word and each (group, level) list the instances the CPU rule and the culling twin put there.
//!
//! Tolerance: the GPU's square root and division may round differently from the CPU's. An
//! instance whose state differs is accepted only when its CPU distance lies within a relative
//! 1e-5 of a level distance, band edge or max distance; it is counted, reported, and its CPU
//! state takes the GPU's so that one rounding does not spread over the frames after.

use glam::{Mat4, Vec3};
use lodkit::gpu::GpuContext;
use lodkit::gpu::select::{
    GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectEntry, GpuSelectFrame,
};
use lodkit::select::{
    InstanceBatch, LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode,
    frustum_planes, select_batch, select_draws_next, select_screen_door_alpha,
    select_sphere_visible, select_update_phase,
};

use crate::harness::say;

const INSTANCES: usize = 12_000;
const FRAMES: u32 = 240;
const DT: f32 = 1.0 / 60.0;

fn groups() -> Vec<LodGroup> {
    vec![
        LodGroup::from_distances(&[0.0, 20.0, 50.0, 120.0]).unwrap(),
        LodGroup::from_distances(&[0.0, 10.0, 14.0, 40.0, 90.0])
            .unwrap()
            .with_max_distance(150.0)
            .unwrap(),
        LodGroup::from_distances(&[0.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 80.0]).unwrap(),
        LodGroup::from_distances(&[0.0])
            .unwrap()
            .with_max_distance(60.0)
            .unwrap(),
    ]
}

/// Where the camera stops (frames 90..150).
const STOP: Vec3 = Vec3::new(0.0, 3.0, 40.0);

/// A field of instances, plus a ring of group-0 instances at view-normalized distance 51 from
/// STOP (`p11` = |P\[1\]\[1\]|): inside the band [48, 52] around level 2 (distance 50,
/// hysteresis 4) while the camera stands there.
fn instances(p11: f32) -> Vec<GpuLodInstance> {
    let mut state = 0x2545_f491_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    let mut out = Vec::with_capacity(INSTANCES);
    let ring = 1000;
    for k in 0..ring {
        let a = k as f32 / ring as f32 * std::f32::consts::TAU;
        let radius = ((51.0 * p11).powi(2) - 9.0).sqrt();
        let c = STOP + Vec3::new(a.cos(), 0.0, a.sin()) * radius - Vec3::Y * 3.0;
        out.push(GpuLodInstance::new(c, 1.0, 1.0, 0));
    }
    while out.len() < INSTANCES {
        let c = Vec3::new(next() * 400.0 - 200.0, next() * 4.0, next() * 400.0 - 300.0);
        let scale = 0.5 + next() * 1.5;
        let group = (next() * 4.0) as u32 % 4;
        out.push(GpuLodInstance::new(c, scale, scale, group));
    }
    out
}

/// The camera of frame `f`: in from z = 140 to STOP, still, back out while turning.
fn camera(f: u32, proj: Mat4) -> (LodCamera, Mat4) {
    let start = Vec3::new(0.0, 3.0, 140.0);
    let (pos, yaw) = match f {
        0..90 => (start.lerp(STOP, f as f32 / 90.0), 0.0),
        90..150 => (STOP, 0.0),
        _ => {
            let t = (f - 150) as f32 / 90.0;
            (STOP.lerp(start + Vec3::X * 30.0, t), t * 1.2)
        }
    };
    let forward = Vec3::new(-yaw.sin(), -0.05, -yaw.cos());
    let view = glam::camera::rh::view::look_at_mat4(pos, pos + forward, Vec3::Y);
    (LodCamera::new(pos, proj), proj * view)
}

/// The CPU's list entries for one frame: per slot, sorted by instance.
#[allow(clippy::too_many_arguments)]
fn cpu_lists(
    selector: &GpuLodSelector,
    groups: &[LodGroup],
    insts: &[GpuLodInstance],
    out: &[LodSelection],
    packed: &[u32],
    planes: &[glam::Vec4; 6],
    frame: u32,
    frame_sequential: bool,
) -> Vec<Vec<GpuSelectEntry>> {
    let mut lists = vec![Vec::new(); selector.slots().len()];
    let slot = |g: u32, level: u8| {
        let first = groups[..g as usize]
            .iter()
            .map(|g| g.levels().len())
            .sum::<usize>();
        first + level as usize
    };
    for (i, (inst, sel)) in insts.iter().zip(out).enumerate() {
        let center = Vec3::from_array(inst.center);
        if !sel.visible || !select_sphere_visible(center, inst.radius, planes) {
            continue;
        }
        let phase = (packed[i] >> 14) & 4;
        let entry = |flags, alpha| GpuSelectEntry {
            instance: i as u32,
            flags,
            transition: sel.transition,
            alpha,
        };
        let Some(next) = sel.next else {
            lists[slot(inst.group, sel.current)].push(entry(0, sel.fade));
            continue;
        };
        let draws_next = select_draws_next(packed[i], frame);
        if !frame_sequential || !draws_next {
            let alpha = select_screen_door_alpha(sel, false);
            lists[slot(inst.group, sel.current)].push(entry(2 | phase, alpha));
        }
        if !frame_sequential || draws_next {
            let alpha = select_screen_door_alpha(sel, true);
            lists[slot(inst.group, next)].push(entry(3 | phase, alpha));
        }
    }
    lists
}

/// Whether `d` is within a relative 1e-5 of a threshold of `group` under hysteresis `h`.
fn near_threshold(group: &LodGroup, h: f32, d: f32) -> bool {
    let data = group.select_data(h).unwrap();
    let mut edges: Vec<f32> = data.levels[..data.level_count as usize]
        .iter()
        .flat_map(|l| [l[0], l[1], l[2]])
        .collect();
    edges.push(data.max_distance);
    edges.push(data.fade_from);
    edges
        .iter()
        .any(|e| e.is_finite() && (d - e).abs() <= 1e-5 * e.abs().max(1.0))
}

/// Runs the path in `mode`; returns the instance-frames accepted under the tolerance.
fn run_path(gpu: &GpuContext, mode: TransitionMode, frame_sequential: bool) -> usize {
    let groups = groups();
    let settings = LodSettings {
        hysteresis: 4.0,
        transition: mode,
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
    let proj = glam::camera::rh::proj::directx::perspective(1.1, 1.6, 0.1, 400.0);
    let insts = instances(proj.y_axis.y.abs());
    selector.set_instances(gpu, &insts).unwrap();
    let view = selector.add_view(gpu).unwrap();
    let positions: Vec<Vec3> = insts.iter().map(|i| Vec3::from_array(i.center)).collect();
    let scales: Vec<f32> = insts.iter().map(|i| i.max_scale).collect();
    let group_ids: Vec<u32> = insts.iter().map(|i| i.group).collect();
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &scales,
        groups: &group_ids,
    };
    let mut states = vec![LodState::NEW; INSTANCES];
    let mut packed = vec![LodState::NEW.packed(); INSTANCES];
    let mut out = vec![LodSelection::default(); INSTANCES];
    let (mut accepted, mut transitions, mut reversals, mut switches) = (0usize, 0, 0, 0);
    let mut last = packed.clone();
    for frame in 0..FRAMES {
        let (cam, view_proj) = camera(frame, proj);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let desc = GpuSelectFrame {
            camera: cam,
            view_proj: Some(view_proj),
            dt: DT,
            frame,
            frame_sequential,
        };
        selector.record(gpu, &mut encoder, view, &desc).unwrap();
        gpu.queue.submit([encoder.finish()]);
        let got = selector.read_back(gpu, view).unwrap();
        select_batch(&cam, &settings, &groups, &batch, DT, &mut states, &mut out).unwrap();
        for i in 0..INSTANCES {
            packed[i] =
                select_update_phase(packed[i] & 0xffff_0000 | states[i].packed(), &out[i], frame);
            let want = [packed[i], states[i].progress().to_bits()];
            if got.states[i] != want {
                let g = &groups[insts[i].group as usize];
                let d = cam.lod_distance(positions[i], scales[i], 1.0);
                assert!(
                    near_threshold(g, settings.hysteresis, d),
                    "{mode:?} frame {frame} instance {i} (distance {d}): GPU state {:x?} vs CPU {:x?}",
                    got.states[i],
                    want
                );
                accepted += 1;
                packed[i] = got.states[i][0];
                states[i] = LodState::from_packed(packed[i], f32::from_bits(got.states[i][1]));
            }
            // A timed transition turned back: level and target swap places.
            let (level, target) = (packed[i] & 0xff, (packed[i] >> 8) & 0xff);
            let (was_level, was_target) = (last[i] & 0xff, (last[i] >> 8) & 0xff);
            if was_level != was_target && level == was_target && target == was_level {
                reversals += 1;
            }
            transitions += out[i].next.is_some() as usize;
            switches += (level != last[i] & 0xff) as usize;
            last[i] = packed[i];
        }
        if frame == 120 && mode == TransitionMode::Distance {
            // The camera stands still with the ring inside the band around level 2: frozen blends.
            assert!(
                out[..1000].iter().all(|s| s.next.is_some()),
                "the ring is inside a band"
            );
        }
        let planes = frustum_planes(&view_proj);
        let want = cpu_lists(
            &selector,
            &groups,
            &insts,
            &out,
            &packed,
            &planes,
            frame,
            frame_sequential,
        );
        for (s, (g, w)) in got.lists.iter().zip(&want).enumerate() {
            let mut g = g.clone();
            g.sort_by_key(|e| e.instance);
            let ids =
                |l: &[GpuSelectEntry]| l.iter().map(|e| (e.instance, e.flags)).collect::<Vec<_>>();
            assert_eq!(
                ids(&g),
                ids(w),
                "{mode:?} frame {frame} slot {s}: instance lists differ"
            );
            for (a, b) in g.iter().zip(w) {
                assert!(
                    (a.transition - b.transition).abs() <= 1e-5
                        && (a.alpha - b.alpha).abs() <= 1e-5,
                    "{mode:?} frame {frame} slot {s} instance {}: GPU {a:?} vs CPU {b:?}",
                    a.instance
                );
            }
        }
    }
    say(&format!(
        "GPU selection {mode:?} (frame-sequential {frame_sequential}): {FRAMES} frames x {INSTANCES} instances, \
         {switches} level switches, {transitions} instance-frames in transition, {reversals} reversals; \
         {accepted} instance-frames within the threshold tolerance"
    ));
    assert!(switches > 1000, "the path switches levels ({switches})");
    if mode != TransitionMode::Hard {
        assert!(
            transitions > 1000,
            "the path exercises transitions ({transitions})"
        );
    }
    if matches!(mode, TransitionMode::Time { .. }) {
        assert!(reversals > 0, "the path turns timed transitions back");
    }
    accepted
}

#[test]
fn gpu_selection_equals_select_batch_along_a_camera_path() {
    let gpu = lodkit_test_gpu!(compute);
    for (mode, fs) in [
        (TransitionMode::Distance, false),
        (TransitionMode::Time { seconds: 0.4 }, true),
        (TransitionMode::Hard, false),
    ] {
        let accepted = run_path(gpu, mode, fs);
        assert!(
            accepted <= 24,
            "{mode:?}: {accepted} instance-frames differ at thresholds"
        );
    }
}

/// Setting more instances grows the buffers and starts every view over: after a small set, a
/// set 36 times larger (with instances of a group past the table, which select nothing) selects
/// as `select_batch` does from fresh states.
#[test]
fn selector_grows_and_starts_over() {
    let gpu = lodkit_test_gpu!(compute);
    let groups = groups();
    let settings = LodSettings {
        hysteresis: 4.0,
        transition: TransitionMode::Time { seconds: 0.4 },
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
    let proj = glam::camera::rh::proj::directx::perspective(1.1, 1.6, 0.1, 400.0);
    let all = instances(proj.y_axis.y.abs());
    let view = selector.add_view(gpu).unwrap();
    let (cam, view_proj) = camera(100, proj);
    // The field, not the ring (whose first instances are behind the camera).
    for n in [300, INSTANCES - 1000] {
        let mut insts = all[1000..1000 + n].to_vec();
        insts[n - 1].group = 7; // past the table
        selector.set_instances(gpu, &insts).unwrap();
        let mut states = vec![LodState::NEW; n];
        let mut out = vec![LodSelection::default(); n];
        let positions: Vec<Vec3> = insts.iter().map(|i| Vec3::from_array(i.center)).collect();
        let scales: Vec<f32> = insts.iter().map(|i| i.max_scale).collect();
        let ids: Vec<u32> = insts.iter().map(|i| i.group).collect();
        let batch = InstanceBatch {
            positions: &positions,
            max_scales: &scales,
            groups: &ids,
        };
        for frame in 0..3 {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let desc = GpuSelectFrame {
                camera: cam,
                view_proj: Some(view_proj),
                dt: DT,
                frame,
                frame_sequential: false,
            };
            selector.record(gpu, &mut encoder, view, &desc).unwrap();
            gpu.queue.submit([encoder.finish()]);
            select_batch(&cam, &settings, &groups, &batch, DT, &mut states, &mut out).unwrap();
        }
        let got = selector.read_back(gpu, view).unwrap();
        assert_eq!(got.states.len(), n);
        for (i, (g, s)) in got.states.iter().zip(&states).enumerate() {
            assert_eq!(g[0] & 0xffff, s.packed(), "{n} instances: state of {i}");
            assert_eq!(
                g[1],
                s.progress().to_bits(),
                "{n} instances: progress of {i}"
            );
        }
        let listed: usize = got.lists.iter().map(Vec::len).sum();
        assert!(listed > 0, "{n} instances: something is drawn");
        assert!(
            got.lists
                .iter()
                .flatten()
                .all(|e| e.instance as usize != n - 1),
            "an instance of no group is drawn"
        );
    }
}
