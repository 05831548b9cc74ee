//! Alpha-tested LODs in the reference passes: a card with a mask (a billboard impostor) drawn by
//! `passes/lod_mesh.wgsl` (single-frame techniques) and `passes/lod_buffer_mesh.wgsl`
//! (frame-sequential) covers exactly the pixels its mask covers, in both.

use glam::{Mat4, Vec2, Vec3, Vec4};
use lodkit::alpha_mask::{AlphaMask, alpha_mask_keep, alpha_mask_rect};
use lodkit::gpu::frame_sequential::{LodBuffers, read_lod_image};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::unpopping::LodRenderState;
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem};
use lodkit_scenes::mesh::{DrawItem, GpuMesh, Mesh, MeshFrame, MeshRenderer, RenderTarget};

use crate::harness::say;

/// An orthographic camera looking down -z that maps x and y in -1..1 onto the whole target.
fn head_on() -> Mat4 {
    glam::camera::rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, 0.1, 10.0)
        * glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y)
}

/// An opaque white draw of `card` with the alpha mask over `rect`.
/// Draws `item` alone into `target` through `renderer`, black clear.
fn draw_one(
    gpu: &lodkit::gpu::GpuContext,
    renderer: &MeshRenderer,
    target: &RenderTarget,
    view_proj: Mat4,
    item: DrawItem,
) {
    let frame = MeshFrame {
        view_proj,
        items: &[item],
        ..Default::default()
    };
    renderer.render(gpu, target, &frame).unwrap();
}

fn card_draw(card: &GpuMesh, rect: Vec4) -> DrawItem<'_> {
    DrawItem {
        mesh: card,
        model: Mat4::IDENTITY,
        color: Vec4::ONE,
        state: LodRenderState::OPAQUE,
        dither_alpha: None,
        sway: [0.0; 2],
        alpha_rect: rect,
    }
}

#[test]
fn an_alpha_tested_card_covers_what_its_mask_covers_in_both_passes() {
    const W: u32 = 64;
    let gpu = lodkit_test_gpu!();
    // A 16x16 ring: its hole and corners must stay empty.
    let size = 16u32;
    let texels: Vec<f32> = (0..size * size)
        .map(|i| {
            let c = Vec2::new((i % size) as f32 + 0.5, (i / size) as f32 + 0.5) - 8.0;
            f32::from(u8::from(c.length() > 3.0 && c.length() < 7.0))
        })
        .collect();
    let mask = AlphaMask { size, texels };
    let (min, max) = (Vec2::new(-1.0, -1.0), Vec2::new(1.0, 1.0));
    let rect = alpha_mask_rect(min, max);
    let card = GpuMesh::new(gpu, &Mesh::card(min, max)).unwrap();
    // Seen head-on through an orthographic camera that maps the card onto the whole target, so
    // each pixel center has an object-space point to test on the CPU.
    let view_proj = head_on();
    let want: Vec<bool> = (0..W * W)
        .map(|i| {
            let uv = (Vec2::new((i % W) as f32, (i / W) as f32) + 0.5) / W as f32;
            let p = Vec3::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0);
            alpha_mask_keep(&mask, p, rect)
        })
        .collect();
    let covered_want = want.iter().filter(|&&k| k).count();
    assert!(covered_want > 1000 && covered_want < 3000, "{covered_want}");

    let mut single = MeshRenderer::new(gpu, false).unwrap();
    single.set_alpha_mask(gpu, &mask).unwrap();
    let target = RenderTarget::new(gpu, W, W).unwrap();
    let item = card_draw(&card, rect);
    draw_one(gpu, &single, &target, view_proj, item);
    let pixels = read_texture_rgba8(gpu, &target.color).unwrap();
    let single_got: Vec<bool> = pixels.chunks(4).map(|p| p[0] > 8).collect();

    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 1);
    let mut lod = LodBufferRenderer::new(gpu, format, &vis, 1.0).unwrap();
    lod.set_alpha_mask(gpu, &mask).unwrap();
    let buffers = LodBuffers::new(gpu, W, W, format).unwrap();
    let item = LodDrawItem {
        mesh: &card,
        model: Mat4::IDENTITY,
        prev_model: Mat4::IDENTITY,
        color: Vec4::ONE,
        id: 3,
        tau: 1.0,
        tau_next: 1.0,
        sway: [0.0; 2],
        prev_sway_phase: 0.0,
        alpha_rect: rect,
    };
    lod.render(
        gpu,
        &buffers,
        &LodBufferFrame {
            view: view_proj.into(),
            items: &[item],
            ..Default::default()
        },
    )
    .unwrap();
    let lod_got: Vec<bool> = read_lod_image(gpu, &buffers, 0)
        .unwrap()
        .ids
        .iter()
        .map(|&id| id == 3)
        .collect();

    for (name, got) in [("lod_mesh", &single_got), ("lod_buffer_mesh", &lod_got)] {
        let wrong = got.iter().zip(&want).filter(|(g, w)| g != w).count();
        assert_eq!(wrong, 0, "{name}: {wrong} pixels differ from the mask");
    }
    // Without the rect the card is whole.
    let mut whole = item;
    whole.alpha_rect = Vec4::ZERO;
    lod.render(
        gpu,
        &buffers,
        &LodBufferFrame {
            view: view_proj.into(),
            items: &[whole],
            ..Default::default()
        },
    )
    .unwrap();
    let ids = read_lod_image(gpu, &buffers, 0).unwrap().ids;
    assert_eq!(ids.iter().filter(|&&id| id == 3).count(), (W * W) as usize);
    say(&format!(
        "alpha-tested card: {covered_want} of {} pixels, as the mask says, in both passes",
        W * W
    ));
}

#[test]
fn a_bad_alpha_mask_is_refused_and_the_old_one_kept() {
    use lodkit::gpu::GpuError;
    let gpu = lodkit_test_gpu!();
    let bad = AlphaMask {
        size: 4,
        texels: vec![1.0; 15],
    };
    let empty = AlphaMask {
        size: 0,
        texels: Vec::new(),
    };
    let mut single = MeshRenderer::new(gpu, false).unwrap();
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 8, 1);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut lod = LodBufferRenderer::new(gpu, format, &vis, 1.0).unwrap();
    for mask in [&bad, &empty] {
        let errors = [
            single.set_alpha_mask(gpu, mask).unwrap_err(),
            lod.set_alpha_mask(gpu, mask).unwrap_err(),
        ];
        for e in errors {
            assert!(matches!(e, GpuError::Mismatch { .. }), "{e}");
            assert!(e.to_string().contains("texels"), "{e}");
        }
    }
    // Both still draw (with the opaque mask they had).
    let target = RenderTarget::new(gpu, 8, 8).unwrap();
    let card = GpuMesh::new(gpu, &Mesh::card(Vec2::splat(-1.0), Vec2::ONE)).unwrap();
    let item = card_draw(&card, alpha_mask_rect(Vec2::splat(-1.0), Vec2::ONE));
    let view_proj = head_on();
    draw_one(gpu, &single, &target, view_proj, item);
    let lit = read_texture_rgba8(gpu, &target.color).unwrap();
    assert!(
        lit.chunks(4).all(|p| p[0] > 8),
        "the opaque mask covers the card"
    );
}
