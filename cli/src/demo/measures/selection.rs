//! GPU LOD selection measured (`GpuLodSelector`, the compute pass
//! `passes/select.wgsl`) against `select_batch` on one core, in the same run, over the same
//! instances and camera path; the bytes the pass moves per instance, counted from the shader;
//! and what a GPU at a stated memory bandwidth would take, on paper.

use std::time::Instant;

use glam::Vec3;
use lodkit::gpu::GpuContext;
use lodkit::gpu::select::{
    GpuLodGroup, GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectFrame,
};
use lodkit::select::{
    InstanceBatch, LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode,
    select_batch,
};
use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::fixtures::clock::{Clock, Timer};

/// Instance counts measured.
pub const SIZES: [usize; 3] = [10_000, 100_000, 1_000_000];
/// The memory bandwidth the figure on paper assumes, bytes per second.
pub const BANDWIDTH: f64 = 400e9;
/// Untimed frames before the timed ones, per size and selector.
pub const WARMUP_FRAMES: u32 = 2;

/// One instance count.
#[derive(Clone, Debug, Serialize)]
pub struct SelectionRow {
    /// Instances selected per frame.
    pub instances: usize,
    /// Instances per second of the GPU selection (the count reset and the dispatches) on the
    /// report's clock: GPU timestamps around a run of frames where the device has them.
    pub gpu_per_second: f64,
    /// Instances per second on the wall clock: one frame recorded, submitted and waited for.
    /// Where the timestamps do not bracket compute work (lavapipe's read a few microseconds
    /// whatever the dispatch), this is the figure to read.
    pub wall_per_second: f64,
    /// Instances per second of `select_batch` on one core.
    pub cpu_per_second: f64,
}

/// The selection section.
#[derive(Clone, Debug, Serialize)]
pub struct SelectionReport {
    /// Timed frames per size and selector.
    pub frames: u32,
    /// The clock of `gpu_per_second`.
    pub clock: Clock,
    /// One row per instance count.
    pub rows: Vec<SelectionRow>,
    /// Bytes the pass reads per instance: (settled instance, at most).
    pub bytes_read: (u64, u64),
    /// Bytes the pass writes per instance: (settled instance, one in transition).
    pub bytes_written: (u64, u64),
    /// Bytes of the reads that are the group table (few groups: it stays in cache).
    pub group_table_bytes: u64,
    /// The bandwidth assumed on paper, bytes per second.
    pub bandwidth: f64,
    /// Instances per second at that bandwidth, from memory traffic alone, the group table in
    /// cache: (the most bytes, the fewest).
    pub bandwidth_bound: (f64, f64),
}

/// Measures the selectors with `frames` timed frames per instance count of `sizes`.
pub fn measure(
    gpu: &GpuContext,
    timer: &Timer,
    frames: u32,
    sizes: &[usize],
) -> Result<SelectionReport, DemoError> {
    let internal = |e: &dyn std::fmt::Display| DemoError::Internal(format!("selection: {e}"));
    let groups = [
        LodGroup::from_distances(&[0.0, 10.0, 30.0])
            .and_then(|g| g.with_max_distance(400.0))
            .map_err(|e| internal(&e))?,
        LodGroup::from_distances(&[0.0, 5.0, 15.0, 40.0]).map_err(|e| internal(&e))?,
    ];
    let settings = LodSettings {
        hysteresis: 3.0,
        transition: TransitionMode::Time { seconds: 0.3 },
        ..Default::default()
    };
    let (read, written) = bytes_per_instance()?;
    let group_table_bytes = std::mem::size_of::<GpuLodGroup>() as u64;
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.6, 0.1, 2000.0);
    let camera = |f: u32| {
        let eye = Vec3::new(0.0, 3.0, -(f as f32) * 1.5);
        let look = glam::camera::rh::view::look_at_mat4(eye, eye - Vec3::Z, Vec3::Y);
        (LodCamera::new(eye, proj), proj * look)
    };
    let mut rows = Vec::new();
    for &n in sizes {
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
        let descriptor = GpuLodSelectorDescriptor {
            groups: &groups,
            settings,
            meshes: &[],
        };
        let mut selector = GpuLodSelector::new(gpu, &descriptor)?;
        selector.set_instances(gpu, &instances)?;
        let view = selector.add_view(gpu)?;
        let (mut gpu_time, mut wall_time) = (0.0, 0.0);
        for f in 0..frames + WARMUP_FRAMES {
            let (cam, view_proj) = camera(f);
            let frame = GpuSelectFrame {
                camera: cam,
                view_proj: Some(view_proj),
                dt: 1.0 / 60.0,
                frame: f,
                frame_sequential: false,
            };
            // On the timer's clock: a run of recordings of this frame's selection.
            let ms = timer.time(gpu, &|e| selector.record(gpu, e, view, &frame))?;
            // On the wall clock: the frame recorded, submitted and waited for.
            let start = Instant::now();
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            selector.record(gpu, &mut encoder, view, &frame)?;
            gpu.queue.submit([encoder.finish()]);
            gpu.wait_idle()?;
            if f >= WARMUP_FRAMES {
                gpu_time += ms * 1e-3;
                wall_time += start.elapsed().as_secs_f64();
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
        for f in 0..frames + WARMUP_FRAMES {
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
            )
            .map_err(|e| internal(&e))?;
            if f >= WARMUP_FRAMES {
                cpu_time += start.elapsed().as_secs_f64();
            }
        }
        let rate = |t: f64| n as f64 * f64::from(frames) / t.max(1e-9);
        rows.push(SelectionRow {
            instances: n,
            gpu_per_second: rate(gpu_time),
            wall_per_second: rate(wall_time),
            cpu_per_second: rate(cpu_time),
        });
    }
    let bound = |bytes: u64| BANDWIDTH / bytes.saturating_sub(group_table_bytes).max(1) as f64;
    Ok(SelectionReport {
        frames,
        clock: timer.clock(),
        rows,
        bytes_read: read,
        bytes_written: written,
        group_table_bytes,
        bandwidth: BANDWIDTH,
        bandwidth_bound: (bound(read.1 + written.1), bound(read.0 + written.0)),
    })
}

/// (settled, at most) bytes, read or written per instance.
type Span = (u64, u64);

/// Bytes the selection pass reads per instance (settled: the main path; at most: every branch),
/// counted from the shader: each storage read `lodkit::shaders::cost` finds, times the size of
/// the element it loads; and bytes it writes: the state, and per list entry the entry and its
/// atomic count (sizes from naga's layouter).
fn bytes_per_instance() -> Result<(Span, Span), DemoError> {
    let internal = |e: &dyn std::fmt::Display| DemoError::Internal(format!("select.wgsl: {e}"));
    let composed = lodkit::shaders::compose_pass("select", &[]).map_err(|e| internal(&e))?;
    let module = &composed.module;
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).map_err(|e| internal(&e))?;
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
        .ok_or_else(|| internal(&"no entry point select_main"))?;
    let (mut always, mut worst) = (0, 0);
    for r in &cost.resources {
        let size = element(&r.resource);
        always += r.always * size;
        worst += (r.always + r.conditional) * size;
    }
    // A settled instance joins one list: its slot's first entry and count are read too.
    let settled = always + element("slot_first") + element("draws");
    let (state, entry, count) = (element("states"), element("entries"), element("draws"));
    Ok((
        (settled, worst),
        (state + entry + count, state + 2 * (entry + count)),
    ))
}
