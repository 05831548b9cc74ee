//! Host time of one recording: lodkit's `CombinePass::record` (its default route: the frame's
//! `CombineData::depth_pass` uploaded with it, the older-level depth pass bound), `UpsamplePass::record` and `GpuLodSelector::record`, each
//! against a plain wgpu pass an engine writes by hand around lodkit's pass shader, with the same
//! bindings and the same uploads (its parameters with `queue.write_buffer`, the combine's data
//! with `queue.write_texture`, its bind group made once), drawing the same full-screen triangle
//! into the same target (the selection: resetting the same counts and dispatching the same
//! workgroups over the same instances). Only the recording is timed: the
//! encoder is made before, submitted after and waited for (so that a software GPU's drawing does
//! not share the cores with the next recording), outside the clock.
//!
//! ```text
//! cargo bench -p lodkit-cli --bench record            # every pass; the table at the end
//! cargo bench -p lodkit-cli --bench record -- combine # criterion's part for one
//! ```
//!
//! After criterion's own lines it prints a table: per pass, the median host time of a recording
//! on each side over 200 recordings each, the two sides taking turns in one loop (so both see
//! the same machine), and their ratio (docs/benchmarks.md has it). Without a GPU adapter it says
//! so and times nothing.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::Criterion;
use glam::Mat4;
use lodkit::combine_coverage::{CombineData, DepthPassFrame, OlderDepth};
use lodkit::gpu::GpuContext;
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions, LodBuffers,
};
use lodkit::gpu::framebuffer_lod::{
    LowResBuffer, UpsampleFrame, UpsamplePass, UpsamplePassDescriptor, UpsampleSettings,
};
use lodkit::gpu::resources::{
    begin_color_pass, buffer_with_data, buffers_bind_group, fullscreen_pipeline_with,
    one_group_layout, texture_2d, texture_entry, uniform_buffer, uniform_entry,
};
use lodkit::gpu::select::{
    GpuLodGroup, GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectCamera,
    GpuSelectChunk, GpuSelectFrame,
};
use lodkit::select::{LodCamera, LodGroup, LodSettings, LodState, distance_kind, frustum_planes};

const W: u32 = 320;
const H: u32 = 180;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// A plain pass: lodkit's pass shader (`shader_lib/passes/<name>.wgsl`, as an engine that
/// writes the pass itself around lodkit's module would), its pipeline over `entries`, and the
/// bind group an engine makes once. The GPU draws the same as lodkit's pass: on a software GPU
/// the two sides' recordings then follow the same work on the same cores.
struct Plain {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
}

