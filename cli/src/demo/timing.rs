//! Pass cost as a ratio against the plainest pass doing the same memory traffic, measured in
//! interleaved pairs so machine noise hits both alike: the combine pass against a copy of the
//! same four textures, the bilateral upsample against a hardware-filtered bilinear fetch. Wall
//! time per pass including submit and wait: read the ratio on a software GPU, not the
//! milliseconds.

use std::time::Instant;

use glam::{Mat4, Vec3, Vec4};
use serde::Serialize;

use super::reads::{Reads, Texels};
use super::upsampling::{SIGMA_N, SIGMA_Z};
use lodkit::gbuffer::GEOMETRY_FORMAT;
use lodkit::gpu::frame_sequential::{CombinePass, LOD_DEPTH_FORMAT, LodBuffers};
use lodkit::gpu::framebuffer_lod::{LowResBuffer, UpsamplePass};
use lodkit::gpu::gbuffer_scene::EdgeScene;
use lodkit::gpu::lod_buffer_scene::{LodBufferRenderer, LodDrawItem};
use lodkit::gpu::resources::{
    begin_color_pass, fullscreen_pipeline_with, one_group_layout, texture_2d, textures_and_uniform,
    uniform_buffer,
};
use lodkit::gpu::scene::{GpuMesh, Mesh};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::lod_buffer::{ID_FORMAT, MOTION_FORMAT};
use lodkit::reproject::new_to_old_matrix;
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary};
use lodkit::visibility::{VisibilityPattern, visibility_texture};

/// A pass timed against its baseline.
#[derive(Clone, Debug, Serialize)]
pub struct PassRatio {
    /// The pass measured.
    pub pass: String,
    /// The baseline pass.
    pub baseline: String,
    /// Image size.
    pub size: (u32, u32),
    /// Median wall time of the pass, ms.
    pub pass_ms: f64,
    /// Median wall time of the baseline, ms.
    pub baseline_ms: f64,
    /// Median of the per-pair ratios.
    pub ratio: f64,
    /// Pairs timed.
    pub pairs: usize,
    /// Texture reads per output pixel of the pass, counted from its shader.
    pub pass_reads: Reads,
    /// Texture reads per output pixel of the baseline.
    pub baseline_reads: Reads,
}

/// Median: the middle value, or the mean of the two middle values for an even count; NaN when
/// empty.
pub fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// Wall time of `f` in milliseconds.
pub fn wall_ms(f: &dyn Fn() -> Result<(), GpuError>) -> Result<f64, GpuError> {
    let t = Instant::now();
    f()?;
    Ok(t.elapsed().as_secs_f64() * 1e3)
}

