//! The low-resolution buffer of framebuffer LOD (Rust twins of `lodkit::gbuffer`): color at
//! location 0 and an `Rgba16Float` geometry texel (view depth, screen-space normal) at location 1;
//! or the packed layout, one `Rgba32Uint` texel holding all of it (color as half floats, the view
//! depth as f32, the foreshortened normal as half floats), which the upsampler reads once per
//! cell corner instead of twice.

use glam::{UVec4, Vec2, Vec3, Vec4};

use crate::normal_distance::foreshortened_normal;

/// Bytes per low-res pixel with an RGBA8 color: 4 + 8.
pub const BYTES_PER_PIXEL: u32 = 12;

/// Format of the geometry target.
#[cfg(feature = "wgpu")]
pub const GEOMETRY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Bytes per low-res pixel in the packed layout (HDR color included).
pub const PACKED_BYTES_PER_PIXEL: u32 = 16;

/// Format of the packed layout's one target.
#[cfg(feature = "wgpu")]
pub const PACKED_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// Largest finite half float; larger magnitudes are packed as this.
pub const GBUFFER_HALF_MAX: f32 = 65504.0;

/// The geometry texel: (view depth, normal).
///
/// ```
/// # use lodkit::gbuffer::*;
/// # use glam::Vec3;
/// let g = gbuffer_pack_geometry(4.5, Vec3::Z);
/// assert_eq!((gbuffer_depth(g), gbuffer_normal(g)), (4.5, Vec3::Z));
/// ```
pub fn gbuffer_pack_geometry(view_depth: f32, normal: Vec3) -> Vec4 {
    Vec4::new(view_depth, normal.x, normal.y, normal.z)
}

/// What `gbuffer_output` writes: the color and the geometry texel.
pub fn gbuffer_output(color: Vec4, view_depth: f32, normal: Vec3) -> (Vec4, Vec4) {
    (color, gbuffer_pack_geometry(view_depth, normal))
}

/// View depth of a geometry texel.
pub fn gbuffer_depth(geometry: Vec4) -> f32 {
    geometry.x
}

/// Normal of a geometry texel.
pub fn gbuffer_normal(geometry: Vec4) -> Vec3 {
    Vec3::new(geometry.y, geometry.z, geometry.w)
}

/// `v` as two IEEE half floats in one word, x in the low 16 bits, exactly as the shaders write
/// it: rounded to nearest (ties away from zero), magnitudes clamped to [`GBUFFER_HALF_MAX`], those
/// below 2^-14 (the smallest normal half) written as +0: the sign of a zero is not kept, since a
/// GPU need not keep it (Vulkan keeps it only under `SignedZeroInfNanPreserve`) and the word
/// must be the same on every driver. Inputs must be finite.
///
/// ```
/// # use lodkit::gbuffer::*;
/// # use glam::Vec2;
/// assert_eq!(gbuffer_pack_half2(Vec2::new(1.0, -2.0)), 0xc000_3c00);
/// assert_eq!(gbuffer_pack_half2(Vec2::new(-0.0, -1e-9)), 0);
/// assert_eq!(gbuffer_unpack_half2(gbuffer_pack_half2(Vec2::new(0.1, 1e6))), Vec2::new(0.099975586, 65504.0));
/// ```
pub fn gbuffer_pack_half2(v: Vec2) -> u32 {
    let half = |x: f32| {
        let a = x.abs().min(GBUFFER_HALF_MAX);
        // Scaling by 2^-112 moves the exponent to the half's bias: the half is then the float's
        // bits shifted right by 13, after adding half of the dropped last place.
        if a < f32::from_bits(0x3880_0000) {
            return 0; // below 2^-14: +0, whatever the sign (a GPU need not keep a zero's sign)
        }
        let magnitude = ((a * f32::from_bits(0x0780_0000)).to_bits() + 0x1000) >> 13;
        magnitude | ((x.to_bits() >> 16) & 0x8000)
    };
    half(v.x) | (half(v.y) << 16)
}

