//! Geometry-aware framebuffer LOD: bilateral upsampling on the GPU (WGSL and GLSL twins) against
//! the Rust twin on hand-built 2x2 neighbourhoods.

use glam::{Vec2, Vec3, Vec4};
use lodkit::bilateral::{bilateral_tent, bilateral_upsample, gpu_sigma};
use lodkit::shaders::SourceLanguage;

use crate::harness::{Probe, assert_close, floats, run_with, words};

struct Case {
    name: &'static str,
    f: Vec2,
    values: [Vec4; 4],
    depths: Vec4,
    normals: [Vec3; 4],
    depth: f32,
    normal: Vec3,
    sigma_z: f32,
    sigma_n: f32,
}

fn cases() -> Vec<Case> {
    let values = [
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, 1.0, 1.0),
        Vec4::new(1.0, 1.0, 1.0, 1.0),
    ];
    let flat = [Vec3::Z; 4];
    let tilted = Vec3::new(0.8, 0.0, 0.6);
    let inf = f32::INFINITY;
    vec![
        Case {
            name: "flat region",
            f: Vec2::new(0.3, 0.6),
            values,
            depths: Vec4::splat(5.0),
            normals: flat,
            depth: 5.0,
            normal: Vec3::Z,
            sigma_z: 0.1,
            sigma_n: 0.3,
        },
        Case {
            name: "depth edge",
            f: Vec2::new(0.5, 0.5),
            values,
            depths: Vec4::new(5.0, 20.0, 5.0, 20.0),
            normals: flat,
            depth: 5.0,
            normal: Vec3::Z,
            sigma_z: 0.1,
            sigma_n: 0.3,
        },
        Case {
            name: "normal crease",
            f: Vec2::new(0.5, 0.25),
            values,
            depths: Vec4::splat(5.0),
            normals: [Vec3::Z, tilted, Vec3::Z, tilted],
            depth: 5.0,
            normal: Vec3::Z,
            sigma_z: 0.1,
            sigma_n: 0.3,
        },
        Case {
            name: "all weights vanish",
            f: Vec2::new(0.5, 0.5),
            values,
            depths: Vec4::new(9.0, 7.5, 12.0, 30.0),
            normals: flat,
            depth: 5.0,
            normal: Vec3::Z,
            sigma_z: 0.1,
            sigma_n: 0.3,
        },
        Case {
            name: "sigma = inf",
            f: Vec2::new(0.7, 0.2),
            values,
            depths: Vec4::new(5.0, 20.0, 1.0, 9.0),
            normals: [Vec3::Z, tilted, -Vec3::X, Vec3::Z],
            depth: 5.0,
            normal: Vec3::Z,
            sigma_z: inf,
            sigma_n: inf,
        },
        Case {
            name: "corner",
            f: Vec2::ZERO,
            values,
            depths: Vec4::splat(1.0),
            normals: flat,
            depth: 1.0,
            normal: Vec3::Z,
            sigma_z: 0.05,
            sigma_n: 0.1,
        },
    ]
}

fn inputs(cases: &[Case]) -> Vec<u32> {
    cases
        .iter()
        .flat_map(|c| {
            let mut v = vec![c.f.x, c.f.y];
            c.values.iter().for_each(|x| v.extend(x.to_array()));
            v.extend(c.depths.to_array());
            c.normals.iter().for_each(|n| v.extend(n.to_array()));
            v.push(c.depth);
            v.extend(c.normal.to_array());
            // A shader is given no infinity: +inf goes in as the finite sigma that does the same.
            v.extend([gpu_sigma(c.sigma_z), gpu_sigma(c.sigma_n)]);
            words(&v)
        })
        .collect()
}

const WGSL: &str = "let f = vec2(inp_f(0u), inp_f(1u));
    var values: array<vec4<f32>, 4>;
    var normals: array<vec3<f32>, 4>;
    for (var i = 0u; i < 4u; i++) {
        values[i] = vec4(inp_f(2u + 4u * i), inp_f(3u + 4u * i), inp_f(4u + 4u * i), inp_f(5u + 4u * i));
        normals[i] = vec3(inp_f(22u + 3u * i), inp_f(23u + 3u * i), inp_f(24u + 3u * i));
    }
    let depths = vec4(inp_f(18u), inp_f(19u), inp_f(20u), inp_f(21u));
    let r = bilateral_upsample(f, values, depths, normals, inp_f(34u), vec3(inp_f(35u), inp_f(36u), inp_f(37u)), inp_f(38u), inp_f(39u));
    out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_f(3u, r.w);";

