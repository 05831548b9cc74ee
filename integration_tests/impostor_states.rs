//! The impostor pass's colour states and refusals: a tint multiplies the baked colour, a blended
//! pass (unpopping, cross-fade) mixes the impostor with what is behind it by the blend constant
//! and writes no depth, and a pass asked for what its target cannot do says so by name.

use glam::{Mat4, Vec3};
use lodkit::gpu::impostor::{
    ImpostorInstance, ImpostorLodView, ImpostorPass, ImpostorPassDescriptor, ImpostorTarget,
};
use lodkit::gpu::readback::{read_depth32, read_texture_rgba8};
use lodkit::gpu::resources::{begin_targets_pass, texture_2d};
use lodkit::gpu::unpopping::lod_blend_constant;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::unpopping::LodRenderState;
use lodkit::visibility::VisibilitySpace;

use crate::impostor_lod_buffer::{bake, camera, impostor_view, lumpy};

const SIZE: u32 = 96;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// What the blended impostor is drawn over.
const BEHIND: wgpu::Color = wgpu::Color {
    r: 0.8,
    g: 0.2,
    b: 0.4,
    a: 1.0,
};

/// `instance` drawn by `pass` over a target cleared to `clear` (the blend constant set from
/// `state`): the colours and the depths.
fn draw(
    gpu: &GpuContext,
    pass: &ImpostorPass,
    instance: ImpostorInstance,
    (clear, state): (wgpu::Color, LodRenderState),
) -> (Vec<u8>, Vec<f32>) {
    let textures = bake(gpu, &lumpy());
    let (view_proj, eye) = camera();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let color = texture_2d(gpu, (SIZE, SIZE), FORMAT, usage, "colour").unwrap();
    // Bound as a texture too: where depth cannot be copied (GL), read_depth32 draws it out.
    let usage = usage | wgpu::TextureUsages::TEXTURE_BINDING;
    let depth_format = wgpu::TextureFormat::Depth32Float;
    let depth = texture_2d(gpu, (SIZE, SIZE), depth_format, usage, "depth").unwrap();
    let view = impostor_view(view_proj, eye);
    let prepared = pass.prepare(gpu, &textures, &view, &[instance]).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let c = color.create_view(&Default::default());
        let d = depth.create_view(&Default::default());
        let mut render = begin_targets_pass(&mut encoder, &[(&c, clear)], &d, 1.0, None, "draw");
        render.set_blend_constant(lod_blend_constant(&state));
        pass.draw(&mut render, &prepared);
    }
    gpu.queue.submit([encoder.finish()]);
    (
        read_texture_rgba8(gpu, &color).unwrap(),
        read_depth32(gpu, &depth).unwrap(),
    )
}

fn new_pass(gpu: &GpuContext, target: ImpostorTarget, state: LodRenderState) -> ImpostorPass {
    let descriptor = ImpostorPassDescriptor {
        color_format: FORMAT,
        target,
        state,
        ..Default::default()
    };
    ImpostorPass::new(gpu, &descriptor).unwrap()
}

#[test]
fn a_tint_multiplies_the_baked_colour_and_a_blended_pass_mixes_by_the_blend_constant() {
    let gpu = lodkit_test_gpu!();
    let opaque = LodRenderState::OPAQUE;
    let blended = LodRenderState {
        alpha: 0.25,
        depth_test: true,
        depth_write: false,
        blend: true,
    };
    let color = ImpostorTarget::Color;
    let (opaque_pass, blended_pass) = (new_pass(gpu, color, opaque), new_pass(gpu, color, blended));
    let transparent = wgpu::Color::TRANSPARENT;
    let whole = ImpostorInstance::new(Mat4::IDENTITY);
    let (plain, depths) = draw(gpu, &opaque_pass, whole, (transparent, opaque));
    let tint = Vec3::new(0.5, 1.0, 0.25);
    let tinted_instance = ImpostorInstance { tint, ..whole };
    let (tinted, _) = draw(gpu, &opaque_pass, tinted_instance, (transparent, opaque));
    let (mixed, mixed_depths) = draw(gpu, &blended_pass, whole, (BEHIND, blended));
    let behind = [BEHIND.r, BEHIND.g, BEHIND.b].map(|c| c as f32);
    let mut covered = 0;
    // 8-bit targets: each result is within one step (plus rounding of the product) of the
    // value computed here from the opaque, untinted picture.
    for p in 0..(SIZE * SIZE) as usize {
        if plain[4 * p + 3] < 128 {
            assert_eq!(
                tinted[4 * p + 3],
                0,
                "pixel {p}: the tint changed the coverage"
            );
            continue;
        }
        covered += 1;
        for c in 0..3 {
            let base = f32::from(plain[4 * p + c]) / 255.0;
            let want_tinted = base * tint[c] * 255.0;
            let got = f32::from(tinted[4 * p + c]);
            assert!(
                (got - want_tinted).abs() <= 1.5,
                "pixel {p} channel {c}: tinted {got}, want {want_tinted}"
            );
            let want_mixed = (0.25 * base + 0.75 * behind[c]) * 255.0;
            let got = f32::from(mixed[4 * p + c]);
            assert!(
                (got - want_mixed).abs() <= 1.5,
                "pixel {p} channel {c}: blended {got}, want {want_mixed}"
            );
        }
        assert!(depths[p] < 1.0, "pixel {p}: the opaque pass wrote no depth");
    }
    assert!(covered > 1000, "the impostor covers only {covered} px");
    assert!(
        mixed_depths.iter().all(|d| *d == 1.0),
        "the blended pass wrote depth"
    );
}

