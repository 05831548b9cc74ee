//! Measures of how a LOD transition looks, on frames read back from any renderer (RGBA8, row
//! after row, alpha ignored): what lodkit's demo and the Bevy examples report, written once.
//!
//! Each run of a technique is measured against a reference run that shows no transition (the
//! same camera path with one level alone), so that what the camera or the scene changes by
//! itself is not charged to the transition. Per pixel and channel, the *deviation* of frame
//! `i` is `d[i] = run[i] - reference[i]`; the transition moves it from `d[0]` (the first
//! level's look) to `d[last]`.
//!
//! - [`transition_change`] and [`pop`]: the share of the transition's change that lands in a
//!   single frame (1: a hard switch; 1/N: spread evenly over N frames).
//! - [`FlickerMeter`] / [`Flicker`]: the total frame-to-frame change of the deviations over
//!   their net change (1: every pixel goes once, in one direction; a pixel that blinks back and
//!   forth adds change and no net change), and the count of per-pixel direction reversals. Pop
//!   cannot see flicker (a transition that blinks every frame spreads its change evenly and
//!   scores a low pop); this does.
//! - [`see_through`] and [`ghosts`]: pixels both levels cover where a frame shows the
//!   background, and pixels neither covers where it shows an object.
//! - [`psnr_rgba8`], [`ssim_rgba8`] and [`median`].
//!
//! ```
//! use lodkit::metrics::{FlickerMeter, pop, transition_change};
//! let reference = [[100u8, 100, 100, 255]; 4];
//! // A pixel that goes from 100 to 200 in two steps, and one that blinks.
//! let smooth = [[100u8, 100, 100, 255], [150, 150, 150, 255], [200, 200, 200, 255], [200, 200, 200, 255]];
//! let blinking = [[100u8, 100, 100, 255], [200, 200, 200, 255], [100, 100, 100, 255], [200, 200, 200, 255]];
//! let mut meter = FlickerMeter::default();
//! for (frame, r) in smooth.iter().zip(&reference) {
//!     meter.push(frame, r).unwrap();
//! }
//! assert_eq!(meter.finish().ratio(), 1.0);
//! let mut meter = FlickerMeter::default();
//! for (frame, r) in blinking.iter().zip(&reference) {
//!     meter.push(frame, r).unwrap();
//! }
//! let flicker = meter.finish();
//! assert_eq!((flicker.ratio(), flicker.reversals), (3.0, 2)); // it turned back twice
//! // Pop sees the blinking run as a smooth one: one third of the change per frame.
//! let change: Vec<f64> = (1..4)
//!     .map(|i| transition_change(&blinking[i - 1], &blinking[i], &reference[i - 1], &reference[i]))
//!     .collect();
//! assert!((pop(&change) - 1.0 / 3.0).abs() < 1e-12);
//! ```

use thiserror::Error;

mod coverage;
pub use coverage::{coverage_distance, ghosts, see_through};

/// A pixel's step smaller than this in every channel (in 8-bit levels) is not a direction: it
/// neither counts as a reversal nor sets the direction a later step reverses (rounding in a renderer's
/// blend or lighting moves a level or two either way).
pub const REVERSAL_MIN_STEP: i16 = 3;

/// A frame that cannot be measured against the others.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum MetricsError {
    /// The frame, or its reference, has another byte length than the first frame measured
    /// (frames are RGBA8, 4 bytes a pixel).
    #[error(
        "frame {frame}: {what} has {len} bytes where the first frame had {expected} (RGBA8 frames of one size)"
    )]
    SizeMismatch {
        /// Index of the frame pushed (0 = the first).
        frame: usize,
        /// "the frame" or "its reference".
        what: &'static str,
        /// Its length in bytes.
        len: usize,
        /// The first frame's length in bytes.
        expected: usize,
    },
    /// A frame of zero bytes, or a length that is not a whole number of RGBA8 pixels.
    #[error("frame {frame}: {len} bytes is not a whole, non-empty RGBA8 image")]
    NotRgba8 {
        /// Index of the frame pushed.
        frame: usize,
        /// Its length in bytes.
        len: usize,
    },
    /// A coverage mask ([`see_through`], [`ghosts`]) with another pixel count than `fine`.
    #[error("the {what} mask has {len} pixels where the fine one has {expected}")]
    MaskMismatch {
        /// "coarse" or "shown" (or, for [`coverage_distance`], "first" or "second").
        what: &'static str,
        /// Its length in pixels.
        len: usize,
        /// The fine mask's length.
        expected: usize,
    },
}