const GLSL: &str = "vec2 f = vec2(inp_f(0u), inp_f(1u));
    vec4 values[4];
    vec3 normals[4];
    for (uint i = 0u; i < 4u; i++) {
        values[i] = vec4(inp_f(2u + 4u * i), inp_f(3u + 4u * i), inp_f(4u + 4u * i), inp_f(5u + 4u * i));
        normals[i] = vec3(inp_f(22u + 3u * i), inp_f(23u + 3u * i), inp_f(24u + 3u * i));
    }
    vec4 depths = vec4(inp_f(18u), inp_f(19u), inp_f(20u), inp_f(21u));
    vec4 r = lodkit_bilateral_upsample(f, values, depths, normals, inp_f(34u), vec3(inp_f(35u), inp_f(36u), inp_f(37u)), inp_f(38u), inp_f(39u));
    out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_f(3u, r.w);";

#[test]
fn bilateral_upsample_twins_match_on_hand_built_neighbourhoods() {
    let gpu = lodkit_test_gpu!(device);
    let cases = cases();
    let want: Vec<f32> = cases
        .iter()
        .flat_map(|c| {
            bilateral_upsample(
                c.f, &c.values, c.depths, &c.normals, c.depth, c.normal, c.sigma_z, c.sigma_n,
            )
            .to_array()
        })
        .collect();
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::bilateral::bilateral_upsample",
            WGSL,
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/bilateral.glsl\"",
            GLSL,
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 40,
            outputs: 4,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = floats(&run_with(gpu, &probe, &inputs(&cases), language, &[]));
        assert_close(
            &got,
            &want,
            1e-5,
            &format!("{language:?} bilateral_upsample"),
        );
    }
}

#[test]
fn bilateral_cases_behave_as_the_paper_says() {
    let bilinear = |c: &Case| {
        let t = bilateral_tent(c.f);
        (0..4).fold(Vec4::ZERO, |acc, i| acc + t[i] * c.values[i])
    };
    let run = |c: &Case| {
        bilateral_upsample(
            c.f, &c.values, c.depths, &c.normals, c.depth, c.normal, c.sigma_z, c.sigma_n,
        )
    };
    let cs = cases();
    let close = |a: Vec4, b: Vec4| (a - b).abs().max_element() < 1e-5;
    // "No bleeding": what crosses the edge is below 0.1 % (the Gaussians never reach exactly 0).
    let no_bleed = |a: Vec4, b: Vec4| (a - b).abs().max_element() < 1e-3;
    assert!(
        close(run(&cs[0]), bilinear(&cs[0])),
        "{}: equals bilinear",
        cs[0].name
    );
    // Depth edge: only the near samples 0 and 2 contribute (equal tent weights -> their mean).
    assert!(
        no_bleed(run(&cs[1]), 0.5 * (cs[1].values[0] + cs[1].values[2])),
        "{}: no bleeding",
        cs[1].name
    );
    // Normal crease: only the facing samples 0 and 2 contribute, in tent proportion 3:1.
    assert!(
        no_bleed(run(&cs[2]), 0.75 * cs[2].values[0] + 0.25 * cs[2].values[2]),
        "{}: no bleeding",
        cs[2].name
    );
    assert_eq!(
        run(&cs[3]),
        cs[3].values[1],
        "{}: the sample closest in depth (7.5)",
        cs[3].name
    );
    assert!(
        close(run(&cs[4]), bilinear(&cs[4])),
        "{}: sigma = inf is bilinear",
        cs[4].name
    );
    assert_eq!(
        run(&cs[5]),
        cs[5].values[0],
        "{}: f = 0 is the first sample",
        cs[5].name
    );
}

mod controller {
    use lodkit::framebuffer_lod::*;
    use proptest::prelude::*;

    const TARGET: f32 = 16.7;

