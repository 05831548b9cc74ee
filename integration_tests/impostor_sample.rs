//! `impostor_sample` on the GPU, the WGSL module (and its WESL form) and the GLSL twin through
//! its hooks, over the same atlas textures and sampler, against each other and against the Rust
//! twin over the CPU atlas. The atlas varies smoothly from texel to texel, so the sampler's
//! fixed-point filter weights (Vulkan promises 4 bits of sub-texel and mip precision) move a
//! result by little: what differs between GPU and CPU is bounded below, and the two languages on
//! one device read the same filtered texels.

use glam::{UVec2, Vec3};
use lodkit::gpu::GpuContext;
use lodkit::gpu::impostor::ImpostorTextures;
use lodkit::impostor::{
    ImpostorAtlas, ImpostorImage, ImpostorLayout, ImpostorShape, impostor_frame_dir,
    impostor_sample, mip_chain,
};
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary, SourceLanguage};
use wgpu::util::DeviceExt;

const FRAMES: u32 = 5;
const FRAME_SIZE: u32 = 16;

/// An atlas whose colour and depth change little from texel to texel: colour (u, v, 0.5 +-
/// 0.05 in a checkerboard, which the mips average away, so a wrong level shows), alpha 1;
/// normal tilting with u; depth 0.5 + 0.2 (u - 0.5).
fn smooth_atlas(shape: ImpostorShape) -> ImpostorAtlas {
    let size = FRAMES * FRAME_SIZE;
    let mut color = ImpostorImage::filled(size, [0.0; 4]);
    let mut normal_depth = ImpostorImage::filled(size, [0.0; 4]);
    for y in 0..size {
        for x in 0..size {
            let (u, v) = (
                (x as f32 + 0.5) / size as f32,
                (y as f32 + 0.5) / size as f32,
            );
            let i = (y * size + x) as usize;
            let checker = if (x + y) % 2 == 0 { 0.05 } else { -0.05 };
            color.texels[i] = [u, v, 0.5 + checker, 1.0];
            let n = Vec3::new(u - 0.5, 1.0, 0.2).normalize() * 0.5 + 0.5;
            normal_depth.texels[i] = [n.x, n.y, n.z, 0.5 + 0.2 * (u - 0.5)];
        }
    }
    ImpostorAtlas {
        layout: ImpostorLayout {
            frames: FRAMES,
            frame_size: FRAME_SIZE,
            shape,
            center: [0.0; 3],
            radius: 1.0,
        },
        color: mip_chain(color, FRAMES, FRAME_SIZE),
        normal_depth: mip_chain(normal_depth, FRAMES, FRAME_SIZE),
    }
}

/// Rays from eyes around the object through points near its centre, at several mip levels.
fn rays() -> Vec<(Vec3, Vec3, f32)> {
    let mut out = Vec::new();
    let mut state = 0x6a09_e667_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    for k in 0..48 {
        let frame = UVec2::new(k % FRAMES, (k / FRAMES) % FRAMES);
        let dir = (impostor_frame_dir(frame, FRAMES, true)
            + Vec3::new(next() - 0.5, next() * 0.3, next() - 0.5) * 0.4)
            .normalize();
        let eye = dir * (3.0 + next() * 5.0);
        let target = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.8;
        out.push((eye, target - eye, (k % 4) as f32 * 0.7));
    }
    out
}

const WGSL: &str = "#import lodkit::impostor::{ImpostorSample, impostor_sample}
@group(0) @binding(0) var<storage, read> rays: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;
@group(0) @binding(2) var color_atlas: texture_2d<f32>;
@group(0) @binding(3) var normal_atlas: texture_2d<f32>;
@group(0) @binding(4) var atlas_sampler: sampler;
@compute @workgroup_size(1)
fn main(@builtin(workgroup_id) id: vec3<u32>) {
    let o = rays[2u * id.x];
    let r = rays[2u * id.x + 1u];
    let s = impostor_sample(color_atlas, normal_atlas, atlas_sampler, FRAMESu, HEMI, o.xyz, r.xyz, o.w);
    results[3u * id.x] = s.color;
    results[3u * id.x + 1u] = vec4<f32>(s.normal, 0.0);
    results[3u * id.x + 2u] = vec4<f32>(s.point, 0.0);
}
";

const GLSL: &str = "#version 450
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 1) in;
layout(std430, set = 0, binding = 0) readonly buffer Rays { vec4 rays[]; };
layout(std430, set = 0, binding = 1) buffer Out { vec4 results[]; };
layout(set = 0, binding = 2) uniform texture2D color_atlas;
layout(set = 0, binding = 3) uniform texture2D normal_atlas;
layout(set = 0, binding = 4) uniform sampler atlas_sampler;
#define LODKIT_IMPOSTOR_HOOKS
#include \"lodkit/impostor.glsl\"
vec4 lodkit_impostor_fetch_color(vec2 uv, float level) { return textureLod(sampler2D(color_atlas, atlas_sampler), uv, level); }
vec4 lodkit_impostor_fetch_normal_depth(vec2 uv, float level) { return textureLod(sampler2D(normal_atlas, atlas_sampler), uv, level); }
uint lodkit_impostor_atlas_texels() { return uint(textureSize(sampler2D(color_atlas, atlas_sampler), 0).x); }
void main() {
    uint i = gl_WorkGroupID.x;
    vec4 o = rays[2u * i];
    vec4 r = rays[2u * i + 1u];
    lodkit_ImpostorSample s = lodkit_impostor_sample(FRAMESu, HEMI, o.xyz, r.xyz, o.w);
    results[3u * i] = s.color;
    results[3u * i + 1u] = vec4(s.normal, 0.0);
    results[3u * i + 2u] = vec4(s.point, 0.0);
}
";