/// Mean absolute per-channel change, in 0..1 over the RGB channels, of `(a1 - r1) - (a0 - r0)`:
/// how much a run's picture changed from frame `a0` to `a1` beyond what its reference changed
/// from `r0` to `r1`. Stops at the shortest of the four.
///
/// ```
/// # use lodkit::metrics::transition_change;
/// let (grey, white) = ([128u8, 128, 128, 255], [255u8, 255, 255, 255]);
/// assert_eq!(transition_change(&grey, &white, &grey, &grey), 127.0 / 255.0);
/// assert_eq!(transition_change(&grey, &white, &grey, &white), 0.0); // the reference's own change
/// ```
pub fn transition_change(a0: &[u8], a1: &[u8], r0: &[u8], r1: &[u8]) -> f64 {
    let n = a0.len().min(a1.len()).min(r0.len()).min(r1.len()) / 4 * 4;
    let mut sum = 0u64;
    for i in (0..n).filter(|i| i % 4 != 3) {
        let d = (i32::from(a1[i]) - i32::from(r1[i])) - (i32::from(a0[i]) - i32::from(r0[i]));
        sum += u64::from(d.unsigned_abs());
    }
    sum as f64 / (n / 4 * 3).max(1) as f64 / 255.0
}

/// Pop: the largest share of the total in one entry of a run's per-frame
/// [`transition_change`]s (1 = all the change in one frame, as a hard switch; 1/N = spread
/// evenly over N frames); 0 when nothing changed.
///
/// ```
/// # use lodkit::metrics::pop;
/// assert_eq!(pop(&[0.0, 0.0, 3.0, 0.0]), 1.0);
/// assert_eq!(pop(&[1.0, 1.0, 1.0, 1.0]), 0.25);
/// assert_eq!(pop(&[]), 0.0);
/// ```
pub fn pop(changes: &[f64]) -> f64 {
    let total: f64 = changes.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    changes.iter().copied().fold(0.0, f64::max) / total
}

/// What a [`FlickerMeter`] measured over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Flicker {
    /// Frames measured.
    pub frames: usize,
    /// The sum over frames of the mean absolute frame-to-frame change of the deviations, per
    /// channel, in 0..1 (the sum of the run's [`transition_change`]s).
    pub change: f64,
    /// The mean absolute change of the deviations from the first frame to the last, per
    /// channel, in 0..1.
    pub net: f64,
    /// Per pixel, the times its deviation turned back: a step (of at least
    /// [`REVERSAL_MIN_STEP`] levels in some channel) against the last such step (their RGB dot
    /// product negative), summed over the pixels.
    pub reversals: u64,
    /// `change` and `net` in 8-bit levels, summed (the ratio is theirs, exactly).
    levels: (u64, u64),
}

impl Flicker {
    /// `change / net`: 1 when every pixel moves once, in one direction (any smooth transition
    /// or a hard switch); each time a pixel goes back and forth adds 2 of its step. 1 when
    /// nothing changed; infinite when pixels changed and came back to where they started.
    pub fn ratio(&self) -> f64 {
        match self.levels {
            (0, _) => 1.0,
            (_, 0) => f64::INFINITY,
            (change, net) => change as f64 / net as f64,
        }
    }
}

/// Accumulates a [`Flicker`] frame by frame, so a renderer can stream its frames: per pixel
/// it keeps the first and the last deviation and the last step that had a direction.
#[derive(Clone, Debug, Default)]
pub struct FlickerMeter {
    first: Vec<i16>,
    last: Vec<i16>,
    direction: Vec<[i16; 3]>,
    change: u64,
    reversals: u64,
    frames: usize,
}

impl FlickerMeter {
    /// Adds the next frame of the run and the reference's frame at the same time (RGBA8 of
    /// equal length, the length of the first frame pushed).
    pub fn push(&mut self, frame: &[u8], reference: &[u8]) -> Result<(), MetricsError> {
        let index = self.frames;
        if frame.is_empty() || !frame.len().is_multiple_of(4) {
            return Err(MetricsError::NotRgba8 {
                frame: index,
                len: frame.len(),
            });
        }
        let expected = if index == 0 {
            frame.len()
        } else {
            self.first.len() / 3 * 4
        };
        for (what, len) in [
            ("the frame", frame.len()),
            ("its reference", reference.len()),
        ] {
            if len != expected {
                return Err(MetricsError::SizeMismatch {
                    frame: index,
                    what,
                    len,
                    expected,
                });
            }
        }
        let deviations = frame
            .chunks_exact(4)
            .zip(reference.chunks_exact(4))
            .flat_map(|(p, q)| (0..3).map(move |c| i16::from(p[c]) - i16::from(q[c])));
        if index == 0 {
            self.first = deviations.collect();
            self.last = self.first.clone();
            self.direction = vec![[0; 3]; self.first.len() / 3];
        } else {
            let now: Vec<i16> = deviations.collect();
            for ((d, last), direction) in now
                .chunks_exact(3)
                .zip(self.last.chunks_exact_mut(3))
                .zip(self.direction.iter_mut())
            {
                let step: [i16; 3] = std::array::from_fn(|c| d[c] - last[c]);
                self.change += step
                    .iter()
                    .map(|s| u64::from(s.unsigned_abs()))
                    .sum::<u64>();
                if step.iter().any(|s| s.abs() >= REVERSAL_MIN_STEP) {
                    let turn: i32 = (0..3)
                        .map(|c| i32::from(step[c]) * i32::from(direction[c]))
                        .sum();
                    self.reversals += u64::from(turn < 0);
                    *direction = step;
                }
                last.copy_from_slice(d);
            }
        }
        self.frames += 1;
        Ok(())
    }

