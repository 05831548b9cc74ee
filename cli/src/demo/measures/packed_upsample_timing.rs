//! The packed low-resolution texel timed against bilinear upsampling: the packed bilateral
//! upsample pass (4 low-resolution loads and the pixel's own geometry), its loads alone (the
//! floor of any packed eq. 1), and the fold-in upsample inside a composite pass against the same
//! composite with a bilinear sample. Same host work on both sides ([`crate::demo::measures::upsample_timing::HOST_WORK`]).

use crate::demo::fixtures::clock::{Record, Timer};
use crate::demo::fixtures::edge_frame::{EdgeFrame, FORMAT};
use crate::demo::measures::reads::{Reads, Texels};
use crate::demo::measures::upsample_timing::{
    BILINEAR, PassRatio, Side, plain_pass, record_fullscreen,
};
use lodkit::gbuffer::{GEOMETRY_FORMAT, PACKED_FORMAT};
use lodkit::gpu::resources::{textures_and_uniform, uniform_buffer};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit_scenes::gbuffer::ShadingTerm;

/// The packed eq. 1's loads at the same texels, summed so none is optimized away, no weights.
const LOADS5: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
struct Scale { uv_scale: vec2<f32>, _pad: vec2<f32> }
@group(0) @binding(0) var low: texture_2d<u32>;
@group(0) @binding(1) var full_geometry: texture_2d<f32>;
@group(0) @binding(2) var<uniform> scale: Scale;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let t0 = vec2<u32>(v.position.xy * scale.uv_scale);
    let t3 = t0 + 1u;
    let s = textureLoad(low, t0, 0) ^ textureLoad(low, vec2<u32>(t3.x, t0.y), 0)
        ^ textureLoad(low, vec2<u32>(t0.x, t3.y), 0) ^ textureLoad(low, t3, 0);
    return textureLoad(full_geometry, vec2<u32>(v.position.xy), 0) + vec4<f32>(s & vec4<u32>(1u));
}
";

/// The fine-grained composite (full-resolution albedo times the upsampled lighting) with a
/// bilinear sample of the lighting: it reads the pixel's geometry as the fold-in composite does
/// (a composite that holds depth and normal for its own work), here for a depth fade.
const COMPOSITE_BILINEAR: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
#import lodkit::gbuffer::gbuffer_depth
struct Scale { uv_scale: vec2<f32>, _pad: vec2<f32> }
@group(0) @binding(0) var low_color: texture_2d<f32>;
@group(0) @binding(1) var low_sampler: sampler;
@group(0) @binding(2) var full_geometry: texture_2d<f32>;
@group(0) @binding(3) var full_albedo: texture_2d<f32>;
@group(0) @binding(4) var<uniform> scale: Scale;
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let p = vec2<u32>(v.position.xy);
    let light = textureSampleLevel(low_color, low_sampler, v.uv * scale.uv_scale, 0.0);
    let fade = min(1.0, 64.0 / max(gbuffer_depth(textureLoad(full_geometry, p, 0)), 1e-3));
    return vec4<f32>(light.rgb * textureLoad(full_albedo, p, 0).rgb * fade, light.a);
}
";

