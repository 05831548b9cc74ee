//! Captured frames: 8-bit sRGB RGBA pixels, compared and laid out side by side. Nothing here
//! depends on Bevy, so the tests run the same code on synthetic frames.

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
