//! Geometry-aware framebuffer LOD (Yang, Sander & Lawrence 2008) in a wgpu frame loop, headless:
//! the smallest complete use of the low-resolution buffer, the upsample pass and a resize
//! controller. Copy the loop body into your renderer.
//!
//! Each frame:
//! 1. a cheap full-resolution prepass writes depth and normal (here the albedo term of the same
//!    shader; in an engine, its depth/normal prepass);
//! 2. the expensive shading renders into `LowResBuffer` at resize factor r (a viewport that
//!    shrinks with r: changing r never reallocates);
//! 3. `UpsamplePass` reconstructs the full-resolution image with eq. 1, guided by the prepass;
//! 4. the frame's GPU time (wall time around a wait here; timestamp queries in an engine) goes to
//!    the controller, which answers the next frame's r.
//!
//! `cargo run --example framebuffer_lod -- [--frames N] [--out DIR]`
//! Writes DIR/framebuffer_lod.png (default DIR: lodkit-out): the full-resolution frame, the last
//! upsampled frame, and their difference x4.

use std::error::Error;
use std::time::Instant;

use glam::{Mat4, Vec3, Vec4};
use lodkit::framebuffer_lod::{ResizeController, ResizeLimits, RlsController};
use lodkit::gpu::GpuContext;
use lodkit::gpu::framebuffer_lod::{
    LowResBuffer, RangeSigmas, UpsampleFrame, UpsamplePass, UpsamplePassDescriptor,
    UpsampleSettings,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::texture_2d;
use lodkit::metrics::psnr_rgba8;
use lodkit_scenes::gbuffer::{GBufferFrame, GBufferRenderer, GDrawItem, ShadingTerm};
use lodkit_scenes::mesh::{GpuMesh, Mesh};

const SIZE: (u32, u32) = (640, 360);
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// View depth of the cleared background (world units).
const FAR: f32 = 60.0;
/// Synthetic shading work per fragment: expensive, smooth shading is what framebuffer LOD saves.
const SHADING_WORK: u32 = 48;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    let at = args.iter().position(|a| a == name)?;
    args.get(at + 1).cloned()
}

/// The scene: a few spheres and boxes in front of a wall.
fn items<'a>(sphere: &'a GpuMesh, cube: &'a GpuMesh) -> Vec<GDrawItem<'a>> {
    let t = Mat4::from_translation;
    let s = |v: f32| Mat4::from_scale(Vec3::splat(v));
    let item = |mesh, model, color| GDrawItem { mesh, model, color };
    vec![
        item(
            cube,
            t(Vec3::new(0.0, 0.0, -12.0)) * Mat4::from_scale(Vec3::new(14.0, 8.0, 0.2)),
            Vec4::new(0.9, 0.85, 0.7, 1.0),
        ),
        item(
            sphere,
            t(Vec3::new(1.3, 0.2, 0.0)) * s(1.0),
            Vec4::new(0.2, 0.5, 0.9, 1.0),
        ),
        item(
            cube,
            t(Vec3::new(-1.5, -0.2, -1.0)) * Mat4::from_rotation_y(0.6) * s(0.8),
            Vec4::new(0.9, 0.3, 0.2, 1.0),
        ),
        item(
            sphere,
            t(Vec3::new(-0.3, 1.1, -3.5)) * s(0.8),
            Vec4::new(0.8, 0.7, 0.2, 1.0),
        ),
    ]
}