    /// The figures so far.
    pub fn finish(&self) -> Flicker {
        let channels = self.first.len().max(1) as f64;
        let net: u64 = self
            .first
            .iter()
            .zip(&self.last)
            .map(|(a, b)| u64::from((b - a).unsigned_abs()))
            .sum();
        Flicker {
            frames: self.frames,
            change: self.change as f64 / channels / 255.0,
            net: net as f64 / channels / 255.0,
            reversals: self.reversals,
            levels: (self.change, net),
        }
    }
}

/// [`Flicker`] of a whole run against its reference run (frames in order; the shorter of the
/// two sets the length).
pub fn flicker<F: AsRef<[u8]>, R: AsRef<[u8]>>(
    run: &[F],
    reference: &[R],
) -> Result<Flicker, MetricsError> {
    let mut meter = FlickerMeter::default();
    for (frame, r) in run.iter().zip(reference) {
        meter.push(frame.as_ref(), r.as_ref())?;
    }
    Ok(meter.finish())
}

/// Peak signal-to-noise ratio in dB between two RGBA8 images (RGB channels only); +inf when equal,
/// NaN when the two differ in length or are empty.
///
/// ```
/// # use lodkit::metrics::psnr_rgba8;
/// let a = [10u8, 20, 30, 255];
/// assert_eq!(psnr_rgba8(&a, &a), f32::INFINITY);
/// let b = [11u8, 20, 30, 0];
/// assert!((psnr_rgba8(&a, &b) - 10.0 * (255.0f32 * 255.0 * 3.0).log10()).abs() < 1e-3);
/// ```
pub fn psnr_rgba8(a: &[u8], b: &[u8]) -> f32 {
    if a.len() != b.len() || a.len() < 4 {
        return f32::NAN;
    }
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for c in 0..3 {
            let d = f64::from(pa[c]) - f64::from(pb[c]);
            sum += d * d;
            n += 1;
        }
    }
    if sum == 0.0 {
        return f32::INFINITY;
    }
    (10.0 * (255.0f64 * 255.0 / (sum / n as f64)).log10()) as f32
}

