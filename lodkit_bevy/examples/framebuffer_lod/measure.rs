//! What the framebuffer_lod example measures on its captured frames: depth edges from the depth
//! probe, errors against the full-resolution effect, error maps, and how long the controller took
//! to settle. Nothing here depends on Bevy; `tests/framebuffer_lod.rs` holds it to hand-made
//! frames.

use crate::frames::Frame;

/// A neighbour this many times nearer or farther makes a pixel a depth discontinuity.
pub const EDGE_DEPTH_RATIO: f32 = 1.3;
/// Pixels within this many pixels (Chebyshev distance) of a discontinuity count as edge pixels.
pub const EDGE_RADIUS: i32 = 2;

/// sRGB-encoded 8-bit value to linear.
fn srgb_to_linear(v: u8) -> f32 {
    let c = f32::from(v) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// View depth per pixel from a depth-probe frame (red = log2(1 + depth) / 16, sRGB-encoded).
pub fn probe_depths(probe: &Frame) -> Vec<f32> {
    probe
        .pixels()
        .map(|p| (srgb_to_linear(p[0]) * 16.0).exp2() - 1.0)
        .collect()
}

/// Per pixel: within [`EDGE_RADIUS`] of a pixel whose right or lower neighbour's depth differs by
/// more than [`EDGE_DEPTH_RATIO`] times.
pub fn edge_mask(depths: &[f32], width: u32, height: u32) -> Vec<bool> {
    let (w, h) = (width as i32, height as i32);
    let at = |x: i32, y: i32| depths[(y * w + x) as usize].max(1e-3);
    let mut edge = vec![false; depths.len()];
    for y in 0..h {
        for x in 0..w {
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if nx < w && ny < h {
                    let (a, b) = (at(x, y), at(nx, ny));
                    if a.max(b) / a.min(b) > EDGE_DEPTH_RATIO {
                        edge[(y * w + x) as usize] = true;
                        edge[(ny * w + nx) as usize] = true;
                    }
                }
            }
        }
    }
    let mut near = vec![false; depths.len()];
    for y in 0..h {
        for x in 0..w {
            if !edge[(y * w + x) as usize] {
                continue;
            }
            for dy in -EDGE_RADIUS..=EDGE_RADIUS {
                for dx in -EDGE_RADIUS..=EDGE_RADIUS {
                    let (px, py) = (x + dx, y + dy);
                    if px >= 0 && py >= 0 && px < w && py < h {
                        near[(py * w + px) as usize] = true;
                    }
                }
            }
        }
    }
    near
}

/// Mean absolute RGB difference (8-bit steps per channel) over the pixels `mask` selects; 0 for
/// an empty mask.
pub fn mean_abs_error(a: &Frame, b: &Frame, mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0u64, 0u64);
    for ((p, q), &m) in a.pixels().zip(b.pixels()).zip(mask) {
        if m {
            sum += p
                .iter()
                .zip(q)
                .map(|(&x, y)| u64::from(x.abs_diff(y)))
                .sum::<u64>();
            n += 3;
        }
    }
    if n == 0 { 0.0 } else { sum as f64 / n as f64 }
}

/// |a - b| per channel times `gain`, as an image (black: no error).
pub fn error_map(a: &Frame, b: &Frame, gain: u8) -> Frame {
    let rgba = a
        .rgba
        .chunks_exact(4)
        .zip(b.rgba.chunks_exact(4))
        .flat_map(|(p, q)| {
            let e = |c: usize| p[c].abs_diff(q[c]).saturating_mul(gain);
            [e(0), e(1), e(2), 255]
        })
        .collect();
    Frame::new(a.width, a.height, rgba)
}

/// The median of `values` (`lodkit::metrics::median`, which lodkit's demo uses too).
pub fn median(values: &[f32]) -> f32 {
    let v: Vec<f64> = values.iter().map(|&x| f64::from(x)).collect();
    lodkit::metrics::median(&v) as f32
}

/// The `window`-frame median of `times` from frame `k` on, over `target` (NaN past the end).
pub fn median_ratio(times: &[f32], target: f32, window: usize, k: usize) -> f32 {
    let Some(w) = times.get(k..k + window.max(1)) else {
        return f32::NAN;
    };
    median(w) / target
}

/// Frames from a workload step until the frame time is back within `tolerance` (a fraction) of
/// `target`: the first frame `k` from which the `window`-frame median stays inside the band for
/// `hold` consecutive frames. `times[0]` is the frame time known at the step's first frame, so a
/// late measurement counts against the controller. `None` when that never happens.
pub fn settle_frames(
    times: &[f32],
    target: f32,
    tolerance: f32,
    window: usize,
    hold: usize,
) -> Option<usize> {
    let inside = |k: usize| (median_ratio(times, target, window, k) - 1.0).abs() <= tolerance;
    (0..times.len()).find(|&k| (k..k + hold.max(1)).all(inside))
}

/// How far a step pushed the frame time: the largest |median / target - 1| over the
/// `window`-frame medians.
pub fn excursion(times: &[f32], target: f32, window: usize) -> f32 {
    (0..times.len())
        .map(|k| (median_ratio(times, target, window, k) - 1.0).abs())
        .filter(|r| r.is_finite())
        .fold(0.0, f32::max)
}

/// Relative spread of frame times measured at one r: 1.4826 x the median absolute deviation over
/// the median (a standard deviation that one stalled frame does not inflate); 0 when empty.
pub fn relative_spread(times: &[f32]) -> f32 {
    let m = median(times);
    let deviations: Vec<f32> = times.iter().map(|t| (t - m).abs()).collect();
    let spread = 1.4826 * median(&deviations) / m;
    if spread.is_finite() { spread } else { 0.0 }
}