fn main() -> Result<(), Box<dyn Error>> {
    let frames: usize = arg("--frames").map_or(Ok(40), |f| f.parse())?;
    let out = std::path::PathBuf::from(arg("--out").unwrap_or_else(|| "lodkit-out".into()));
    let gpu = GpuContext::new_headless(&Default::default())?;
    println!("adapter: {}", gpu.adapter_summary());
    let (w, h) = SIZE;

    // Resources, made once. L and the prepass are allocated at full size.
    let mut shading = GBufferRenderer::new(&gpu, FORMAT, ShadingTerm::Full)?;
    shading.set_shading_work(SHADING_WORK);
    let prepass_pass = GBufferRenderer::new(&gpu, FORMAT, ShadingTerm::Albedo)?;
    let low = LowResBuffer::new(&gpu, w, h, FORMAT)?;
    let prepass = LowResBuffer::new(&gpu, w, h, FORMAT)?;
    let upsample = UpsamplePass::new(
        &gpu,
        &UpsamplePassDescriptor {
            target_format: FORMAT,
            ..Default::default()
        },
    )?;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(&gpu, SIZE, FORMAT, usage, "frame")?;
    let target_view = target.create_view(&Default::default());
    let (sphere, cube) = (
        GpuMesh::new(&gpu, &Mesh::sphere(32, 64))?,
        GpuMesh::new(&gpu, &Mesh::cube())?,
    );
    let items = items(&sphere, &cube);
    let eye = Vec3::new(0.4, 1.0, 6.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
    let aspect = w as f32 / h as f32;
    let proj = glam::camera::rh::proj::directx::perspective(0.9, aspect, 0.1, 100.0);
    let clear = wgpu::Color {
        r: 0.1,
        g: 0.12,
        b: 0.15,
        a: 1.0,
    };
    // The scene at full resolution (r = 1): the prepass's draw, and the shading's at each r.
    let scene = GBufferFrame {
        view,
        proj,
        items: &items,
        clear,
        far_view_depth: FAR,
        ..Default::default()
    };

    // One frame at resize factor r; returns its time in milliseconds.
    let frame = |r: f32| -> Result<f32, Box<dyn Error>> {
        let start = Instant::now();
        prepass_pass.render(&gpu, &prepass, &scene)?;
        shading.render(&gpu, &low, &GBufferFrame { r, ..scene })?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let sigmas = RangeSigmas::default();
        let upsampled = UpsampleFrame {
            low: &low,
            full_geometry: prepass.geometry(),
            full_albedo: None,
            target: &target_view,
            settings: UpsampleSettings { r, sigmas },
        };
        upsample.record(&gpu, &mut encoder, &upsampled)?;
        gpu.queue.submit([encoder.finish()]);
        gpu.wait_idle()?;
        Ok(start.elapsed().as_secs_f32() * 1e3)
    };

    // The full-resolution frame, for the picture and to set a budget it cannot meet.
    shading.render(&gpu, &low, &scene)?;
    let reference = read_texture_rgba8(&gpu, low.color())?;
    let full_ms = (0..3).map(|_| frame(1.0)).collect::<Result<Vec<_>, _>>()?;
    let full_ms = full_ms.iter().copied().fold(f32::INFINITY, f32::min);
    let budget = 0.5 * full_ms;
    println!("full resolution: {full_ms:.1} ms; budget: {budget:.1} ms");

    let mut controller = RlsController::new(budget, ResizeLimits::default());
    for i in 0..frames {
        let r = controller.r();
        let ms = frame(r)?;
        controller.update(ms);
        if i % 5 == 0 || i + 1 == frames {
            println!("frame {i:>3}: r = {r:.2}, {ms:.1} ms");
        }
    }

    let upsampled = read_texture_rgba8(&gpu, &target)?;
    let r = controller.r();
    println!(
        "last r = {r:.2}; PSNR vs full resolution: {:.1} dB",
        psnr_rgba8(&upsampled, &reference)
    );
    let mut sheet = image::RgbaImage::new(w * 3, h);
    for (i, pixels) in [&reference, &upsampled].into_iter().enumerate() {
        let tile = image::RgbaImage::from_raw(w, h, pixels.clone()).ok_or("tile size")?;
        image::imageops::replace(&mut sheet, &tile, i64::from(w) * i as i64, 0);
    }
    let diff = reference
        .iter()
        .zip(&upsampled)
        .enumerate()
        .map(|(k, (a, b))| {
            if k % 4 == 3 {
                255
            } else {
                a.abs_diff(*b).saturating_mul(4)
            }
        });
    let diff = image::RgbaImage::from_raw(w, h, diff.collect()).ok_or("tile size")?;
    image::imageops::replace(&mut sheet, &diff, 2 * i64::from(w), 0);
    std::fs::create_dir_all(&out)?;
    let path = out.join("framebuffer_lod.png");
    sheet.save(&path)?;
    println!("wrote {}", path.display());
    Ok(())
}