#[test]
fn a_pass_refuses_what_its_target_cannot_do_by_name() {
    let gpu = lodkit_test_gpu!();
    let blended = LodRenderState {
        alpha: 0.5,
        depth_test: true,
        depth_write: false,
        blend: true,
    };
    let lod_buffer = ImpostorTarget::LodBuffer { motion: true };
    let descriptor = ImpostorPassDescriptor {
        color_format: FORMAT,
        target: lod_buffer,
        state: blended,
        ..Default::default()
    };
    let err = ImpostorPass::new(gpu, &descriptor).unwrap_err();
    assert!(
        matches!(
            err,
            GpuError::Invalid {
                parameter: "state",
                ..
            }
        ),
        "{err}"
    );
    let descriptor = ImpostorPassDescriptor {
        depth_format: wgpu::TextureFormat::Depth24Plus,
        state: LodRenderState::OPAQUE,
        ..descriptor
    };
    let err = ImpostorPass::new(gpu, &descriptor).unwrap_err();
    assert!(
        matches!(
            err,
            GpuError::Invalid {
                parameter: "depth_format",
                ..
            }
        ),
        "{err}"
    );

    let textures = bake(gpu, &lumpy());
    let (view_proj, eye) = camera();
    let view = impostor_view(view_proj, eye);
    let instances = [ImpostorInstance::new(Mat4::IDENTITY)];
    let lod_pass = new_pass(gpu, lod_buffer, LodRenderState::OPAQUE);
    let color_pass = new_pass(gpu, ImpostorTarget::Color, LodRenderState::OPAQUE);
    let err = lod_pass
        .prepare(gpu, &textures, &view, &instances)
        .unwrap_err();
    assert!(err.to_string().contains("prepare_lod_buffer"), "{err}");
    let err = lod_pass
        .render(gpu, &textures, &view, &instances, (8, 8))
        .unwrap_err();
    assert!(matches!(err, GpuError::Mismatch { .. }), "{err}");
    let vis = lodkit::gpu::resources::r32float_texture(gpu, 1, &[0.5], "vis").unwrap();
    let vis_view = vis.create_view(&Default::default());
    let lod = ImpostorLodView {
        prev_view_proj: view_proj,
        size: (8, 8),
        visibility: &vis_view,
        space: VisibilitySpace::Object,
        vis_scale: f32::NAN,
    };
    let err = lod_pass
        .prepare_lod_buffer(gpu, &textures, &view, &lod, &instances)
        .unwrap_err();
    assert!(
        matches!(
            err,
            GpuError::Invalid {
                parameter: "lod.vis_scale",
                ..
            }
        ),
        "{err}"
    );
    let screen = ImpostorLodView {
        space: VisibilitySpace::Screen,
        ..lod
    };
    let err = color_pass
        .prepare_lod_buffer(gpu, &textures, &view, &screen, &instances)
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("ImpostorPass::prepare for a colour"),
        "{err}"
    );
}

