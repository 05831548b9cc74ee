//! The transition metrics: pop, see-through and cost of every technique on one scene, with the
//! strips and false-color images that show them.

mod coverage;

use std::path::Path;

use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::fixtures::render::{
    Background, Frame, LEAD_FRAMES, RunSpec, SceneRenderer, Technique,
};
use coverage::LevelMasks;
use lodkit::combine::PixelSource;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::metrics::{Flicker, FlickerMeter, pop, transition_change};

/// Metrics of one technique on one scene.
#[derive(Clone, Debug, Serialize)]
pub struct TransitionMetrics {
    /// Scene name.
    pub scene: String,
    /// Technique name.
    pub technique: String,
    /// Pop with the static camera: the largest single-frame share of the total image change the
    /// transition causes (1 = all of it in one frame, as a hard switch; 1/N = spread evenly).
    pub pop_static: f32,
    /// Pop with the moving camera (camera motion subtracted through a run without transition).
    pub pop_moving: f32,
    /// Flicker with the static camera: the frame-to-frame change of the image beyond the
    /// reference run's, summed over the run, over its net change from the first frame to the
    /// last (`lodkit::metrics::Flicker::ratio`; 1 = every pixel changes once, in one
    /// direction).
    pub flicker_static: f64,
    /// Flicker with the moving camera.
    pub flicker_moving: f64,
    /// Per-pixel direction reversals over the static camera's run
    /// (`lodkit::metrics::Flicker::reversals`).
    pub reversals_static: u64,
    /// The same with the moving camera.
    pub reversals_moving: u64,
    /// Flicker with the static camera measured against the coarse level's reference run (the
    /// fields above: against the fine level's). A technique that flickers less against one
    /// reference only has not shown less flicker.
    pub flicker_static_coarse: f64,
    /// The same with the moving camera.
    pub flicker_moving_coarse: f64,
    /// Reversals with the static camera against the coarse level's reference.
    pub reversals_static_coarse: u64,
    /// The same with the moving camera.
    pub reversals_moving_coarse: u64,
    /// Share of the transitioning objects' interior (pixels both LODs cover) where the
    /// background contributes to the static camera's middle frame.
    pub see_through: f32,
    /// Silhouette error with the moving camera at the middle frame: pixels both LODs cover that
    /// show the background, plus pixels neither covers that show a transitioning object, as a
    /// share of the pixels either covers.
    pub silhouette_error: f32,
    /// Pixels both LODs cover that show the background (`lodkit::metrics::see_through`),
    /// summed over every frame of the transition, static and moving camera: pixel-frames.
    pub see_through_pixel_frames: usize,
    /// Pixels neither LOD covers that show a transitioning object (`lodkit::metrics::ghosts`),
    /// summed the same way.
    pub ghost_pixel_frames: usize,
    /// Pixels of objects in transition, in either LOD buffer, outside the combine pass's
    /// rectangles, summed over the frames of both runs (frame-sequential; 0 otherwise). Pixels
    /// there show the newer buffer alone, so the see-through figure holds only when this is 0.
    pub outside_rects: u64,
    /// Triangles submitted over the transition, relative to a hard switch.
    pub triangles_vs_hard: f64,
    /// Counted fragments over the transition, relative to a hard switch (None when the
    /// adapter's counter is not a count).
    pub fragments_vs_hard: Option<f64>,
    /// Counted fragments on the frames before and after the transition (no t-instance on
    /// screen), relative to a hard switch's on the same frames (None when the adapter's counter
    /// is not a count).
    pub idle_fragments_vs_hard: Option<f64>,
    /// Triangles submitted over the transition.
    pub triangles: u64,
    /// Counted fragments over the transition (frame-sequential: plus one per pixel of the
    /// combine pass's rectangles); None when the adapter's counter is not a count.
    pub fragments: Option<u64>,
    /// Counted fragments on the frames with no t-instance.
    pub idle_fragments: Option<u64>,
    /// Per-frame change attributable to the transition, static camera (mean |delta| per channel,
    /// 0..1), from frame 1 on.
    pub change_static: Vec<f32>,
    /// The same with the moving camera.
    pub change_moving: Vec<f32>,
}

