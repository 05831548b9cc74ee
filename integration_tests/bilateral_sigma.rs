//! The depth sigma as the hosts take it, a fraction of the pixel's view depth
//! (`lodkit::bilateral::bilateral_relative_sigma`): WGSL and GLSL against the Rust twin.

use lodkit::bilateral::{BILATERAL_SIGMA_OFF, bilateral_relative_sigma};
use lodkit::shaders::SourceLanguage;

use crate::harness::{Probe, assert_close, floats, run_with, words};

/// `bilateral_relative_sigma`, WGSL and GLSL, against the Rust twin: a max and one multiply,
/// which WGSL and GLSL round correctly, so the results are equal bit for bit (a tolerance of
/// 0). The cases: a depth of 20, none (the floor), off, far, behind the camera (the floor), and
/// under the floor.
#[test]
fn relative_sigma_twins_match() {
    let gpu = lodkit_test_gpu!(device);
    let cases: [(f32, f32); 6] = [
        (0.05, 20.0),
        (0.05, 0.0),
        (BILATERAL_SIGMA_OFF, 5.0),
        (0.02, 1.0e4),
        (0.3, -1.0),
        (0.05, 1.0e-7),
    ];
    let want: Vec<f32> = cases
        .iter()
        .map(|&(relative, depth)| bilateral_relative_sigma(relative, depth))
        .collect();
    let inputs: Vec<u32> = cases.iter().flat_map(|&(r, d)| words(&[r, d])).collect();
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::bilateral::bilateral_relative_sigma",
            "out_f(0u, bilateral_relative_sigma(inp_f(0u), inp_f(1u)));",
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/bilateral.glsl\"",
            "out_f(0u, lodkit_bilateral_relative_sigma(inp_f(0u), inp_f(1u)));",
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 2,
            outputs: 1,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = floats(&run_with(gpu, &probe, &inputs, language, &[]));
        assert_close(
            &got,
            &want,
            0.0,
            &format!("{language:?} bilateral_relative_sigma"),
        );
    }
}

/// The upsample pass takes the depth sigma as a fraction of each pixel's view depth: the same
/// scene at 8 times the size (every position, the camera and the clip planes: the same pixels
/// covered, view depths 8 times as far, exactly, being powers of two apart) upsamples to the
/// same picture. Within one level of 8-bit colour: the albedo's interpolated object position and
/// the normals' normalization need not scale bit for bit on every GPU. The scene has a floor
/// seen at a grazing angle, whose neighbouring samples differ in depth by about the sigma: an
/// absolute sigma would weigh them 8 times apart at the two sizes.
#[test]
fn the_upsample_pass_sigma_follows_the_view_depth() {
    use glam::{Mat4, Vec3, Vec4};
    use lodkit::bilateral::RangeSigmas;
    use lodkit::gpu::framebuffer_lod::{
        LowResBuffer, UpsampleFrame, UpsamplePass, UpsamplePassDescriptor, UpsampleSettings,
    };
    use lodkit::gpu::readback::read_texture_rgba8;
    use lodkit::gpu::resources::texture_2d;
    use lodkit_scenes::gbuffer::{GBufferFrame, GBufferRenderer, GDrawItem, ShadingTerm};
    use lodkit_scenes::mesh::{GpuMesh, Mesh};

    let gpu = lodkit_test_gpu!();
    let (w, h) = (96u32, 64u32);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let renderer = GBufferRenderer::new(gpu, format, ShadingTerm::Albedo).unwrap();
    let (sphere, cube) = (
        GpuMesh::new(gpu, &Mesh::sphere(16, 32)).unwrap(),
        GpuMesh::new(gpu, &Mesh::cube()).unwrap(),
    );
    let upsample = UpsamplePass::new(
        gpu,
        &UpsamplePassDescriptor {
            target_format: format,
            ..Default::default()
        },
    )
    .unwrap();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(gpu, (w, h), format, usage, "upsampled").unwrap();
    let view = target.create_view(&Default::default());
    let picture = |k: f32| {
        let t = |x: f32, y: f32, z: f32| Mat4::from_translation(Vec3::new(x, y, z) * k);
        let s = |x: f32, y: f32, z: f32| Mat4::from_scale(Vec3::new(x, y, z) * k);
        let items = [
            // The floor, seen at a grazing angle.
            GDrawItem {
                mesh: &cube,
                model: t(0.0, -1.0, -6.0) * s(8.0, 0.05, 12.0),
                color: Vec4::new(0.8, 0.75, 0.6, 1.0),
            },
            GDrawItem {
                mesh: &sphere,
                model: t(-0.6, -0.2, -3.0) * s(0.7, 0.7, 0.7),
                color: Vec4::new(0.2, 0.5, 0.9, 1.0),
            },
            GDrawItem {
                mesh: &cube,
                model: t(1.0, -0.4, -5.0) * Mat4::from_rotation_y(0.6) * s(0.6, 0.6, 0.6),
                color: Vec4::new(0.9, 0.3, 0.2, 1.0),
            },
        ];
        let eye = Vec3::new(0.0, 0.2, 2.0) * k;
        let frame = GBufferFrame {
            view: glam::camera::rh::view::look_at_mat4(
                eye,
                Vec3::new(0.0, -0.6, -4.0) * k,
                Vec3::Y,
            ),
            proj: glam::camera::rh::proj::directx::perspective(
                0.9,
                w as f32 / h as f32,
                0.125 * k,
                128.0 * k,
            ),
            items: &items,
            far_view_depth: 64.0 * k,
            ..Default::default()
        };
        let full = LowResBuffer::new(gpu, w, h, format).unwrap();
        let low = LowResBuffer::new(gpu, w, h, format).unwrap();
        renderer.render(gpu, &full, &frame).unwrap();
        renderer
            .render(gpu, &low, &GBufferFrame { r: 2.0, ..frame })
            .unwrap();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let sigmas = RangeSigmas {
            depth: 0.02,
            normal: f32::INFINITY,
        };
        let frame = UpsampleFrame {
            low: &low,
            full_geometry: full.geometry(),
            full_albedo: None,
            target: &view,
            settings: UpsampleSettings { r: 2.0, sigmas },
        };
        upsample.record(gpu, &mut encoder, &frame).unwrap();
        gpu.queue.submit([encoder.finish()]);
        read_texture_rgba8(gpu, &target).unwrap()
    };
    let (near, far) = (picture(1.0), picture(8.0));
    let worst = near
        .iter()
        .zip(&far)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    let differing = near
        .chunks_exact(4)
        .zip(far.chunks_exact(4))
        .filter(|(a, b)| a != b)
        .count();
    crate::harness::say(&format!(
        "upsample at 1x and 8x the scene's size: {differing} pixels differ, by at most {worst} levels"
    ));
    assert!(
        worst <= 1,
        "{differing} pixels differ, by up to {worst} levels"
    );
}