/// Times `a` and `b` (each must wait for the GPU itself) in `pairs` interleaved pairs after a
/// few warm-up rounds, alternating which goes first. Returns the medians of a, b and a/b.
pub fn interleaved(
    a: &dyn Fn() -> Result<(), GpuError>,
    b: &dyn Fn() -> Result<(), GpuError>,
    pairs: usize,
) -> Result<(f64, f64, f64), GpuError> {
    let time = wall_ms;
    for _ in 0..5 {
        a()?;
        b()?;
    }
    let (mut ta, mut tb, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..pairs.max(1) {
        let (x, y) = if i % 2 == 0 {
            let x = time(a)?;
            (x, time(b)?)
        } else {
            let y = time(b)?;
            (time(a)?, y)
        };
        ta.push(x);
        tb.push(y);
        ratio.push(x / y);
    }
    Ok((median(&ta), median(&tb), median(&ratio)))
}

/// A fullscreen pipeline (`vs_main`, `fs_main`, RGBA8 target) from WGSL `source` that may
/// import lodkit modules; `name` labels it and names the file in errors.
pub fn plain_pass(
    gpu: &GpuContext,
    source: &str,
    name: &str,
) -> Result<wgpu::RenderPipeline, GpuError> {
    plain_pass_with(gpu, source, name, None)
}

/// [`plain_pass`] with an explicit pipeline `layout` (`None`: derived from the shader).
fn plain_pass_with(
    gpu: &GpuContext,
    source: &str,
    name: &str,
    layout: Option<&wgpu::PipelineLayout>,
) -> Result<wgpu::RenderPipeline, GpuError> {
    let composed = ShaderLibrary::new()?.compose(&ComposeDescriptor {
        source,
        file_path: name,
        ..Default::default()
    })?;
    let module = gpu.shader_module(name, &composed)?;
    fullscreen_pipeline_with(gpu, &module, FORMAT, layout, name)
}

/// Target format of the timed passes.
pub(super) const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A fullscreen pass reading color, id word and depth of both buffers and the object motion at
/// the pixel, summed so none is optimized away; `$depth` adds more to the depth sum.
macro_rules! buffer_reads {
    ($depth:literal) => {
        concat!(
            "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
@group(0) @binding(0) var a: texture_2d<f32>;
@group(0) @binding(1) var b: texture_2d<u32>;
@group(0) @binding(2) var c: texture_2d<f32>;
@group(0) @binding(3) var d: texture_2d<f32>;
@group(0) @binding(4) var e: texture_2d<u32>;
@group(0) @binding(5) var f: texture_2d<f32>;
@group(0) @binding(6) var g: texture_2d<f32>;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let p = vec2<u32>(v.position.xy);
    let ids = textureLoad(b, p, 0).x ^ textureLoad(e, p, 0).x;
    let depth = textureLoad(c, p, 0).x + textureLoad(f, p, 0).x",
            $depth,
            ";
    let motion = textureLoad(g, p, 0).xy;
    return textureLoad(a, p, 0) + textureLoad(d, p, 0) + vec4<f32>(f32(ids & 1u), depth, motion);
}
"
        )
    };
}

/// The seven textures the combine reads, each once at the pixel: the combine's baseline.
const COPY7: &str = buffer_reads!("");

/// The combine's main-path loads without its arithmetic: COPY7 and the older depth once more
/// (the combine's first estimate), at a neighbouring texel: the floor of any combine.
const LOADS8: &str =
    buffer_reads!(" + textureLoad(f, min(p + 1u, textureDimensions(f, 0) - 1u), 0).x");

/// LOADS8 and the four older-id loads the combine makes under its id-mismatch branch (three side
/// texels and the matched one), all made for every pixel: on a GPU that runs both sides of a
/// divergent branch under a mask (llvmpipe), the floor of the combine as it is written.
const LOADS12: &str = buffer_reads!(
    " + textureLoad(f, min(p + 1u, textureDimensions(f, 0) - 1u), 0).x
        + f32((textureLoad(e, min(p + vec2<u32>(1u, 0u), textureDimensions(e, 0) - 1u), 0).x
        ^ textureLoad(e, min(p + vec2<u32>(0u, 1u), textureDimensions(e, 0) - 1u), 0).x
        ^ textureLoad(e, min(p + 1u, textureDimensions(e, 0) - 1u), 0).x
        ^ textureLoad(e, min(p + vec2<u32>(2u, 0u), textureDimensions(e, 0) - 1u), 0).x) & 1u)"
);

/// The bilinear baseline: one hardware-filtered sample of L.
pub(super) const BILINEAR: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
struct Scale { uv_scale: vec2<f32>, _pad: vec2<f32> }
@group(0) @binding(0) var low_color: texture_2d<f32>;
@group(0) @binding(1) var low_sampler: sampler;
@group(0) @binding(2) var<uniform> scale: Scale;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    return textureSampleLevel(low_color, low_sampler, v.uv * scale.uv_scale, 0.0);
}
";

