//! Screen-door transparency with complementary patterns (DigitalRune LOD blending): the current
//! LOD is drawn with alpha -(1 - t), the next with +t; a negative alpha inverts the pattern, so
//! the two LODs cover disjoint pixel sets whose union is every pixel, at every t.
//!
//! Rust twins of `lodkit::screen_door`. Two patterns: a 4x4 ordered (Bayer) dither, the default,
//! and a 16x16 void-and-cluster blue-noise dither (shader def `LODKIT_SCREEN_DOOR_BLUE_NOISE`),
//! which has no visible grid structure at the same cost.

use std::sync::OnceLock;

use glam::Vec2;

/// Seed of the blue-noise dither array embedded in the shaders.
pub const BLUE_NOISE_SEED: u64 = 0x5c2e_e4d0;

/// The dither pattern behind the threshold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DitherPattern {
    /// 4x4 Bayer matrix, 16 levels (the shader default).
    #[default]
    Bayer4x4,
    /// 16x16 void-and-cluster blue noise, 256 levels (`LODKIT_SCREEN_DOOR_BLUE_NOISE`).
    BlueNoise16x16,
}

/// The 4x4 Bayer matrix, row-major.
pub const BAYER_4X4: [u32; 16] = [0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5];

/// Ranks 0..256 of the 16x16 blue-noise dither array (row-major), from
/// [`void_and_cluster`](crate::noise::void_and_cluster)`(16, BLUE_NOISE_SEED)`.
pub fn blue_noise_ranks() -> &'static [u32] {
    static RANKS: OnceLock<Vec<u32>> = OnceLock::new();
    RANKS.get_or_init(|| crate::noise::void_and_cluster(16, BLUE_NOISE_SEED))
}

/// Packs ranks below 2^bits, `32 / bits` per word, lowest bits first: the layout of the
/// shaders' constant tables.
pub fn pack_ranks(ranks: &[u32], bits: u32) -> Vec<u32> {
    let per_word = (32 / bits) as usize;
    ranks
        .chunks(per_word)
        .map(|c| {
            c.iter()
                .enumerate()
                .fold(0, |w, (i, r)| w | (r << (i as u32 * bits)))
        })
        .collect()
}

/// Dither threshold in (0, 1) at pixel `frag_coord` (framebuffer coordinates, pixel centers at
/// .5): (rank + 0.5) / levels.
///
/// ```
/// # use lodkit::screen_door::{screen_door_threshold, DitherPattern};
/// # use glam::Vec2;
/// assert_eq!(screen_door_threshold(Vec2::new(0.5, 0.5), DitherPattern::Bayer4x4), 0.5 / 16.0);
/// assert_eq!(screen_door_threshold(Vec2::new(5.5, 4.5), DitherPattern::Bayer4x4), 8.5 / 16.0);
/// ```
pub fn screen_door_threshold(frag_coord: Vec2, pattern: DitherPattern) -> f32 {
    let x = frag_coord.x.floor() as i32;
    let y = frag_coord.y.floor() as i32;
    match pattern {
        DitherPattern::Bayer4x4 => {
            let i = ((y & 3) * 4 + (x & 3)) as usize;
            (BAYER_4X4[i] as f32 + 0.5) / 16.0
        }
        DitherPattern::BlueNoise16x16 => {
            let i = ((y & 15) * 16 + (x & 15)) as usize;
            (blue_noise_ranks()[i] as f32 + 0.5) / 256.0
        }
    }
}

/// Whether a fragment at `frag_coord` survives screen-door alpha `alpha` with the Bayer pattern
/// (see [`screen_door_keep_with`]).
pub fn screen_door_keep(frag_coord: Vec2, alpha: f32) -> bool {
    screen_door_keep_with(DitherPattern::Bayer4x4, frag_coord, alpha)
}

/// Whether a fragment survives alpha `alpha`: for alpha >= 0, kept where threshold < alpha (a
/// share alpha of the pixels); for alpha < 0, the inverted pattern: kept where
/// threshold >= 1 + alpha (a share -alpha). So alphas -(1 - t) and +t split the pixels between
/// two LODs with no overlap and no gap.
///
/// ```
/// # use lodkit::screen_door::{screen_door_keep_with, DitherPattern};
/// # use glam::Vec2;
/// for t in [0.0, 0.3, 0.5, 1.0] {
///     for y in 0..4 {
///         for x in 0..4 {
///             let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
///             let current = screen_door_keep_with(DitherPattern::Bayer4x4, p, -(1.0 - t));
///             let next = screen_door_keep_with(DitherPattern::Bayer4x4, p, t);
///             assert!(current != next); // exactly one of the two
///         }
///     }
/// }
/// ```
pub fn screen_door_keep_with(pattern: DitherPattern, frag_coord: Vec2, alpha: f32) -> bool {
    let threshold = screen_door_threshold(frag_coord, pattern);
    if alpha < 0.0 {
        threshold >= 1.0 + alpha
    } else {
        threshold < alpha
    }
}