impl Plain {
    fn new(
        gpu: &GpuContext,
        (name, defs): (&str, &[&str]),
        entries: &[wgpu::BindGroupLayoutEntry],
        bind: &[Bound],
    ) -> Self {
        let device = &gpu.device;
        let (layout, pipeline_layout) = one_group_layout(gpu, entries, "plain");
        let module = gpu.pass_module(name, defs).expect("the pass module");
        let pipeline =
            fullscreen_pipeline_with(gpu, &module, FORMAT, Some(&pipeline_layout), "plain")
                .expect("the plain pipeline");
        let views: Vec<Option<wgpu::TextureView>> = bind
            .iter()
            .map(|b| match b {
                Bound::Texture(t) => Some(t.create_view(&Default::default())),
                Bound::Buffer(_) => None,
            })
            .collect();
        let group_entries: Vec<wgpu::BindGroupEntry> = entries
            .iter()
            .zip(bind.iter().zip(&views))
            .map(|(entry, (b, view))| wgpu::BindGroupEntry {
                binding: entry.binding,
                resource: match (b, view) {
                    (_, Some(view)) => wgpu::BindingResource::TextureView(view),
                    (Bound::Buffer(buffer), None) => buffer.as_entire_binding(),
                    (Bound::Texture(_), None) => unreachable!("a texture has a view"),
                },
            })
            .collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("plain"),
            layout: &layout,
            entries: &group_entries,
        });
        Self { pipeline, group }
    }

    /// The pass itself: what lodkit's recording also records.
    fn draw(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView) {
        let mut pass = begin_color_pass(encoder, target, wgpu::Color::BLACK, "plain");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// What a plain pass binds at each of its entries.
enum Bound<'a> {
    Texture(&'a wgpu::Texture),
    Buffer(&'a wgpu::Buffer),
}

/// The host time of one recording into a fresh encoder; the encoder is submitted and waited
/// for after the clock stops.
fn once(gpu: &GpuContext, record: &mut dyn FnMut(&mut wgpu::CommandEncoder)) -> Duration {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let start = Instant::now();
    record(&mut encoder);
    let spent = start.elapsed();
    gpu.queue.submit([encoder.finish()]);
    // The GPU's work is done before the next recording: on a software GPU (lavapipe) it runs on
    // the same cores and would slow the next recording by what it draws, which is not host
    // cost. Waiting also polls, as a frame loop does: the staging memory of finished work comes
    // back for reuse.
    gpu.wait_idle().expect("the device");
    spent
}

/// Criterion's timing of `record`.
fn time(
    gpu: &GpuContext,
    iters: u64,
    record: &mut dyn FnMut(&mut wgpu::CommandEncoder),
) -> Duration {
    (0..iters).map(|_| once(gpu, record)).sum()
}

/// Recordings per side in the table.
const TABLE_RECORDINGS: usize = 200;

/// The median host time (µs) of each side's recording, the sides taking turns.
fn medians(gpu: &GpuContext, sides: [&mut dyn FnMut(&mut wgpu::CommandEncoder); 2]) -> [f64; 2] {
    let mut spent = [Vec::new(), Vec::new()];
    let [a, b] = sides;
    for _ in 0..TABLE_RECORDINGS {
        spent[0].push(once(gpu, a).as_secs_f64() * 1e6);
        spent[1].push(once(gpu, b).as_secs_f64() * 1e6);
    }
    spent.map(|mut s| {
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    })
}

/// Times `lodkit` and `plain` with criterion (group `name`), then takes turns for the table row.
fn compare(
    c: &mut Criterion,
    gpu: &GpuContext,
    name: &str,
    lodkit: &mut dyn FnMut(&mut wgpu::CommandEncoder),
    plain: &mut dyn FnMut(&mut wgpu::CommandEncoder),
) -> String {
    let mut group = c.benchmark_group(name);
    group.bench_function("lodkit", |b| {
        b.iter_custom(|iters| time(gpu, iters, lodkit))
    });
    group.bench_function("plain", |b| b.iter_custom(|iters| time(gpu, iters, plain)));
    group.finish();
    let [l, p] = medians(gpu, [lodkit, plain]);
    format!("| {name} | {l:.1} µs | {p:.1} µs | {:.2}x |", l / p)
}

fn target(gpu: &GpuContext, label: &str) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST;
    texture_2d(gpu, (W, H), FORMAT, usage, label).expect("a target")
}

fn combine(c: &mut Criterion, gpu: &GpuContext) -> String {
    let buffers = LodBuffers::new(gpu, W, H, FORMAT).expect("LOD buffers");
    let pass = CombinePass::new(
        gpu,
        &CombinePassDescriptor {
            target_format: FORMAT,
            ..Default::default()
        },
    )
    .expect("the combine");
    let out = target(gpu, "combine target");
    let view = out.create_view(&Default::default());
    // One object in transition on the default route, the older-level depth pass: one row of
    // data texels.
    let m = Mat4::IDENTITY;
    let objects = [OlderDepth {
        id: 1,
        new_to_old: None,
        older_tau: None,
    }];
    let data = CombineData::depth_pass(&DepthPassFrame {
        new_to_old: m,
        objects: &objects,
        ..Default::default()
    })
    .expect("the data");
    let frame = CombineFrame {
        buffers: &buffers,
        newer: 0,
        new_to_old: m,
        target: &view,
        regions: CombineRegions::Everywhere,
        coverage: CombineCoverage::Known {
            data: &data,
            level_depth: Some(buffers.level_depth()),
            pattern: None,
        },
    };
    // The plain pass: the same eleven bindings (six buffer textures, motion, parameters, data,
    // level depth, pattern), its parameters and data written on the queue.
    let mut entries = CombinePass::buffer_layout_entries(0);
    entries.push(CombinePass::motion_layout_entry(6));
    entries.push(uniform_entry(7, false));
    entries.push(texture_entry(8, wgpu::TextureSampleType::Uint));
    entries.push(CombinePass::motion_layout_entry(9));
    entries.push(CombinePass::motion_layout_entry(10));
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    let data_texture = texture_2d(
        gpu,
        (data.width, data.height),
        wgpu::TextureFormat::Rgba32Uint,
        usage,
        "plain data",
    )
    .expect("a data texture");
    let params = uniform_buffer(gpu, 64, "plain params").expect("a uniform");
    let motion = buffers.motion().expect("a motion target");
    let bind = [
        Bound::Texture(buffers.color(0)),
        Bound::Texture(buffers.id(0)),
        Bound::Texture(buffers.depth(0)),
        Bound::Texture(buffers.color(1)),
        Bound::Texture(buffers.id(1)),
        Bound::Texture(buffers.depth(1)),
        Bound::Texture(motion),
        Bound::Buffer(&params),
        Bound::Texture(&data_texture),
        Bound::Texture(buffers.level_depth()),
        Bound::Texture(motion),
    ];
    let plain = Plain::new(gpu, ("combine", &["LODKIT_COMBINE_KNOWN"]), &entries, &bind);
    compare(
        c,
        gpu,
        "combine",
        &mut |encoder| {
            black_box(pass.record(gpu, encoder, &frame)).expect("a recording");
        },
        &mut |encoder| {
            gpu.queue
                .write_buffer(&params, 0, bytemuck::bytes_of(&m.to_cols_array()));
            gpu.queue.write_texture(
                data_texture.as_image_copy(),
                bytemuck::cast_slice(&data.texels),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(data.width * 16),
                    rows_per_image: Some(data.height),
                },
                data_texture.size(),
            );
            plain.draw(encoder, &view);
        },
    )
}

