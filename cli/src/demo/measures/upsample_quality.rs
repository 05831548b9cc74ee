//! Framebuffer LOD on the edge scene: PSNR and SSIM against the full-resolution reference at
//! several resize factors for bilinear, bilateral and fine-grained resizing (the last two also
//! from a packed L, read with 4 loads per pixel instead of 8), comparison sheets with difference
//! heat maps and whole-frame speed-ups.

use std::path::Path;

use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::fixtures::clock::{Timer, median};
use lodkit::gpu::framebuffer_lod::{
    LowResBuffer, LowResLayout, RangeSigmas, UpsampleFrame, UpsamplePass, UpsamplePassDescriptor,
    UpsampleSettings,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::texture_2d;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::metrics::{psnr_rgba8, ssim_rgba8};
use lodkit_scenes::gbuffer::{EdgeScene, ShadingTerm};

/// Resize factors the demo measures.
pub const RESIZE_FACTORS: [f32; 4] = [1.5, 2.0, 3.0, 4.0];

/// Synthetic shading work of the edge scene in the demo (sky directions per fragment): the
/// expensive low-frequency shading framebuffer LOD is meant for (Yang et al. measure heavy pixel
/// shaders). The scene costs little to shade without it.
pub const SHADING_WORK: u32 = 64;

use crate::demo::fixtures::edge_frame::sigmas as demo_sigmas;

/// Quality and speed of one resize factor.
#[derive(Clone, Debug, Serialize)]
pub struct UpsampleRow {
    /// Resize factor r (the low-res buffer is 1/r of the size in each direction).
    pub r: f32,
    /// PSNR (dB) of each of [`METHODS`].
    pub psnr: [f32; 5],
    /// SSIM of the same.
    pub ssim: [f32; 5],
    /// Whole-frame speed-up over rendering at full resolution (median wall time ratio) for each
    /// of [`ROUTES`].
    pub speedup: [f64; 4],
}

/// Method names in the order of [`UpsampleRow::psnr`]: the last two read a packed L.
pub const METHODS: [&str; 5] = [
    "bilinear",
    "bilateral",
    "fine-grained",
    "bilateral, packed L",
    "fine-grained, packed L",
];

/// Whole-frame routes in the order of [`UpsampleRow::speedup`], and the method of each.
pub const ROUTES: [(&str, usize); 4] = [
    ("bilateral route", 1),
    ("fine-grained route", 2),
    ("bilateral route, packed L", 3),
    ("fine-grained route, packed L", 4),
];

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

/// Renders the comparisons at `size`, writes `upsample/r<r>.png` sheets (reference, bilinear,
/// bilateral, fine-grained on top; their |error| x 4 below, blue none, red 64/255 or more), and
/// times whole frames over `rounds` rounds.
pub fn measure_upsampling(
    gpu: &GpuContext,
    timer: &Timer,
    size: (u32, u32),
    rounds: usize,
    out: &Path,
    tick: &mut dyn FnMut(&str),
) -> Result<Vec<UpsampleRow>, DemoError> {
    let (w, h) = size;
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut scene = EdgeScene::new(gpu, format, w as f32 / h as f32)?;
    scene.set_shading_work(SHADING_WORK);
    let full = LowResBuffer::new(gpu, w, h, format)?;
    scene.render(gpu, &full, 1.0)?;
    let reference = read_texture_rgba8(gpu, full.color())?;
    let lows = [
        LowResBuffer::new(gpu, w, h, format)?,
        LowResBuffer::packed(gpu, w, h)?,
    ];
    let albedo = LowResBuffer::new(gpu, w, h, format)?;
    let layouts = [LowResLayout::ColorAndGeometry, LowResLayout::Packed];
    let pass = |layout, times_albedo| {
        let desc = crate::demo::fixtures::edge_frame::pass_descriptor(layout, times_albedo);
        UpsamplePass::new(
            gpu,
            &UpsamplePassDescriptor {
                target_format: format,
                ..desc
            },
        )
    };
    let upsample = [pass(layouts[0], false)?, pass(layouts[1], false)?];
    let fine_pass = [pass(layouts[0], true)?, pass(layouts[1], true)?];
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(gpu, size, format, usage, "upsampled")?;
    let view = target.create_view(&Default::default());
    // `p` picks the layout of L: 0 color + geometry, 1 packed.
    let record_upsample = |e: &mut wgpu::CommandEncoder,
                           p: usize,
                           r: f32,
                           geometry: &wgpu::Texture,
                           sigmas: RangeSigmas| {
        let frame = UpsampleFrame {
            low: &lows[p],
            full_geometry: geometry,
            full_albedo: None,
            target: &view,
            settings: UpsampleSettings { r, sigmas },
        };
        upsample[p].record(gpu, e, &frame)
    };
    // Fine-grained: the upsampled lighting times the full-resolution albedo, in the upsample.
    let record_fine = |e: &mut wgpu::CommandEncoder, p: usize, r: f32| {
        let frame = UpsampleFrame {
            low: &lows[p],
            full_geometry: albedo.geometry(),
            full_albedo: Some(albedo.color()),
            target: &view,
            settings: crate::demo::fixtures::edge_frame::settings(r),
        };
        fine_pass[p].record(gpu, e, &frame)
    };
    let submit = |record: &dyn Fn(&mut wgpu::CommandEncoder) -> Result<(), GpuError>| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        record(&mut encoder)?;
        gpu.queue.submit([encoder.finish()]);
        Ok::<(), GpuError>(())
    };
    let upsample_with = |p: usize, r: f32, geometry: &wgpu::Texture, sigmas: RangeSigmas| {
        submit(&|e| record_upsample(e, p, r, geometry, sigmas))
    };
    let fine_with = |p: usize, r: f32| submit(&|e| record_fine(e, p, r));
    let mut rows = Vec::new();
    for r in RESIZE_FACTORS {
        let mut images = Vec::new();
        scene.render(gpu, &lows[0], r)?;
        upsample_with(0, r, full.geometry(), RangeSigmas::OFF)?;
        images.push(read_texture_rgba8(gpu, &target)?);
        upsample_with(0, r, full.geometry(), demo_sigmas())?;
        images.push(read_texture_rgba8(gpu, &target)?);
        // Fine-grained: only the lighting goes through the low-res buffer; the upsample pass
        // multiplies it by the full-res albedo (the frame the timing below measures).
        scene.render_term(gpu, &albedo, 1.0, ShadingTerm::Albedo)?;
        scene.render_term(gpu, &lows[0], r, ShadingTerm::Lighting)?;
        fine_with(0, r)?;
        images.push(read_texture_rgba8(gpu, &target)?);
        // The same two from a packed L.
        scene.render(gpu, &lows[1], r)?;
        upsample_with(1, r, full.geometry(), demo_sigmas())?;
        images.push(read_texture_rgba8(gpu, &target)?);
        scene.render_term(gpu, &lows[1], r, ShadingTerm::Lighting)?;
        fine_with(1, r)?;
        images.push(read_texture_rgba8(gpu, &target)?);
        let psnr: [f32; 5] = std::array::from_fn(|k| psnr_rgba8(&images[k], &reference));
        let ssim: [f32; 5] = std::array::from_fn(|k| ssim_rgba8(&images[k], &reference, w));
        let mut sheet = image::RgbaImage::from_pixel(w * 4, h * 2, image::Rgba([24, 24, 32, 255]));
        let mut tiles = vec![(0, 0, reference.clone())];
        for (k, img) in images.iter().take(3).enumerate() {
            tiles.push((k as u32 + 1, 0, img.clone()));
            tiles.push((k as u32 + 1, 1, heat(img, &reference)));
        }
        for (x, y, pixels) in tiles {
            let tile = image::RgbaImage::from_raw(w, h, pixels)
                .ok_or_else(|| DemoError::Internal("tile of the wrong size".to_owned()))?;
            image::imageops::replace(&mut sheet, &tile, i64::from(x * w), i64::from(y * h));
        }
        crate::demo::error::save(&sheet, &out.join(format!("upsample/r{r}.png")))?;
        rows.push(UpsampleRow {
            r,
            psnr,
            ssim,
            speedup: [0.0; 4],
        });
        tick(&format!("r = {r}"));
    }
    // Whole frames, interleaved round by round: full-res shading against a full-res geometry
    // prepass (with the cheap albedo) + low-res shading + upsample, and against the fine-grained
    // route (full-res albedo, which writes the geometry too, + low-res lighting + the upsample
    // that multiplies them: the frame whose image is measured above); each from both layouts.
    let prepass = LowResBuffer::new(gpu, w, h, format)?;
    let time = |f: &dyn Fn(&mut wgpu::CommandEncoder) -> Result<(), GpuError>| timer.time(gpu, f);
    let mut base = Vec::new();
    let mut times = vec![vec![Vec::new(); ROUTES.len()]; RESIZE_FACTORS.len()];
    let (full_term, albedo_term) = (ShadingTerm::Full, ShadingTerm::Albedo);
    for round in 0..rounds + 2 {
        let t0 = time(&|e| scene.record_term(gpu, e, &full, 1.0, full_term))?;
        let mut ts = Vec::new();
        for &r in &RESIZE_FACTORS {
            for (p, low) in lows.iter().enumerate() {
                ts.push(time(&|e| {
                    scene.record_term(gpu, e, &prepass, 1.0, albedo_term)?;
                    scene.record_term(gpu, e, low, r, full_term)?;
                    record_upsample(e, p, r, prepass.geometry(), demo_sigmas())
                })?);
                ts.push(time(&|e| {
                    scene.record_term(gpu, e, &albedo, 1.0, albedo_term)?;
                    scene.record_term(gpu, e, low, r, ShadingTerm::Lighting)?;
                    record_fine(e, p, r)
                })?);
            }
        }
        if round >= 2 {
            base.push(t0);
            for (k, t) in ts.into_iter().enumerate() {
                times[k / ROUTES.len()][k % ROUTES.len()].push(t);
            }
        }
    }
    let base = median(&base);
    for (row, t) in rows.iter_mut().zip(&times) {
        row.speedup = std::array::from_fn(|k| base / median(&t[k]));
    }
    tick("timing");
    Ok(rows)
}
