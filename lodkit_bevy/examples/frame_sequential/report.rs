//! The comparison: the references (one level alone), then lodkit's frame-sequential LOD and
//! Bevy's crossfade in the two kinds of app (without a prepass; with the depth and
//! motion-vector prepass an app runs anyway for TAA or motion blur), each with the still and the
//! moving camera; the figures, the strips and, with `--frames`, every frame as PNG.

use std::path::Path;

use bevy::prelude::*;
use lodkit_bevy::frame_sequential::FrameSequentialStats;
use serde_json::{Map, Value};

use crate::Args;
use crate::frames::{Frame, strip};
use crate::headless::save_png;
use crate::measure::{coverage, flicker, ghosts, pop, see_through, still_flicker};
use crate::run::{BACKGROUND, Failure, HEIGHT, Harness, PARTS, Pass, Run, WIDTH};
use crate::scene::{FRAMES, Technique};

/// A technique in a kind of app: its report name and what its camera has.
struct Contender {
    name: &'static str,
    technique: Technique,
    prepass: bool,
}

const CONTENDERS: [Contender; 4] = [
    Contender {
        name: "frame_sequential",
        technique: Technique::FrameSequential,
        prepass: false,
    },
    Contender {
        name: "bevy_crossfade",
        technique: Technique::BevyCrossfade,
        prepass: false,
    },
    Contender {
        name: "frame_sequential_with_prepass",
        technique: Technique::FrameSequential,
        prepass: true,
    },
    Contender {
        name: "bevy_crossfade_with_prepass",
        technique: Technique::BevyCrossfade,
        prepass: true,
    },
];

/// What the runs of one contender add up to over both camera paths.
#[derive(Default)]
struct Totals {
    see_through: usize,
    ghosts: usize,
    min_coverage: Option<f64>,
    fragments: [f64; PARTS],
    gpu_ms: [f64; PARTS],
}

fn io(message: String) -> Failure {
    Failure(2, message)
}

/// 7 frames evenly over the frames in transition.
fn strip_of(run: &Run) -> Frame {
    let frames: Vec<usize> = (0..FRAMES).filter(|&f| run.in_transition[f]).collect();
    let (first, last) = (frames[0], frames[frames.len() - 1]);
    let picks: Vec<Frame> = (0..7)
        .map(|k| run.frames[first + (last - first) * k / 6].clone())
        .collect();
    strip(&picks)
}

/// Writes every frame of a run as `DIR/<run>_<path>/<frame>.png`.
fn save_frames(dir: &Path, run: &str, path: &str, frames: &[Frame]) -> Result<(), Failure> {
    let folder = dir.join(format!("{run}_{path}"));
    std::fs::create_dir_all(&folder).map_err(|e| io(format!("{}: {e}", folder.display())))?;
    for (i, frame) in frames.iter().enumerate() {
        save_png(frame, &folder.join(format!("{i:03}.png"))).map_err(io)?;
    }
    Ok(())
}

