//! `GpuLodSelector` (passes/select.wgsl) against `select_batch` frame by frame: a camera path of
//! 240 frames over 12,000 instances in four groups, in each transition mode; the camera flies
//! in, stops where a ring of instances sits inside a hysteresis band, turns and flies back out
//! while turning (culling). Every frame the GPU state buffer must equal the CPU states word for
//! word and each (group, level) list the instances the CPU rule and the culling twin put there.
//!
//! Tolerance, derived from WGSL's stated accuracy (`harness::accuracy`): the GPU's distance
//! `sqrt(dx^2 + dy^2 + dz^2) x factor / |scale|` may differ from the CPU's by
//! [`DISTANCE_ULPS`] ULP of the distance (sqrt 4.5 and division 2.5 ULP on the GPU, 0.5 each on
//! the CPU, the sum of squares' three roundings halved by the root, the product's 0.5 on each
//! side: 8.25 + 2.25 = 10.5). The rule's decisions compare that distance with the
//! band edges: an instance whose state differs is accepted only when its CPU distance lies
//! within a relative 1e-5 (84 ULP) of a level distance, band edge or max distance; it is
//! counted, reported, and its CPU state takes the GPU's so that one rounding does not spread
//! over the frames after. A list entry's transition `(d - lo) / (hi - lo)` and fade
//! `(max - d) / h` carry the distance's error times their condition number d / (hi - lo) and
//! d / h (a transition across a 4-wide band at distance 90 multiplies it by 22), plus a few ULP
//! of their own division and products: [`entry_tolerance`]. No better-conditioned form exists:
//! the transition's sensitivity to the instance's position is the rule itself.

use glam::{Mat4, Vec3};
use lodkit::gpu::GpuContext;
use lodkit::gpu::select::{
    GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectEntry, GpuSelectFrame,
};
use lodkit::select::{
    InstanceBatch, LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode,
    distance_kind, frustum_planes, select_batch, select_distance, select_draws_next,
    select_screen_door_alpha, select_sphere_visible, select_update_phase,
};

use crate::harness::{accuracy, float_matches, say};

/// How many ULP of the distance the GPU's may differ from the CPU's (module docs): on the GPU
/// the sum of squares' three roundings halved by the root, the root, the product and the
/// division; on the CPU the same with every operation correctly rounded.
const DISTANCE_ULPS: f32 = (1.5 * accuracy::CORRECTLY_ROUNDED
    + accuracy::SQRT
    + accuracy::CORRECTLY_ROUNDED
    + accuracy::DIV)
    + (1.5 * accuracy::CORRECTLY_ROUNDED + 3.0 * accuracy::CORRECTLY_ROUNDED);