fn upsample(c: &mut Criterion, gpu: &GpuContext) -> String {
    let low = LowResBuffer::new(gpu, W, H, FORMAT).expect("L");
    let full = LowResBuffer::new(gpu, W, H, FORMAT).expect("the full-resolution geometry");
    let pass = UpsamplePass::new(
        gpu,
        &UpsamplePassDescriptor {
            target_format: FORMAT,
            ..Default::default()
        },
    )
    .expect("the upsample");
    let out = target(gpu, "upsample target");
    let view = out.create_view(&Default::default());
    let frame = UpsampleFrame {
        low: &low,
        full_geometry: full.geometry(),
        full_albedo: None,
        target: &view,
        settings: UpsampleSettings::default(),
    };
    let float = wgpu::TextureSampleType::Float { filterable: false };
    let entries = [
        texture_entry(0, float),
        texture_entry(1, float),
        texture_entry(2, float),
        uniform_entry(3, false),
    ];
    let params = uniform_buffer(gpu, 32, "plain params").expect("a uniform");
    let bind = [
        Bound::Texture(low.color()),
        Bound::Texture(low.geometry()),
        Bound::Texture(full.geometry()),
        Bound::Buffer(&params),
    ];
    let plain = Plain::new(gpu, ("upsample", &[]), &entries, &bind);
    compare(
        c,
        gpu,
        "upsample",
        &mut |encoder| {
            black_box(pass.record(gpu, encoder, &frame)).expect("a recording");
        },
        &mut |encoder| {
            gpu.queue.write_buffer(&params, 0, &[0u8; 32]);
            plain.draw(encoder, &view);
        },
    )
}

/// Instances the selection selects (one chunk: one dispatch).
const SELECT_INSTANCES: usize = 10_000;
/// Its workgroup size (`passes/select.wgsl`).
const SELECT_WORKGROUP: u32 = 64;
/// Bytes of one slot's indirect draw arguments.
const DRAW_BYTES: usize = 20;
/// Bytes of one list entry.
const ENTRY_BYTES: usize = 16;

