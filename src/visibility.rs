//! Visibility textures for frame-sequential LOD (Scherzer & Wimmer 2008, sec. 3.3), looked up in
//! object space or anchored to the screen: Rust twins of `lodkit::visibility` and the generators
//! of the textures themselves.

use glam::{IVec2, UVec2, Vec2, Vec3, Vec4};

/// Lookup coordinate of an object-space position: (p.x + p.z, p.y + p.z).
///
/// ```
/// # use lodkit::visibility::visibility_coord;
/// assert_eq!(visibility_coord(glam::Vec3::new(1.0, 2.0, 3.0)), glam::Vec2::new(4.0, 5.0));
/// ```
pub fn visibility_coord(object_pos: Vec3) -> Vec2 {
    Vec2::new(object_pos.x + object_pos.z, object_pos.y + object_pos.z)
}

/// Threshold tau of one LOD of a t-instance at `progress` (Fig. 2): incoming min(2p, 1),
/// outgoing min(2(1 - p), 1). The same schedule as [`unpopping_alpha`](crate::unpopping::unpopping_alpha).
///
/// ```
/// # use lodkit::visibility::visibility_threshold;
/// assert_eq!((visibility_threshold(0.0, true), visibility_threshold(0.0, false)), (0.0, 1.0));
/// assert_eq!((visibility_threshold(0.5, true), visibility_threshold(0.5, false)), (1.0, 1.0));
/// assert_eq!((visibility_threshold(1.0, true), visibility_threshold(1.0, false)), (1.0, 0.0));
/// ```
pub fn visibility_threshold(progress: f32, incoming: bool) -> f32 {
    crate::unpopping::unpopping_alpha(progress, incoming)
}

/// Threshold of one LOD under the complementary schedule: the incoming LOD shows the texels
/// v <= progress, the outgoing LOD the others (tau = -(1 - progress), the inverted pattern of
/// [`visibility_shown`]). Progress is clamped to [0, 1].
///
/// ```
/// # use lodkit::visibility::{visibility_shown, visibility_threshold_complementary as c};
/// assert_eq!((c(0.25, true), c(0.25, false)), (0.25, -0.75));
/// // Every texel is shown by exactly one LOD.
/// for v in [0.1f32, 0.3, 0.9] {
///     assert_ne!(visibility_shown(v, c(0.25, true)), visibility_shown(v, c(0.25, false)));
/// }
/// ```
pub fn visibility_threshold_complementary(progress: f32, incoming: bool) -> f32 {
    let p = progress.clamp(0.0, 1.0);
    if incoming { p } else { -(1.0 - p) }
}

/// Whether texel value `v` is shown at threshold `tau`: v <= tau for tau >= 0 (the paper's
/// eq. 1); for tau < 0 the inverted pattern, v > 1 + tau. -0 counts as 0 (nothing shown).
///
/// ```
/// # use lodkit::visibility::visibility_shown;
/// assert!(visibility_shown(0.3, 0.5) && !visibility_shown(0.7, 0.5));
/// assert!(!visibility_shown(0.3, -0.5) && visibility_shown(0.7, -0.5));
/// assert!(!visibility_shown(0.5, -0.0) && visibility_shown(0.5, -1.0));
/// ```
pub fn visibility_shown(v: f32, tau: f32) -> bool {
    if tau < 0.0 { v > 1.0 + tau } else { v <= tau }
}

/// Display-time visibility flags from texel value `v`: bit 0 shown at `tau_now`, bit 1 at
/// `tau_next` (the Rust twin of `visibility_flags`, with the texel already looked up).
///
/// ```
/// # use lodkit::visibility::visibility_flags_of;
/// assert_eq!(visibility_flags_of(0.4, 0.3, 0.5), 0b10);
/// ```
pub fn visibility_flags_of(v: f32, tau_now: f32, tau_next: f32) -> u32 {
    u32::from(visibility_shown(v, tau_now)) | (u32::from(visibility_shown(v, tau_next)) << 1)
}

/// A square visibility texture: `size` x `size` values in (0, 1), row-major (upload as R32Float
/// or R8Unorm/R16Unorm).
#[derive(Clone, Debug, PartialEq)]
pub struct VisibilityTexture {
    /// Width and height.
    pub size: u32,
    /// Texel values, all strictly between 0 and 1.
    pub texels: Vec<f32>,
}