/// The most a list entry's transition or alpha may differ between GPU and CPU for an instance at
/// CPU distance `d` in `group` with hysteresis `h` selected as `sel`: the distance's error over
/// the band the transition runs across, plus over h where the fade is below 1, plus 8 ULP for
/// the divisions (2.5 + 0.5 ULP each side), subtractions and products of t, fade and alpha.
pub(crate) fn entry_tolerance(
    group: &LodGroup,
    h: f32,
    d: f32,
    sel: &LodSelection,
    mode: TransitionMode,
) -> f32 {
    let data = group.select_data(h).unwrap();
    let dd = DISTANCE_ULPS * accuracy::ULP * d;
    // t's and the fade's division (GPU and CPU) and subtraction, and the products of alpha.
    let own =
        2.0 * (accuracy::DIV + accuracy::CORRECTLY_ROUNDED) + 4.0 * accuracy::CORRECTLY_ROUNDED;
    let mut tol = own * accuracy::ULP;
    if let (Some(next), TransitionMode::Distance) = (sel.next, mode) {
        let b = data.levels[usize::from(sel.current.max(next))];
        tol += dd / (b[2] - b[1]);
    }
    if sel.fade < 1.0 && h > 0.0 {
        tol += dd / h;
    }
    tol
}

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
fn cpu_lists(
    groups: &[LodGroup],
    insts: &[GpuLodInstance],
    out: &[LodSelection],
    packed: &[u32],
    planes: &[glam::Vec4; 6],
    frame: u32,
    frame_sequential: bool,
) -> Vec<Vec<GpuSelectEntry>> {
    let slot_count: usize = groups.iter().map(|g| g.levels().len()).sum();
    let mut lists = vec![Vec::new(); slot_count];
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

/// Holds the GPU's lists to the CPU's, slot by slot: the same (instance, flags) pairs, with
/// transition and alpha within `tolerance(instance)` (alpha: twice that, as `+-t x fade` carries
/// both errors). An instance listed on one side only, or with other flags, is accepted where
/// `rounding_decides(instance)` (its distance at a threshold, or its sphere on a frustum plane:
/// tests a GPU may round either way). Returns how many were accepted, or the first
/// disagreement.
pub(crate) fn lists_match(
    got: &[Vec<GpuSelectEntry>],
    want: &[Vec<GpuSelectEntry>],
    rounding_decides: impl Fn(usize) -> bool,
    tolerance: impl Fn(usize) -> f32,
) -> Result<usize, String> {
    if got.len() != want.len() {
        return Err(format!("{} lists, the CPU {}", got.len(), want.len()));
    }
    let mut accepted = 0;
    for (s, (g, w)) in got.iter().zip(want).enumerate() {
        let mut g = g.clone();
        g.sort_by_key(|e| e.instance);
        let mut w = w.clone();
        w.sort_by_key(|e| e.instance);
        let (mut a, mut b) = (g.iter().peekable(), w.iter().peekable());
        loop {
            let (x, y) = (a.peek().copied(), b.peek().copied());
            let (one, both) = match (x, y) {
                (None, None) => break,
                (Some(x), Some(y)) if x.instance == y.instance => {
                    a.next();
                    b.next();
                    (None, Some((x, y)))
                }
                (Some(x), Some(y)) if x.instance < y.instance => (a.next(), None),
                (Some(_), Some(_)) | (None, Some(_)) => (b.next(), None),
                (Some(_), None) => (a.next(), None),
            };
            let i = one.or(both.map(|p| p.0)).unwrap().instance as usize;
            match both {
                Some((x, y)) if x.flags == y.flags => {
                    let tol = tolerance(i);
                    if !(float_matches(x.transition, y.transition, tol)
                        && float_matches(x.alpha, y.alpha, 2.0 * tol))
                    {
                        return Err(format!(
                            "slot {s} instance {i}: GPU {x:?} vs CPU {y:?} (tolerance {tol:e})"
                        ));
                    }
                }
                _ if rounding_decides(i) => accepted += 1,
                _ => {
                    let find =
                        |l: &[GpuSelectEntry]| l.iter().find(|e| e.instance as usize == i).copied();
                    return Err(format!(
                        "slot {s} instance {i}: GPU {:?} vs CPU {:?}",
                        find(&g),
                        find(&w)
                    ));
                }
            }
        }
    }
    Ok(accepted)
}

/// Whether an instance's bounding sphere touches a frustum plane within a relative 1e-5: where
/// the culling test's sum of products may round either way.
fn near_plane(planes: &[glam::Vec4; 6], inst: &GpuLodInstance) -> bool {
    let c = Vec3::from_array(inst.center);
    planes.iter().any(|p| {
        let side = p.truncate().dot(c) + p.w + inst.radius;
        let scale = p.truncate().abs().dot(c.abs()) + p.w.abs() + inst.radius;
        side.abs() <= 1e-5 * scale.max(1.0)
    })
}

/// Whether `d` is within a relative 1e-5 of a threshold of `group` under hysteresis `h`.
pub(crate) fn near_threshold(group: &LodGroup, h: f32, d: f32) -> bool {
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

/// What a run of the path found.
struct PathRun {
    /// Instance-frames whose state differed within the threshold tolerance.
    accepted: usize,
    /// The first disagreement beyond the tolerances, if any.
    failure: Option<String>,
}

/// Runs the path in `mode`, the CPU twin's distances scaled by `1 + perturb` (0: the twin as it
/// is; a perturbed twin stands in for a GPU that rounds differently).
fn run_path(
    gpu: &GpuContext,
    mode: TransitionMode,
    frame_sequential: bool,
    perturb: f32,
) -> PathRun {
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
    let fail = |accepted, message: String| PathRun {
        accepted,
        failure: Some(message),
    };
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
        let (kind, factor) = distance_kind(&cam, &settings);
        let distance = |i: usize| {
            select_distance(positions[i], cam.position, factor, scales[i], kind) * (1.0 + perturb)
        };
        if perturb == 0.0 {
            select_batch(&cam, &settings, &groups, &batch, DT, &mut states, &mut out).unwrap();
        } else {
            for i in 0..INSTANCES {
                let g = &groups[insts[i].group as usize];
                out[i] = g.select(distance(i), &settings, DT, &mut states[i]);
            }
        }
        for i in 0..INSTANCES {
            packed[i] =
                select_update_phase(packed[i] & 0xffff_0000 | states[i].packed(), &out[i], frame);
            // The state word exactly; the progress (sums of the same step, correctly rounded on
            // both sides) as a float, +0 and -0 alike.
            let progress = f32::from_bits(got.states[i][1]);
            let same =
                got.states[i][0] == packed[i] && float_matches(progress, states[i].progress(), 0.0);
            if !same {
                let g = &groups[insts[i].group as usize];
                let d = distance(i);
                if !near_threshold(g, settings.hysteresis, d) {
                    return fail(
                        accepted,
                        format!(
                            "{mode:?} frame {frame} instance {i} (distance {d}): GPU state {:x?} vs CPU [{:x}, {}]",
                            got.states[i],
                            packed[i],
                            states[i].progress()
                        ),
                    );
                }
                accepted += 1;
                packed[i] = got.states[i][0];
                states[i] = LodState::from_packed(packed[i], progress);
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
            &groups,
            &insts,
            &out,
            &packed,
            &planes,
            frame,
            frame_sequential,
        );
        let rounding_decides = |i: usize| {
            let group = &groups[insts[i].group as usize];
            near_threshold(group, settings.hysteresis, distance(i))
                || near_plane(&planes, &insts[i])
        };
        let tolerance = |i: usize| {
            let group = &groups[insts[i].group as usize];
            entry_tolerance(group, settings.hysteresis, distance(i), &out[i], mode)
        };
        match lists_match(&got.lists, &want, rounding_decides, tolerance) {
            Ok(n) => accepted += n,
            Err(e) => return fail(accepted, format!("{mode:?} frame {frame}: {e}")),
        }
    }
    say(&format!(
        "GPU selection {mode:?} (frame-sequential {frame_sequential}, twin distances x (1 + {perturb:e})): \
         {FRAMES} frames x {INSTANCES} instances, {switches} level switches, {transitions} \
         instance-frames in transition, {reversals} reversals; {accepted} instance-frames within \
         the threshold tolerance"
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
    PathRun {
        accepted,
        failure: None,
    }
}

#[test]
fn gpu_selection_equals_select_batch_along_a_camera_path() {
    let gpu = lodkit_test_gpu!(compute);
    for (mode, fs) in [
        (TransitionMode::Distance, false),
        (TransitionMode::Time { seconds: 0.4 }, true),
        (TransitionMode::Hard, false),
    ] {
        let run = run_path(gpu, mode, fs, 0.0);
        assert!(run.failure.is_none(), "{}", run.failure.unwrap());
        assert!(
            run.accepted <= 24,
            "{mode:?}: {} instance-frames differ at thresholds",
            run.accepted
        );
    }
}

/// The failure class a real GPU showed (a transition some hundred ULP off the CPU's, from a
/// distance a few ULP off, amplified by the band): the same comparison against a twin whose
/// distances are off by as much as WGSL allows the GPU's to be still passes, and against one
/// off by eight times that it fails, so the tolerance is neither too tight for a conformant GPU
/// nor too loose to see a wrong distance.
#[test]
fn selection_tolerance_holds_a_perturbed_twin_and_rejects_a_wrong_one() {
    let gpu = lodkit_test_gpu!(compute);
    let bound = DISTANCE_ULPS * accuracy::ULP;
    for perturb in [bound, -bound] {
        let run = run_path(gpu, TransitionMode::Distance, false, perturb);
        assert!(
            run.failure.is_none(),
            "perturbed by {perturb:e}: {}",
            run.failure.unwrap()
        );
    }
    let run = run_path(gpu, TransitionMode::Distance, false, 8.0 * bound);
    let failure = run.failure.expect("a twin 8x the bound off must be seen");
    say(&format!("a twin off by 8x the bound: {failure}"));
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
            assert!(
                float_matches(f32::from_bits(g[1]), s.progress(), 0.0),
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
