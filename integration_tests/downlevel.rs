//! Downlevel devices (GL 3.3, GLES 3.0, WebGL2 class): what `GpuContext::capabilities` says
//! matches what the device does, every pass either builds or refuses with the capability it
//! lacks, and the probes' fragment route gives the words the compute route gives.
//!
//! CI runs these on llvmpipe at GL 4.5, and again as a GL 3.3 / GLSL 330 context
//! (`MESA_GL_VERSION_OVERRIDE=3.3 MESA_GLSL_VERSION_OVERRIDE=330`), with and without
//! `GL_ARB_compute_shader` in the driver's list (`MESA_EXTENSION_OVERRIDE`), which is what
//! decides whether wgpu 30 binds a GLSL 330 pipeline's resources by name.

use lodkit::gpu::select::{GpuLodSelector, GpuLodSelectorDescriptor};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::select::LodSettings;
use lodkit::shaders::SourceLanguage;
use wgpu::util::DeviceExt;

use crate::harness::{Probe, Route, run_on, say};

/// Two textures and two uniform buffers, each read into one channel of the pixel.
const TWO_OF_EACH: &str = "struct V { v: vec4<f32> }
@group(0) @binding(0) var a: texture_2d<f32>;
@group(0) @binding(1) var b: texture_2d<f32>;
@group(0) @binding(2) var<uniform> u: V;
@group(0) @binding(3) var<uniform> w: V;
@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
@fragment
fn fs() -> @location(0) vec4<f32> {
    return vec4<f32>(textureLoad(a, vec2<u32>(0u), 0).x, textureLoad(b, vec2<u32>(0u), 0).x, u.v.x, w.v.x);
}
";

/// Draws [`TWO_OF_EACH`] straight through wgpu (past lodkit's check) into one RGBA8 pixel with
/// a = 51/255, b = 102/255, u = 0.6, w = 0.8.
fn draw_two_of_each(gpu: &GpuContext) -> [u8; 4] {
    let device = &gpu.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("two of each"),
        source: wgpu::ShaderSource::Wgsl(TWO_OF_EACH.into()),
    });
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("two of each"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let texel = |value: u8| {
        device
            .create_texture_with_data(
                &gpu.queue,
                &wgpu::TextureDescriptor {
                    label: Some("one texel"),
                    size: wgpu::Extent3d::default(),
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                &[value, 0, 0, 255],
            )
            .create_view(&Default::default())
    };
    let uniform = |value: f32| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("one vec4"),
            contents: bytemuck::cast_slice(&[value, 0.0, 0.0, 0.0]),
            usage: wgpu::BufferUsages::UNIFORM,
        })
    };
    let (a, b, u, w) = (texel(51), texel(102), uniform(0.6), uniform(0.8));
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("two of each"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&a),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&b),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: u.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: w.as_entire_binding(),
            },
        ],
    });
    let target = lodkit_scenes::mesh::RenderTarget::new(gpu, 1, 1).unwrap();
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let view = target.color.create_view(&Default::default());
        let mut pass = lodkit::gpu::resources::begin_color_pass(
            &mut encoder,
            &view,
            wgpu::Color::BLACK,
            "two of each",
        );
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    gpu.check("draw_two_of_each").unwrap();
    let pixel = lodkit::gpu::readback::read_texture_rgba8(gpu, &target.color).unwrap();
    [pixel[0], pixel[1], pixel[2], pixel[3]]
}

/// `binding_layout` is what the device does: a pipeline with two textures and two uniform
/// buffers reads each where the capability says it can, and (wgpu 30 on a GL 3.3 context whose
/// driver lists GL_ARB_compute_shader) the first of each twice where it says it cannot. A wgpu
/// that fixes its GL backend fails the second half: then the capability must follow it.
#[test]
fn the_binding_layout_capability_says_what_the_device_does() {
    let gpu = lodkit_test_gpu!(device);
    let caps = gpu.capabilities();
    let got = draw_two_of_each(gpu);
    // 0.6 and 0.8 are 153 and 204 of 255; one step of rounding allowed, the wrong resource is
    // 51 steps away.
    let want = [51u8, 102, 153, 204];
    let right = got.iter().zip(want).all(|(&g, w)| g.abs_diff(w) <= 1);
    say(&format!(
        "two textures and two uniform buffers read {got:?} (want {want:?}); {caps}"
    ));
    assert_eq!(
        right, caps.binding_layout,
        "the device read {got:?} for {want:?}, but GpuCapabilities says binding_layout = {} ({caps})",
        caps.binding_layout
    );
    if !right {
        // Every texture read unit 0 and every uniform block binding point 0.
        assert!(
            got[1].abs_diff(51) <= 1 && got[3].abs_diff(153) <= 1,
            "{got:?}"
        );
    }
}

/// What each pass binds, read off `shader_lib/passes/*.wgsl` (no shader defs): whether it needs
/// several textures or uniform buffers in one pipeline, and whether it is a compute pass.
const PASSES: [(&str, bool, bool); 9] = [
    ("blit", false, false),           // 1 texture + its sampler
    ("combine", true, false),         // 7 textures, 1 uniform buffer
    ("gbuffer_mesh", true, false),    // 2 uniform buffers
    ("impostor", true, false),        // 2 textures, 1 uniform buffer
    ("impostor_bake", false, false),  // 1 texture, 1 uniform buffer
    ("lod_buffer_mesh", true, false), // 2 textures, 2 uniform buffers
    ("lod_mesh", true, false),        // 1 texture, 2 uniform buffers
    ("select", false, true),          // compute, storage buffers
    ("upsample", true, false),        // 3 textures, 1 uniform buffer
];