/// How fragments of a t-instance appear and vanish.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisibilityPattern {
    /// Uniform white noise: the paper's choice (64x64).
    WhiteNoise,
    /// Void-and-cluster blue noise: the same share of fragments, spread evenly, without the
    /// clumps and holes of white noise.
    BlueNoise,
    /// Decreasing from the center outward: fragments appear from the rim inward (and the outgoing
    /// LOD vanishes from the center out).
    Radial,
}

/// Generates a visibility texture, deterministic for `seed` (the radial pattern ignores it). The
/// size is clamped to 4096.
///
/// ```
/// # use lodkit::visibility::{visibility_texture, VisibilityPattern};
/// let t = visibility_texture(VisibilityPattern::BlueNoise, 16, 3);
/// assert!(t.texels.iter().all(|&v| v > 0.0 && v < 1.0));
/// ```
pub fn visibility_texture(pattern: VisibilityPattern, size: u32, seed: u64) -> VisibilityTexture {
    let size = size.min(4096);
    let n = (size * size) as usize;
    let texels = match pattern {
        VisibilityPattern::WhiteNoise => crate::noise::white_noise(n, seed)
            .into_iter()
            .map(|v| v.max(0.5 / (1 << 24) as f32))
            .collect(),
        VisibilityPattern::BlueNoise => crate::noise::void_and_cluster(size as usize, seed)
            .into_iter()
            .map(|r| (r as f32 + 0.5) / n as f32)
            .collect(),
        VisibilityPattern::Radial => {
            let c = size as f32 / 2.0;
            let max = c * std::f32::consts::SQRT_2;
            (0..n)
                .map(|i| {
                    let p = Vec2::new(
                        (i as u32 % size) as f32 + 0.5,
                        (i as u32 / size) as f32 + 0.5,
                    );
                    let r = p.distance(Vec2::splat(c)) / max;
                    (1.0 - r).clamp(0.5 / n as f32, 1.0 - 0.5 / n as f32)
                })
                .collect()
        }
    };
    VisibilityTexture { size, texels }
}

/// The texel of a `size` visibility texture that `object_pos` looks up: repeat addressing,
/// nearest texel.
///
/// ```
/// # use lodkit::visibility::visibility_texel;
/// # use glam::{UVec2, Vec3};
/// assert_eq!(visibility_texel(UVec2::splat(64), Vec3::new(0.25, 0.5, 1.0)), UVec2::new(16, 32));
/// ```
pub fn visibility_texel(size: UVec2, object_pos: Vec3) -> UVec2 {
    let c = visibility_coord(object_pos);
    let uv = c - c.floor();
    let texel = UVec2::new((uv.x * size.x as f32) as u32, (uv.y * size.y as f32) as u32);
    texel.min(size.saturating_sub(UVec2::ONE))
}

impl VisibilityTexture {
    /// The texel value an object-space position looks up, as the shader does. An empty or short
    /// texture reads as 1 (every fragment kept).
    pub fn lookup(&self, object_pos: Vec3) -> f32 {
        self.value(visibility_texel(UVec2::splat(self.size), object_pos))
    }

    /// The value of texel `t`; 1 outside the texels.
    fn value(&self, t: UVec2) -> f32 {
        let index = u64::from(t.y) * u64::from(self.size) + u64::from(t.x);
        self.texels.get(index as usize).copied().unwrap_or(1.0)
    }
}

/// Whether a fragment at `object_pos` is kept for threshold `tau` ([`visibility_shown`]): the
/// Rust twin of `check_visibility`, with the texture given as data.
pub fn check_visibility(vis_tex: &VisibilityTexture, object_pos: Vec3, tau: f32) -> bool {
    visibility_shown(vis_tex.lookup(object_pos), tau)
}

/// Display-time flags of a fragment at `object_pos` (the Rust twin of `visibility_flags`).
pub fn visibility_flags(
    vis_tex: &VisibilityTexture,
    object_pos: Vec3,
    tau_now: f32,
    tau_next: f32,
) -> u32 {
    visibility_flags_of(vis_tex.lookup(object_pos), tau_now, tau_next)
}

