//! GPU-driven LOD selection in a wgpu frame loop, headless: a field of 102,400 instances whose
//! levels, hysteresis, timed transitions and frustum culling are decided on the GPU
//! (`GpuLodSelector`, the rule of `lodkit::select`), drawn through the indirect arguments it
//! writes, with complementary screen-door transitions (`lodkit::screen_door`). The CPU selects
//! nothing and reads nothing back while the frames run.
//!
//! Each frame:
//! 1. `GpuLodSelector::record`: one dispatch that updates every instance's state and fills one
//!    instance list and `DrawIndexedIndirectArgs` per level;
//! 2. one `draw_indexed_indirect` per level, whose vertex stage reads `entries[instance_index]`
//!    (the instance and its screen-door alpha) and whose fragment stage keeps the pixels the
//!    alpha gives that level.
//!
//! `cargo run --example gpu_select -- [--out DIR] [--frames N]`
//! Writes DIR/gpu_select.png (default DIR: lodkit-out): frames of the flight side by side; level
//! 0 green, 1 blue, 2 orange, and dithered mixes of two where a transition runs. The last frame's
//! per-level counts are read back once, after the loop, and printed.
//!
//! The selection's throughput against `select_batch` and the bytes it moves per instance are in
//! the demo's report (`lodkit demo`, section "GPU LOD selection").

use std::error::Error;

use glam::Vec3;
use lodkit::gpu::GpuContext;
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::buffer_with_data;
use lodkit::gpu::select::{
    GpuLodInstance, GpuLodSelector, GpuLodSelectorDescriptor, GpuSelectFrame, LevelMesh,
};
use lodkit::select::{LodCamera, LodGroup, LodSettings, TransitionMode};
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary, SourceLanguage};
use lodkit_scenes::mesh::{MESH_VERTEX_LAYOUT, Mesh, RenderTarget};

const SIZE: (u32, u32) = (320, 180);
const SIDE: usize = 320; // 320 x 320 = 102,400 instances
const COLUMNS: usize = 5;

/// The draw shader: an instance from its level's list, dithered by its screen-door alpha.
const DRAW: &str = "#import lodkit::screen_door::screen_door_keep

struct Camera { view_proj: mat4x4<f32>, color: vec4<f32> }
struct Instance { center: vec3<f32>, radius: f32, max_scale: f32, group: u32, pad_a: u32, pad_b: u32 }
struct Entry { instance: u32, flags: u32, transition: f32, alpha: f32 }

@group(0) @binding(0) var<storage, read> instances: array<Instance>;
@group(1) @binding(0) var<uniform> camera: Camera;
@group(1) @binding(1) var<storage, read> entries: array<Entry>;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) @interpolate(flat) alpha: f32,
}