fn to_image(size: (u32, u32), pixels: Vec<u8>) -> Result<image::RgbaImage, DemoError> {
    image::RgbaImage::from_raw(size.0, size.1, pixels)
        .ok_or_else(|| DemoError::Internal("frame of the wrong size".to_owned()))
}

/// Strip frames: 7 evenly over the transition.
fn strip_frames(renderer: &SceneRenderer) -> Vec<usize> {
    let n = renderer.transition_frames();
    (0..7).map(|k| LEAD_FRAMES + (k * n + 3) / 6).collect()
}

/// The frames of a run without transition, which camera motion and animation are measured
/// against: every frame for the moving camera or an animated scene, else the one picture of the
/// static camera. All single-frame techniques
/// draw the same frames without a transition (the fine LOD, opaque), and so do both
/// frame-sequential patterns, so one run per family and camera serves them all.
fn reference_run(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    technique: Technique,
    moving: bool,
    hold_level: usize,
) -> Result<Vec<Vec<u8>>, GpuError> {
    let spec = RunSpec {
        technique,
        moving,
        transition: false,
        hold_level,
        background: Background::Scene,
    };
    let animated = renderer.animated();
    let wanted = |f: usize| moving || animated || f == 0;
    let mut frames = Vec::new();
    renderer.run(gpu, spec, &wanted, &mut |_, f| frames.push(f.pixels), None)?;
    Ok(frames)
}

/// What one transition run measured.
struct TransitionRun {
    change: Vec<f32>,
    /// Against the fine level's reference and against the coarse level's.
    flicker: [Flicker; 2],
    triangles: u64,
    fragments: u64,
    idle_fragments: u64,
    strip: image::RgbaImage,
    sources: Option<Vec<PixelSource>>,
}

/// Runs `technique` with the static or moving camera against `references` (the fine and the
/// coarse level's, see [`reference_run`]), streaming: the per-frame change, triangles and fragments over the
/// transition, the strip, and for frame-sequential the combine rule of the middle frame.
fn transition_run(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    technique: Technique,
    moving: bool,
    references: [&[Vec<u8>]; 2],
    size: (u32, u32),
) -> Result<TransitionRun, DemoError> {
    let spec = RunSpec {
        technique,
        moving,
        transition: true,
        hold_level: 0,
        background: Background::Scene,
    };
    let [reference, coarse_reference] = references;
    let reference_at = |f: usize| reference.get(f).or(reference.last());
    let coarse_at = |f: usize| coarse_reference.get(f).or(coarse_reference.last());
    let span = LEAD_FRAMES..=LEAD_FRAMES + renderer.transition_frames();
    let strip_at = strip_frames(renderer);
    let mut run = TransitionRun {
        change: Vec::new(),
        flicker: [Flicker::default(); 2],
        triangles: 0,
        fragments: 0,
        idle_fragments: 0,
        strip: image::RgbaImage::new(size.0 * 7, size.1),
        sources: None,
    };
    let mut previous: Option<Vec<u8>> = None;
    let mut meter = FlickerMeter::default();
    let mut coarse_meter = FlickerMeter::default();
    let mut failed = None;
    let mut sources = None;
    let mut on_sources = |s| sources = Some(s);
    let sourced = technique.maps_sources();
    renderer.run(
        gpu,
        spec,
        &|_| true,
        &mut |f, frame: Frame| {
            if let (Some(prev), Some(r0), Some(r1)) = (
                &previous,
                reference_at(f.saturating_sub(1)),
                reference_at(f),
            ) {
                run.change
                    .push(transition_change(prev, &frame.pixels, r0, r1) as f32);
            }
            for (meter, r) in [
                (&mut meter, reference_at(f)),
                (&mut coarse_meter, coarse_at(f)),
            ] {
                if let Some(r) = r
                    && let Err(e) = meter.push(&frame.pixels, r)
                {
                    failed = Some(DemoError::Internal(e.to_string()));
                }
            }
            if span.contains(&f) {
                run.triangles += frame.triangles;
                run.fragments += frame.fragments;
            } else {
                run.idle_fragments += frame.fragments;
            }
            if let Some(slot) = strip_at.iter().position(|&s| s == f) {
                match to_image(size, frame.pixels.clone()) {
                    Ok(tile) => image::imageops::replace(
                        &mut run.strip,
                        &tile,
                        i64::from(slot as u32 * size.0),
                        0,
                    ),
                    Err(e) => failed = Some(e),
                }
            }
            previous = Some(frame.pixels);
        },
        (sourced && moving).then_some(&mut on_sources as &mut dyn FnMut(Vec<PixelSource>)),
    )?;
    run.sources = sources;
    run.flicker = [meter.finish(), coarse_meter.finish()];
    match failed {
        Some(e) => Err(e),
        None => Ok(run),
    }
}