/// The reads of eq. 1 at the same texels, summed so none is optimized away, no weights.
const LOADS9: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
struct Scale { uv_scale: vec2<f32>, _pad: vec2<f32> }
@group(0) @binding(0) var low_color: texture_2d<f32>;
@group(0) @binding(1) var low_geometry: texture_2d<f32>;
@group(0) @binding(2) var full_geometry: texture_2d<f32>;
@group(0) @binding(3) var<uniform> scale: Scale;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let t0 = vec2<u32>(v.position.xy * scale.uv_scale);
    let t3 = t0 + 1u;
    let t1 = vec2<u32>(t3.x, t0.y);
    let t2 = vec2<u32>(t0.x, t3.y);
    var s = textureLoad(full_geometry, vec2<u32>(v.position.xy), 0);
    s += textureLoad(low_color, t0, 0) + textureLoad(low_color, t1, 0);
    s += textureLoad(low_color, t2, 0) + textureLoad(low_color, t3, 0);
    s += textureLoad(low_geometry, t0, 0) + textureLoad(low_geometry, t1, 0);
    s += textureLoad(low_geometry, t2, 0) + textureLoad(low_geometry, t3, 0);
    return s;
}
";

/// A baseline pass timed as lodkit's passes run: its bind group built and its uniform (if any)
/// written per call inside the same error scopes ([`GpuContext::guarded`]), then submit and
/// wait. The lodkit pass and its baseline so do the same host work per call.
pub(super) fn draw_fullscreen(
    gpu: &GpuContext,
    pipeline: &wgpu::RenderPipeline,
    group: &dyn Fn() -> Result<wgpu::BindGroup, GpuError>,
    uniform: Option<(&wgpu::Buffer, &[u8])>,
    target: &wgpu::TextureView,
) -> Result<(), GpuError> {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    gpu.guarded("baseline", || {
        if let Some((buffer, bytes)) = uniform {
            gpu.queue.write_buffer(buffer, 0, bytes);
        }
        let group = group()?;
        let mut pass = begin_color_pass(&mut encoder, target, wgpu::Color::BLACK, "baseline");
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    })?;
    gpu.queue.submit([encoder.finish()]);
    gpu.wait_idle()
}

/// What the timed pass and its baseline each do on the host per call.
pub const HOST_WORK: &str = "each call builds its bind group, writes its uniform (where it has \
    one), records inside wgpu error scopes, submits and waits";