/// Runs `source` over `rays` with `textures` bound; 12 floats a ray.
fn run(
    gpu: &GpuContext,
    source: &str,
    language: SourceLanguage,
    textures: &ImpostorTextures,
    rays: &[(Vec3, Vec3, f32)],
) -> Vec<f32> {
    let composed = ShaderLibrary::new()
        .unwrap()
        .compose(&ComposeDescriptor {
            source,
            file_path: "impostor_sample_probe",
            language,
            ..Default::default()
        })
        .unwrap_or_else(|e| panic!("{}\n{source}", crate::harness::render(&e)));
    let module = gpu
        .shader_module("impostor sample probe", &composed)
        .unwrap();
    let device = &gpu.device;
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("impostor sample probe"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input: Vec<[f32; 4]> = rays
        .iter()
        .flat_map(|(o, r, level)| [o.extend(*level).to_array(), r.extend(0.0).to_array()])
        .collect();
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&input),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (rays.len() * 12 * 4) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let view = |t: &wgpu::Texture| t.create_view(&Default::default());
    let (color, normal) = (view(&textures.color), view(&textures.normal_depth));
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&color),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&normal),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Sampler(&textures.sampler),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(rays.len() as u32, 1, 1);
    }
    let bytes = lodkit::gpu::readback::read_buffer(gpu, encoder, &output, size).unwrap();
    bytemuck::cast_slice(&bytes).to_vec()
}

#[test]
fn impostor_sample_agrees_across_languages_and_with_its_rust_twin() {
    let gpu = lodkit_test_gpu!(compute);
    for shape in [ImpostorShape::Hemi, ImpostorShape::Full] {
        let atlas = smooth_atlas(shape);
        let textures = ImpostorTextures::new(gpu, &atlas).unwrap();
        let rays = rays();
        let hemi = if shape == ImpostorShape::Hemi {
            "true"
        } else {
            "false"
        };
        let fill = |s: &str| {
            s.replace("FRAMES", &FRAMES.to_string())
                .replace("HEMI", hemi)
        };
        let wgsl = fill(WGSL);
        let got_wgsl = run(gpu, &wgsl, SourceLanguage::Wgsl, &textures, &rays);
        let wesl = lodkit::shaders::naga_oil_to_wesl(&wgsl, "", "").unwrap();
        let got_wesl = run(gpu, &wesl, SourceLanguage::Wesl, &textures, &rays);
        let glsl = fill(GLSL);
        let glsl_language = SourceLanguage::Glsl(naga::ShaderStage::Compute);
        let got_glsl = run(gpu, &glsl, glsl_language, &textures, &rays);
        assert_eq!(
            got_wesl, got_wgsl,
            "{shape:?}: the WESL form computes other results"
        );
        // The languages on one device: the same texels through the same sampler, arithmetic a
        // few ulps apart (|values| <= ~10: 1e-5).
        for (k, (a, b)) in got_wgsl.iter().zip(&got_glsl).enumerate() {
            assert!(
                (a - b).abs() <= 1e-5,
                "{shape:?} ray {} word {}: WGSL {a} GLSL {b}",
                k / 12,
                k % 12
            );
        }
        // The Rust twin on the CPU atlas. Colour: 8-bit sRGB storage (half a step: <= 0.0045 in
        // linear near 1) plus filter and mip weights quantized to 1/16 (an error of 1/32 of a
        // texel step: 1/80 in red and green, 0.1 in blue, 0.003): 0.01. The
        // normal: half floats and the same weights, renormalized: 0.01. The point: the depth
        // (a texel step of 0.0025, half precision) moves it along the ray by at most
        // 2 x 0.0025 / |dot(ray, dir)| (>= 0.2 for these rays) in height: 0.03.
        for (k, (o, r, level)) in rays.iter().enumerate() {
            let want = impostor_sample(&atlas, *o, *r, *level);
            let got = &got_wgsl[k * 12..k * 12 + 12];
            let close = |g: &[f32], w: &[f32], tol: f32, what: &str| {
                for (a, b) in g.iter().zip(w) {
                    assert!(
                        (a - b).abs() <= tol,
                        "{shape:?} ray {k} {what}: GPU {g:?} twin {w:?}"
                    );
                }
            };
            close(&got[0..4], &want.color.to_array(), 0.01, "colour");
            close(&got[4..7], &want.normal.to_array(), 0.01, "normal");
            close(&got[8..11], &want.point.to_array(), 0.03, "point");
        }
    }
}
