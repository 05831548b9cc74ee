//! `--bench`: GPU selection throughput against `select_batch` on one core, in the same run, and
//! the bytes the pass moves per instance.

use std::error::Error;
use std::time::Instant;

use glam::Vec3;
use lodkit::gpu::GpuContext;
use lodkit::gpu::select::{
    GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectFrame,
};
use lodkit::select::{
    InstanceBatch, LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode,
    select_batch,
};

/// Frames timed per size (after two untimed ones).
const FRAMES: u32 = 20;
/// The bandwidth the figure on paper assumes, bytes per second.
const BANDWIDTH: f64 = 400e9;

pub fn run(gpu: &GpuContext) -> Result<(), Box<dyn Error>> {
    let groups = [
        LodGroup::from_distances(&[0.0, 10.0, 30.0])?.with_max_distance(400.0)?,
        LodGroup::from_distances(&[0.0, 5.0, 15.0, 40.0])?,
    ];
    let settings = LodSettings {
        hysteresis: 3.0,
        transition: TransitionMode::Time { seconds: 0.3 },
        ..Default::default()
    };
    let (read, written) = bytes_per_instance()?;
    println!(
        "passes/select.wgsl per instance: reads {} B settled .. {} B at most, writes {} B settled \
         .. {} B in transition (state 8, per list entry 16 + its 4-byte count)",
        read.0, read.1, written.0, written.1
    );
    // The group table is a few hundred bytes read by every thread: it stays in cache, so the
    // memory traffic is the rest.
    let group = std::mem::size_of::<lodkit::gpu::select::GpuLodGroup>() as u64;
    println!(
        "on paper at {:.0} GB/s, the group table ({group} B of the reads) in cache: {:.2e} .. \
         {:.2e} instances/s (bandwidth only)",
        BANDWIDTH / 1e9,
        BANDWIDTH / (read.1 - group + written.1) as f64,
        BANDWIDTH / (read.0 - group + written.0) as f64
    );
    println!("| instances | GPU (instances/s) | select_batch, one core (instances/s) |");
    println!("|---|---|---|");
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.6, 0.1, 2000.0);
    for n in [10_000usize, 100_000, 1_000_000] {
        let side = (n as f32).sqrt().ceil() as usize;
        let instances: Vec<GpuLodInstance> = (0..n)
            .map(|i| {
                let c = Vec3::new(
                    (i % side) as f32 * 2.0 - side as f32,
                    0.5,
                    -((i / side) as f32) * 2.0,
                );
                GpuLodInstance::new(c, 0.6, 1.0, (i % 2) as u32)
            })
            .collect();
        let mut selector = GpuLodSelector::new(
            gpu,
            &GpuLodSelectorDescriptor {
                groups: &groups,
                settings,
                meshes: &[],
            },
        )?;
        selector.set_instances(gpu, &instances)?;
        let view = selector.add_view(gpu)?;
        let camera = |f: u32| {
            let eye = Vec3::new(0.0, 3.0, -(f as f32) * 1.5);
            let look = glam::camera::rh::view::look_at_mat4(eye, eye - Vec3::Z, Vec3::Y);
            (LodCamera::new(eye, proj), proj * look)
        };
        let mut gpu_time = 0.0;
        for f in 0..FRAMES + 2 {
            let (cam, view_proj) = camera(f);
            let start = Instant::now();
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let frame = GpuSelectFrame {
                camera: cam,
                view_proj: Some(view_proj),
                dt: 1.0 / 60.0,
                frame: f,
                frame_sequential: false,
            };
            selector.record(gpu, &mut encoder, view, &frame)?;
            gpu.queue.submit([encoder.finish()]);
            gpu.wait_idle()?;
            if f >= 2 {
                gpu_time += start.elapsed().as_secs_f64();
            }
        }
        let positions: Vec<Vec3> = instances
            .iter()
            .map(|i| Vec3::from_array(i.center))
            .collect();
        let scales = vec![1.0; n];
        let ids: Vec<u32> = instances.iter().map(|i| i.group).collect();
        let batch = InstanceBatch {
            positions: &positions,
            max_scales: &scales,
            groups: &ids,
        };
        let mut states = vec![LodState::NEW; n];
        let mut out = vec![LodSelection::default(); n];
        let mut cpu_time = 0.0;
        for f in 0..FRAMES + 2 {
            let (cam, _) = camera(f);
            let start = Instant::now();
            select_batch(
                &cam,
                &settings,
                &groups,
                &batch,
                1.0 / 60.0,
                &mut states,
                &mut out,
            )?;
            if f >= 2 {
                cpu_time += start.elapsed().as_secs_f64();
            }
        }
        let rate = |t: f64| (n as f64 * f64::from(FRAMES)) / t;
        println!("| {n} | {:.3e} | {:.3e} |", rate(gpu_time), rate(cpu_time));
    }
    Ok(())
}

/// Bytes the selection pass reads per instance (settled: the main path; at most: every branch),
/// counted from the shader: each storage read `lodkit::shaders::cost` finds, times the size of
/// the element it loads; and bytes it writes: the state, and per list entry the entry and its
/// atomic count (sizes from naga's layouter).
/// (settled, at most) bytes read and written per instance.
type Span = (u64, u64);

fn bytes_per_instance() -> Result<(Span, Span), Box<dyn Error>> {
    let composed = lodkit::shaders::compose_pass("select", &[])?;
    let module = &composed.module;
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx())?;
    let element = |name: &str| -> u64 {
        let Some((_, var)) = module
            .global_variables
            .iter()
            .find(|(_, v)| v.name.as_deref() == Some(name))
        else {
            return 0;
        };
        match module.types[var.ty].inner {
            naga::TypeInner::Array { stride, .. } => u64::from(stride),
            _ => u64::from(layouter[var.ty].size),
        }
    };
    let cost = lodkit::shaders::cost::entry_point_costs(module)
        .into_iter()
        .find(|c| c.name == "select_main")
        .ok_or("select_main")?;
    let (mut always, mut worst) = (0, 0);
    for r in &cost.resources {
        let size = element(&r.resource);
        always += r.always * size;
        worst += (r.always + r.conditional) * size;
    }
    // A settled instance joins one list: its slot's first entry and count are read too.
    let settled = always + element("slot_first") + element("draws");
    let (state, entry) = (element("states"), element("entries"));
    let count = element("draws");
    Ok((
        (settled, worst),
        (state + entry + count, state + 2 * (entry + count)),
    ))
}