/// The combine pass against a plain pass reading the same seven textures (color, id and depth of
/// each buffer, the object motion) at `size` x `size`, on two LOD buffers of a grid of spheres
/// and boxes with a third of them in transition and the camera moved between the frames; then,
/// against the same baseline, the combine's eight main-path loads alone (its floor), and those
/// with the four loads of its id-mismatch branch all made (its floor where both sides of a
/// divergent branch run).
pub fn combine_vs_copy(
    gpu: &GpuContext,
    size: u32,
    pairs: usize,
) -> Result<[PassRatio; 3], GpuError> {
    let buffers = LodBuffers::new(gpu, size, size, FORMAT)?;
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 64, 1);
    let renderer = LodBufferRenderer::new(gpu, FORMAT, &vis, 0.25)?;
    let meshes = [
        GpuMesh::new(gpu, &Mesh::sphere(16, 24))?,
        GpuMesh::new(gpu, &Mesh::cube())?,
    ];
    let proj = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 100.0);
    let views = [0.0f32, 0.1]
        .map(|x| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 3.0, 7.0), Vec3::ZERO, Vec3::Y));
    for (i, view) in views.iter().enumerate() {
        let items: Vec<LodDrawItem> = (0..15)
            .map(|k| LodDrawItem {
                mesh: &meshes[(k + i) % 2],
                model: Mat4::from_translation(Vec3::new(
                    (k % 5) as f32 * 2.0 - 4.0,
                    0.0,
                    -((k / 5) as f32) * 2.0,
                )),
                color: Vec4::new(0.8, 0.2, 0.2, 1.0),
                id: if k % 3 == 0 { k as u32 + 1 } else { 0 },
                tau: if k % 3 == 0 { 0.5 } else { 1.0 },
                tau_next: if k % 3 == 0 { 0.55 } else { 1.0 },
                sway: [0.0; 2],
                prev_model: Mat4::from_translation(Vec3::new(
                    (k % 5) as f32 * 2.0 - 4.0,
                    0.0,
                    -((k / 5) as f32) * 2.0,
                )),
                prev_sway_phase: 0.0,
                alpha_rect: Vec4::ZERO,
            })
            .collect();
        renderer.render(
            gpu,
            &buffers,
            i,
            proj * *view,
            &items,
            wgpu::Color::BLACK,
            None,
        )?;
    }
    let target = texture_2d(
        gpu,
        (size, size),
        FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
        "target",
    )?;
    let target_view = target.create_view(&Default::default());
    let combine = CombinePass::new(gpu, FORMAT, false)?;
    let m = new_to_old_matrix(&views[1], &proj, &views[0], &proj);
    let mut entries = CombinePass::buffer_layout_entries(0);
    entries.push(CombinePass::motion_layout_entry(6));
    let (layout, pipeline_layout) = one_group_layout(gpu, &entries, "copy7");
    // The baselines bind the combine's textures in its layout.
    let pipeline = |source, name| plain_pass_with(gpu, source, name, Some(&pipeline_layout));
    let copy7 = pipeline(COPY7, "copy7.wgsl")?;
    let loads8 = pipeline(LOADS8, "loads8.wgsl")?;
    let loads12 = pipeline(LOADS12, "loads12.wgsl")?;
    let textures = [1, 0].map(|i| [buffers.color(i), buffers.id(i), buffers.depth(i)]);
    let mut textures = textures.as_flattened().to_vec();
    // LodBuffers::new has the motion target.
    textures.extend(buffers.motion());
    let group = || textures_and_uniform(gpu, &layout, &textures, None, "copy7");
    let run_combine = || {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        combine.encode(gpu, &mut encoder, &buffers, 1, m, &target_view)?;
        gpu.queue.submit([encoder.finish()]);
        gpu.wait_idle()
    };
    let run_copy = || draw_fullscreen(gpu, &copy7, &group, None, &target_view);
    let run_loads = || draw_fullscreen(gpu, &loads8, &group, None, &target_view);
    let run_loads12 = || draw_fullscreen(gpu, &loads12, &group, None, &target_view);
    // Counted from the shaders: the copy reads color, id and depth of each buffer and the object
    // motion; the combine the same, the older depth at its first estimate, and under branches
    // the older ids of its search.
    let buffer = |color, id, depth| {
        [
            (color, FORMAT, Texels::One),
            (id, ID_FORMAT, Texels::One),
            (depth, LOD_DEPTH_FORMAT, Texels::One),
        ]
    };
    let mut copy_formats = [buffer("a", "b", "c"), buffer("d", "e", "f")].concat();
    copy_formats.push(("g", MOTION_FORMAT, Texels::One));
    let copy = Reads::of_source(COPY7, "copy7.wgsl", &copy_formats)?;
    let mut combine_formats = [
        buffer("newer_color", "newer_id", "newer_depth"),
        buffer("older_color", "older_id", "older_depth"),
    ]
    .concat();
    combine_formats.push(("object_motion", MOTION_FORMAT, Texels::One));
    let combine_reads = Reads::of_pass("combine", &combine_formats)?;
    let loads_reads = Reads::of_source(LOADS8, "loads8.wgsl", &copy_formats)?;
    let loads12_reads = Reads::of_source(LOADS12, "loads12.wgsl", &copy_formats)?;
    let time = |pass: &str, reads: Reads, run: &dyn Fn() -> Result<(), GpuError>| {
        let (pass_ms, baseline_ms, ratio) = interleaved(run, &run_copy, pairs)?;
        Ok::<_, GpuError>(PassRatio {
            pass: pass.to_owned(),
            baseline: "plain copy of the same 7 textures".to_owned(),
            size: (size, size),
            pass_ms,
            baseline_ms,
            ratio,
            pairs,
            pass_reads: reads,
            baseline_reads: copy,
        })
    };
    Ok([
        time("combine (frame-sequential)", combine_reads, &run_combine)?,
        time(
            "the combine's 8 main-path loads alone",
            loads_reads,
            &run_loads,
        )?,
        time(
            "the same and the 4 loads of its id-mismatch branch, all made",
            loads12_reads,
            &run_loads12,
        )?,
    ])
}

