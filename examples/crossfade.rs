//! The same LOD transition drawn five ways, headless: hard switch, cross-fade, complementary
//! screen-door dither (Bayer and blue noise) and unpopping. Writes one PNG strip per technique
//! (9 frames, t = 0 .. 1) and prints how much of the backdrop shows through the object.
//!
//! `cargo run --release --example crossfade -- [--out DIR] [--size N]` (default DIR:
//! lodkit-out/crossfade, N = 160).

use std::path::PathBuf;

use lodkit::gpu::transition_scene::{
    SceneParts, SingleFrameTechnique, TransitionScene, see_through,
};
use lodkit::gpu::{GpuContext, GpuOptions};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(arg("--out").unwrap_or_else(|| "lodkit-out/crossfade".to_owned()));
    let size: u32 = arg("--size").map(|s| s.parse()).transpose()?.unwrap_or(160);
    let gpu = GpuContext::new_headless(&GpuOptions::default())?;
    println!("adapter: {}", gpu.adapter_summary());
    let scene = TransitionScene::new(&gpu, size, size)?;
    let fine = scene.render(
        &gpu,
        SingleFrameTechnique::Unpopping,
        0.0,
        SceneParts::FineOnly,
    );
    let coarse = scene.render(
        &gpu,
        SingleFrameTechnique::Unpopping,
        0.0,
        SceneParts::CoarseOnly,
    );
    std::fs::create_dir_all(&out)?;
    let frames = 9u32;
    println!(
        "{:<18} see-through of the object's interior at t = 0.25 / 0.5 / 0.75",
        "technique"
    );
    for technique in SingleFrameTechnique::ALL {
        let mut strip = image::RgbaImage::new(size * frames, size);
        for f in 0..frames {
            let t = f as f32 / (frames - 1) as f32;
            let pixels = scene.render(&gpu, technique, t, SceneParts::All);
            let frame = image::RgbaImage::from_raw(size, size, pixels).ok_or("bad frame size")?;
            image::imageops::replace(&mut strip, &frame, i64::from(f * size), 0);
        }
        let file = out.join(format!("{}.png", technique.name()));
        strip.save(&file)?;
        let shares: Vec<String> = [0.25, 0.5, 0.75]
            .iter()
            .map(|&t| {
                let (share, _) = see_through(
                    &scene.render(&gpu, technique, t, SceneParts::All),
                    &fine,
                    &coarse,
                );
                format!("{:5.1}%", share * 100.0)
            })
            .collect();
        println!(
            "{:<18} {}   -> {}",
            technique.name(),
            shares.join(" / "),
            file.display()
        );
    }
    Ok(())
}