fn select(c: &mut Criterion, gpu: &GpuContext) -> String {
    let groups = [
        LodGroup::from_distances(&[0.0, 10.0, 30.0]).expect("a group"),
        LodGroup::from_distances(&[0.0, 5.0, 15.0, 40.0]).expect("a group"),
    ];
    let slots: u32 = groups.iter().map(|g| g.levels().len() as u32).sum();
    let side = (SELECT_INSTANCES as f32).sqrt().ceil() as usize;
    let instances: Vec<GpuLodInstance> = (0..SELECT_INSTANCES)
        .map(|i| {
            let at = glam::Vec3::new((i % side) as f32 * 2.0, 0.5, -((i / side) as f32) * 2.0);
            GpuLodInstance::new(at, 0.6, 1.0, (i % 2) as u32)
        })
        .collect();
    let mut selector = GpuLodSelector::new(
        gpu,
        &GpuLodSelectorDescriptor {
            groups: &groups,
            settings: LodSettings::default(),
            meshes: &[],
        },
    )
    .expect("the selector");
    selector
        .set_instances(gpu, &instances)
        .expect("the instances");
    let view = selector.add_view(gpu).expect("a view");
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 1.6, 0.1, 2000.0);
    let eye = glam::Vec3::new(0.0, 3.0, 5.0);
    let look = glam::camera::rh::view::look_at_mat4(eye, eye - glam::Vec3::Z, glam::Vec3::Y);
    let frame = GpuSelectFrame {
        camera: LodCamera::new(eye, proj),
        view_proj: Some(proj * look),
        dt: 1.0 / 60.0,
        frame: 0,
        frame_sequential: false,
    };
    // The plain pass: lodkit's select shader in a compute pipeline of the engine's, its eight
    // buffers (camera, groups, instances, slot starts, states, counts, lists, chunk) filled by
    // the engine with lodkit's math (`select_data`, `distance_kind`, `select_mode`,
    // `frustum_planes`) and bound once, the counts reset from a template by a copy, as lodkit's
    // recording does. Its data is lodkit's, so the GPU does the same work on both sides: on a
    // software GPU the work a recording follows (same cores, same caches) changes its host time.
    let device = &gpu.device;
    let module = gpu.pass_module("select", &[]).expect("the pass module");
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("plain select"),
        layout: None,
        module: &module,
        entry_point: None,
        compilation_options: Default::default(),
        cache: None,
    });
    let settings = LodSettings::default();
    let mut table = Vec::new();
    let mut firsts = Vec::new();
    let mut entries = 0u32;
    for (g, group) in groups.iter().enumerate() {
        let data = group
            .select_data(settings.hysteresis)
            .expect("at most 8 levels");
        table.push(GpuLodGroup::new(&data, firsts.len() as u32));
        let members = instances.iter().filter(|i| i.group == g as u32).count() as u32;
        for _ in 0..data.level_count {
            firsts.push(entries);
            entries += members;
        }
    }
    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
    let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
    let filled = |bytes: &[u8], usage: wgpu::BufferUsages, label: &str| {
        buffer_with_data(gpu, bytes, usage, label).expect("a buffer")
    };
    let states = vec![[LodState::NEW.packed(), 0u32]; SELECT_INSTANCES];
    let counts = vec![0u8; slots as usize * DRAW_BYTES];
    let chunk = GpuSelectChunk {
        first_instance: 0,
        count: SELECT_INSTANCES as u32,
        draw_base: 0,
        pad: 0,
    };
    let bound = [
        filled(&[0; size_of::<GpuSelectCamera>()], uniform, "plain camera"),
        filled(bytemuck::cast_slice(&table), storage, "plain groups"),
        filled(bytemuck::cast_slice(&instances), storage, "plain instances"),
        filled(bytemuck::cast_slice(&firsts), storage, "plain slot starts"),
        filled(bytemuck::cast_slice(&states), storage, "plain states"),
        filled(
            &counts,
            storage | wgpu::BufferUsages::INDIRECT,
            "plain counts",
        ),
        filled(
            &vec![0u8; entries as usize * ENTRY_BYTES],
            storage,
            "plain lists",
        ),
        filled(bytemuck::bytes_of(&chunk), uniform, "plain chunk"),
    ];
    let template = filled(&counts, wgpu::BufferUsages::COPY_SRC, "plain template");
    let group = buffers_bind_group(
        device,
        &pipeline.get_bind_group_layout(0),
        &bound.each_ref(),
        "plain select",
    );
    let (distance_kind, factor) = distance_kind(&frame.camera, &settings);
    let (mode, step) = settings.select_mode(frame.dt);
    let camera_bytes = GpuSelectCamera {
        planes: frustum_planes(&(proj * look)).map(|p| p.to_array()),
        position: eye.to_array(),
        factor,
        distance_kind,
        mode,
        step,
        frame: frame.frame,
        instance_count: SELECT_INSTANCES as u32,
        group_count: groups.len() as u32,
        frame_sequential: 0,
        cull: 1,
    };
    let workgroups = (SELECT_INSTANCES as u32).div_ceil(SELECT_WORKGROUP);
    compare(
        c,
        gpu,
        "select",
        &mut |encoder| {
            black_box(selector.record(gpu, encoder, view, &frame)).expect("a recording");
        },
        &mut |encoder| {
            gpu.queue
                .write_buffer(&bound[0], 0, bytemuck::bytes_of(&camera_bytes));
            encoder.copy_buffer_to_buffer(&template, 0, &bound[5], 0, template.size());
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(workgroups, 1, 1);
        },
    )
}

fn main() {
    let gpu = match GpuContext::new_headless(&Default::default()) {
        Ok(gpu) => gpu,
        Err(e) => {
            eprintln!("no GPU adapter, nothing timed: {e}");
            return;
        }
    };
    let mut c = Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    let rows = [
        combine(&mut c, &gpu),
        upsample(&mut c, &gpu),
        select(&mut c, &gpu),
    ];
    c.final_summary();
    println!(
        "\nhost time per recording, median of {TABLE_RECORDINGS} each, {}",
        gpu.adapter_summary()
    );
    println!("| pass | lodkit `record` | plain wgpu pass | ratio |");
    println!("|---|---|---|---|");
    for row in rows {
        println!("{row}");
    }
}