/// False color of the combine rule per pixel: gray newer, orange older, magenta average of the
/// two LODs, cyan outside the older view.
pub fn sources_image(size: (u32, u32), sources: &[PixelSource]) -> image::RgbaImage {
    image::RgbaImage::from_fn(size.0, size.1, |x, y| {
        let s = sources.get((y * size.0 + x) as usize);
        image::Rgba(match s {
            Some(PixelSource::Newer) | None => [90, 90, 90, 255],
            Some(PixelSource::Older) => [255, 150, 0, 255],
            Some(PixelSource::Average) => [230, 0, 200, 255],
            Some(PixelSource::OutsideOlder) => [0, 220, 230, 255],
        })
    })
}

/// Close-ups of the transitioning objects at the middle of the transition, static camera: one
/// row per technique (in `strips` order), one column per object, each enlarged twice. Objects
/// off screen are left out; at most six columns.
fn close_ups(
    renderer: &SceneRenderer,
    strips: &[image::RgbaImage],
    size: (u32, u32),
) -> image::RgbaImage {
    const SCALE: u32 = 2;
    const GAP: u32 = 4;
    let rects: Vec<_> = renderer
        .transition_rects()
        .into_iter()
        .flatten()
        .take(6)
        .collect();
    let width: u32 = rects.iter().map(|r| r.width * SCALE + GAP).sum();
    let row = rects.iter().map(|r| r.height * SCALE).max().unwrap_or(0) + GAP;
    let mut sheet =
        image::RgbaImage::from_pixel(width, row * strips.len() as u32, image::Rgba([255; 4]));
    // The strip's middle tile (slot 3 of 7) is the transition's middle frame.
    for (y, strip) in strips.iter().enumerate() {
        let mut x = 0;
        for r in &rects {
            let crop = image::imageops::crop_imm(strip, 3 * size.0 + r.x, r.y, r.width, r.height);
            let big = image::imageops::resize(
                &*crop,
                r.width * SCALE,
                r.height * SCALE,
                image::imageops::FilterType::Nearest,
            );
            image::imageops::replace(&mut sheet, &big, i64::from(x), i64::from(row * y as u32));
            x += r.width * SCALE + GAP;
        }
    }
    sheet
}

