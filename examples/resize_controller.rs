//! Framerate control for framebuffer LOD in a simulator: t = K workload / r^2 + C + noise, with
//! the workload doubling at frame 60 and going back at frame 160. Compares a fixed r, the paper's
//! controller (K from a calibration run), lodkit's online estimator and an HDRP-style step
//! heuristic; prints settling time, overshoot and spread (median over 50 noise seeds) and plots
//! the frame-time curves like the paper's Fig. 5.
//!
//! `cargo run --release --example resize_controller -- [--out DIR] [--noise 0.03]`
//! Writes DIR/controllers.svg (default DIR: lodkit-out/resize-controller).

use std::path::PathBuf;

use lodkit::framebuffer_lod::*;
use plotters::prelude::*;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

const TARGET: f32 = 16.7;
const FRAMES: usize = 220;

fn controllers() -> Vec<(&'static str, Box<dyn ResizeController>)> {
    let limits = ResizeLimits::default();
    vec![
        ("fixed r = 1.6", Box::new(FixedController { r: 1.6 })),
        (
            "paper (calibrated K)",
            Box::new(PaperController::new(TARGET, 40.0, limits)),
        ),
        (
            "lodkit (online K, C)",
            Box::new(RlsController::new(TARGET, limits)),
        ),
        (
            "step heuristic (HDRP-like)",
            Box::new(StepController::new(TARGET, limits)),
        ),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out =
        PathBuf::from(arg("--out").unwrap_or_else(|| "lodkit-out/resize-controller".to_owned()));
    let noise: f32 = arg("--noise")
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(0.03);
    let model = FrameTimeModel {
        k: 40.0,
        c: 3.0,
        noise,
    };
    let workload = |f: usize| if (60..160).contains(&f) { 2.0 } else { 1.0 };
    println!(
        "target {TARGET} ms; K = 40 ms, C = 3 ms, noise {:.0} %; workload x2 at frame 60",
        noise * 100.0
    );
    println!(
        "{:<28} {:>16} {:>14} {:>10}",
        "controller", "settling frames", "overshoot", "spread"
    );
    for (i, (name, _)) in controllers().iter().enumerate() {
        let mut settle = Vec::new();
        let mut over = Vec::new();
        let mut spread = Vec::new();
        for seed in 0..50 {
            let mut c = controllers().swap_remove(i).1;
            let frames = simulate(c.as_mut(), &model, workload, 160, seed);
            let r = step_response(&frames, 60, TARGET, 0.05);
            settle.push(r.settling_frames.map_or(f32::INFINITY, |s| s as f32));
            over.push(r.overshoot);
            spread.push(r.spread);
        }
        let median = |v: &mut Vec<f32>| {
            v.sort_by(f32::total_cmp);
            v[v.len() / 2]
        };
        let s = median(&mut settle);
        let settle_text = if s.is_finite() {
            format!("{s}")
        } else {
            "never".to_owned()
        };
        println!(
            "{name:<28} {settle_text:>16} {:>13.1}% {:>9.1}%",
            median(&mut over) * 100.0,
            median(&mut spread) * 100.0
        );
    }
    std::fs::create_dir_all(&out)?;
    let file = out.join("controllers.svg");
    let root = SVGBackend::new(&file, (960, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Frame time under a 2x workload step (frames 60-160)",
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(52)
        .build_cartesian_2d(0f32..FRAMES as f32, 0f32..40f32)?;
    chart
        .configure_mesh()
        .x_desc("frame")
        .y_desc("frame time (ms)")
        .draw()?;
    chart
        .draw_series(LineSeries::new(
            [(0.0, TARGET), (FRAMES as f32, TARGET)],
            BLACK.mix(0.5),
        ))?
        .label("target");
    for (i, (name, mut c)) in controllers().into_iter().enumerate() {
        let frames = simulate(c.as_mut(), &model, workload, FRAMES, 1);
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                frames
                    .iter()
                    .enumerate()
                    .map(|(f, s)| (f as f32, s.measured)),
                color.stroke_width(2),
            ))?
            .label(name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()?;
    root.present()?;
    println!("wrote {}", file.display());
    Ok(())
}