/// The median of `values` (the mean of the middle two for an even count; NaN when empty). NaNs
/// sort last.
///
/// ```
/// # use lodkit::metrics::median;
/// assert_eq!(median(&[4.0, 1.0, 3.0]), 3.0);
/// assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
/// assert!(median(&[]).is_nan());
/// ```
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// Mean structural similarity (SSIM, Wang et al. 2004) of two RGBA8 images of `width` pixels per
/// row, on luma (Rec. 601) over 8x8 windows every 4 pixels, with the usual constants
/// (K1 = 0.01, K2 = 0.03, L = 255): 1 for equal images, lower as structure differs. NaN when
/// the sizes differ or the images are smaller than one window. The windows are uniform (not
/// Gaussian) and use population variances, so figures differ slightly from reference
/// implementations with an 11x11 Gaussian.
///
/// ```
/// # use lodkit::metrics::ssim_rgba8;
/// let a: Vec<u8> = (0..16 * 16).flat_map(|i| [(i * 7 % 256) as u8, 0, 0, 255]).collect();
/// assert!((ssim_rgba8(&a, &a, 16) - 1.0).abs() < 1e-6);
/// let flat = vec![128u8; a.len()];
/// assert!(ssim_rgba8(&a, &flat, 16) < 0.2);
/// // Two flat grays: no structure, only the luminance term (2 ma mb + C1) / (ma^2 + mb^2 + C1).
/// let (g100, g150) = (vec![100u8; 16 * 16 * 4], vec![150u8; 16 * 16 * 4]);
/// let c1 = (0.01f64 * 255.0).powi(2);
/// let expected = (2.0 * 100.0 * 150.0 + c1) / (100.0f64.powi(2) + 150.0f64.powi(2) + c1);
/// assert!((f64::from(ssim_rgba8(&g100, &g150, 16)) - expected).abs() < 1e-4);
/// ```
pub fn ssim_rgba8(a: &[u8], b: &[u8], width: u32) -> f32 {
    const WIN: usize = 8;
    let w = width as usize;
    if a.len() != b.len() || w < WIN || !a.len().is_multiple_of(4 * w) || a.len() / (4 * w) < WIN {
        return f32::NAN;
    }
    let h = a.len() / (4 * w);
    let luma = |img: &[u8]| -> Vec<f64> {
        img.chunks_exact(4)
            .map(|p| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]))
            .collect()
    };
    let (la, lb) = (luma(a), luma(b));
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let (mut sum, mut windows) = (0.0f64, 0usize);
    for y0 in (0..=h - WIN).step_by(4) {
        for x0 in (0..=w - WIN).step_by(4) {
            let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for y in y0..y0 + WIN {
                for x in x0..x0 + WIN {
                    let (p, q) = (la[y * w + x], lb[y * w + x]);
                    sa += p;
                    sb += q;
                    saa += p * p;
                    sbb += q * q;
                    sab += p * q;
                }
            }
            let n = (WIN * WIN) as f64;
            let (ma, mb) = (sa / n, sb / n);
            let va = saa / n - ma * ma;
            let vb = sbb / n - mb * mb;
            let cov = sab / n - ma * mb;
            sum += ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            windows += 1;
        }
    }
    (sum / windows as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames of one pixel, grey levels `v` against a constant reference of 0.
    fn run(levels: &[u8]) -> Flicker {
        let frames: Vec<[u8; 4]> = levels.iter().map(|&v| [v, v, v, 255]).collect();
        let reference = vec![[0u8, 0, 0, 255]; levels.len()];
        flicker(&frames, &reference).unwrap()
    }

    #[test]
    fn a_hard_switch_and_a_ramp_do_not_flicker() {
        for levels in [&[0u8, 0, 90, 90][..], &[0, 30, 60, 90], &[0, 0, 0, 0]] {
            let f = run(levels);
            assert_eq!((f.ratio(), f.reversals), (1.0, 0), "{levels:?}");
        }
    }

    #[test]
    fn an_alternating_sequence_scores_as_flicker() {
        // 0 -> 90 -> 0 -> 90 -> 0 -> 90: five steps of 90 for a net change of 90.
        let f = run(&[0, 90, 0, 90, 0, 90]);
        assert_eq!(f.ratio(), 5.0);
        // It turned back four times.
        assert_eq!(f.reversals, 4);
        // Back where it started: all change, no net change.
        assert_eq!(run(&[0, 90, 0]).ratio(), f64::INFINITY);
    }

    #[test]
    fn steps_below_the_threshold_are_no_direction() {
        // Up by 90 with a 2-level wobble: no reversal, and the wobble's change counts.
        let f = run(&[0, 45, 43, 45, 90]);
        assert_eq!(f.reversals, 0);
        assert!((f.ratio() - 94.0 / 90.0).abs() < 1e-12);
        // A 3-level step back is a reversal.
        assert_eq!(run(&[0, 45, 42, 90]).reversals, 2);
    }

    #[test]
    fn a_colour_change_in_one_direction_is_no_reversal() {
        // Orange to blue in two steps: red goes down while blue goes up, both steps alike.
        let frames = [
            [240u8, 140, 50, 255],
            [145, 160, 130, 255],
            [50, 180, 215, 255],
        ];
        let reference = [[240u8, 140, 50, 255]; 3];
        let f = flicker(&frames, &reference).unwrap();
        assert_eq!((f.ratio(), f.reversals), (1.0, 0));
    }

    #[test]
    fn the_reference_change_is_not_the_transitions() {
        // The run and the reference both change (a moving camera): no deviation moves.
        let frames = [[10u8, 20, 30, 255], [200, 20, 30, 255], [10, 20, 30, 255]];
        assert_eq!(flicker(&frames, &frames).unwrap().change, 0.0);
        assert_eq!(flicker(&frames, &frames).unwrap().ratio(), 1.0);
    }

    #[test]
    fn frames_of_another_size_are_refused_by_index() {
        let mut meter = FlickerMeter::default();
        meter.push(&[0; 8], &[0; 8]).unwrap();
        assert_eq!(
            meter.push(&[0; 8], &[0; 4]),
            Err(MetricsError::SizeMismatch {
                frame: 1,
                what: "its reference",
                len: 4,
                expected: 8
            })
        );
        assert_eq!(
            FlickerMeter::default().push(&[0; 6], &[0; 6]),
            Err(MetricsError::NotRgba8 { frame: 0, len: 6 })
        );
        let message = meter.push(&[0; 4], &[0; 4]).unwrap_err().to_string();
        assert!(
            message.starts_with("frame 1: the frame has 4 bytes"),
            "{message}"
        );
    }
}
