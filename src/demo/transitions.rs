//! The transition metrics: pop, see-through and cost of every technique on one scene, with the
//! strips and false-color images that show them.

use std::path::Path;

use glam::Vec4;
use serde::Serialize;

use super::DemoError;
use super::render::{Background, Frame, LEAD_FRAMES, RunSpec, SceneRenderer, Technique};
use crate::combine::PixelSource;
use crate::gpu::GpuContext;

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
    /// Share of the transitioning objects' interior (pixels both LODs cover) where the
    /// background contributes to the middle frame.
    pub see_through: f32,
    /// Triangles submitted over the transition, relative to a hard switch.
    pub triangles_vs_hard: f64,
    /// Counted fragments over the transition, relative to a hard switch (None when the
    /// adapter's counter is not a count).
    pub fragments_vs_hard: Option<f64>,
    /// Triangles submitted over the transition.
    pub triangles: u64,
    /// Counted fragments over the transition (frame-sequential: plus one per pixel for the
    /// combine pass); None when the adapter's counter is not a count.
    pub fragments: Option<u64>,
    /// Per-frame change attributable to the transition, static camera (mean |delta| per channel,
    /// 0..1), from frame 1 on.
    pub change_static: Vec<f32>,
    /// The same with the moving camera.
    pub change_moving: Vec<f32>,
}

/// Mean absolute per-channel difference of `(a1 - r1) - (a0 - r0)` over RGB, in 0..1: how much
/// the picture changed from one frame to the next beyond what the reference run changed.
pub fn transition_change(a0: &[u8], a1: &[u8], r0: &[u8], r1: &[u8]) -> f32 {
    let n = a0.len().min(a1.len()).min(r0.len()).min(r1.len());
    let mut sum = 0.0f64;
    for i in (0..n).filter(|i| i % 4 != 3) {
        let d = (i32::from(a1[i]) - i32::from(r1[i])) - (i32::from(a0[i]) - i32::from(r0[i]));
        sum += f64::from(d.unsigned_abs());
    }
    let channels = (n / 4 * 3).max(1);
    (sum / channels as f64 / 255.0) as f32
}

/// The largest share of the total in one entry (0 when nothing changed).
///
/// ```
/// # use lodkit::demo::transitions::pop;
/// assert_eq!(pop(&[0.0, 0.0, 3.0, 0.0]), 1.0);
/// assert_eq!(pop(&[1.0, 1.0, 1.0, 1.0]), 0.25);
/// ```
pub fn pop(change: &[f32]) -> f32 {
    let total: f32 = change.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    change.iter().copied().fold(0.0, f32::max) / total
}

