//! Rust twins of the atlas-sampling functions of `lodkit::impostor`: what a fragment sees,
//! from the CPU atlas with the filter a linear, mipmapped, clamp-to-edge sampler applies (the
//! GPU's 8-bit colour and its sampler's fixed-point weights round differently).

use glam::{UVec2, Vec3, Vec4};

use super::{
    ImpostorAtlas, ImpostorImage, impostor_atlas_uv, impostor_blend, impostor_depth_height,
    impostor_frame_basis, impostor_frame_dir, impostor_frame_inset, impostor_frame_uv,
    impostor_ray_at_height,
};

/// What one impostor fragment sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorSample {
    /// Blended colour; alpha is the blended coverage.
    pub color: Vec4,
    /// Blended object-space normal (unit length, or zero where nothing was covered).
    pub normal: Vec3,
    /// The point on the ray the frames saw, normalized object space.
    pub point: Vec3,
}

/// `images` (a mip chain, level 0 first) at `uv` and mip `level`: bilinear within a level
/// (texel centres at half-integers, clamped to the edge), linear between the two levels around
/// `level` (clamped to the chain). Zero for an empty chain or one with an image whose texel
/// count is not its size squared.
pub fn impostor_sample_level(images: &[ImpostorImage], uv: glam::Vec2, level: f32) -> Vec4 {
    let whole = |i: &ImpostorImage| i.size > 0 && i.texels.len() == (i.size as usize).pow(2);
    let Some(last) = images
        .len()
        .checked_sub(1)
        .filter(|_| images.iter().all(whole))
    else {
        return Vec4::ZERO;
    };
    let level = level.clamp(0.0, last as f32);
    let l0 = level.floor() as usize;
    let l1 = (l0 + 1).min(last);
    let t = level - l0 as f32;
    let bilinear = |image: &ImpostorImage| {
        let s = image.size as f32;
        let x = uv.x * s - 0.5;
        let y = uv.y * s - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let max = image.size as i64 - 1;
        let at = |xi: f32, yi: f32| {
            let cx = (xi as i64).clamp(0, max) as u32;
            let cy = (yi as i64).clamp(0, max) as u32;
            Vec4::from(image.texel(cx, cy))
        };
        let top = at(x0, y0).lerp(at(x0 + 1.0, y0), fx);
        let bottom = at(x0, y0 + 1.0).lerp(at(x0 + 1.0, y0 + 1.0), fx);
        top.lerp(bottom, fy)
    };
    bilinear(&images[l0]).lerp(bilinear(&images[l1]), t)
}

/// One frame's look along the ray `origin + t ray` (normalized object space): where the ray
/// meets its plane, that texel's depth, and the colour, normal and point at the height that
/// depth gives (one parallax step), read inside the frame's inset ([`impostor_frame_inset`]).
/// Outside the frame's square the coverage is 0.
pub fn impostor_sample_frame(
    atlas: &ImpostorAtlas,
    frame: UVec2,
    origin: Vec3,
    ray: Vec3,
    level: f32,
) -> ImpostorSample {
    let n = atlas.layout.frames;
    let dir = impostor_frame_dir(frame, n, atlas.layout.shape.is_hemi());
    let basis = impostor_frame_basis(dir);
    let texels = atlas.color.first().map_or(0.0, |i| i.size as f32) / n as f32;
    let inset = impostor_frame_inset(texels, level);
    let inside =
        |uv: glam::Vec2| uv.clamp(glam::Vec2::splat(inset), glam::Vec2::splat(1.0 - inset));
    let uv0 = impostor_frame_uv(&basis, impostor_ray_at_height(origin, ray, dir, 0.0));
    let depth0 = impostor_sample_level(
        &atlas.normal_depth,
        impostor_atlas_uv(frame, n, inside(uv0)),
        level,
    )
    .w;
    let point = impostor_ray_at_height(origin, ray, dir, impostor_depth_height(depth0));
    let uv = impostor_frame_uv(&basis, point);
    let at = impostor_atlas_uv(frame, n, inside(uv));
    let mut color = impostor_sample_level(&atlas.color, at, level);
    if uv != uv.clamp(glam::Vec2::ZERO, glam::Vec2::ONE) {
        color.w = 0.0;
    }
    let normal = impostor_sample_level(&atlas.normal_depth, at, level).truncate() * 2.0 - 1.0;
    ImpostorSample {
        color,
        normal,
        point,
    }
}

/// The blended look of an impostor along the ray `origin + t ray` (normalized object space; ray
/// from the eye, not necessarily unit), at mip `level`.
pub fn impostor_sample(
    atlas: &ImpostorAtlas,
    origin: Vec3,
    ray: Vec3,
    level: f32,
) -> ImpostorSample {
    let layout = &atlas.layout;
    let b = impostor_blend((-ray).normalize(), layout.frames, layout.shape.is_hemi());
    let s = b
        .frames
        .map(|f| impostor_sample_frame(atlas, f, origin, ray, level));
    let w = b.weights;
    let color = w.x * s[0].color + w.y * s[1].color + w.z * s[2].color;
    let normal = w.x * s[0].normal + w.y * s[1].normal + w.z * s[2].normal;
    let length_squared = normal.length_squared();
    let unit = if length_squared > 1e-12 {
        normal / length_squared.sqrt()
    } else {
        Vec3::ZERO
    };
    ImpostorSample {
        color,
        normal: unit,
        point: w.x * s[0].point + w.y * s[1].point + w.z * s[2].point,
    }
}