/// At resize factor `r` on the edge scene: the packed bilateral upsample pass and its five loads
/// alone against the bilinear pass; then the fold-in (`UpsampleComposite::TimesAlbedo` over a packed L, the
/// fine-grained route's composite with `bilateral_upsample_packed_at` inside) against the same
/// composite with a bilinear sample.
pub fn packed_upsample_vs_bilinear(
    gpu: &GpuContext,
    timer: &Timer,
    size: (u32, u32),
    r: f32,
    pairs: usize,
) -> Result<[PassRatio; 3], GpuError> {
    let (w, h) = size;
    let (frame, scene) = EdgeFrame::new(gpu, timer, size)?;
    let (full, low, packed, view) = (&frame.prepass, &frame.low[0], &frame.low[1], &frame.view);
    scene.render_term(gpu, full, 1.0, ShadingTerm::Albedo)?;
    scene.render_term(gpu, low, r, ShadingTerm::Lighting)?;
    scene.render_term(gpu, packed, r, ShadingTerm::Lighting)?;
    // The fine-grained route's upsample multiplies by the prepass's albedo: the fold-in.
    let run_pass = |encoder: &mut wgpu::CommandEncoder, fine: bool| {
        let term = if fine {
            ShadingTerm::Lighting
        } else {
            ShadingTerm::Full
        };
        frame.record_upsample(encoder, r, term, 1)
    };
    let (vw, vh) = low.viewport(r);
    let s = [vw as f32 / w as f32, vh as f32 / h as f32, 0.0, 0.0];
    let scale = uniform_buffer(gpu, 16, "scale")?;
    let scale_bytes: &[u8] = bytemuck::cast_slice(&s);
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let low_view = low.color().create_view(&Default::default());
    let full_views = [full.geometry(), full.color()].map(|t| t.create_view(&Default::default()));
    // The bilinear pass and the bilinear composite: L's lighting through the sampler.
    let bilinear = plain_pass(gpu, BILINEAR, "bilinear.wgsl")?;
    let composite = plain_pass(gpu, COMPOSITE_BILINEAR, "composite_bilinear.wgsl")?;
    let group = |pipeline: &wgpu::RenderPipeline, with_full: bool| {
        let mut resources = vec![
            wgpu::BindingResource::TextureView(&low_view),
            wgpu::BindingResource::Sampler(&sampler),
        ];
        if with_full {
            resources.extend(full_views.iter().map(wgpu::BindingResource::TextureView));
        }
        resources.push(scale.as_entire_binding());
        let entries: Vec<wgpu::BindGroupEntry> = resources
            .into_iter()
            .enumerate()
            .map(|(binding, resource)| wgpu::BindGroupEntry {
                binding: binding as u32,
                resource,
            })
            .collect();
        Ok::<_, GpuError>(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        }))
    };
    let uniform = Some((&scale, scale_bytes));
    let run_bilinear = |e: &mut wgpu::CommandEncoder| {
        record_fullscreen(
            gpu,
            e,
            &bilinear,
            &|| group(&bilinear, false),
            uniform,
            view,
        )
    };
    let run_composite = |e: &mut wgpu::CommandEncoder| {
        record_fullscreen(
            gpu,
            e,
            &composite,
            &|| group(&composite, true),
            uniform,
            view,
        )
    };
    let loads = plain_pass(gpu, LOADS5, "loads5.wgsl")?;
    let layout = loads.get_bind_group_layout(0);
    let textures = [packed.color(), full.geometry()];
    let loads_group = || textures_and_uniform(gpu, &layout, &textures, Some(&scale), "loads5");
    let run_loads = |e: &mut wgpu::CommandEncoder| {
        record_fullscreen(gpu, e, &loads, &loads_group, uniform, view)
    };
    // Counted from the shaders.
    let packed_bound = [
        ("low", PACKED_FORMAT, Texels::One),
        ("full_geometry", GEOMETRY_FORMAT, Texels::One),
        ("full_albedo", FORMAT, Texels::One),
    ];
    let defs = ["LODKIT_UPSAMPLE_PACKED"];
    let upsample_reads = Reads::of_pass_with("upsample", &defs, &packed_bound)?;
    let fine_defs = ["LODKIT_UPSAMPLE_PACKED", "LODKIT_UPSAMPLE_MODULATE"];
    let fold_in_reads = Reads::of_pass_with("upsample", &fine_defs, &packed_bound)?;
    let loads_reads = Reads::of_source(LOADS5, "loads5.wgsl", &packed_bound)?;
    let bilinear_bound = [
        ("low_color", FORMAT, Texels::Linear),
        ("full_geometry", GEOMETRY_FORMAT, Texels::One),
        ("full_albedo", FORMAT, Texels::One),
    ];
    let bilinear_reads = Reads::of_source(BILINEAR, "bilinear.wgsl", &bilinear_bound)?;
    let composite_reads = Reads::of_source(
        COMPOSITE_BILINEAR,
        "composite_bilinear.wgsl",
        &bilinear_bound,
    )?;
    let time = |name: String,
                reads: Reads,
                run: Record<'_>,
                baseline: &str,
                baseline_reads: Reads,
                run_baseline: Record<'_>| {
        let baseline = Side {
            name: baseline.to_owned(),
            reads: baseline_reads,
            run: run_baseline,
        };
        PassRatio::time(
            gpu,
            timer,
            size,
            pairs,
            Side { name, reads, run },
            &baseline,
        )
    };
    let bilinear_name = "bilinear upsample (hardware filter)";
    Ok([
        time(
            format!("bilateral upsample, packed L (r = {r})"),
            upsample_reads,
            &|e| run_pass(e, false),
            bilinear_name,
            bilinear_reads,
            &run_bilinear,
        )?,
        time(
            "packed eq. 1's 5 texel loads alone".to_owned(),
            loads_reads,
            &run_loads,
            bilinear_name,
            bilinear_reads,
            &run_bilinear,
        )?,
        time(
            format!("fold-in upsample in the composite, packed L (r = {r})"),
            fold_in_reads,
            &|e| run_pass(e, true),
            "the same composite, bilinear upsample",
            composite_reads,
            &run_composite,
        )?,
    ])
}