@vertex
fn vs_main(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>, @builtin(instance_index) k: u32) -> VertexOut {
    let e = entries[k];
    let inst = instances[e.instance];
    var out: VertexOut;
    out.position = camera.view_proj * vec4<f32>(inst.center + p * inst.radius, 1.0);
    out.normal = n;
    out.alpha = e.alpha;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (!screen_door_keep(in.position.xy, in.alpha)) {
        discard;
    }
    let light = max(dot(normalize(in.normal), normalize(vec3<f32>(0.4, 0.8, 0.5))), 0.0);
    return vec4<f32>(camera.color.rgb * (0.3 + 0.7 * light), 1.0);
}
";

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| args.iter().skip_while(|a| *a != name).nth(1).cloned();
    let out = arg("--out").unwrap_or_else(|| "lodkit-out".into());
    let frames: u32 = arg("--frames").map_or(Ok(48), |f| f.parse())?;
    let gpu = GpuContext::new_headless(&Default::default())?;
    println!("adapter: {}", gpu.adapter_summary());

    // One group, three levels from view-normalized distances 0, 10 and 30; hidden beyond 120
    // (fading over the last 3), timed transitions of 0.3 s.
    let levels = [Mesh::sphere(8, 16), Mesh::sphere(4, 8), Mesh::sphere(2, 4)];
    let colors = [
        [0.2, 0.8, 0.3, 1.0],
        [0.2, 0.5, 1.0, 1.0],
        [1.0, 0.55, 0.1, 1.0],
    ];
    let group = LodGroup::from_distances(&[0.0, 10.0, 30.0])?.with_max_distance(120.0)?;
    let settings = LodSettings {
        hysteresis: 3.0,
        transition: TransitionMode::Time { seconds: 0.3 },
        ..Default::default()
    };
    let meshes: Vec<LevelMesh> = levels
        .iter()
        .map(|m| LevelMesh {
            index_count: m.indices.len() as u32,
            ..Default::default()
        })
        .collect();
    let mut selector = GpuLodSelector::new(
        &gpu,
        &GpuLodSelectorDescriptor {
            groups: std::slice::from_ref(&group),
            settings,
            meshes: &[&meshes],
        },
    )?;
    let instances: Vec<GpuLodInstance> = (0..SIDE * SIDE)
        .map(|i| {
            let (x, z) = ((i % SIDE) as f32, (i / SIDE) as f32);
            let center = Vec3::new(x * 2.0 - SIDE as f32, 0.5, -z * 2.0);
            GpuLodInstance::new(center, 0.6, 1.0, 0)
        })
        .collect();
    selector.set_instances(&gpu, &instances)?;
    let view = selector.add_view(&gpu)?;
    println!("{} instances, {} levels", instances.len(), levels.len());

    let target = RenderTarget::new(&gpu, SIZE.0, SIZE.1)?;
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let proj = glam::camera::rh::proj::directx::perspective(1.0, aspect, 0.1, 500.0);
    let drawing = draw_pipeline(&gpu, &levels, &instances)?;
    // Per level: its camera-and-color uniform and its list, bound at the list's offset.
    let uniforms: Vec<wgpu::Buffer> = colors
        .iter()
        .map(|_| lodkit::gpu::resources::uniform_buffer(&gpu, 80, "camera"))
        .collect::<Result<_, _>>()?;
    // One bind group per list: a list is a (group, level) slot of one chunk of instances (one
    // chunk unless a storage binding cannot hold them all), bound from its chunk's entries.
    let slot_groups: Vec<Option<wgpu::BindGroup>> = selector
        .slots()
        .iter()
        .map(|slot| {
            let uniform = &uniforms[slot.slot as usize];
            let entries = selector.entries_buffer(view, slot.chunk)?;
            (slot.capacity > 0).then(|| {
                gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("level"),
                    layout: &drawing.level_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: uniform.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                buffer: entries,
                                offset: slot.entries_offset,
                                size: wgpu::BufferSize::new(u64::from(slot.capacity) * 16),
                            }),
                        },
                    ],
                })
            })
        })
        .collect();

    let mut strip_frames = Vec::new();
    for frame in 0..frames {
        // The camera flies over the field and turns a little.
        let t = frame as f32 / frames.max(2) as f32;
        let eye = Vec3::new(-10.0 + 20.0 * t, 3.0, -10.0 - 30.0 * t);
        let yaw = 0.6 * t - 0.3;
        let look = eye + Vec3::new(yaw.sin(), -0.25, -yaw.cos());
        let view_proj = proj * glam::camera::rh::view::look_at_mat4(eye, look, Vec3::Y);
        for (uniform, color) in uniforms.iter().zip(colors) {
            let mut bytes = view_proj.to_cols_array().to_vec();
            bytes.extend(color);
            gpu.queue
                .write_buffer(uniform, 0, bytemuck::cast_slice(&bytes));
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let select = GpuSelectFrame {
            camera: LodCamera::new(eye, proj),
            view_proj: Some(view_proj),
            dt: 1.0 / 30.0,
            frame,
            frame_sequential: false,
        };
        selector.record(&gpu, &mut encoder, view, &select)?;
        draw(
            &mut encoder,
            &target,
            &drawing,
            &slot_groups,
            &selector,
            view,
        )?;
        gpu.queue.submit([encoder.finish()]);
        let last = frames.saturating_sub(1) as usize;
        let sample = (0..COLUMNS).any(|k| k * last / (COLUMNS - 1) == frame as usize);
        if sample {
            strip_frames.push(read_texture_rgba8(&gpu, &target.color)?);
        }
    }
    // After the loop: what the last frame drew, read back once.
    let got = selector.read_back(&gpu, view)?;
    let counts: Vec<usize> = got.lists.iter().map(Vec::len).collect();
    println!("last frame: instances per level {counts:?}");
    write_strip(&out, &strip_frames)
}