/// The bilateral upsample pass against a hardware-filtered bilinear pass over the same low-res
/// color, on the edge scene at resize factor `r`; then, against the same baseline, a pass that
/// only makes eq. 1's nine texel loads (no arithmetic): the floor of any per-pixel eq. 1.
pub fn upsample_vs_bilinear(
    gpu: &GpuContext,
    size: (u32, u32),
    r: f32,
    pairs: usize,
) -> Result<[PassRatio; 2], GpuError> {
    let (w, h) = size;
    let scene = EdgeScene::new(gpu, FORMAT, w as f32 / h as f32)?;
    let full = LowResBuffer::new(gpu, w, h, FORMAT)?;
    scene.render(gpu, &full, 1.0)?;
    let low = LowResBuffer::new(gpu, w, h, FORMAT)?;
    scene.render(gpu, &low, r)?;
    let upsample = UpsamplePass::new(gpu, FORMAT)?;
    let target = texture_2d(
        gpu,
        size,
        FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
        "target",
    )?;
    let view = target.create_view(&Default::default());
    let bilinear = plain_pass(gpu, BILINEAR, "bilinear.wgsl")?;
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let scale = uniform_buffer(gpu, 16, "scale")?;
    let (vw, vh) = low.viewport(r);
    let s = [vw as f32 / w as f32, vh as f32 / h as f32, 0.0, 0.0];
    gpu.queue.write_buffer(&scale, 0, bytemuck::cast_slice(&s));
    let low_view = low.color().create_view(&Default::default());
    let group = || {
        Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &bilinear.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&low_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: scale.as_entire_binding(),
                },
            ],
        }))
    };
    let run_bilateral = || {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        upsample.encode(
            gpu,
            &mut encoder,
            &low,
            r,
            full.geometry(),
            SIGMA_Z,
            SIGMA_N,
            &view,
        )?;
        gpu.queue.submit([encoder.finish()]);
        gpu.wait_idle()
    };
    let scale_bytes: &[u8] = bytemuck::cast_slice(&s);
    let run_bilinear =
        || draw_fullscreen(gpu, &bilinear, &group, Some((&scale, scale_bytes)), &view);
    let loads = plain_pass(gpu, LOADS9, "loads9.wgsl")?;
    let textures = [low.color(), low.geometry(), full.geometry()];
    let layout = loads.get_bind_group_layout(0);
    let loads_group = || textures_and_uniform(gpu, &layout, &textures, Some(&scale), "loads9");
    let run_loads = || {
        draw_fullscreen(
            gpu,
            &loads,
            &loads_group,
            Some((&scale, scale_bytes)),
            &view,
        )
    };
    // Counted from the shaders: eq. 1 reads the pixel's own geometry and the 2x2 cell's colors
    // and geometry; the bilinear pass one filtered sample (4 texels).
    let eq1_formats = [
        ("low_color", FORMAT, Texels::One),
        ("low_geometry", GEOMETRY_FORMAT, Texels::One),
        ("full_geometry", GEOMETRY_FORMAT, Texels::One),
    ];
    let bilateral_reads = Reads::of_pass("upsample", &eq1_formats)?;
    let loads_reads = Reads::of_source(LOADS9, "loads9.wgsl", &eq1_formats)?;
    let bilinear_reads = Reads::of_source(
        BILINEAR,
        "bilinear.wgsl",
        &[("low_color", FORMAT, Texels::Linear)],
    )?;
    let time = |pass: String, reads: Reads, run: &dyn Fn() -> Result<(), GpuError>| {
        let (pass_ms, baseline_ms, ratio) = interleaved(run, &run_bilinear, pairs)?;
        Ok::<_, GpuError>(PassRatio {
            pass,
            baseline: "bilinear upsample (hardware filter)".to_owned(),
            size,
            pass_ms,
            baseline_ms,
            ratio,
            pairs,
            pass_reads: reads,
            baseline_reads: bilinear_reads,
        })
    };
    Ok([
        time(
            format!("bilateral upsample (r = {r})"),
            bilateral_reads,
            &run_bilateral,
        )?,
        time(
            "eq. 1's 9 texel loads alone".to_owned(),
            loads_reads,
            &run_loads,
        )?,
    ])
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median(&[4.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
