//! The probes' route where compute shaders do not work (GL 3.3, GLES 3.0, WebGL2 class
//! contexts, [`GpuCapabilities::compute_shaders`](lodkit::gpu::GpuCapabilities::compute_shaders)):
//! one fragment per case. A case's input words are texels of an `R32Uint` texture read with
//! `textureLoad` (row `case / cols`, words `(case % cols) * inputs ..` along it), its output words
//! go to `Rgba32Uint` render targets, four words each, at pixel `(case % cols, case / cols)`.
//! The probe's own textures keep their bindings (2, 4.., 12..); the input texture is binding 0,
//! the first texture of the pipeline, so a probe without textures of its own binds one texture.

use lodkit::gpu::GpuContext;
use lodkit::gpu::readback::read_texture;
use lodkit::gpu::resources::texture_2d;
use wgpu::util::DeviceExt;

use crate::harness::Probe;

/// Most output words per case: eight `Rgba32Uint` targets.
const MAX_OUTPUTS: usize = 32;

/// Where the cases lie: `cols` cases per row of the input texture and of the targets.
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    /// Cases.
    pub n: usize,
    /// Cases per row.
    pub cols: usize,
    /// Rows.
    pub rows: usize,
}

impl Grid {
    /// As many cases per row as the input texture's width allows on `gpu`.
    pub fn new(gpu: &GpuContext, probe: &Probe, n: usize) -> Self {
        assert!(n > 0, "a probe needs a case");
        assert!(
            probe.outputs <= MAX_OUTPUTS,
            "the fragment probe writes at most {MAX_OUTPUTS} words per case"
        );
        let max = gpu.device.limits().max_texture_dimension_2d as usize;
        let cols = (max / probe.inputs).clamp(1, n);
        let rows = n.div_ceil(cols);
        assert!(rows <= max, "{n} cases do not fit in {max} rows");
        Self { n, cols, rows }
    }

    /// Render targets per case.
    fn targets(probe: &Probe) -> usize {
        probe.outputs.div_ceil(4)
    }
}

