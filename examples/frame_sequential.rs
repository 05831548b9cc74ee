//! Frame-sequential LOD interpolation on a SIMPLE-like scene (Scherzer & Wimmer 2008, Fig. 9):
//! red spheres (LOD0) turn into blue boxes (LOD1) while the camera drifts, headless. Each frame
//! renders ONE LOD buffer; the combine pass merges it with the previous one.
//!
//! Writes DIR/strip.png (every 4th combined frame of the transition), DIR/sources.png (which
//! rule each pixel of the middle frame came from: gray newer, orange older, magenta average of
//! the two LODs, cyan outside the older view) and prints triangles drawn per frame for a hard
//! switch, frame-sequential, and drawing both LODs.
//!
//! `cargo run --release --example frame_sequential -- [--out DIR] [--pattern white|blue|radial]`
//! (default DIR: lodkit-out/frame-sequential).

use std::path::PathBuf;

use glam::{Mat4, Vec3, Vec4};
use lodkit::combine::{DepthConvention, PixelSource, combine_images};
use lodkit::frame_sequential::{Drive, TransitionScheduler};
use lodkit::gpu::frame_sequential::{CombinePass, LodBuffers, read_lod_image};
use lodkit::gpu::lod_buffer_scene::{LodBufferRenderer, LodDrawItem};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::scene::{GpuMesh, Mesh};
use lodkit::gpu::{GpuContext, GpuOptions};
use lodkit::reproject::new_to_old_matrix;
use lodkit::visibility::{VisibilityPattern, visibility_texture};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