/// What the draws need besides the selector's buffers.
struct Drawing {
    pipeline: wgpu::RenderPipeline,
    /// Each level's vertex and index buffers.
    meshes: Vec<(wgpu::Buffer, wgpu::Buffer)>,
    /// Layout of a level's bind group (camera and color, its list).
    level_layout: wgpu::BindGroupLayout,
    /// The instances, as the selector reads them.
    instances: wgpu::BindGroup,
}

/// The draw pipeline, each level's buffers and the instances' bind group.
fn draw_pipeline(
    gpu: &GpuContext,
    levels: &[Mesh],
    instances: &[GpuLodInstance],
) -> Result<Drawing, Box<dyn Error>> {
    let composed = ShaderLibrary::new()?.compose(&ComposeDescriptor {
        source: DRAW,
        file_path: "gpu_select_draw.wgsl",
        language: SourceLanguage::Wgsl,
        shader_defs: Default::default(),
    })?;
    let module = gpu.shader_module("gpu_select draw", &composed)?;
    let storage = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let instances_layout = gpu
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("instances"),
            entries: &[storage(0)],
        });
    let mut uniform = lodkit::gpu::resources::uniform_entry(0, false);
    uniform.visibility = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let level_layout = gpu
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("level"),
            entries: &[uniform, storage(1)],
        });
    let layout = gpu
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gpu_select draw"),
            bind_group_layouts: &[Some(&instances_layout), Some(&level_layout)],
            immediate_size: 0,
        });
    let pipeline = gpu
        .device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gpu_select draw"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(MESH_VERTEX_LAYOUT)],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(lodkit_scenes::mesh::COLOR_FORMAT.into())],
            }),
            primitive: wgpu::PrimitiveState {
                cull_mode: Some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: lodkit_scenes::mesh::DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
    let mut buffers = Vec::new();
    for mesh in levels {
        let v = buffer_with_data(
            gpu,
            bytemuck::cast_slice(&mesh.vertices),
            wgpu::BufferUsages::VERTEX,
            "vertices",
        )?;
        let i = buffer_with_data(
            gpu,
            bytemuck::cast_slice(&mesh.indices),
            wgpu::BufferUsages::INDEX,
            "indices",
        )?;
        buffers.push((v, i));
    }
    let instance_buffer = buffer_with_data(
        gpu,
        bytemuck::cast_slice(instances),
        wgpu::BufferUsages::STORAGE,
        "instances",
    )?;
    let instances = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("instances"),
        layout: &instances_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: instance_buffer.as_entire_binding(),
        }],
    });
    Ok(Drawing {
        pipeline,
        meshes: buffers,
        level_layout,
        instances,
    })
}

/// Clears the target and draws every level through its indirect arguments.
fn draw(
    encoder: &mut wgpu::CommandEncoder,
    target: &RenderTarget,
    drawing: &Drawing,
    slot_groups: &[Option<wgpu::BindGroup>],
    selector: &GpuLodSelector,
    view: lodkit::gpu::select::ViewId,
) -> Result<(), Box<dyn Error>> {
    let color = target.color.create_view(&Default::default());
    let depth = target.depth.create_view(&Default::default());
    let draws = selector.draws_buffer(view).ok_or("view")?;
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("gpu_select draw"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: 0.55,
                    g: 0.7,
                    b: 0.85,
                    a: 1.0,
                }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(&drawing.pipeline);
    pass.set_bind_group(0, &drawing.instances, &[]);
    for (slot, group) in selector.slots().iter().zip(slot_groups) {
        let Some(group) = group else { continue };
        let (vertices, indices) = &drawing.meshes[slot.slot as usize];
        pass.set_bind_group(1, group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed_indirect(draws, slot.draw_offset);
    }
    Ok(())
}

/// Writes the sampled frames side by side.
fn write_strip(out: &str, frames: &[Vec<u8>]) -> Result<(), Box<dyn Error>> {
    let (w, h) = SIZE;
    let mut strip = image::RgbaImage::new(w * frames.len().max(1) as u32, h);
    for (x, pixels) in frames.iter().enumerate() {
        let tile = image::RgbaImage::from_raw(w, h, pixels.clone()).ok_or("tile size")?;
        image::imageops::replace(&mut strip, &tile, i64::from(w) * x as i64, 0);
    }
    std::fs::create_dir_all(out)?;
    let path = std::path::Path::new(out).join("gpu_select.png");
    strip.save(&path)?;
    println!("wrote {}", path.display());
    Ok(())
}