/// Images of one technique's run, written by [`measure_scene`].
struct Images {
    strip: image::RgbaImage,
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

/// Runs `technique` with the static or moving camera, with and without transition, and returns
/// the per-frame change and triangles and fragments over the transition, drawing the strip into
/// `images`. Only the reference run of a moving camera is kept whole (a frame-sequential run
/// cannot be interleaved with another); the transition run streams.
fn change_run(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    technique: Technique,
    moving: bool,
    images: &mut Images,
    size: (u32, u32),
) -> Result<(Vec<f32>, u64, u64), DemoError> {
    let all = |_: usize| true;
    let spec = RunSpec {
        technique,
        moving,
        transition: true,
        background: Background::Scene,
    };
    let reference_spec = RunSpec {
        transition: false,
        ..spec
    };
    let mut reference: Vec<Vec<u8>> = Vec::new();
    if moving {
        renderer.run(
            gpu,
            reference_spec,
            &all,
            &mut |_, f| reference.push(f.pixels),
            None,
        );
    } else {
        // A static camera without transition renders the same picture every frame.
        let first = |f: usize| f == 0;
        renderer.run(
            gpu,
            reference_spec,
            &first,
            &mut |_, f| reference.push(f.pixels),
            None,
        );
    }
    let reference_at = |f: usize| reference.get(f).or(reference.last());
    let span = LEAD_FRAMES..=LEAD_FRAMES + renderer.transition_frames();
    let strip = strip_frames(renderer);
    let (mut change, mut triangles, mut fragments) = (Vec::new(), 0u64, 0u64);
    let mut previous: Option<Vec<u8>> = None;
    let mut failed = None;
    renderer.run(
        gpu,
        spec,
        &all,
        &mut |f, frame: Frame| {
            if let (Some(prev), Some(r0), Some(r1)) = (
                &previous,
                reference_at(f.saturating_sub(1)),
                reference_at(f),
            ) {
                change.push(transition_change(prev, &frame.pixels, r0, r1));
            }
            if span.contains(&f) {
                triangles += frame.triangles;
                fragments += frame.fragments;
            }
            if let Some(slot) = strip.iter().position(|&s| s == f) {
                match to_image(size, frame.pixels.clone()) {
                    Ok(tile) => image::imageops::replace(
                        &mut images.strip,
                        &tile,
                        i64::from(slot as u32 * size.0),
                        0,
                    ),
                    Err(e) => failed = Some(e),
                }
            }
            previous = Some(frame.pixels);
        },
        None,
    );
    match failed {
        Some(e) => Err(e),
        None => Ok((change, triangles, fragments)),
    }
}

/// See-through at the middle frame: renders it over black and over white scenery; interior
/// pixels that differ show the background. Returns the share and a false-color map (interior
/// gray, see-through red).
fn see_through(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    technique: Technique,
    masks: &[Vec<bool>; 2],
    size: (u32, u32),
) -> Result<(f32, image::RgbaImage), DemoError> {
    let middle = LEAD_FRAMES + renderer.transition_frames() / 2;
    let only_middle = |f: usize| f == middle;
    let mut over = Vec::new();
    for flat in [Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::ONE] {
        let spec = RunSpec {
            technique,
            moving: false,
            transition: true,
            background: Background::Flat(flat),
        };
        let mut pixels = Vec::new();
        renderer.run(gpu, spec, &only_middle, &mut |_, f| pixels = f.pixels, None);
        over.push(pixels);
    }
    let (mut interior, mut seen) = (0usize, 0usize);
    let mut map = image::RgbaImage::new(size.0, size.1);
    for (i, px) in map.pixels_mut().enumerate() {
        if !(masks[0][i] && masks[1][i]) {
            *px = image::Rgba([20, 20, 30, 255]);
            continue;
        }
        interior += 1;
        let differs = (0..3).any(|c| over[0][i * 4 + c].abs_diff(over[1][i * 4 + c]) > 2);
        if differs {
            seen += 1;
            *px = image::Rgba([235, 40, 30, 255]);
        } else {
            *px = image::Rgba([150, 150, 150, 255]);
        }
    }
    let share = if interior == 0 {
        0.0
    } else {
        seen as f32 / interior as f32
    };
    Ok((share, map))
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
    let masks = renderer.lod_masks(gpu);
    let counts = renderer.counter().kind().is_count();
    let mut rows: Vec<TransitionMetrics> = Vec::new();
    for technique in Technique::ALL {
        let name = technique.name();
        let mut changes = Vec::new();
        let mut cost = (0, 0);
        for moving in [false, true] {
            let mut images = Images {
                strip: image::RgbaImage::new(size.0 * 7, size.1),
            };
            let (change, tris, frags) =
                change_run(gpu, renderer, technique, moving, &mut images, size)?;
            let camera = if moving { "moving" } else { "static" };
            super::save(
                &images.strip,
                &out.join(format!("strips/{scene}-{name}-{camera}.png")),
            )?;
            if !moving {
                cost = (tris, frags);
            }
            changes.push(change);
        }
        let (share, map) = see_through(gpu, renderer, technique, &masks, size)?;
        super::save(&map, &out.join(format!("see-through/{scene}-{name}.png")))?;
        if let Technique::FrameSequential(_) = technique {
            let spec = RunSpec {
                technique,
                moving: true,
                transition: true,
                background: Background::Scene,
            };
            let mut sources = Vec::new();
            renderer.run(
                gpu,
                spec,
                &|_| false,
                &mut |_, _| {},
                Some(&mut |s| sources = s),
            );
            let img = sources_image(size, &sources);
            super::save(&img, &out.join(format!("sources/{scene}-{name}.png")))?;
        }
        let moving_change = changes.pop().unwrap_or_default();
        let static_change = changes.pop().unwrap_or_default();
        rows.push(TransitionMetrics {
            scene: scene.to_owned(),
            technique: name.to_owned(),
            pop_static: pop(&static_change),
            pop_moving: pop(&moving_change),
            see_through: share,
            triangles_vs_hard: 0.0,
            fragments_vs_hard: None,
            triangles: cost.0,
            fragments: counts.then_some(cost.1),
            change_static: static_change,
            change_moving: moving_change,
        });
        tick(name);
    }
    let hard = rows
        .iter()
        .find(|r| r.technique == "hard-switch")
        .map(|r| (r.triangles.max(1), r.fragments.map(|f| f.max(1))));
    if let Some((t, f)) = hard {
        for r in &mut rows {
            r.triangles_vs_hard = r.triangles as f64 / t as f64;
            r.fragments_vs_hard = r.fragments.zip(f).map(|(a, b)| a as f64 / b as f64);
        }
    }
    Ok(rows)
}
