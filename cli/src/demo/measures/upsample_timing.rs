//! Pass cost as a ratio against the plainest pass doing the same memory traffic, measured in
//! interleaved pairs so machine noise hits both alike: the bilateral upsample against a
//! hardware-filtered bilinear fetch (the combine's timings are in
//! [`combine_timing`](crate::demo::measures::combine_timing), the packed upsample's in
//! [`packed_upsample_timing`](crate::demo::measures::packed_upsample_timing)). Each figure is
//! read from the [`Clock`] it names: GPU timestamps around a run of recordings where the device
//! has them, so the submission's fixed cost sits on neither side of a ratio; the wall clock
//! otherwise.

use serde::Serialize;

use crate::demo::fixtures::clock::{Clock, Record, Timer, interleaved};
use crate::demo::fixtures::edge_frame::{EdgeFrame, FORMAT};
use crate::demo::measures::reads::{Reads, Texels};
use lodkit::gbuffer::GEOMETRY_FORMAT;
use lodkit::gpu::resources::{
    begin_color_pass, fullscreen_pipeline_with, textures_and_uniform, uniform_buffer,
};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary};
use lodkit_scenes::gbuffer::ShadingTerm;

/// A pass timed against its baseline.
#[derive(Clone, Debug, Serialize)]
pub struct PassRatio {
    /// The pass measured.
    pub pass: String,
    /// The baseline pass.
    pub baseline: String,
    /// Image size.
    pub size: (u32, u32),
    /// Median time of one recording of the pass, ms.
    pub pass_ms: f64,
    /// Median time of one recording of the baseline, ms.
    pub baseline_ms: f64,
    /// Median of the per-pair ratios.
    pub ratio: f64,
    /// Pairs timed.
    pub pairs: usize,
    /// The clock the times were read from.
    pub clock: Clock,
    /// Recordings per timed run.
    pub recordings: usize,
    /// Texture reads per output pixel of the pass, counted from its shader.
    pub pass_reads: Reads,
    /// Texture reads per output pixel of the baseline.
    pub baseline_reads: Reads,
}

/// One side of a timed pair: what it is called, its texture reads per pixel, its recording.
pub struct Side<'a> {
    /// The pass's name in the report.
    pub name: String,
    /// Its texture reads per output pixel.
    pub reads: Reads,
    /// One recording of it.
    pub run: Record<'a>,
}

impl PassRatio {
    /// Times `pass` against `baseline` in `pairs` interleaved pairs ([`interleaved`]) on images
    /// of `size`.
    pub fn time(
        gpu: &GpuContext,
        timer: &Timer,
        size: (u32, u32),
        pairs: usize,
        pass: Side<'_>,
        baseline: &Side<'_>,
    ) -> Result<Self, GpuError> {
        let (pass_ms, baseline_ms, ratio) = interleaved(gpu, timer, pass.run, baseline.run, pairs)?;
        Ok(PassRatio {
            pass: pass.name,
            baseline: baseline.name.clone(),
            size,
            pass_ms,
            baseline_ms,
            ratio,
            pairs,
            clock: timer.clock(),
            recordings: timer.recordings(),
            pass_reads: pass.reads,
            baseline_reads: baseline.reads,
        })
    }
}

pub use crate::demo::fixtures::clock::median;

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
pub(crate) fn plain_pass_with(
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

/// The bilinear baseline: one hardware-filtered sample of L.
pub(crate) const BILINEAR: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
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

/// Records a baseline pass as lodkit's passes record: its bind group built and its uniform (if
/// any) written per recording inside the same error scopes ([`GpuContext::guarded`]).
pub(crate) fn record_fullscreen(
    gpu: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    group: &dyn Fn() -> Result<wgpu::BindGroup, GpuError>,
    uniform: Option<(&wgpu::Buffer, &[u8])>,
    target: &wgpu::TextureView,
) -> Result<(), GpuError> {
    gpu.recording("baseline", || {
        if let Some((buffer, bytes)) = uniform {
            gpu.queue.write_buffer(buffer, 0, bytes);
        }
        let group = group()?;
        let mut pass = begin_color_pass(encoder, target, wgpu::Color::BLACK, "baseline");
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    })
}

/// What the timed pass and its baseline each do per recording, and what the clock counts.
pub const HOST_WORK: &str = "each recording builds its bind group and writes its uniform (where \
    it has one) inside wgpu error scopes; a run of recordings shares one encoder and one \
    submission, and GPU timestamps around the run count the GPU's time alone (the wall clock, \
    where there are none, also counts the submission and the wait)";

/// The bilateral upsample pass against a hardware-filtered bilinear pass over the same low-res
/// color, on the edge scene at resize factor `r`; then, against the same baseline, a pass that
/// only makes eq. 1's nine texel loads (no arithmetic): the floor of any per-pixel eq. 1.
pub fn upsample_vs_bilinear(
    gpu: &GpuContext,
    timer: &Timer,
    size: (u32, u32),
    r: f32,
    pairs: usize,
) -> Result<[PassRatio; 2], GpuError> {
    let (w, h) = size;
    let (frame, scene) = EdgeFrame::new(gpu, timer, size)?;
    let (full, low, view) = (&frame.prepass, &frame.low[0], &frame.view);
    scene.render_term(gpu, full, 1.0, ShadingTerm::Albedo)?;
    scene.render(gpu, low, r)?;
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
    let run_bilateral = |encoder: &mut wgpu::CommandEncoder| {
        frame.record_upsample(encoder, r, ShadingTerm::Full, 0)
    };
    let scale_bytes: &[u8] = bytemuck::cast_slice(&s);
    let run_bilinear = |encoder: &mut wgpu::CommandEncoder| {
        let uniform = Some((&scale, scale_bytes));
        record_fullscreen(gpu, encoder, &bilinear, &group, uniform, view)
    };
    let loads = plain_pass(gpu, LOADS9, "loads9.wgsl")?;
    let textures = [low.color(), low.geometry(), full.geometry()];
    let layout = loads.get_bind_group_layout(0);
    let loads_group = || textures_and_uniform(gpu, &layout, &textures, Some(&scale), "loads9");
    let run_loads = |encoder: &mut wgpu::CommandEncoder| {
        let uniform = Some((&scale, scale_bytes));
        record_fullscreen(gpu, encoder, &loads, &loads_group, uniform, view)
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
    let bilinear = Side {
        name: "bilinear upsample (hardware filter)".to_owned(),
        reads: bilinear_reads,
        run: &run_bilinear,
    };
    let time = |name: String, reads: Reads, run: Record<'_>| {
        PassRatio::time(
            gpu,
            timer,
            size,
            pairs,
            Side { name, reads, run },
            &bilinear,
        )
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