pub fn run(args: &Args) -> Result<(), Failure> {
    std::fs::create_dir_all(&args.out).map_err(|e| io(format!("{}: {e}", args.out.display())))?;
    let mut h = Harness::new();
    let latency = h.diagnostics_latency(args)?;
    println!("render diagnostics arrive {latency} update(s) after their frame");
    let background = Frame::filled(1, 1, srgb8(BACKGROUND)).rgb(0, 0);
    let mut report = Map::new();
    let contenders: Vec<&Contender> = CONTENDERS
        .iter()
        .filter(|c| !c.prepass || args.with_prepass)
        .collect();
    let mut totals: Vec<Totals> = contenders.iter().map(|_| Totals::default()).collect();
    for moving in [false, true] {
        let path = if moving { "moving" } else { "static" };
        let fine = h.run(Technique::Reference(0), false, moving, args)?;
        let coarse = h.run(Technique::Reference(1), false, moving, args)?;
        if fine.frames[0].object_pixels(background) == 0 {
            return Err(Failure(
                1,
                "nothing rendered: the reference frame is empty".into(),
            ));
        }
        if let Some(dir) = &args.frames {
            save_frames(dir, "reference_fine", path, &fine.frames)?;
            save_frames(dir, "reference_coarse", path, &coarse.frames)?;
        }
        for (c, total) in contenders.iter().zip(&mut totals) {
            let run = h.run(c.technique, c.prepass, moving, args)?;
            let name = c.name;
            let p = pop(&run.frames, &fine.frames);
            let f = flicker(&run.frames, &fine.frames).map_err(|e| Failure(1, e.to_string()))?;
            // Against the coarse level's frames too: a verdict that turns with the reference
            // does not show less flicker.
            let fc = flicker(&run.frames, &coarse.frames).map_err(|e| Failure(1, e.to_string()))?;
            let holes = see_through(&run.frames, &fine.frames, &coarse.frames, background);
            let shown = coverage(&run.frames, &fine.frames, &coarse.frames, background);
            let window: Vec<usize> = (0..FRAMES).filter(|&f| run.in_transition[f]).collect();
            let seen: usize = window.iter().map(|&f| holes[f]).sum();
            total.see_through += seen;
            let extra = ghosts(&run.frames, &fine.frames, &coarse.frames, background);
            let ghosted: usize = window.iter().map(|&f| extra[f]).sum();
            total.ghosts += ghosted;
            let low = window.iter().map(|&f| shown[f]).fold(1.0, f64::min);
            total.min_coverage = Some(total.min_coverage.map_or(low, |m: f64| m.min(low)));
            let fragments = run.transition_fragments(latency);
            for (t, f) in total.fragments.iter_mut().zip(fragments) {
                *t += f;
            }
            let gpu_ms = run.transition_gpu_ms(latency);
            for (t, ms) in total.gpu_ms.iter_mut().zip(gpu_ms) {
                *t += ms;
            }
            println!(
                "{name:30} {path:6}: pop {p:.3}, flicker {:.2} ({} reversals; vs coarse {:.2}, {} \
                 reversals), see-through {seen} px, ghosts {ghosted} px, fragments {:.0} (prepass \
                 {:.0}, opaque {:.0}, older depth {:.0}, combine {:.0})",
                f.ratio(),
                f.reversals,
                fc.ratio(),
                fc.reversals,
                fragments.iter().sum::<f64>(),
                fragments[0],
                fragments[1],
                fragments[2],
                fragments[3],
            );
            println!(
                "{name:30} {path:6}: GPU time {:.3} ms (prepass {:.3}, opaque {:.3}, older depth \
                 {:.3}, combine {:.3})",
                gpu_ms.iter().sum::<f64>(),
                gpu_ms[0],
                gpu_ms[1],
                gpu_ms[2],
                gpu_ms[3],
            );
            report.insert(format!("pop_{name}_{path}"), p.into());
            report.insert(format!("flicker_{name}_{path}"), f.ratio().into());
            report.insert(format!("reversals_{name}_{path}"), f.reversals.into());
            report.insert(format!("flicker_{name}_{path}_coarse"), fc.ratio().into());
            report.insert(
                format!("reversals_{name}_{path}_coarse"),
                fc.reversals.into(),
            );
            // The silhouettes' CPU time per frame, over the frames that found any (the first
            // of a mesh builds its surface too).
            let times: Vec<f64> = run
                .silhouettes
                .iter()
                .filter(|(_, triangles)| *triangles > 0)
                .map(|(us, _)| *us)
                .collect();
            if c.technique == Technique::FrameSequential && !times.is_empty() {
                let triangles = run.silhouettes.iter().map(|s| s.1).max().unwrap_or(0);
                let us = lodkit::metrics::median(&times);
                println!(
                    "{name:30} {path:6}: silhouettes {us:.1} us per frame (median of {}), up to {triangles} triangles",
                    times.len()
                );
                report.insert(format!("silhouette_us_{name}_{path}"), us.into());
                report.insert(
                    format!("silhouette_triangles_{name}_{path}"),
                    triangles.into(),
                );
            }
            if !moving {
                let still = still_flicker(&run.frames, &fine.frames, &coarse.frames)
                    .map_err(|e| Failure(1, e.to_string()))?;
                report.insert(format!("flicker_{name}_still_pixels"), still.ratio().into());
            }
            if moving {
                let file = args.out.join(format!("strip_{name}.png"));
                save_png(&strip_of(&run), &file).map_err(io)?;
                report.insert(
                    format!("png_strip_{name}"),
                    file.display().to_string().into(),
                );
            }
            if let Some(dir) = &args.frames {
                save_frames(dir, name, path, &run.frames)?;
            }
        }
    }
    for (c, total) in contenders.iter().zip(&totals) {
        let name = c.name;
        report.insert(format!("see_through_{name}"), total.see_through.into());
        report.insert(format!("ghosts_{name}"), total.ghosts.into());
        report.insert(
            format!("min_coverage_{name}"),
            total.min_coverage.unwrap_or(1.0).into(),
        );
        report.insert(
            format!("fragments_{name}"),
            total.fragments.iter().sum::<f64>().into(),
        );
        for (pass, f) in Pass::ALL.iter().zip(total.fragments) {
            report.insert(format!("fragments_{name}_{}", pass.name()), f.into());
        }
        // GPU time over the frames in transition, from Bevy's render diagnostics (timestamp
        // queries): what the fragment counts cost on this GPU.
        report.insert(
            format!("gpu_ms_{name}"),
            total.gpu_ms.iter().sum::<f64>().into(),
        );
        for (pass, ms) in Pass::ALL.iter().zip(total.gpu_ms) {
            report.insert(format!("gpu_ms_{name}_{}", pass.name()), ms.into());
        }
    }
    for measure in ["fragments", "gpu_ms"] {
        for (suffix, ours, theirs) in [
            ("", "frame_sequential", "bevy_crossfade"),
            (
                "_with_prepass",
                "frame_sequential_with_prepass",
                "bevy_crossfade_with_prepass",
            ),
        ] {
            let get = |k: &str| {
                report
                    .get(&format!("{measure}_{k}"))
                    .and_then(Value::as_f64)
            };
            if let (Some(a), Some(b)) = (get(ours), get(theirs))
                && b > 0.0
            {
                report.insert(format!("{measure}_ratio{suffix}"), (a / b).into());
            }
        }
    }
    report.insert("frames_per_run".into(), FRAMES.into());
    report.insert("size".into(), vec![WIDTH, HEIGHT].into());
    report.insert("diagnostics_latency".into(), latency.into());
    report.insert(
        "schedule".into(),
        format!("{:?}", args.schedule).to_lowercase().into(),
    );
    report.insert(
        "anchor".into(),
        format!("{:?}", args.anchor).to_lowercase().into(),
    );
    report.insert("reprojection".into(), args.reprojection.into());
    report.insert("msaa".into(), args.msaa.into());
    report.insert(
        "coverage".into(),
        format!("{:?}", args.coverage).to_lowercase().into(),
    );
    report.insert(
        "combine_region".into(),
        format!("{:?}", args.combine_region).to_lowercase().into(),
    );
    if let Some(dir) = &args.frames {
        report.insert("frames_dir".into(), dir.display().to_string().into());
    }
    // With --chain, the moving group's levels as lodkit's LOD chain built them.
    if crate::scene::groups()[2].from_chain {
        let chain = crate::scene::chain().chain();
        let distances = crate::scene::chain()
            .lod_group(&crate::scene::chain_camera())
            .map_err(|e| Failure(1, format!("the chain's group: {e}")))?;
        let levels: Vec<Value> = chain
            .levels()
            .iter()
            .zip(distances.levels())
            .map(|(level, lod)| {
                serde_json::json!({
                    "triangles": level.triangles(),
                    "error": level.error(),
                    "distance": lod.distance * crate::scene::p11(),
                })
            })
            .collect();
        report.insert("chain_levels".into(), levels.into());
        report.insert(
            "chain_pixel_error".into(),
            crate::scene::CHAIN_PIXEL_ERROR.into(),
        );
    }
    let stats = h.app().world().resource::<FrameSequentialStats>().clone();
    report.insert("frames_scheduled".into(), stats.frames.into());
    report.insert("frames_kept".into(), stats.frames_kept.into());
    let json = serde_json::to_string_pretty(&report).expect("a JSON map serializes");
    println!("{json}");
    if let Some(path) = &args.report {
        std::fs::write(path, &json).map_err(|e| io(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}

/// `color` as 8-bit sRGB, as the render target stores it.
fn srgb8(color: Color) -> [u8; 3] {
    let c = color.to_srgba();
    [c.red, c.green, c.blue].map(|v| (v * 255.0).round() as u8)
}
