//! Where a transition shows the wrong thing at its objects' outlines: see-through (the scenery
//! shown where each level alone covers the pixel) and ghosts (a transitioning object shown where
//! neither level does), counted with `lodkit::metrics` on every frame of the transition, still
//! and moving camera, as lodkit_bevy's frame-sequential example counts them.

use glam::Vec4;

use crate::demo::error::DemoError;
use crate::demo::fixtures::render::{Background, LEAD_FRAMES, RunSpec, SceneRenderer, Technique};
use lodkit::gpu::GpuContext;

/// What each level alone covers ([`SceneRenderer::lod_masks`]) at every frame of the
/// transition, for one camera: entry `k` is frame `LEAD_FRAMES + k`, `[fine, coarse]`.
pub(super) struct LevelMasks(Vec<[Vec<bool>; 2]>);

impl LevelMasks {
    /// The masks of the static or `moving` camera's transition frames.
    pub(super) fn render(
        gpu: &GpuContext,
        renderer: &SceneRenderer,
        moving: bool,
    ) -> Result<Self, DemoError> {
        let frames = (0..=renderer.transition_frames())
            .map(|k| renderer.lod_masks(gpu, moving, LEAD_FRAMES + k))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self(frames))
    }
}

/// What [`measure`] counted for one technique.
pub(super) struct CoverageFigures {
    /// Share of the transitioning objects' interior (pixels both levels cover) where the
    /// scenery shows, static camera, middle frame.
    pub see_through_share: f32,
    /// That frame's false-color map: interior gray, see-through red.
    pub map: image::RgbaImage,
    /// Moving camera, middle frame: see-through plus ghost pixels over the pixels either level
    /// covers.
    pub silhouette_error: f32,
    /// See-through pixel-frames over the transition's frames, both cameras.
    pub see_through: usize,
    /// Ghost pixel-frames over the transition's frames, both cameras.
    pub ghosts: usize,
}

/// Renders `technique`'s transition over black and over white scenery (every object but the
/// transitioning ones in the flat color) with each camera and counts, frame by frame against
/// `masks` (`[static, moving]`), the pixels where the renders differ though both levels cover
/// them (see-through) and those the render over black lights though neither covers them
/// (ghosts). Single-frame techniques draw the frame's own geometry; frame-sequential LOD
/// reprojects last frame's buffer, and this is where that shows.
pub(super) fn measure(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    technique: Technique,
    masks: &[LevelMasks; 2],
    size: (u32, u32),
) -> Result<CoverageFigures, DemoError> {
    let internal = |e: lodkit::metrics::MetricsError| DemoError::Internal(e.to_string());
    let middle = renderer.transition_frames() / 2;
    let mut figures = CoverageFigures {
        see_through_share: 0.0,
        map: image::RgbaImage::new(size.0, size.1),
        silhouette_error: 0.0,
        see_through: 0,
        ghosts: 0,
    };
    for (moving, masks) in [false, true].into_iter().zip(masks) {
        let frames = over_black_and_white(gpu, renderer, technique, moving)?;
        if frames.len() != masks.0.len() {
            return Err(DemoError::Internal(format!(
                "{} frames over two backgrounds for {} frames of masks",
                frames.len(),
                masks.0.len()
            )));
        }
        for (k, (over, [fine, coarse])) in frames.iter().zip(&masks.0).enumerate() {
            let n = fine.len().min(coarse.len()).min(over[0].len() / 4);
            let (fine, coarse) = (&fine[..n], &coarse[..n]);
            let opaque: Vec<bool> = (0..n).map(|i| !shows_background(over, i)).collect();
            let lit: Vec<bool> = (0..n)
                .map(|i| over[0][i * 4..i * 4 + 3].iter().any(|&c| c > 8))
                .collect();
            let holes = lodkit::metrics::see_through(fine, coarse, &opaque).map_err(internal)?;
            let ghosts = lodkit::metrics::ghosts(fine, coarse, &lit).map_err(internal)?;
            figures.see_through += holes;
            figures.ghosts += ghosts;
            if k != middle {
                continue;
            }
            let interior = (0..n).filter(|&i| fine[i] && coarse[i]).count();
            let union = (0..n).filter(|&i| fine[i] || coarse[i]).count();
            if moving {
                figures.silhouette_error = share(holes + ghosts, union);
            } else {
                figures.see_through_share = share(holes, interior);
                for (i, px) in figures.map.pixels_mut().enumerate().take(n) {
                    *px = match (fine[i] && coarse[i], opaque[i]) {
                        (false, _) => image::Rgba([20, 20, 30, 255]),
                        (true, false) => image::Rgba([235, 40, 30, 255]),
                        (true, true) => image::Rgba([150, 150, 150, 255]),
                    };
                }
            }
        }
    }
    Ok(figures)
}

/// Every transition frame of `technique` over black and over white scenery, with the static or
/// `moving` camera: entry `k` is frame `LEAD_FRAMES + k`, `[over black, over white]`.
fn over_black_and_white(
    gpu: &GpuContext,
    renderer: &SceneRenderer,
    technique: Technique,
    moving: bool,
) -> Result<Vec<[Vec<u8>; 2]>, DemoError> {
    let span = LEAD_FRAMES..=LEAD_FRAMES + renderer.transition_frames();
    let in_span = |f: usize| span.contains(&f);
    let mut over = [Vec::new(), Vec::new()];
    for (flat, frames) in [Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::ONE]
        .iter()
        .zip(&mut over)
    {
        let spec = RunSpec {
            technique,
            moving,
            transition: true,
            hold_level: 0,
            background: Background::Flat(*flat),
        };
        renderer.run(gpu, spec, &in_span, &mut |_, f| frames.push(f.pixels), None)?;
    }
    let [black, white] = over;
    Ok(black.into_iter().zip(white).map(|(b, w)| [b, w]).collect())
}

/// Whether pixel `i` differs between the two renders `over` (the background shows there).
fn shows_background(over: &[Vec<u8>; 2], i: usize) -> bool {
    (0..3).any(|c| over[0][i * 4 + c].abs_diff(over[1][i * 4 + c]) > 2)
}

/// `part` over `whole`, 0 when `whole` is.
fn share(part: usize, whole: usize) -> f32 {
    if whole == 0 {
        0.0
    } else {
        part as f32 / whole as f32
    }
}
