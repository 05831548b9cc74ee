//! Framebuffer LOD on the GPU: the bilateral upsample pass against a plain bilinear upsample pass
//! (hardware-filtered lookup of the same low-res color), and the whole frame (low-res pass +
//! upsample) at r = 1, 2, 4 with the PSNR each reaches, like the paper's Fig. 3. Interleaved
//! wall-time medians including submit and wait: read the ratios on a software GPU.
//!
//! `cargo bench --bench upsample`

use std::time::Instant;

use lodkit::framebuffer_lod::psnr_rgba8;
use lodkit::gpu::framebuffer_lod::{LowResBuffer, UpsamplePass};
use lodkit::gpu::gbuffer_scene::EdgeScene;
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::{begin_color_pass, fullscreen_pipeline, texture_2d};
use lodkit::gpu::{GpuContext, GpuOptions};
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary};

const W: u32 = 640;
const H: u32 = 480;
const ROUNDS: usize = 60;

const BILINEAR: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
struct Scale { uv_scale: vec2<f32>, _pad: vec2<f32> }
@group(0) @binding(0) var low_color: texture_2d<f32>;
@group(0) @binding(1) var low_sampler: sampler;
@group(0) @binding(2) var<uniform> scale: Scale;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    return textureSampleLevel(low_color, low_sampler, v.uv * scale.uv_scale, 0.0);
}
";

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let gpu = match GpuContext::new_headless(&GpuOptions::default()) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("upsample bench skipped: {e}");
            return;
        }
    };
    println!("adapter: {}", gpu.adapter_summary());
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let scene = EdgeScene::new(&gpu, format, W as f32 / H as f32).unwrap();
    let full = LowResBuffer::new(&gpu, W, H, format);
    scene.render(&gpu, &full, 1.0);
    let reference = read_texture_rgba8(&gpu, full.color());
    let low = LowResBuffer::new(&gpu, W, H, format);
    let upsample = UpsamplePass::new(&gpu, format).unwrap();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(&gpu, (W, H), format, usage, "target");
    let view = target.create_view(&Default::default());

    let composed = ShaderLibrary::new()
        .unwrap()
        .compose(&ComposeDescriptor {
            source: BILINEAR,
            file_path: "bilinear.wgsl",
            ..Default::default()
        })
        .unwrap();
    let module = gpu.shader_module("bilinear", &composed);
    let bilinear = fullscreen_pipeline(&gpu, &module, format, "bilinear");
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let scale_buffer = lodkit::gpu::resources::uniform_buffer(&gpu, 16, "scale");
    let low_view = low.color().create_view(&Default::default());
    let bilinear_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &bilinear.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&low_view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: scale_buffer.as_entire_binding(),
            },
        ],
    });
    let time = |f: &dyn Fn()| {
        let t = Instant::now();
        f();
        gpu.wait_idle();
        t.elapsed().as_secs_f64() * 1e3
    };
    let run_bilateral = |r: f32| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        upsample.encode(
            &gpu,
            &mut encoder,
            &low,
            r,
            full.geometry(),
            0.25,
            0.4,
            &view,
        );
        gpu.queue.submit([encoder.finish()]);
    };
    let run_bilinear = |r: f32| {
        let (vw, vh) = low.viewport(r);
        let s = [vw as f32 / W as f32, vh as f32 / H as f32, 0.0, 0.0];
        gpu.queue
            .write_buffer(&scale_buffer, 0, bytemuck::cast_slice(&s));
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = begin_color_pass(&mut encoder, &view, wgpu::Color::BLACK, "bilinear");
            pass.set_pipeline(&bilinear);
            pass.set_bind_group(0, &bilinear_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
    };

    println!("\nupsample passes at {W}x{H} (r = 2), {ROUNDS} interleaved pairs");
    scene.render(&gpu, &low, 2.0);
    let (mut a, mut b, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..ROUNDS + 5 {
        let (ta, tb) = if i % 2 == 0 {
            let ta = time(&|| run_bilateral(2.0));
            (ta, time(&|| run_bilinear(2.0)))
        } else {
            let tb = time(&|| run_bilinear(2.0));
            (time(&|| run_bilateral(2.0)), tb)
        };
        if i >= 5 {
            a.push(ta);
            b.push(tb);
            ratio.push(ta / tb);
        }
    }
    println!("| pass | median ms |\n|---|---|");
    println!("| bilateral upsample (lodkit) | {:.3} |", median(&mut a));
    println!(
        "| bilinear upsample (hardware filter) | {:.3} |",
        median(&mut b)
    );
    println!(
        "median bilateral / bilinear ratio: {:.3}",
        median(&mut ratio)
    );

    println!("\nwhole frame (low-res pass + bilateral upsample) at {W}x{H}, {ROUNDS} rounds");
    println!(
        "| r | median ms | speed-up vs r = 1 | PSNR dB (bilateral) | PSNR dB (bilinear) |\n|---|---|---|---|---|"
    );
    let rs = [1.0f32, 2.0, 4.0];
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); rs.len()];
    for round in 0..ROUNDS + 3 {
        for (k, &r) in rs.iter().enumerate() {
            let t = time(&|| {
                scene.render(&gpu, &low, r);
                run_bilateral(r);
            });
            if round >= 3 {
                times[k].push(t);
            }
        }
    }
    let base = median(&mut times[0].clone());
    for (k, &r) in rs.iter().enumerate() {
        scene.render(&gpu, &low, r);
        run_bilateral(r);
        let p_bilateral = psnr_rgba8(&read_texture_rgba8(&gpu, &target), &reference);
        run_bilinear(r);
        let p_bilinear = psnr_rgba8(&read_texture_rgba8(&gpu, &target), &reference);
        let m = median(&mut times[k]);
        println!(
            "| {r} | {m:.3} | {:.2}x | {p_bilateral:.2} | {p_bilinear:.2} |",
            base / m
        );
    }
}