    fn step_workload(f: usize) -> f32 {
        if f < 60 { 1.0 } else { 2.0 }
    }

    #[test]
    fn online_controller_settles_after_a_2x_step_without_noise() {
        let model = FrameTimeModel {
            k: 40.0,
            c: 3.0,
            noise: 0.0,
        };
        let mut c = RlsController::new(TARGET, ResizeLimits::default());
        let frames = simulate(&mut c, &model, step_workload, 160, 0);
        let r = step_response(&frames, 60, TARGET, 0.05);
        let settling = r.settling_frames.expect("settles");
        assert!(settling <= 10, "settled after {settling} frames");
        assert!(r.overshoot <= 0.10, "overshoot {}", r.overshoot);
        // It found the model: r^2 = 2K / (target - C).
        let want = (80.0f32 / (TARGET - 3.0)).sqrt();
        assert!(
            (frames.last().unwrap().r - want).abs() < 0.02,
            "r {} vs {want}",
            frames.last().unwrap().r
        );
    }

    #[test]
    fn online_controller_settles_under_noise_in_most_runs() {
        let model = FrameTimeModel {
            k: 40.0,
            c: 3.0,
            noise: 0.03,
        };
        let (mut fast, mut worst_overshoot) = (0, 0.0f32);
        for seed in 0..50 {
            let mut c = RlsController::new(TARGET, ResizeLimits::default());
            let r = step_response(
                &simulate(&mut c, &model, step_workload, 160, seed),
                60,
                TARGET,
                0.05,
            );
            fast += usize::from(r.settling_frames.is_some_and(|s| s <= 10));
            worst_overshoot = worst_overshoot.max(r.overshoot);
        }
        assert!(
            fast >= 45,
            "only {fast} of 50 noisy runs settled within 10 frames"
        );
        assert!(worst_overshoot <= 0.10, "overshoot {worst_overshoot}");
    }

    /// A GPU that slows down (a laptop clocking down, a data-center part idling between the
    /// slow frames of a debug build): the whole frame, K and C alike, takes 2x longer over 200
    /// frames, with 3 % noise. r must follow it up, and the frame time must come back within 10 %
    /// of the target and stay there, while the speed drifts and after it stops.
    #[test]
    fn online_controller_follows_a_gpu_whose_speed_drifts_2x_over_200_frames() {
        let (k, c) = (40.0f32, 3.0f32);
        let speed = |f: usize| 1.0 + (f.saturating_sub(50).min(200) as f32) / 200.0;
        let expected = |f: usize, r: f32| speed(f) * (k / (r * r) + c);
        for seed in 0..20u64 {
            let mut controller = RlsController::new(TARGET, ResizeLimits::default());
            let mut noise = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
            let mut uniform = || {
                noise ^= noise << 13;
                noise ^= noise >> 7;
                noise ^= noise << 17;
                (noise >> 40) as f32 / (1u64 << 24) as f32
            };
            let mut worst_after_settling = 0.0f32;
            let mut r_at = Vec::new();
            for f in 0..400 {
                let r = controller.r();
                let t = expected(f, r);
                r_at.push(r);
                if f >= 30 {
                    worst_after_settling = worst_after_settling.max((t - TARGET).abs() / TARGET);
                }
                controller.update(t * (1.0 + 0.03 * (2.0 * uniform() - 1.0)));
            }
            // r followed: from the speed-1 solution to the speed-2 one.
            let solve = |s: f32| (k / (TARGET / s - c)).sqrt();
            assert!(
                (r_at[49] - solve(1.0)).abs() < 0.1,
                "seed {seed}: r {} before the drift",
                r_at[49]
            );
            assert!(
                (r_at[399] - solve(2.0)).abs() < 0.1,
                "seed {seed}: r {} after it",
                r_at[399]
            );
            // The frame time stayed within the band all along once settled.
            assert!(
                worst_after_settling <= 0.10,
                "seed {seed}: the frame time strayed {worst_after_settling:.3} from the target"
            );
        }
    }