#[test]
fn an_update_in_place_draws_what_a_new_preparation_draws_and_ranges_draw_their_instances() {
    let gpu = lodkit_test_gpu!();
    let textures = bake(gpu, &lumpy());
    let (view_proj, eye) = camera();
    let view = impostor_view(view_proj, eye);
    let pass = new_pass(gpu, ImpostorTarget::Color, LodRenderState::OPAQUE);
    let opaque = (wgpu::Color::TRANSPARENT, LodRenderState::OPAQUE);
    let left = ImpostorInstance::new(Mat4::from_translation(Vec3::new(-0.9, 0.0, 0.0)));
    let right = ImpostorInstance {
        tint: Vec3::new(1.0, 0.3, 0.3),
        ..ImpostorInstance::new(Mat4::from_translation(Vec3::new(0.9, 0.0, -0.5)))
    };
    let both = [left, right];
    // Prepared for one instance, then updated to two (the buffer grows) and to another view:
    // byte for byte what a fresh preparation of the same draws.
    let mut kept = pass.prepare(gpu, &textures, &view, &[right]).unwrap();
    let moved = impostor_view(
        Mat4::from_translation(Vec3::new(0.1, 0.0, 0.0)) * view_proj,
        eye,
    );
    for v in [view, moved] {
        pass.update(gpu, &mut kept, &textures, &v, None, &both)
            .unwrap();
        let fresh = pass.prepare(gpu, &textures, &v, &both).unwrap();
        let (a, b) = (
            draw_prepared(gpu, &pass, &kept, opaque, ..),
            draw_prepared(gpu, &pass, &fresh, opaque, ..),
        );
        assert!(
            a.iter().filter(|p| p[3] > 127).count() > 500,
            "nothing drawn"
        );
        assert_eq!(a, b, "an updated set draws other pixels than a new one");
    }
    // A range draws its instances only: the two ranges make up the whole.
    pass.update(gpu, &mut kept, &textures, &view, None, &both)
        .unwrap();
    let whole = draw_prepared(gpu, &pass, &kept, opaque, 0..2);
    let first = draw_prepared(gpu, &pass, &kept, opaque, 0..1);
    let second = draw_prepared(gpu, &pass, &kept, opaque, 1..9);
    let alone = |i: ImpostorInstance| draw(gpu, &pass, i, opaque).0;
    let (left_alone, right_alone) = (alone(left), alone(right));
    assert_eq!(
        first.concat(),
        left_alone,
        "range 0..1 is the first instance alone"
    );
    assert_eq!(
        second.concat(),
        right_alone,
        "range 1..9 is the second instance alone"
    );
    let fresh = pass.prepare(gpu, &textures, &view, &both).unwrap();
    let want = draw_prepared(gpu, &pass, &fresh, opaque, ..);
    assert_eq!(whole, want, "range 0..2 is both instances");
}

/// `prepared`'s instances in `range` drawn into a cleared target: its pixels.
fn draw_prepared(
    gpu: &GpuContext,
    pass: &ImpostorPass,
    prepared: &lodkit::gpu::impostor::PreparedImpostors,
    (clear, state): (wgpu::Color, LodRenderState),
    range: impl std::ops::RangeBounds<u32>,
) -> Vec<[u8; 4]> {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let color = texture_2d(gpu, (SIZE, SIZE), FORMAT, usage, "colour").unwrap();
    // Bound as a texture too: where depth cannot be copied (GL), read_depth32 draws it out.
    let usage = usage | wgpu::TextureUsages::TEXTURE_BINDING;
    let depth_format = wgpu::TextureFormat::Depth32Float;
    let depth = texture_2d(gpu, (SIZE, SIZE), depth_format, usage, "depth").unwrap();
    let start = match range.start_bound() {
        std::ops::Bound::Included(s) => *s,
        _ => 0,
    };
    let end = match range.end_bound() {
        std::ops::Bound::Excluded(e) => *e,
        _ => u32::MAX,
    };
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let c = color.create_view(&Default::default());
        let d = depth.create_view(&Default::default());
        let mut render = begin_targets_pass(&mut encoder, &[(&c, clear)], &d, 1.0, None, "draw");
        render.set_blend_constant(lod_blend_constant(&state));
        pass.draw_instances(&mut render, prepared, start..end);
    }
    gpu.queue.submit([encoder.finish()]);
    read_texture_rgba8(gpu, &color)
        .unwrap()
        .chunks(4)
        .map(|p| [p[0], p[1], p[2], p[3]])
        .collect()
}