/// The vertex stage: one triangle over the whole target.
const FULLSCREEN: &str = "@vertex
fn probe_vertex(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
";

/// The WGSL fragment probe (naga_oil: the header `#import`s lodkit); entry point `main`.
pub fn wgsl(p: &Probe, grid: Grid) -> String {
    let targets = Grid::targets(p);
    let words = targets * 4;
    let fields: String = (0..targets)
        .map(|t| format!("    @location({t}) o{t}: vec4<u32>,\n"))
        .collect();
    let values: Vec<String> = (0..targets)
        .map(|t| {
            let w: Vec<String> = (0..4)
                .map(|j| format!("probe_words[{}]", t * 4 + j))
                .collect();
            format!("vec4<u32>({})", w.join(", "))
        })
        .collect();
    format!(
        "{header}
{textures}
@group(0) @binding(0) var probe_in: texture_2d<u32>;
var<private> probe_case: u32;
var<private> probe_words: array<u32, {words}>;
fn inp_u(k: u32) -> u32 {{
    let x = (probe_case % {cols}u) * {inputs}u + k;
    return textureLoad(probe_in, vec2<u32>(x, probe_case / {cols}u), 0).x;
}}
fn inp_f(k: u32) -> f32 {{ return bitcast<f32>(inp_u(k)); }}
fn out_u(k: u32, v: u32) {{ probe_words[k] = v; }}
fn out_f(k: u32, v: f32) {{ out_u(k, bitcast<u32>(v)); }}
fn probe_run() {{
    {body}
}}
struct ProbeOut {{
{fields}}}
@fragment
fn main(@builtin(position) probe_position: vec4<f32>) -> ProbeOut {{
    let cell = vec2<u32>(probe_position.xy);
    probe_case = cell.y * {cols}u + cell.x;
    if (probe_case >= {n}u) {{
        discard;
    }}
    probe_run();
    return ProbeOut({values});
}}
",
        header = p.header,
        textures = wgsl_textures(p),
        cols = grid.cols,
        n = grid.n,
        inputs = p.inputs,
        body = p.body,
        values = values.join(", "),
    )
}

/// The probe's own textures in WGSL (the bindings of the compute probe).
fn wgsl_textures(p: &Probe) -> String {
    let mut out = String::new();
    if p.texture.is_some() {
        out.push_str("@group(0) @binding(2) var probe_tex: texture_2d<f32>;\n");
    }
    for k in 0..p.rgba.len() {
        let b = 4 + k;
        out.push_str(&format!(
            "@group(0) @binding({b}) var probe_rgba{k}: texture_2d<f32>;\n"
        ));
    }
    for k in 0..p.urgba.len() {
        let b = 12 + k;
        out.push_str(&format!(
            "@group(0) @binding({b}) var probe_urgba{k}: texture_2d<u32>;\n"
        ));
    }
    out
}

/// The GLSL fragment probe (`#include`s resolved against the library); entry point `main`.
pub fn glsl(p: &Probe, grid: Grid) -> String {
    let targets = Grid::targets(p);
    let words = targets * 4;
    let mut textures = String::new();
    if p.texture.is_some() {
        textures.push_str("layout(set = 0, binding = 2) uniform texture2D probe_tex;\n");
    }
    for k in 0..p.rgba.len() {
        let b = 4 + k;
        textures.push_str(&format!(
            "layout(set = 0, binding = {b}) uniform texture2D probe_rgba{k};\n"
        ));
    }
    for k in 0..p.urgba.len() {
        let b = 12 + k;
        textures.push_str(&format!(
            "layout(set = 0, binding = {b}) uniform utexture2D probe_urgba{k};\n"
        ));
    }
    let outs: String = (0..targets)
        .map(|t| format!("layout(location = {t}) out uvec4 probe_out{t};\n"))
        .collect();
    let stores: String = (0..targets)
        .map(|t| {
            let w: Vec<String> = (0..4)
                .map(|j| format!("probe_words[{}]", t * 4 + j))
                .collect();
            format!("    probe_out{t} = uvec4({});\n", w.join(", "))
        })
        .collect();
    format!(
        "#version 450
#extension GL_GOOGLE_include_directive : require
layout(set = 0, binding = 0) uniform utexture2D probe_in;
layout(set = 0, binding = 3) uniform sampler probe_sampler;
{textures}
{header}
{outs}
uint probe_case;
uint probe_words[{words}];
uint inp_u(uint k) {{
    uint x = (probe_case % {cols}u) * {inputs}u + k;
    return texelFetch(usampler2D(probe_in, probe_sampler), ivec2(int(x), int(probe_case / {cols}u)), 0).x;
}}
float inp_f(uint k) {{ return uintBitsToFloat(inp_u(k)); }}
void out_u(uint k, uint v) {{ probe_words[k] = v; }}
void out_f(uint k, float v) {{ out_u(k, floatBitsToUint(v)); }}
void probe_run() {{
    {body}
}}
void main() {{
    uvec2 cell = uvec2(gl_FragCoord.xy);
    probe_case = cell.y * {cols}u + cell.x;
    if (probe_case >= {n}u) {{
        discard;
    }}
    for (uint i = 0u; i < {words}u; i++) {{
        probe_words[i] = 0u;
    }}
    probe_run();
{stores}}}
",
        header = p.header,
        cols = grid.cols,
        n = grid.n,
        inputs = p.inputs,
        body = p.body,
    )
}

/// Draws the probe `module` (entry point `main`) over `grid` with the input words `cases` and
/// the probe's own texture views `textures` ((binding, view)), and returns the output words.
pub fn run(
    gpu: &GpuContext,
    probe: &Probe,
    grid: Grid,
    cases: &[u32],
    module: &wgpu::ShaderModule,
    textures: &[(u32, wgpu::TextureView)],
) -> Vec<u32> {
    let device = &gpu.device;
    let format = wgpu::TextureFormat::Rgba32Uint;
    let vertex = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("probe vertex"),
        source: wgpu::ShaderSource::Wgsl(FULLSCREEN.into()),
    });
    let targets: Vec<Option<wgpu::ColorTargetState>> = (0..Grid::targets(probe))
        .map(|_| Some(format.into()))
        .collect();
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("fragment probe"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &vertex,
            entry_point: Some("probe_vertex"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    });
    // The input words, padded with zeros to whole rows.
    let width = grid.cols * probe.inputs;
    let mut words = cases.to_vec();
    words.resize(width * grid.rows, 0);
    let input = device
        .create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("probe inputs"),
                size: wgpu::Extent3d {
                    width: width as u32,
                    height: grid.rows as u32,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&words),
        )
        .create_view(&Default::default());
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: wgpu::BindingResource::TextureView(&input),
    }];
    for (binding, view) in textures {
        entries.push(wgpu::BindGroupEntry {
            binding: *binding,
            resource: wgpu::BindingResource::TextureView(view),
        });
    }
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fragment probe"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let size = (grid.cols as u32, grid.rows as u32);
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let outputs: Vec<wgpu::Texture> = (0..targets.len())
        .map(|_| texture_2d(gpu, size, format, usage, "probe outputs").expect("probe target"))
        .collect();
    let views: Vec<wgpu::TextureView> = outputs
        .iter()
        .map(|t| t.create_view(&Default::default()))
        .collect();
    let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views
        .iter()
        .map(|view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("fragment probe"),
            color_attachments: &attachments,
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    let read: Vec<Vec<u32>> = outputs
        .iter()
        .map(|t| {
            let bytes = read_texture(gpu, t, 16).expect("probe readback");
            bytemuck::cast_slice(&bytes).to_vec()
        })
        .collect();
    let mut out = Vec::with_capacity(grid.n * probe.outputs);
    for case in 0..grid.n {
        for k in 0..probe.outputs {
            out.push(read[k / 4][case * 4 + k % 4]);
        }
    }
    out
}