    #[test]
    fn the_papers_controller_overshoots_when_its_calibration_is_stale() {
        // The comparison the online estimator is for: K calibrated before the workload doubled.
        let model = FrameTimeModel {
            k: 40.0,
            c: 3.0,
            noise: 0.0,
        };
        let mut paper = PaperController::new(TARGET, 40.0, ResizeLimits::default());
        let r = step_response(
            &simulate(&mut paper, &model, step_workload, 160, 0),
            60,
            TARGET,
            0.05,
        );
        assert!(
            r.settling_frames.is_none_or(|s| s > 10) || r.overshoot > 0.10,
            "{r:?}"
        );
    }

    fn arb_workload() -> impl Strategy<Value = Vec<f32>> {
        prop::collection::vec(
            prop_oneof![0.2f32..4.0, Just(f32::NAN), Just(0.0), Just(-1.0)],
            1..8,
        )
    }

    proptest! {
        #[test]
        fn every_controller_keeps_r_in_bounds(levels in arb_workload(), noise in 0.0f32..0.2, r_max in 1.0f32..6.0, seed in any::<u64>()) {
            let limits = ResizeLimits { r_max, max_step: 0.2 };
            let mut controllers: Vec<Box<dyn ResizeController>> = vec![
                Box::new(RlsController::new(TARGET, limits)),
                Box::new(PaperController::new(TARGET, 40.0, limits)),
                Box::new(StepController::new(TARGET, limits)),
            ];
            let model = FrameTimeModel { k: 40.0, c: 3.0, noise };
            for c in controllers.iter_mut() {
                // Workload levels (NaN, 0 and negative ones give NaN/0/negative frame times).
                let frames = simulate(c.as_mut(), &model, |f| levels[(f / 20) % levels.len()], 160, seed);
                let mut previous = 1.0f32;
                for f in &frames {
                    prop_assert!(f.r >= 1.0 && f.r <= r_max.max(1.0), "r {} out of [1, {}]", f.r, r_max);
                    prop_assert!((f.r - previous).abs() <= 0.2 + 1e-6, "step {} -> {}", previous, f.r);
                    previous = f.r;
                }
            }
        }
    }

    #[test]
    fn bad_samples_are_ignored() {
        let mut c = RlsController::new(TARGET, ResizeLimits::default());
        for _ in 0..5 {
            c.update(30.0);
        }
        let (r, estimates) = (c.r(), c.estimates());
        for bad in [f32::NAN, 0.0, -5.0, f32::INFINITY] {
            assert_eq!(c.update(bad), r);
        }
        assert_eq!(c.estimates(), estimates);
    }
}

mod rendered {
    use lodkit::gpu::GpuError;
    use lodkit::gpu::framebuffer_lod::{
        LowResBuffer, RangeSigmas, UpsampleComposite, UpsampleFrame, UpsamplePass,
        UpsamplePassDescriptor, UpsampleSettings,
    };
    use lodkit::gpu::readback::read_texture_rgba8;
    use lodkit::gpu::resources::texture_2d;
    use lodkit::metrics::psnr_rgba8;
    use lodkit_scenes::gbuffer::{EdgeScene, ShadingTerm};

    use crate::harness::say;

    const W: u32 = 160;
    const H: u32 = 120;