const W: u32 = 256;
const H: u32 = 160;
const FRAMES: usize = 36;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out =
        PathBuf::from(arg("--out").unwrap_or_else(|| "lodkit-out/frame-sequential".to_owned()));
    let pattern = match arg("--pattern").as_deref() {
        None | Some("white") => VisibilityPattern::WhiteNoise,
        Some("blue") => VisibilityPattern::BlueNoise,
        Some("radial") => VisibilityPattern::Radial,
        Some(other) => {
            return Err(format!("unknown pattern `{other}` (white, blue, radial)").into());
        }
    };
    let gpu = GpuContext::new_headless(&GpuOptions::default())?;
    println!("adapter: {}", gpu.adapter_summary());
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(pattern, 64, 1);
    let renderer = LodBufferRenderer::new(&gpu, format, &vis, 0.25)?;
    let buffers = LodBuffers::new(&gpu, W, H, format);
    let combine = CombinePass::new(&gpu, format, false)?;
    let meshes = [Mesh::sphere(16, 24), Mesh::cube()];
    let gpu_meshes = [
        GpuMesh::new(&gpu, &meshes[0]),
        GpuMesh::new(&gpu, &meshes[1]),
    ];
    let colors = [
        Vec4::new(0.9, 0.15, 0.1, 1.0),
        Vec4::new(0.15, 0.3, 0.95, 1.0),
    ];

    // A 5 x 3 grid; the middle row transitions (t-instances), the others stay (n-instances).
    let mut scheduler = TransitionScheduler::new();
    let objects: Vec<(Vec3, _)> = (0..15)
        .map(|i| {
            let p = Vec3::new((i % 5) as f32 * 2.2 - 4.4, 0.0, -((i / 5) as f32) * 2.5);
            (p, scheduler.insert(if i / 5 == 2 { 1 } else { 0 }))
        })
        .collect();
    for (_, key) in objects.iter().skip(5).take(5) {
        scheduler.begin_transition(
            *key,
            1,
            Drive::Time {
                seconds: FRAMES as f32 / 30.0,
            },
        )?;
    }
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = lodkit::gpu::resources::texture_2d(&gpu, (W, H), format, usage, "combined");
    let proj = glam::camera::rh::proj::directx::perspective(0.8, W as f32 / H as f32, 0.1, 100.0);
    let mut previous_view: Option<Mat4> = None;
    let mut strip = image::RgbaImage::new(W * 5, H * 2);
    println!(
        "{:>5} {:>12} {:>16} {:>12}",
        "frame", "hard switch", "frame-sequential", "both LODs"
    );
    let mut totals = [0u64; 3];
    for frame in 0..=FRAMES + 4 {
        if frame > 0 {
            scheduler.advance(1.0 / 30.0);
        }
        let eye = Vec3::new(-1.0 + 0.05 * frame as f32, 3.0, 7.5);
        let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -2.5), Vec3::Y);
        let mut items = Vec::new();
        let (mut hard, mut both) = (0u64, 0u64);
        for (p, key) in &objects {
            let d = scheduler.draw(*key)?;
            let model = Mat4::from_translation(*p) * Mat4::from_scale(Vec3::splat(0.8));
            items.push(LodDrawItem {
                mesh: &gpu_meshes[d.lod as usize],
                model,
                color: colors[d.lod as usize],
                id: d.id,
                tau: d.tau,
            });
            let tri = |lod: usize| meshes[lod].triangles() as u64;
            if d.id == 0 {
                hard += tri(d.lod as usize);
                both += tri(d.lod as usize);
            } else {
                // Hard switch: the old LOD until half-way, then the new one. Both: every frame both.
                hard += if d.progress < 0.5 { tri(0) } else { tri(1) };
                both += tri(0) + tri(1);
            }
        }
        let drawn = renderer.render(
            &gpu,
            &buffers,
            scheduler.buffer_index(),
            proj * view,
            &items,
            wgpu::Color {
                r: 0.03,
                g: 0.03,
                b: 0.06,
                a: 1.0,
            },
        );
        totals[0] += hard;
        totals[1] += drawn;
        totals[2] += both;
        if frame % 3 == 0 {
            println!("{frame:>5} {hard:>12} {drawn:>16} {both:>12}");
        }
        let m = previous_view.map_or(CombinePass::NO_HISTORY, |old| {
            new_to_old_matrix(&view, &proj, &old, &proj)
        });
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        combine.encode(
            &gpu,
            &mut encoder,
            &buffers,
            scheduler.buffer_index(),
            m,
            &target.create_view(&Default::default()),
        );
        gpu.queue.submit([encoder.finish()]);
        if frame % 4 == 0 && frame / 4 < 10 {
            let pixels = image::RgbaImage::from_raw(W, H, read_texture_rgba8(&gpu, &target))
                .ok_or("frame size")?;
            let slot = (frame / 4) as u32;
            image::imageops::replace(
                &mut strip,
                &pixels,
                i64::from((slot % 5) * W),
                i64::from((slot / 5) * H),
            );
        }
        if frame == FRAMES / 2 + 1 {
            let newer = read_lod_image(&gpu, &buffers, scheduler.buffer_index());
            let older = read_lod_image(&gpu, &buffers, 1 - scheduler.buffer_index());
            let sources = combine_images(&newer, &older, &m, DepthConvention::Standard);
            let false_color = image::RgbaImage::from_fn(W, H, |x, y| {
                image::Rgba(match sources[(y * W + x) as usize].source {
                    PixelSource::Newer => [90, 90, 90, 255],
                    PixelSource::Older => [255, 150, 0, 255],
                    PixelSource::Average => [230, 0, 200, 255],
                    PixelSource::OutsideOlder => [0, 220, 230, 255],
                })
            });
            std::fs::create_dir_all(&out)?;
            false_color.save(out.join("sources.png"))?;
        }
        previous_view = Some(view);
    }
    std::fs::create_dir_all(&out)?;
    strip.save(out.join("strip.png"))?;
    println!(
        "total triangles: hard switch {}, frame-sequential {} ({:.3}x), both LODs {} ({:.3}x)",
        totals[0],
        totals[1],
        totals[1] as f64 / totals[0] as f64,
        totals[2],
        totals[2] as f64 / totals[0] as f64
    );
    println!(
        "wrote {} and {}",
        out.join("strip.png").display(),
        out.join("sources.png").display()
    );
    Ok(())
}
