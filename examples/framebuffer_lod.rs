//! Geometry-aware framebuffer LOD on an edge-heavy scene, headless: the full-resolution
//! reference, plain bilinear upsampling and bilateral (eq. 1) upsampling at r = 2 and 4, side by
//! side, with difference heat maps and the PSNR of each.
//!
//! `cargo run --release --example framebuffer_lod -- [--out DIR] [--sigma-z 0.25] [--sigma-n 0.4]`
//! Writes DIR/r2.png and DIR/r4.png (reference | bilinear | bilateral on top, |error| x 4 of
//! bilinear and bilateral below); default DIR: lodkit-out/framebuffer-lod.

use std::path::PathBuf;

use lodkit::framebuffer_lod::psnr_rgba8;
use lodkit::gpu::framebuffer_lod::{LowResBuffer, UpsamplePass};
use lodkit::gpu::gbuffer_scene::EdgeScene;
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::texture_2d;
use lodkit::gpu::{GpuContext, GpuOptions};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

const W: u32 = 320;
const H: u32 = 240;

fn heat(image: &[u8], reference: &[u8]) -> Vec<u8> {
    image
        .chunks(4)
        .zip(reference.chunks(4))
        .flat_map(|(a, b)| {
            let e = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            let v = (u32::from(e) * 4).min(255) as u8;
            [v, v / 3, 255 - v, 255]
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out =
        PathBuf::from(arg("--out").unwrap_or_else(|| "lodkit-out/framebuffer-lod".to_owned()));
    let sigma_z: f32 = arg("--sigma-z")
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(0.25);
    let sigma_n: f32 = arg("--sigma-n")
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(0.4);
    let gpu = GpuContext::new_headless(&GpuOptions::default())?;
    println!("adapter: {}", gpu.adapter_summary());
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let scene = EdgeScene::new(&gpu, format, W as f32 / H as f32)?;
    let full = LowResBuffer::new(&gpu, W, H, format);
    scene.render(&gpu, &full, 1.0);
    let reference = read_texture_rgba8(&gpu, full.color());
    let low = LowResBuffer::new(&gpu, W, H, format);
    let upsample = UpsamplePass::new(&gpu, format)?;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(&gpu, (W, H), format, usage, "upsampled");
    let view = target.create_view(&Default::default());
    std::fs::create_dir_all(&out)?;
    println!(
        "{:>4} {:>14} {:>15} {:>8}",
        "r", "bilinear (dB)", "bilateral (dB)", "gain"
    );
    for r in [2.0f32, 4.0] {
        scene.render(&gpu, &low, r);
        let mut images = Vec::new();
        for (sz, sn) in [(f32::INFINITY, f32::INFINITY), (sigma_z, sigma_n)] {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            upsample.encode(&gpu, &mut encoder, &low, r, full.geometry(), sz, sn, &view);
            gpu.queue.submit([encoder.finish()]);
            images.push(read_texture_rgba8(&gpu, &target));
        }
        let (a, b) = (
            psnr_rgba8(&images[0], &reference),
            psnr_rgba8(&images[1], &reference),
        );
        println!("{r:>4} {a:>14.2} {b:>15.2} {:>+8.2}", b - a);
        let mut sheet = image::RgbaImage::new(W * 3, H * 2);
        let tiles = [
            (0, 0, reference.clone()),
            (1, 0, images[0].clone()),
            (2, 0, images[1].clone()),
            (1, 1, heat(&images[0], &reference)),
            (2, 1, heat(&images[1], &reference)),
        ];
        for (x, y, pixels) in tiles {
            let tile = image::RgbaImage::from_raw(W, H, pixels).ok_or("tile size")?;
            image::imageops::replace(&mut sheet, &tile, i64::from(x * W), i64::from(y * H));
        }
        let file = out.join(format!("r{r}.png"));
        sheet.save(&file)?;
        println!("     -> {}", file.display());
    }
    Ok(())
}