    #[test]
    fn bilateral_beats_bilinear_by_3_db_at_r_2() {
        let gpu = lodkit_test_gpu!();
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let scene = EdgeScene::new(gpu, format, W as f32 / H as f32).unwrap();
        let full = LowResBuffer::new(gpu, W, H, format).unwrap();
        scene.render(gpu, &full, 1.0).unwrap();
        let reference = read_texture_rgba8(gpu, full.color()).unwrap();
        let low = LowResBuffer::new(gpu, W, H, format).unwrap();
        let albedo = LowResBuffer::new(gpu, W, H, format).unwrap();
        let desc = UpsamplePassDescriptor {
            target_format: format,
            ..Default::default()
        };
        let upsample = UpsamplePass::new(gpu, &desc).unwrap();
        let fine_desc = UpsamplePassDescriptor {
            composite: UpsampleComposite::TimesAlbedo,
            ..desc
        };
        let fine_pass = UpsamplePass::new(gpu, &fine_desc).unwrap();
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let target = texture_2d(gpu, (W, H), format, usage, "upsampled").unwrap();
        let view = target.create_view(&Default::default());
        fn frame<'a>(
            (low, full, view): (&'a LowResBuffer, &'a LowResBuffer, &'a wgpu::TextureView),
            r: f32,
            sigmas: RangeSigmas,
            albedo: Option<&'a wgpu::Texture>,
        ) -> UpsampleFrame<'a> {
            UpsampleFrame {
                low,
                full_geometry: full.geometry(),
                full_albedo: albedo,
                target: view,
                settings: UpsampleSettings { r, sigmas },
            }
        }
        let frame = |r, sigmas, albedo| frame((&low, &full, &view), r, sigmas, albedo);
        let sigmas = RangeSigmas::default();
        // An albedo where the pass has no composite, and none where it has: refused.
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let wrong = fine_pass.record(gpu, &mut encoder, &frame(2.0, sigmas, None));
        assert!(matches!(wrong, Err(GpuError::Mismatch { .. })), "{wrong:?}");
        let with_albedo = frame(2.0, sigmas, Some(albedo.color()));
        let wrong = upsample.record(gpu, &mut encoder, &with_albedo);
        assert!(matches!(wrong, Err(GpuError::Mismatch { .. })), "{wrong:?}");
        let run = |pass: &UpsamplePass, f: UpsampleFrame| {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            pass.record(gpu, &mut encoder, &f).unwrap();
            gpu.queue.submit([encoder.finish()]);
            read_texture_rgba8(gpu, &target).unwrap()
        };
        let mut rows = Vec::new();
        let mut gain_at_2 = 0.0;
        for r in [2.0f32, 4.0] {
            scene.render(gpu, &low, r).unwrap();
            let mut psnr = [0.0f32; 2];
            for (i, s) in [RangeSigmas::OFF, sigmas].into_iter().enumerate() {
                psnr[i] = psnr_rgba8(&run(&upsample, frame(r, s, None)), &reference);
            }
            // Fine-grained: only the lighting goes through L; the albedo is drawn at full res.
            scene
                .render_term(gpu, &low, r, ShadingTerm::Lighting)
                .unwrap();
            let lighting = run(&upsample, frame(r, sigmas, None));
            scene
                .render_term(gpu, &albedo, 1.0, ShadingTerm::Albedo)
                .unwrap();
            let albedo_pixels = read_texture_rgba8(gpu, albedo.color()).unwrap();
            // The fine-grained pass multiplies in the upsample: within 1 of the product of the
            // two RGBA8 images (it multiplies before the lighting is quantized).
            let composite = run(&fine_pass, frame(r, sigmas, Some(albedo.color())));
            let product = super::multiply_rgba8(&lighting, &albedo_pixels);
            let worst = composite
                .iter()
                .zip(&product)
                .map(|(a, b)| a.abs_diff(*b))
                .max();
            assert!(
                worst <= Some(1),
                "composite vs product: {worst:?} at r = {r}"
            );
            let fine = psnr_rgba8(&composite, &reference);
            rows.push(format!(
                "r = {r}: bilinear {:.2} dB, bilateral {:.2} dB, gain {:+.2} dB; fine-grained {fine:.2} dB",
                psnr[0],
                psnr[1],
                psnr[1] - psnr[0]
            ));
            assert!(
                fine > psnr[1],
                "fine-grained resizing must beat full resizing at r = {r}"
            );
            if r == 2.0 {
                gain_at_2 = psnr[1] - psnr[0];
            }
            assert!(psnr[1] > psnr[0], "bilateral must beat bilinear at r = {r}");
        }
        say(&format!(
            "edge scene {W}x{H}, PSNR vs full-res reference:\n{}",
            rows.join("\n")
        ));
        assert!(
            gain_at_2 >= 3.0,
            "gain at r = 2 is {gain_at_2:.2} dB, target >= 3 dB"
        );
    }

    /// Two upsamples recorded in one encoder with different parameters (r = 2 and r = 3, and
    /// other sigmas), each into a target of its own, give each the image the same recording
    /// gives alone: every recording reads its own parameters, whatever else the encoder holds.
    #[test]
    fn two_recordings_in_one_encoder_each_read_their_own_parameters() {
        let gpu = lodkit_test_gpu!();
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let scene = EdgeScene::new(gpu, format, W as f32 / H as f32).unwrap();
        let full = LowResBuffer::new(gpu, W, H, format).unwrap();
        scene.render(gpu, &full, 1.0).unwrap();
        let lows = [2.0f32, 3.0].map(|r| {
            let low = LowResBuffer::new(gpu, W, H, format).unwrap();
            scene.render(gpu, &low, r).unwrap();
            (low, r)
        });
        let desc = UpsamplePassDescriptor {
            target_format: format,
            ..Default::default()
        };
        let pass = UpsamplePass::new(gpu, &desc).unwrap();
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let targets = [0, 1].map(|_| texture_2d(gpu, (W, H), format, usage, "t").unwrap());
        let views = targets
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        let sigmas = [
            RangeSigmas::default(),
            RangeSigmas {
                depth: 0.05,
                normal: 0.1,
            },
        ];
        let frame = |k: usize| UpsampleFrame {
            low: &lows[k].0,
            full_geometry: full.geometry(),
            full_albedo: None,
            target: &views[k],
            settings: UpsampleSettings {
                r: lows[k].1,
                sigmas: sigmas[k],
            },
        };
        let alone: Vec<Vec<u8>> = (0..2)
            .map(|k| {
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                pass.record(gpu, &mut encoder, &frame(k)).unwrap();
                gpu.queue.submit([encoder.finish()]);
                read_texture_rgba8(gpu, &targets[k]).unwrap()
            })
            .collect();
        assert_ne!(
            alone[0], alone[1],
            "the two recordings draw different images"
        );
        for t in &targets {
            // Cleared, so that a recording that drew nothing would be seen.
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let view = t.create_view(&Default::default());
            drop(lodkit::gpu::resources::begin_color_pass(
                &mut encoder,
                &view,
                wgpu::Color::RED,
                "clear",
            ));
            gpu.queue.submit([encoder.finish()]);
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        pass.record(gpu, &mut encoder, &frame(0)).unwrap();
        pass.record(gpu, &mut encoder, &frame(1)).unwrap();
        gpu.queue.submit([encoder.finish()]);
        for k in 0..2 {
            let together = read_texture_rgba8(gpu, &targets[k]).unwrap();
            assert!(
                together == alone[k],
                "recording {k} in one encoder with another differs from it alone"
            );
        }
    }

    #[test]
    fn changing_r_does_not_reallocate_the_low_res_buffer() {
        let _shared = lodkit_test_gpu!();
        // A device of its own, so that the live-texture count is this test's alone.
        let gpu = &lodkit::gpu::GpuContext::new_headless(&Default::default()).unwrap();
        let textures = || {
            gpu.instance
                .generate_report()
                .map(|r| r.hub_report().textures.num_kept_from_user)
        };
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let scene = EdgeScene::new(gpu, format, 4.0 / 3.0).unwrap();
        let low = LowResBuffer::new(gpu, 64, 48, format).unwrap();
        scene.render(gpu, &low, 1.0).unwrap();
        gpu.wait_idle().unwrap();
        let before = textures();
        for r in [1.0f32, 1.2, 1.4, 2.0, 3.7, 4.0] {
            scene.render(gpu, &low, r).unwrap();
            gpu.wait_idle().unwrap();
            assert_eq!(
                textures(),
                before,
                "textures were allocated or freed at r = {r}"
            );
            let (w, h) = low.viewport(r);
            assert_eq!((w, h), ((64.0 / r).ceil() as u32, (48.0 / r).ceil() as u32));
            assert_eq!(
                (low.color().width(), low.color().height()),
                (64, 48),
                "L stays at full size"
            );
        }
    }
}