/// Every pass builds where the device can run it and refuses with the capability it lacks
/// elsewhere (never builds into a wrong picture); the host objects built on them too.
#[test]
fn every_pass_builds_or_names_the_capability_it_lacks() {
    let gpu = lodkit_test_gpu!(device);
    let caps = gpu.capabilities();
    let on_disk = lodkit::shaders::modules()
        .iter()
        .filter(|m| m.kind == lodkit::shaders::ModuleKind::Pass)
        .count();
    assert_eq!(on_disk, PASSES.len(), "a pass is missing from the table");
    for (name, bindings, compute) in PASSES {
        let lacking = if compute && !caps.compute_shaders() {
            Some("COMPUTE_SHADERS")
        } else if bindings && !caps.binding_layout {
            Some("SHADER_BINDING_LAYOUT")
        } else {
            None
        };
        match (gpu.pass_module(name, &[]), lacking) {
            (Ok(_), None) => {}
            (Err(GpuError::MissingCapability { capability, .. }), Some(want)) => {
                assert_eq!(capability, want, "{name}")
            }
            (got, want) => panic!(
                "{name}: {:?}, expected to lack {want:?} ({caps})",
                got.err()
            ),
        }
    }
    let renderer = lodkit_scenes::mesh::MeshRenderer::new(gpu, false);
    assert_eq!(
        matches!(renderer, Err(GpuError::MissingCapability { .. })),
        !caps.binding_layout,
        "MeshRenderer::new: {:?}",
        renderer.err()
    );
    let selector = GpuLodSelector::new(
        gpu,
        &GpuLodSelectorDescriptor {
            groups: &[],
            settings: LodSettings::default(),
            meshes: &[],
        },
    );
    let refused = matches!(
        selector,
        Err(GpuError::MissingCapability {
            capability: "COMPUTE_SHADERS",
            ..
        })
    );
    assert_eq!(refused, !caps.compute_shaders(), "{:?}", selector.err());
    say(&format!(
        "passes on {caps}: each builds or names what it lacks"
    ));
}

/// A probe over more cases than fit in one row of the fragment route's grid on any device
/// (16384 texels wide at most), with outputs in three render targets.
fn wide_probe() -> (Probe<'static>, Probe<'static>, Vec<u32>) {
    let wgsl = Probe {
        header: "",
        body: "let a = inp_u(0u);
    let b = inp_f(1u);
    out_u(0u, a * 3u + 1u);
    out_u(1u, a ^ probe_case);
    out_f(2u, b * 0.5);
    out_u(8u, a >> 3u);",
        inputs: 2,
        outputs: 9,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    let glsl = Probe {
        body: "uint a = inp_u(0u);
    float b = inp_f(1u);
    out_u(0u, a * 3u + 1u);
    out_u(1u, a ^ probe_case);
    out_f(2u, b * 0.5);
    out_u(8u, a >> 3u);",
        ..wgsl
    };
    let cases = (0..9000u32)
        .flat_map(|i| [i.wrapping_mul(2_654_435_761), (i as f32 - 4500.0).to_bits()])
        .collect();
    (wgsl, glsl, cases)
}

/// The words of [`wide_probe`], computed on the CPU; outputs 3..8 are never written (0).
fn wide_want(cases: &[u32]) -> Vec<u32> {
    cases
        .chunks(2)
        .enumerate()
        .flat_map(|(case, c)| {
            let (a, b) = (c[0], f32::from_bits(c[1]));
            let mut out = [0u32; 9];
            out[0] = a.wrapping_mul(3).wrapping_add(1);
            out[1] = a ^ case as u32;
            out[2] = (b * 0.5).to_bits();
            out[8] = a >> 3;
            out
        })
        .collect()
}

/// The fragment route (one fragment per case, inputs from a texture, outputs in integer render
/// targets) gives the words the CPU computes, for WGSL, WESL and GLSL, on every device; and the
/// words of the compute route where compute shaders work.
#[test]
fn the_fragment_probe_gives_the_words_the_compute_probe_gives() {
    let gpu = lodkit_test_gpu!(device);
    let (wgsl, glsl, cases) = wide_probe();
    let want = wide_want(&cases);
    let routes = Route::every(gpu);
    for &route in &routes {
        // run_on holds the WESL form to the WGSL one's words.
        let got = run_on(gpu, route, &wgsl, &cases, SourceLanguage::Wgsl, &[]);
        assert!(
            got == want,
            "{route:?} WGSL probe: {}",
            first_diff(&got, &want)
        );
        let stage = SourceLanguage::Glsl(naga::ShaderStage::Compute);
        let got = run_on(gpu, route, &glsl, &cases, stage, &[]);
        assert!(
            got == want,
            "{route:?} GLSL probe: {}",
            first_diff(&got, &want)
        );
    }
    say(&format!(
        "probe routes {routes:?}: {} cases, 9 words each, as computed on the CPU",
        cases.len() / 2
    ));
}

/// Where two word lists first differ.
fn first_diff(got: &[u32], want: &[u32]) -> String {
    if got.len() != want.len() {
        return format!("{} words for {}", got.len(), want.len());
    }
    let i = got.iter().zip(want).position(|(g, w)| g != w).unwrap_or(0);
    format!(
        "case {} word {}: {:#x} for {:#x}",
        i / 9,
        i % 9,
        got[i],
        want[i]
    )
}
