//! GPU cost of the frame-sequential combine pass against a plain fullscreen pass that reads the
//! same four textures (two colors, two id/depth) and writes one: the pass's own overhead.
//! Wall time per pass including submit and wait, so read the ratio, not the absolute figures,
//! on a software GPU.
//!
//! `cargo bench --bench combine`

use criterion::{Criterion, criterion_group, criterion_main};

use glam::{Mat4, Vec3, Vec4};
use lodkit::gpu::frame_sequential::{CombinePass, LodBuffers};
use lodkit::gpu::lod_buffer_scene::{LodBufferRenderer, LodDrawItem};
use lodkit::gpu::resources::{begin_color_pass, fullscreen_pipeline, texture_2d};
use lodkit::gpu::scene::{GpuMesh, Mesh};
use lodkit::gpu::{GpuContext, GpuOptions};
use lodkit::reproject::new_to_old_matrix;
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary};
use lodkit::visibility::{VisibilityPattern, visibility_texture};

const SIZE: u32 = 512;

const COPY4: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
@group(0) @binding(0) var a: texture_2d<f32>;
@group(0) @binding(1) var b: texture_2d<u32>;
@group(0) @binding(2) var c: texture_2d<f32>;
@group(0) @binding(3) var d: texture_2d<u32>;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let p = vec2<u32>(v.position.xy);
    let ids = textureLoad(b, p, 0).xy ^ textureLoad(d, p, 0).xy;
    return textureLoad(a, p, 0) + textureLoad(c, p, 0) + vec4<f32>(f32(ids.x & 1u), f32(ids.y & 1u), 0.0, 0.0);
}
";

fn benches(c: &mut Criterion) {
    let gpu = match GpuContext::new_headless(&GpuOptions::default()) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("combine bench skipped: {e}");
            return;
        }
    };
    eprintln!("adapter: {}", gpu.adapter_summary());
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let buffers = LodBuffers::new(&gpu, SIZE, SIZE, format);
    let renderer = LodBufferRenderer::new(
        &gpu,
        format,
        &visibility_texture(VisibilityPattern::WhiteNoise, 64, 1),
        0.25,
    )
    .unwrap();
    let meshes = [
        GpuMesh::new(&gpu, &Mesh::sphere(16, 24)),
        GpuMesh::new(&gpu, &Mesh::cube()),
    ];
    let proj = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 100.0);
    let views = [0.0f32, 0.1]
        .map(|x| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 3.0, 7.0), Vec3::ZERO, Vec3::Y));
    for (i, view) in views.iter().enumerate() {
        let items: Vec<LodDrawItem> = (0..15)
            .map(|k| LodDrawItem {
                mesh: &meshes[(k + i) % 2],
                model: Mat4::from_translation(Vec3::new(
                    (k % 5) as f32 * 2.0 - 4.0,
                    0.0,
                    -((k / 5) as f32) * 2.0,
                )),
                color: Vec4::new(0.8, 0.2, 0.2, 1.0),
                id: if k % 3 == 0 { k as u32 + 1 } else { 0 },
                tau: if k % 3 == 0 { 0.5 } else { 1.0 },
            })
            .collect();
        renderer.render(&gpu, &buffers, i, proj * *view, &items, wgpu::Color::BLACK);
    }
    let target = texture_2d(
        &gpu,
        (SIZE, SIZE),
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
        "target",
    );
    let target_view = target.create_view(&Default::default());
    let combine = CombinePass::new(&gpu, format, false).unwrap();
    let m = new_to_old_matrix(&views[1], &proj, &views[0], &proj);

    let composed = ShaderLibrary::new()
        .unwrap()
        .compose(&ComposeDescriptor {
            source: COPY4,
            file_path: "copy4.wgsl",
            ..Default::default()
        })
        .unwrap();
    let module = gpu.shader_module("copy4", &composed);
    let copy4 = fullscreen_pipeline(&gpu, &module, format, "copy4");
    let views4 = [
        buffers.color(1),
        buffers.id_depth(1),
        buffers.color(0),
        buffers.id_depth(0),
    ]
    .map(|t| t.create_view(&Default::default()));
    let entries: Vec<wgpu::BindGroupEntry> = views4
        .iter()
        .enumerate()
        .map(|(i, v)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: wgpu::BindingResource::TextureView(v),
        })
        .collect();
    let copy_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &copy4.get_bind_group_layout(0),
        entries: &entries,
    });

    let run_combine = || {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        combine.encode(&gpu, &mut encoder, &buffers, 1, m, &target_view);
        gpu.queue.submit([encoder.finish()]);
        gpu.wait_idle();
    };
    let run_copy = || {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass =
                begin_color_pass(&mut encoder, &target_view, wgpu::Color::BLACK, "copy4");
            pass.set_pipeline(&copy4);
            pass.set_bind_group(0, &copy_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
        gpu.wait_idle();
    };
    // Interleaved pairs (alternating which goes first), so machine noise hits both alike; the
    // figure to read is the median of the per-pair ratios.
    let time = |f: &dyn Fn()| {
        let t = std::time::Instant::now();
        f();
        t.elapsed().as_secs_f64() * 1e3
    };
    for _ in 0..10 {
        run_combine();
        run_copy();
    }
    let (mut a, mut b, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..PAIRS {
        let (tc, tp) = if i % 2 == 0 {
            let tc = time(&run_combine);
            (tc, time(&run_copy))
        } else {
            let tp = time(&run_copy);
            (time(&run_combine), tp)
        };
        a.push(tc);
        b.push(tp);
        ratio.push(tc / tp);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!(
        "fullscreen passes at {SIZE}x{SIZE}, {PAIRS} interleaved pairs, wall time per pass incl. submit + wait"
    );
    println!("| pass | median ms |");
    println!("|---|---|");
    println!("| combine (lodkit) | {:.3} |", median(&mut a));
    println!(
        "| plain copy of the same 4 textures | {:.3} |",
        median(&mut b)
    );
    println!("median combine / copy ratio: {:.3}", median(&mut ratio));
    let _ = c;
}

const PAIRS: usize = 200;

criterion_group!(combine_benches, benches);
criterion_main!(combine_benches);