/// Measures every technique on `renderer`'s scene, writing strips, see-through maps and the
/// frame-sequential source maps under `out`; `tick` is called after each technique.
pub fn measure_scene(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    scene: &str,
    size: (u32, u32),
    out: &Path,
    tick: &mut dyn FnMut(&str),
) -> Result<Vec<TransitionMetrics>, DemoError> {
    let masks = [
        LevelMasks::render(gpu, renderer, false)?,
        LevelMasks::render(gpu, renderer, true)?,
    ];
    let counts = renderer.counter().kind().is_count();
    let mut rows: Vec<TransitionMetrics> = Vec::new();
    // Reference runs of the current technique family (single-frame or frame-sequential),
    // static and moving camera, each with the fine level and with the coarse level alone.
    type References = [[Vec<Vec<u8>>; 2]; 2];
    let mut references: Option<(bool, References)> = None;
    let mut static_strips = Vec::new();
    for technique in Technique::ALL {
        let name = technique.name();
        let family = matches!(technique, Technique::FrameSequential(..));
        if references.as_ref().is_none_or(|(f, _)| *f != family) {
            drop(references.take()); // frees the other family's frames first
            let run = |moving| -> Result<[Vec<Vec<u8>>; 2], GpuError> {
                let level = |hold| reference_run(gpu, renderer, technique, moving, hold);
                Ok([level(0)?, level(1)?])
            };
            references = Some((family, [run(false)?, run(true)?]));
        }
        let Some((_, reference)) = &references else {
            return Err(DemoError::Internal("no reference run".to_owned()));
        };
        let mut changes = Vec::new();
        let mut flickers = Vec::new();
        let mut cost = (0, 0, 0);
        renderer.take_outside_rects(); // the reference runs' count is not this technique's
        for (moving, reference) in [false, true].into_iter().zip(reference) {
            let reference = [&reference[0][..], &reference[1][..]];
            let run = transition_run(gpu, renderer, technique, moving, reference, size)?;
            let camera = if moving { "moving" } else { "static" };
            crate::demo::error::save(
                &run.strip,
                &out.join(format!("strips/{scene}-{name}-{camera}.png")),
            )?;
            if let Some(sources) = &run.sources {
                let img = sources_image(size, sources);
                crate::demo::error::save(&img, &out.join(format!("sources/{scene}-{name}.png")))?;
            }
            if !moving {
                cost = (run.triangles, run.fragments, run.idle_fragments);
                static_strips.push(run.strip.clone());
            }
            changes.push(run.change);
            flickers.push(run.flicker);
        }
        let outside_rects = renderer.take_outside_rects();
        let coverage = coverage::measure(gpu, renderer, technique, &masks, size)?;
        crate::demo::error::save(
            &coverage.map,
            &out.join(format!("see-through/{scene}-{name}.png")),
        )?;
        let moving_change = changes.pop().unwrap_or_default();
        let static_change = changes.pop().unwrap_or_default();
        let [still, moved] = [0, 1].map(|k| flickers.get(k).copied().unwrap_or_default());
        let [still, still_coarse] = still;
        let [moved, moved_coarse] = moved;
        let as_f64 = |c: &[f32]| c.iter().map(|&v| f64::from(v)).collect::<Vec<f64>>();
        rows.push(TransitionMetrics {
            scene: scene.to_owned(),
            technique: name.to_owned(),
            pop_static: pop(&as_f64(&static_change)) as f32,
            pop_moving: pop(&as_f64(&moving_change)) as f32,
            flicker_static: still.ratio(),
            flicker_moving: moved.ratio(),
            reversals_static: still.reversals,
            reversals_moving: moved.reversals,
            flicker_static_coarse: still_coarse.ratio(),
            flicker_moving_coarse: moved_coarse.ratio(),
            reversals_static_coarse: still_coarse.reversals,
            reversals_moving_coarse: moved_coarse.reversals,
            see_through: coverage.see_through_share,
            outside_rects,
            silhouette_error: coverage.silhouette_error,
            see_through_pixel_frames: coverage.see_through,
            ghost_pixel_frames: coverage.ghosts,
            triangles_vs_hard: 0.0,
            fragments_vs_hard: None,
            idle_fragments_vs_hard: None,
            triangles: cost.0,
            fragments: counts.then_some(cost.1),
            idle_fragments: counts.then_some(cost.2),
            change_static: static_change,
            change_moving: moving_change,
        });
        tick(name);
    }
    let sheet = close_ups(renderer, &static_strips, size);
    crate::demo::error::save(&sheet, &out.join(format!("close-ups/{scene}.png")))?;
    let hard = rows
        .iter()
        .find(|r| r.technique == "hard-switch")
        .map(|r| (r.triangles.max(1), r.fragments, r.idle_fragments));
    let ratio = |a: Option<u64>, b: Option<u64>| a.zip(b).map(|(a, b)| a as f64 / b.max(1) as f64);
    if let Some((t, f, idle)) = hard {
        for r in &mut rows {
            r.triangles_vs_hard = r.triangles as f64 / t as f64;
            r.fragments_vs_hard = ratio(r.fragments, f);
            r.idle_fragments_vs_hard = ratio(r.idle_fragments, idle);
        }
    }
    Ok(rows)
}