#[test]
fn bilateral_upsample_at_twins_match_on_real_textures() {
    use lodkit::bilateral::{Image, bilateral_upsample_at};
    let gpu = lodkit_test_gpu!();
    // L textures of 6x5 with only 5x4 rendered (the viewport), a 10x8 full-res target: r = 2.
    let (lw, lh) = (6u32, 5u32);
    let noise = lodkit::noise::white_noise((lw * lh * 8) as usize, 21);
    let colors: Vec<Vec4> = noise
        .chunks(8)
        .map(|c| Vec4::new(c[0], c[1], c[2], 1.0))
        .collect();
    let geometry: Vec<Vec4> = (0..lw * lh)
        .map(|i| {
            let (x, n) = ((i % lw) as f32, &noise[(i * 8) as usize..]);
            let depth = if x < 2.5 {
                3.0 + 0.1 * n[3]
            } else {
                9.0 + 0.1 * n[4]
            };
            Vec4::new(depth, n[5] * 0.6 - 0.3, n[6] * 0.6 - 0.3, 0.9)
        })
        .collect();
    let (viewport, full) = (Vec2::new(5.0, 4.0), Vec2::new(10.0, 8.0));
    let pixels: Vec<(Vec2, f32, Vec3)> = (0..80)
        .map(|i| {
            let p = Vec2::new((i % 10) as f32 + 0.5, (i / 10) as f32 + 0.5);
            let depth = if p.x < 5.0 { 3.05 } else { 9.05 };
            (p, depth, Vec3::new(0.1, -0.1, 0.99).normalize())
        })
        .collect();
    let inputs: Vec<u32> = pixels
        .iter()
        .flat_map(|(p, d, n)| words(&[p.x, p.y, *d, n.x, n.y, n.z]))
        .collect();
    let want: Vec<f32> = pixels
        .iter()
        .flat_map(|(p, d, n)| {
            let c = Image {
                width: lw,
                texels: &colors,
            };
            let g = Image {
                width: lw,
                texels: &geometry,
            };
            bilateral_upsample_at(c, g, viewport, full, *p, *d, *n, 0.3, 0.5).to_array()
        })
        .collect();
    let wgsl = "let r = bilateral_upsample_at(probe_rgba0, probe_rgba1, vec2(5.0, 4.0), vec2(10.0, 8.0), vec2(inp_f(0u), inp_f(1u)), inp_f(2u), vec3(inp_f(3u), inp_f(4u), inp_f(5u)), 0.3, 0.5);
        out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_f(3u, r.w);";
    let glsl = "vec4 r = lodkit_bilateral_upsample_at(sampler2D(probe_rgba0, probe_sampler), sampler2D(probe_rgba1, probe_sampler), vec2(5.0, 4.0), vec2(10.0, 8.0), vec2(inp_f(0u), inp_f(1u)), inp_f(2u), vec3(inp_f(3u), inp_f(4u), inp_f(5u)), 0.3, 0.5);
        out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_f(3u, r.w);";
    let textures = [(lw, lh, &colors[..]), (lw, lh, &geometry[..])];
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::bilateral::bilateral_upsample_at",
            wgsl,
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/bilateral.glsl\"",
            glsl,
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 6,
            outputs: 4,
            texture: None,
            rgba: &textures,
            urgba: &[],
        };
        let got = floats(&run_with(gpu, &probe, &inputs, language, &[]));
        assert_close(
            &got,
            &want,
            1e-5,
            &format!("{language:?} bilateral_upsample_at"),
        );
    }
}

/// Multiplies two RGBA8 images channel by channel (RGB; alpha 255), rounding to nearest: the
/// composite of fine-grained resizing (an upsampled term times a full-resolution term) done on
/// the CPU.
fn multiply_rgba8(a: &[u8], b: &[u8]) -> Vec<u8> {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .flat_map(|(x, y)| {
            let m = |c: usize| ((u32::from(x[c]) * u32::from(y[c]) + 127) / 255) as u8;
            [m(0), m(1), m(2), 255]
        })
        .collect()
}

#[test]
fn multiply_rgba8_rounds_each_channel_and_makes_alpha_opaque() {
    // 255 * 128 / 255 = 128; 128 * 255 / 255 = 128; 0 * 9 = 0; alpha 255 whatever the inputs.
    assert_eq!(
        multiply_rgba8(&[255, 128, 0, 255], &[128, 255, 9, 7]),
        vec![128, 128, 0, 255]
    );
    // 100 * 100 / 255 = 39.2 -> 39; 200 * 200 / 255 = 156.9 -> 157.
    assert_eq!(
        multiply_rgba8(&[100, 200, 0, 0], &[100, 200, 0, 0]),
        vec![39, 157, 0, 255]
    );
}
