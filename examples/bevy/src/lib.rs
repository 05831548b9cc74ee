//! Frame analysis for the lodkit Bevy example: the captured frames, the PNG strip layout and the
//! two checks a complementary screen-door crossfade must pass.
//!
//! Nothing here depends on Bevy, so `tests/strip.rs` can hold the checks against synthetic frames
//! (a hard pop, a non-complementary dither) without a GPU, and the binary runs the same code on
//! what Bevy rendered.

/// Largest share of the first-to-last change that one frame-to-frame step may account for.
pub const MAX_STEP_SHARE: f64 = 0.4;

/// Per-channel tolerance (in 8-bit sRGB steps) when telling the background from the object.
pub const BACKGROUND_TOLERANCE: u8 = 2;

/// One captured frame: tightly packed 8-bit sRGB RGBA, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba: Vec<u8>,
}

impl Frame {
    /// A frame from packed RGBA bytes; panics if the length does not match the size.
    pub fn new(width: u32, height: u32, rgba: Vec<u8>) -> Self {
        assert_eq!(
            rgba.len(),
            width as usize * height as usize * 4,
            "RGBA size mismatch"
        );
        Self {
            width,
            height,
            rgba,
        }
    }

    /// A frame filled with one opaque color.
    pub fn filled(width: u32, height: u32, rgb: [u8; 3]) -> Self {
        let pixel = [rgb[0], rgb[1], rgb[2], 255];
        Self::new(
            width,
            height,
            pixel.repeat(width as usize * height as usize),
        )
    }

    /// The color at `(x, y)`, alpha dropped.
    pub fn rgb(&self, x: u32, y: u32) -> [u8; 3] {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        [self.rgba[i], self.rgba[i + 1], self.rgba[i + 2]]
    }

    /// Sets the color at `(x, y)` (opaque).
    pub fn set_rgb(&mut self, x: u32, y: u32, rgb: [u8; 3]) {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        self.rgba[i..i + 4].copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
    }

    /// Every pixel's color, row-major, alpha dropped.
    pub fn pixels(&self) -> impl Iterator<Item = [u8; 3]> + '_ {
        self.rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2]])
    }

    /// The background color, read at the top-left corner (the example keeps the object centered).
    pub fn corner(&self) -> [u8; 3] {
        self.rgb(0, 0)
    }

    /// Per pixel, row-major: is something other than `background` there?
    pub fn coverage(&self, background: [u8; 3]) -> Vec<bool> {
        self.pixels()
            .map(|p| !is_background(p, background))
            .collect()
    }

    /// Number of pixels that are not `background`.
    pub fn object_pixels(&self, background: [u8; 3]) -> usize {
        self.pixels()
            .filter(|&p| !is_background(p, background))
            .count()
    }
}

/// Whether `color` is `background` within [`BACKGROUND_TOLERANCE`] on every channel.
pub fn is_background(color: [u8; 3], background: [u8; 3]) -> bool {
    color
        .iter()
        .zip(background)
        .all(|(&c, b)| c.abs_diff(b) <= BACKGROUND_TOLERANCE)
}

/// Sum of absolute RGB differences over all pixels of two frames of the same size.
pub fn difference(a: &Frame, b: &Frame) -> u64 {
    a.pixels()
        .zip(b.pixels())
        .map(|(p, q)| {
            p.iter()
                .zip(q)
                .map(|(&x, y)| u64::from(x.abs_diff(y)))
                .sum::<u64>()
        })
        .sum()
}

/// The frames side by side, left to right (all must have the same size).
pub fn strip(frames: &[Frame]) -> Frame {
    let (w, h) = (frames[0].width as usize, frames[0].height as usize);
    let mut rgba = Vec::with_capacity(w * h * 4 * frames.len());
    for y in 0..h {
        for f in frames {
            rgba.extend_from_slice(&f.rgba[y * w * 4..(y + 1) * w * 4]);
        }
    }
    Frame::new((w * frames.len()) as u32, h as u32, rgba)
}

/// What the checks measured over a transition's frames (first frame: the outgoing LOD alone,
/// last frame: the incoming LOD alone).
#[derive(Clone, Debug, PartialEq)]
pub struct TransitionReport {
    /// `difference(frame[i], frame[i + 1])` for every step.
    pub step_changes: Vec<u64>,
    /// `difference(first, last)`: the whole change the transition has to spread out.
    pub total_change: u64,
    /// Largest step change divided by the total change (0 when nothing changed).
    pub largest_step_share: f64,
    /// Pixels covered by the object in both the first and the last frame.
    pub silhouette: usize,
    /// Per frame, how many silhouette pixels show the background (see-through).
    pub see_through: Vec<usize>,
}

impl TransitionReport {
    /// Measures `frames` against `background`; panics on fewer than two frames or mixed sizes.
    pub fn measure(frames: &[Frame], background: [u8; 3]) -> Self {
        assert!(frames.len() >= 2, "a transition needs at least two frames");
        let (first, last) = (&frames[0], &frames[frames.len() - 1]);
        assert!(
            frames
                .iter()
                .all(|f| (f.width, f.height) == (first.width, first.height)),
            "frames differ in size"
        );
        let step_changes: Vec<u64> = frames
            .windows(2)
            .map(|w| difference(&w[0], &w[1]))
            .collect();
        let total_change = difference(first, last);
        let largest = step_changes.iter().copied().max().unwrap_or(0);
        let largest_step_share = if total_change == 0 {
            0.0
        } else {
            largest as f64 / total_change as f64
        };
        // The silhouette: inside both the outgoing and the incoming LOD.
        let inside: Vec<bool> = first
            .coverage(background)
            .into_iter()
            .zip(last.coverage(background))
            .map(|(a, b)| a && b)
            .collect();
        let see_through = frames
            .iter()
            .map(|f| {
                f.pixels()
                    .zip(&inside)
                    .filter(|&(p, &both)| both && is_background(p, background))
                    .count()
            })
            .collect();
        Self {
            step_changes,
            total_change,
            largest_step_share,
            silhouette: inside.iter().filter(|&&i| i).count(),
            see_through,
        }
    }

    /// What is wrong, one sentence per problem; empty when the transition passes.
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.total_change == 0 {
            out.push("the first and last frames are identical: no LOD switch is visible".into());
        } else if self.largest_step_share > MAX_STEP_SHARE {
            let step = self
                .step_changes
                .iter()
                .enumerate()
                .max_by_key(|&(_, change)| *change)
                .map_or(0, |(i, _)| i);
            out.push(format!(
                "popping: step {step} -> {} makes {:.0}% of the whole change (at most {:.0}% allowed)",
                step + 1,
                self.largest_step_share * 100.0,
                MAX_STEP_SHARE * 100.0
            ));
        }
        if self.silhouette == 0 {
            out.push("the object is not visible in both the first and the last frame".into());
        }
        for (frame, &n) in self.see_through.iter().enumerate().filter(|(_, n)| **n > 0) {
            out.push(format!(
                "see-through: frame {frame} shows the background at {n} of the {} pixels \
                 both LODs cover",
                self.silhouette
            ));
        }
        out
    }
}