/// The two halves of `word` (x from the low 16 bits) as floats; exact for what
/// [`gbuffer_pack_half2`] writes.
pub fn gbuffer_unpack_half2(word: u32) -> Vec2 {
    let lo = ((word << 13) & 0x0fff_e000) | ((word << 16) & 0x8000_0000);
    let hi = ((word >> 3) & 0x0fff_e000) | (word & 0x8000_0000);
    let scale = f32::from_bits(0x7780_0000); // 2^112
    Vec2::new(f32::from_bits(lo) * scale, f32::from_bits(hi) * scale)
}

/// The packed texel: color as halves, the view depth as f32 bits, the foreshortened normal
/// ([`foreshortened_normal`]) as halves.
///
/// ```
/// # use lodkit::gbuffer::*;
/// # use glam::{Vec2, Vec3, Vec4};
/// let t = gbuffer_pack_texel(Vec4::new(0.5, 2.0, 40.0, 1.0), 7.25, Vec3::new(0.6, 0.0, 0.8));
/// assert_eq!(gbuffer_texel_color(t), Vec4::new(0.5, 2.0, 40.0, 1.0));
/// assert_eq!(gbuffer_texel_depth(t), 7.25);
/// assert_eq!(gbuffer_texel_projected_normal(t), Vec2::new(0.75, 0.0));
/// ```
pub fn gbuffer_pack_texel(color: Vec4, view_depth: f32, normal: Vec3) -> UVec4 {
    UVec4::new(
        gbuffer_pack_half2(color.truncate().truncate()),
        gbuffer_pack_half2(Vec2::new(color.z, color.w)),
        view_depth.to_bits(),
        gbuffer_pack_half2(foreshortened_normal(normal)),
    )
}

/// Color of a packed texel (half precision).
pub fn gbuffer_texel_color(texel: UVec4) -> Vec4 {
    let (rg, ba) = (gbuffer_unpack_half2(texel.x), gbuffer_unpack_half2(texel.y));
    Vec4::new(rg.x, rg.y, ba.x, ba.y)
}

/// View depth of a packed texel (full precision).
pub fn gbuffer_texel_depth(texel: UVec4) -> f32 {
    f32::from_bits(texel.z)
}

/// The normal of a packed texel through the foreshortening map (half precision).
pub fn gbuffer_texel_projected_normal(texel: UVec4) -> Vec2 {
    gbuffer_unpack_half2(texel.w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every half the packer can write comes back exactly, and every float lands on the nearest
    /// half (ties away from zero) or, below 2^-14, on +0: checked against f64 arithmetic.
    #[test]
    fn halves_round_to_nearest() {
        for h in (0u32..0x7c00).chain(0x8000..0xfc00) {
            let f = gbuffer_unpack_half2(h).x;
            if (h >> 10) & 0x1f == 0 && h & 0x3ff != 0 {
                continue; // subnormal halves are never written
            }
            if h == 0x8000 {
                // -0 is never written: a zero packs without its sign.
                assert_eq!(gbuffer_pack_half2(Vec2::new(f, 0.0)), 0, "-0 packs as +0");
                continue;
            }
            assert_eq!(
                gbuffer_pack_half2(Vec2::new(f, 0.0)) & 0xffff,
                h,
                "{h:#x} -> {f}"
            );
        }
        let mut x = 6.2e-5_f32;
        while x < 70000.0 {
            let got = gbuffer_unpack_half2(gbuffer_pack_half2(Vec2::new(x, -x)));
            // The nearest half by f64 arithmetic: 11 significant bits.
            let e = (x as f64).log2().floor();
            let step = 2f64.powf(e - 10.0);
            let want = ((x as f64 / step) + 0.5).floor() * step;
            let want = want.min(GBUFFER_HALF_MAX as f64) as f32;
            assert_eq!((got.x, got.y), (want, -want), "{x}");
            x *= 1.0137;
        }
        // Below 2^-14 both are +0, the negative one too.
        assert_eq!(gbuffer_pack_half2(Vec2::new(6.0e-5, -1e-30)), 0);
    }
}
