use glam::{Mat4, Vec2, Vec3, Vec4};
use proptest::prelude::*;

use super::*;
use crate::alpha_mask::{alpha_mask_keep, alpha_mask_rect};
use crate::silhouette::{SILHOUETTE_TIE, silhouette_distance, winding};

/// Target size (pixels) of the property test.
const SIZE: u32 = 24;

/// Where the ray through pixel center `p` meets the card's plane (z = 0, object space), in front
/// of the camera; found by unprojecting the pixel, not by the outline's projection.
fn hit(clip_from_local: Mat4, p: Vec2) -> Option<Vec3> {
    let ndc = Vec2::new(p.x / SIZE as f32 * 2.0 - 1.0, 1.0 - p.y / SIZE as f32 * 2.0);
    let local_from_clip = clip_from_local.inverse();
    let near = local_from_clip.project_point3(ndc.extend(0.0));
    let far = local_from_clip.project_point3(ndc.extend(1.0));
    let t = -near.z / (far.z - near.z);
    (t >= 0.0 && t.is_finite()).then(|| near + t * (far - near))
}

proptest! {
    /// At every pixel center not within SILHOUETTE_TIE of the outline, its winding number is
    /// not 0 exactly where the alpha test keeps the card's fragment at the point the pixel sees.
    #[test]
    fn the_outline_covers_what_the_alpha_test_keeps(
        n in 1u32..=6,
        bits in any::<u64>(),
        corner in (-1.5f32..-0.5, -1.5f32..-0.5),
        extent in (0.8f32..2.5, 0.8f32..2.5),
        eye in (-1.5f32..1.5, -1.5f32..1.5, 1.8f32..4.0),
        behind in any::<bool>(),
    ) {
        let texels = (0..n * n).map(|i| f32::from(u8::from(bits >> (i % 64) & 1 == 1))).collect();
        let mask = AlphaMask { size: n, texels };
        let min = Vec2::new(corner.0, corner.1);
        let rect = alpha_mask_rect(min, min + Vec2::new(extent.0, extent.1));
        let outline = MaskOutline::new(&mask, rect).unwrap();
        // Either side of the card (it is drawn without culling).
        let eye = Vec3::new(eye.0, eye.1, if behind { -eye.2 } else { eye.2 });
        let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
        let proj = glam::camera::rh::proj::directx::perspective(1.2, 1.0, 0.1, 100.0);
        let clip = proj * view;
        let segments = outline.silhouette(clip, (SIZE, SIZE)).unwrap();
        for y in 0..SIZE {
            for x in 0..SIZE {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let near_edge = segments.iter().any(|s| {
                    silhouette_distance(p, Vec2::new(s[0], s[1]), Vec2::new(s[2], s[3]))
                        < SILHOUETTE_TIE
                });
                if near_edge {
                    continue;
                }
                let kept = hit(clip, p).is_some_and(|q| alpha_mask_keep(&mask, q, rect));
                prop_assert_eq!(
                    winding(&segments, p) != 0,
                    kept,
                    "pixel ({}, {}) of a {}x{} mask {:?}",
                    x,
                    y,
                    n,
                    n,
                    mask.texels
                );
            }
        }
    }
}

#[test]
fn a_covered_mask_is_its_rectangle_and_an_empty_one_has_no_edges() {
    let rect = alpha_mask_rect(Vec2::splat(-1.0), Vec2::ONE);
    let full = AlphaMask {
        size: 4,
        texels: vec![1.0; 16],
    };
    assert_eq!(MaskOutline::new(&full, rect).unwrap().edges(), 4);
    let empty = AlphaMask {
        size: 4,
        texels: vec![0.25; 16],
    };
    assert_eq!(MaskOutline::new(&empty, rect).unwrap().edges(), 0);
    // A checkerboard's texels touch only at corners: 4 edges each, none merged.
    let checker = AlphaMask {
        size: 2,
        texels: vec![1.0, 0.0, 0.0, 1.0],
    };
    assert_eq!(MaskOutline::new(&checker, rect).unwrap().edges(), 8);
}

#[test]
fn a_mask_without_a_rect_or_with_missing_texels_is_an_error() {
    let mask = AlphaMask::opaque();
    assert_eq!(
        MaskOutline::new(&mask, Vec4::ZERO),
        Err(MaskOutlineError::NoMask { rect: [0.0; 4] })
    );
    let short = AlphaMask {
        size: 3,
        texels: vec![1.0; 8],
    };
    let rect = alpha_mask_rect(Vec2::ZERO, Vec2::ONE);
    let err = MaskOutline::new(&short, rect).unwrap_err();
    assert_eq!(err, MaskOutlineError::TexelCount { size: 3, texels: 8 });
    assert_eq!(err.to_string(), "the mask is 3x3 but holds 8 texels");
}

#[test]
fn an_edge_behind_the_camera_is_an_error() {
    let mask = AlphaMask::opaque();
    let outline = MaskOutline::new(&mask, alpha_mask_rect(Vec2::splat(-1.0), Vec2::ONE)).unwrap();
    // w = -1 everywhere: behind the camera.
    let flip = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::Z, Vec4::new(0.0, 0.0, 0.0, -1.0));
    assert_eq!(
        outline.silhouette(flip, (8, 8)),
        Err(SilhouetteError::BehindCamera)
    );
}
