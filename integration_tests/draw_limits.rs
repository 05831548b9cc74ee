//! Renderers refuse more draw items than one call takes (`MAX_DRAWS`) with an error naming the
//! call, the count and the limit; they used to draw the first `MAX_DRAWS` and drop the rest.

use glam::{Mat4, Vec3, Vec4};
use lodkit::gpu::GpuError;
use lodkit::gpu::frame_sequential::LodBuffers;
use lodkit::gpu::framebuffer_lod::LowResBuffer;
use lodkit::gpu::resources::DrawUniforms;
use lodkit::unpopping::LodRenderState;
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::gbuffer::{GBufferFrame, GBufferRenderer, GDrawItem, ShadingTerm};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem};
use lodkit_scenes::mesh::{DrawItem, GpuMesh, Mesh, MeshFrame, MeshRenderer, RenderTarget};

const RGBA8: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

#[test]
fn more_draws_than_a_renderer_takes_is_an_error_naming_the_limit() {
    let gpu = lodkit_test_gpu!();
    let mesh = GpuMesh::new(gpu, &Mesh::cube()).unwrap();
    let too_many = |call: &str, max: usize, r: Result<(), GpuError>| match r {
        Err(GpuError::TooManyDraws {
            call: c,
            count,
            max: m,
        }) => {
            assert_eq!((c, count, m), (call, max + 1, max));
        }
        other => panic!("{call} with {} items: {other:?}", max + 1),
    };

    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 8, 1);
    let renderer = LodBufferRenderer::new(gpu, RGBA8, &vis, 1.0).unwrap();
    let buffers = LodBuffers::new(gpu, 8, 8, RGBA8).unwrap();
    let item = LodDrawItem {
        mesh: &mesh,
        model: Mat4::IDENTITY,
        prev_model: Mat4::IDENTITY,
        color: Vec4::ONE,
        id: 1,
        tau: 1.0,
        tau_next: 1.0,
        sway: [0.0; 2],
        prev_sway_phase: 0.0,
        alpha_rect: Vec4::ZERO,
    };
    let max = LodBufferRenderer::MAX_DRAWS;
    let render = |n: usize| {
        let items = vec![item; n];
        let clear = wgpu::Color::BLACK;
        renderer.render(
            gpu,
            &buffers,
            &LodBufferFrame {
                index: 0,
                view: Mat4::IDENTITY.into(),
                items: &items,
                clear,
                ..Default::default()
            },
        )
    };
    // Every one of MAX_DRAWS items is drawn; one more is refused, not cut off.
    assert_eq!(render(max).unwrap().0, max as u64 * 12);
    too_many("LodBufferRenderer::render", max, render(max + 1).map(drop));

    let mesh_renderer = MeshRenderer::new(gpu, false).unwrap();
    let target = RenderTarget::new(gpu, 8, 8).unwrap();
    let item = DrawItem {
        mesh: &mesh,
        model: Mat4::IDENTITY,
        color: Vec4::ONE,
        state: LodRenderState::OPAQUE,
        dither_alpha: None,
        sway: [0.0; 2],
        alpha_rect: Vec4::ZERO,
    };
    let max = MeshRenderer::MAX_DRAWS;
    let items = vec![item; max + 1];
    let r = {
        let light = Vec3::Y;
        let clear = wgpu::Color::BLACK;
        mesh_renderer.render(
            gpu,
            &target,
            &MeshFrame {
                clear,
                view_proj: Mat4::IDENTITY,
                light_dir: light,
                items: &items,
                ..Default::default()
            },
        )
    };
    too_many("MeshRenderer::render", max, r.map(drop));

    let g = GBufferRenderer::new(gpu, RGBA8, ShadingTerm::Full).unwrap();
    let low = LowResBuffer::new(gpu, 8, 8, RGBA8).unwrap();
    let item = GDrawItem {
        mesh: &mesh,
        model: Mat4::IDENTITY,
        color: Vec4::ONE,
    };
    let max = GBufferRenderer::MAX_DRAWS;
    let items = vec![item; max + 1];
    let r = {
        let (view, proj) = (Mat4::IDENTITY, Mat4::IDENTITY);
        g.render(
            gpu,
            &low,
            &GBufferFrame {
                r: 1.0,
                view,
                proj,
                items: &items,
                clear: wgpu::Color::BLACK,
                far_view_depth: 1.0,
            },
        )
    };
    too_many("GBufferRenderer::render", max, r);
    // The 1024 draws may still be running: a process that exits under them crashes in the
    // driver's teardown.
    gpu.wait_idle().unwrap();
}

#[test]
fn draw_uniforms_refuse_more_items_than_their_capacity() {
    let gpu = lodkit_test_gpu!();
    let draws = DrawUniforms::new(gpu, 16, 4, "d").unwrap();
    assert_eq!(draws.write(gpu, &[[0u32; 4]; 4]).unwrap(), 4);
    assert!(
        matches!(
            draws.write(gpu, &[[0u32; 4]; 9]),
            Err(GpuError::TooManyDraws {
                call: "DrawUniforms::write",
                count: 9,
                max: 4
            })
        ),
        "more items than the capacity are refused, not cut off"
    );
}