/// Where a t-instance's visibility pattern is anchored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VisibilitySpace {
    /// Tiled over the screen, one texel per pixel, and looked up at the pixel where the fragment
    /// is displayed ([`visibility_flags_screen`]). The pattern holds still while objects and the
    /// camera move, as a dither does: under motion a pixel changes only where the threshold
    /// passes its texel. The default.
    #[default]
    Screen,
    /// At the fragment's object-space position before animation ([`visibility_flags`]), the
    /// paper's choice: the pattern moves with the object like a texture, and under motion every
    /// pixel of a blend samples another texel each frame.
    Object,
}

/// The texel of a `size` visibility texture tiled over the framebuffer, one texel per pixel,
/// under framebuffer position `frag_coord` (pixels; repeat addressing, either sign; the position
/// clamped to +-2^24 pixels, the size to 1..2^24).
///
/// ```
/// # use lodkit::visibility::visibility_screen_texel;
/// # use glam::{UVec2, Vec2};
/// assert_eq!(visibility_screen_texel(UVec2::splat(64), Vec2::new(70.5, 3.5)), UVec2::new(6, 3));
/// assert_eq!(visibility_screen_texel(UVec2::splat(64), Vec2::new(-0.5, 3.5)), UVec2::new(63, 3));
/// // Sizes past 2^24 count as 2^24; nothing overflows.
/// let huge = visibility_screen_texel(UVec2::splat(u32::MAX), Vec2::new(-3.5, 2.5));
/// assert_eq!(huge, UVec2::new((1 << 24) - 4, 2)); // floor(-3.5) = -4
/// ```
pub fn visibility_screen_texel(size: UVec2, frag_coord: Vec2) -> UVec2 {
    const LIMIT: i32 = 1 << 24;
    let s = size
        .clamp(UVec2::ONE, UVec2::splat(LIMIT as u32))
        .as_ivec2();
    let p = frag_coord
        .floor()
        .clamp(Vec2::splat(-16_777_216.0), Vec2::splat(16_777_216.0));
    let p = IVec2::new(p.x as i32, p.y as i32);
    // Shifted by a multiple of s to non-negative first, as the shaders do.
    ((p + s * (IVec2::splat(LIMIT) / s + 1)) % s).as_uvec2()
}

/// Where a fragment at framebuffer position `frag_coord` is expected in the next frame: as far
/// again as it moved since the previous one. `then_clip` is its surface point in the previous
/// frame seen by the previous camera (clip space), `viewport` the framebuffer size in pixels;
/// `frag_coord` itself when `then_clip` lies behind that camera.
///
/// ```
/// # use lodkit::visibility::visibility_next_coord;
/// # use glam::{Vec2, Vec4};
/// // Clip (0, 0) is the center (50, 50) of a 100 x 100 target; now at (52.5, 50.5).
/// let next = visibility_next_coord(Vec2::new(52.5, 50.5), Vec4::new(0.0, 0.0, 0.5, 1.0), Vec2::splat(100.0));
/// assert_eq!(next, Vec2::new(55.0, 51.0));
/// ```
pub fn visibility_next_coord(frag_coord: Vec2, then_clip: Vec4, viewport: Vec2) -> Vec2 {
    if then_clip.w <= 0.0 {
        return frag_coord;
    }
    let ndc = Vec2::new(then_clip.x, then_clip.y) / then_clip.w;
    let then_px = (ndc * Vec2::new(0.5, -0.5) + 0.5) * viewport;
    2.0 * frag_coord - then_px
}

impl VisibilityTexture {
    /// The texel value under framebuffer position `frag_coord` with the texture tiled over the
    /// screen, as the shader reads it. An empty or short texture reads as 1.
    pub fn lookup_screen(&self, frag_coord: Vec2) -> f32 {
        self.value(visibility_screen_texel(UVec2::splat(self.size), frag_coord))
    }
}

/// Display-time flags with the pattern anchored to the screen (the Rust twin of
/// `visibility_flags_screen`): bit 0 when the texel under `frag_coord` is shown at `tau_now`,
/// bit 1 when the texel under `next_coord` ([`visibility_next_coord`]) is shown at `tau_next`.
pub fn visibility_flags_screen(
    vis_tex: &VisibilityTexture,
    frag_coord: Vec2,
    next_coord: Vec2,
    tau_now: f32,
    tau_next: f32,
) -> u32 {
    u32::from(visibility_shown(vis_tex.lookup_screen(frag_coord), tau_now))
        | (u32::from(visibility_shown(
            vis_tex.lookup_screen(next_coord),
            tau_next,
        )) << 1)
}
