//! The GPU test harness: one shared headless device, and a probe that runs a shader function over
//! a table of inputs (one compute invocation per case, or one fragment per case where compute
//! shaders do not work: `fragment_probe.rs`) and reads the results back.
//!
//! The shared GPU and the skip rules live in `support.rs` (shared with the CLI's tests).

pub use crate::support::{say, strict, test_name};

use lodkit::gpu::GpuContext;
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary, SourceLanguage};
use wgpu::util::DeviceExt;

use crate::fragment_probe::{self, Grid};

/// How a probe runs its cases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Route {
    /// One compute invocation per case, outputs in a storage buffer.
    Compute,
    /// One fragment per case, inputs from a texture, outputs in integer render targets.
    Fragment,
}

impl Route {
    /// Compute where the device's compute shaders work, fragments elsewhere.
    pub fn of(gpu: &GpuContext) -> Self {
        if gpu.capabilities().compute_shaders() {
            Self::Compute
        } else {
            Self::Fragment
        }
    }

    /// Every route a twin test runs on: fragments on every device (GL 3.3 and WebGL2 class
    /// contexts have no compute), compute where the device's compute shaders work.
    pub fn every(gpu: &GpuContext) -> Vec<Self> {
        let mut routes = vec![Self::Fragment];
        if gpu.capabilities().compute_shaders() {
            routes.push(Self::Compute);
        }
        routes
    }
}

/// Every run of a twin test, as (route, language, header, body): on each of [`Route::every`],
/// the WGSL probe and the GLSL probe (compiled as a compute shader's source; the fragment route
/// wraps it the same way).
pub fn twin_runs<'a>(
    gpu: &GpuContext,
    wgsl: (&'a str, &'a str),
    glsl: (&'a str, &'a str),
) -> Vec<(Route, SourceLanguage, &'a str, &'a str)> {
    let glsl_language = SourceLanguage::Glsl(naga::ShaderStage::Compute);
    Route::every(gpu)
        .into_iter()
        .flat_map(|r| {
            [
                (r, SourceLanguage::Wgsl, wgsl.0, wgsl.1),
                (r, glsl_language, glsl.0, glsl.1),
            ]
        })
        .collect()
}

/// Runs `program` (which must not fail to spawn) or, if it is missing, fails under
/// `LODKIT_REQUIRE_GPU=1` and skips loudly otherwise. Returns `None` when skipped.
pub fn tool(program: &str) -> Option<std::process::Command> {
    let found = std::process::Command::new(program)
        .arg("--version")
        .output()
        .is_ok();
    if found {
        return Some(std::process::Command::new(program));
    }
    if strict() {
        panic!(
            "LODKIT_REQUIRE_GPU=1 but `{program}` is not installed (apt-get install glslang-tools spirv-tools)"
        );
    }
    say(&format!(
        "SKIPPED {}: `{program}` is not installed",
        test_name()
    ));
    None
}

/// A shader function under test: the WGSL and GLSL text around it. Inside `body`,
/// `inp_f(k)`/`inp_u(k)` read input word k of the current case, `out_f(k, v)`/`out_u(k, v)`
/// write output word k.
pub struct Probe<'a> {
    /// Imports (WGSL) or includes (GLSL) at the top of the shader.
    pub header: &'a str,
    /// Statements run once per case.
    pub body: &'a str,
    /// Input words (f32 or u32 bits) per case.
    pub inputs: usize,
    /// Output words per case.
    pub outputs: usize,
    /// An R32Float texture (size, row-major texels) bound as `probe_tex` (WGSL `texture_2d<f32>`;
    /// GLSL `texture2D`, with `probe_sampler` to make a `sampler2D`).
    pub texture: Option<(u32, &'a [f32])>,
    /// Rgba32Float textures (width, height, texels) bound as `probe_rgba0`, `probe_rgba1`, ...
    /// (GLSL: `texture2D`s to combine with `probe_sampler`).
    pub rgba: &'a [(u32, u32, &'a [glam::Vec4])],
    /// Rgba32Uint textures (width, height, texels) bound as `probe_urgba0`, ... (WGSL
    /// `texture_2d<u32>`; GLSL `utexture2D`s to combine with `probe_sampler`).
    pub urgba: &'a [(u32, u32, &'a [[u32; 4]])],
}

/// The GLSL header of a probe of `lodkit/combine_coverage.glsl`: the include and the hooks it
/// reads its textures through, over the probe's textures (the older color `probe_rgba0`, the
/// older depth `probe_rgba1`, the older id words `probe_urgba0`, the combine's data texture
/// `probe_urgba1`).
pub const COMBINE_COVERAGE_GLSL: &str = "#include \"lodkit/combine_coverage.glsl\"
vec4 lodkit_combine_fetch_color(uvec2 t) { return texelFetch(sampler2D(probe_rgba0, probe_sampler), ivec2(t), 0); }
uint lodkit_combine_fetch_word(uvec2 t) { return texelFetch(usampler2D(probe_urgba0, probe_sampler), ivec2(t), 0).x; }
float lodkit_combine_fetch_depth(uvec2 t) { return texelFetch(sampler2D(probe_rgba1, probe_sampler), ivec2(t), 0).x; }
uvec2 lodkit_combine_fetch_size() { return uvec2(textureSize(sampler2D(probe_rgba0, probe_sampler), 0)); }
uvec4 lodkit_silhouette_fetch(uint i) {
    uint w = uint(textureSize(usampler2D(probe_urgba1, probe_sampler), 0).x);
    return texelFetch(usampler2D(probe_urgba1, probe_sampler), ivec2(int(i % w), int(i / w)), 0);
}";

/// The WGSL probe shader (naga_oil: the header `#import`s lodkit).
pub fn wgsl_probe(p: &Probe) -> String {
    let mut texture = if p.texture.is_some() {
        "@group(0) @binding(2) var probe_tex: texture_2d<f32>;".to_owned()
    } else {
        String::new()
    };
    for k in 0..p.rgba.len() {
        texture.push_str(&format!(
            "\n@group(0) @binding({}) var probe_rgba{k}: texture_2d<f32>;",
            4 + k
        ));
    }
    for k in 0..p.urgba.len() {
        texture.push_str(&format!(
            "\n@group(0) @binding({}) var probe_urgba{k}: texture_2d<u32>;",
            12 + k
        ));
    }
    format!(
        "{header}
{texture}
@group(0) @binding(0) var<storage, read> probe_in: array<u32>;
@group(0) @binding(1) var<storage, read_write> probe_out: array<u32>;
var<private> probe_case: u32;
fn inp_u(k: u32) -> u32 {{ return probe_in[probe_case * {inputs}u + k]; }}
fn inp_f(k: u32) -> f32 {{ return bitcast<f32>(inp_u(k)); }}
fn out_u(k: u32, v: u32) {{ probe_out[probe_case * {outputs}u + k] = v; }}
fn out_f(k: u32, v: f32) {{ out_u(k, bitcast<u32>(v)); }}
@compute @workgroup_size(1)
fn main(@builtin(workgroup_id) id: vec3<u32>) {{
    probe_case = id.x;
    {body}
}}
",
        header = p.header,
        inputs = p.inputs,
        outputs = p.outputs,
        body = p.body
    )
}

/// The GLSL probe shader (compute, `#include`s resolved against the library).
pub fn glsl_probe(p: &Probe) -> String {
    let mut texture = String::new();
    if p.texture.is_some() {
        texture.push_str("layout(set = 0, binding = 2) uniform texture2D probe_tex;\n");
    }
    for k in 0..p.rgba.len() {
        texture.push_str(&format!(
            "layout(set = 0, binding = {}) uniform texture2D probe_rgba{k};\n",
            4 + k
        ));
    }
    for k in 0..p.urgba.len() {
        texture.push_str(&format!(
            "layout(set = 0, binding = {}) uniform utexture2D probe_urgba{k};\n",
            12 + k
        ));
    }
    if p.texture.is_some() || !p.rgba.is_empty() || !p.urgba.is_empty() {
        texture.push_str("layout(set = 0, binding = 3) uniform sampler probe_sampler;\n");
    }
    format!(
        "#version 450
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 1) in;
layout(std430, set = 0, binding = 0) readonly buffer ProbeIn {{ uint probe_in[]; }};
layout(std430, set = 0, binding = 1) buffer ProbeOut {{ uint probe_out[]; }};
{texture}
{header}
uint probe_case;
uint inp_u(uint k) {{ return probe_in[probe_case * {inputs}u + k]; }}
float inp_f(uint k) {{ return uintBitsToFloat(inp_u(k)); }}
void out_u(uint k, uint v) {{ probe_out[probe_case * {outputs}u + k] = v; }}
void out_f(uint k, float v) {{ out_u(k, floatBitsToUint(v)); }}
void main() {{
    probe_case = gl_WorkGroupID.x;
    {body}
}}
",
        header = p.header,
        inputs = p.inputs,
        outputs = p.outputs,
        body = p.body
    )
}

/// Runs the WGSL probe over `cases` (flattened input words) and returns the output words.
pub fn run_wgsl(gpu: &GpuContext, probe: &Probe, cases: &[u32]) -> Vec<u32> {
    run_with(gpu, probe, cases, SourceLanguage::Wgsl, &[])
}

/// Runs the GLSL probe (the GLSL twins) over `cases`.
pub fn run_glsl(gpu: &GpuContext, probe: &Probe, cases: &[u32]) -> Vec<u32> {
    let glsl = SourceLanguage::Glsl(naga::ShaderStage::Compute);
    run_with(gpu, probe, cases, glsl, &[])
}

/// Runs the probe in `language` with the boolean shader defs `defs` switched on, on the device's
/// route ([`Route::of`]). A WGSL probe runs twice: composed from the naga_oil modules, and
/// converted to WESL (`naga_oil_to_wesl`) and linked by wesl-rs against the WESL package; both
/// must give the same words, so every table a test holds against a Rust twin also holds for the
/// WESL form. (A GLSL probe's stage follows the route whatever `language` names.)
pub fn run_with(
    gpu: &GpuContext,
    probe: &Probe,
    cases: &[u32],
    language: SourceLanguage,
    defs: &[&str],
) -> Vec<u32> {
    run_on(gpu, Route::of(gpu), probe, cases, language, defs)
}

/// [`run_with`] on the given route.
pub fn run_on(
    gpu: &GpuContext,
    route: Route,
    probe: &Probe,
    cases: &[u32],
    language: SourceLanguage,
    defs: &[&str],
) -> Vec<u32> {
    assert_eq!(
        cases.len() % probe.inputs,
        0,
        "inputs are not a whole number of cases"
    );
    let grid = Grid::new(gpu, probe, cases.len() / probe.inputs);
    let (source, language) = match (language, route) {
        (SourceLanguage::Glsl(_), Route::Compute) => (
            glsl_probe(probe),
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
        ),
        (SourceLanguage::Glsl(_), Route::Fragment) => (
            fragment_probe::glsl(probe, grid),
            SourceLanguage::Glsl(naga::ShaderStage::Fragment),
        ),
        (_, Route::Compute) => (wgsl_probe(probe), language),
        (_, Route::Fragment) => (fragment_probe::wgsl(probe, grid), language),
    };
    let shader_defs: lodkit::shaders::ShaderDefs = defs
        .iter()
        .map(|d| (d.to_string(), lodkit::shaders::ShaderDefValue::Bool(true)))
        .collect();
    let run = |source: &str, language| {
        let module = probe_module(gpu, source, language, shader_defs.clone());
        match route {
            Route::Compute => run_compute(gpu, probe, grid.n, cases, &module),
            Route::Fragment => {
                let textures = probe_textures(gpu, probe);
                fragment_probe::run(gpu, probe, grid, cases, &module, &textures)
            }
        }
    };
    let words = run(&source, language);
    if language == SourceLanguage::Wgsl {
        let wesl = lodkit::shaders::naga_oil_to_wesl(&source, "", "")
            .unwrap_or_else(|e| panic!("the probe has no WESL form: {e}\n{source}"));
        let wesl_words = run(&wesl, SourceLanguage::Wesl);
        if let Some(k) = (0..words.len()).find(|&k| wesl_words.get(k) != words.get(k)) {
            panic!(
                "the WESL modules compute other results than the naga_oil modules (defs {defs:?}): \
                 first at case {} word {}: {:#x} vs {:#x}\n{wesl}",
                k / probe.outputs,
                k % probe.outputs,
                wesl_words.get(k).copied().unwrap_or_default(),
                words[k]
            );
        }
    }
    words
}

/// The probe's shader module, composed with lodkit's library.
fn probe_module(
    gpu: &GpuContext,
    source: &str,
    language: SourceLanguage,
    shader_defs: lodkit::shaders::ShaderDefs,
) -> wgpu::ShaderModule {
    let mut library = ShaderLibrary::new().expect("library");
    let composed = library
        .compose(&ComposeDescriptor {
            source,
            file_path: "probe",
            language,
            shader_defs,
        })
        .unwrap_or_else(|e| panic!("probe does not compose:\n{}\n{source}", render(&e)));
    gpu.shader_module("probe", &composed)
        .unwrap_or_else(|e| panic!("probe module: {e}\n{source}"))
}

/// The probe's own textures as (binding, view): `probe_tex` at 2, float ones from 4 (at most
/// 8), unsigned ones from 12.
fn probe_textures(gpu: &GpuContext, probe: &Probe) -> Vec<(u32, wgpu::TextureView)> {
    let device = &gpu.device;
    let mut out = Vec::new();
    if let Some((size, texels)) = probe.texture {
        let texture = lodkit::gpu::resources::r32float_texture(gpu, size, texels, "probe texture")
            .expect("probe texture");
        out.push((2, texture.create_view(&Default::default())));
    }
    let texture = |(w, h): (u32, u32), format, bytes: &[u8]| {
        device
            .create_texture_with_data(
                &gpu.queue,
                &wgpu::TextureDescriptor {
                    label: Some("probe rgba"),
                    size: wgpu::Extent3d {
                        width: w,
                        height: h,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                bytes,
            )
            .create_view(&Default::default())
    };
    for (k, (w, h, texels)) in probe.rgba.iter().enumerate() {
        let flat: Vec<f32> = texels.iter().flat_map(|v| v.to_array()).collect();
        let format = wgpu::TextureFormat::Rgba32Float;
        out.push((
            4 + k as u32,
            texture((*w, *h), format, bytemuck::cast_slice(&flat)),
        ));
    }
    for (k, (w, h, texels)) in probe.urgba.iter().enumerate() {
        let format = wgpu::TextureFormat::Rgba32Uint;
        out.push((
            12 + k as u32,
            texture((*w, *h), format, bytemuck::cast_slice(texels)),
        ));
    }
    out
}

/// Dispatches the compute probe `module` over `n` cases and returns the output words.
fn run_compute(
    gpu: &GpuContext,
    probe: &Probe,
    n: usize,
    cases: &[u32],
    module: &wgpu::ShaderModule,
) -> Vec<u32> {
    let device = &gpu.device;
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("probe"),
        layout: None,
        module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe in"),
        contents: bytemuck::cast_slice(cases),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (n * probe.outputs * 4) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let textures = probe_textures(gpu, probe);
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: input.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: output.as_entire_binding(),
        },
    ];
    for (binding, view) in &textures {
        entries.push(wgpu::BindGroupEntry {
            binding: *binding,
            resource: wgpu::BindingResource::TextureView(view),
        });
    }
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(n as u32, 1, 1);
    }
    let bytes =
        lodkit::gpu::readback::read_buffer(gpu, encoder, &output, size).expect("probe readback");
    bytemuck::cast_slice(&bytes).to_vec()
}

/// Human rendering of a shader error (the diagnostic when there is one).
pub fn render(e: &lodkit::shaders::ShaderError) -> String {
    e.diagnostic().map_or_else(|| e.to_string(), |d| d.render())
}

/// f32 inputs as probe words.
pub fn words(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// Probe words as f32.
pub fn floats(words: &[u32]) -> Vec<f32> {
    words.iter().map(|w| f32::from_bits(*w)).collect()
}

/// WGSL's stated accuracy for f32 ("Floating Point Accuracy" in the WGSL spec), in ULP: how far a
/// conformant GPU may be from the correctly rounded result, which is what the Rust twins compute
/// (Rust rounds every operation correctly and fuses nothing). Tolerances of the twin tests are
/// derived from these and from each function's conditioning, beside each test.
pub mod accuracy {
    /// One ULP relative to a normal value's magnitude: ulp(x) <= 2^-23 |x|.
    pub const ULP: f32 = f32::EPSILON;
    /// `x + y`, `x - y`, `x * y`, `abs`, `min`, `max`, `clamp`, `select`, negation: correctly
    /// rounded (at most 0.5 ULP, the CPU's own rounding; a GPU may also fuse a multiply and an
    /// add, which differs from the CPU by at most that much per operation).
    pub const CORRECTLY_ROUNDED: f32 = 0.5;
    /// `x / y` for |y| in [2^-126, 2^126]: 2.5 ULP.
    pub const DIV: f32 = 2.5;
    /// `sqrt` inherits `1.0 / inverseSqrt(x)`: inverseSqrt's 2 ULP, then the division's 2.5.
    pub const SQRT: f32 = 4.5;
}

/// How one output word of a probe is held to its Rust twin's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Word {
    /// An integer, a flag or packed bits: equal.
    Exact,
    /// A float within this absolute tolerance. +0 and -0 are equal (Vulkan keeps a zero's sign
    /// only under `SignedZeroInfNanPreserve`, which naga does not ask for; WGSL and GL promise
    /// nothing either), and a NaN matches nothing.
    Float(f32),
}

/// Whether float `got` is within `tol` of `want`: +0 and -0 equal, a NaN never.
pub fn float_matches(got: f32, want: f32, tol: f32) -> bool {
    got == want || (got - want).abs() <= tol
}

/// Where `got` first differs from the twin's `want` (flattened cases of `kinds.len()` words,
/// each word held as its kind says), described; `None` when every word matches.
pub fn twin_mismatch(got: &[u32], want: &[u32], kinds: &[Word]) -> Option<String> {
    if got.len() != want.len() {
        return Some(format!("{} words, the twin {}", got.len(), want.len()));
    }
    let n = kinds.len();
    for (case, (g, w)) in got.chunks(n).zip(want.chunks(n)).enumerate() {
        for (k, kind) in kinds.iter().enumerate() {
            let ok = match kind {
                Word::Exact => g[k] == w[k],
                Word::Float(tol) => float_matches(f32::from_bits(g[k]), f32::from_bits(w[k]), *tol),
            };
            if !ok {
                let show = |v: &[u32]| {
                    v.iter()
                        .zip(kinds)
                        .map(|(x, kind)| match kind {
                            Word::Exact => format!("{x:#x}"),
                            Word::Float(_) => format!("{:?}", f32::from_bits(*x)),
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                return Some(format!(
                    "case {case} word {k} ({kind:?}): GPU [{}] vs Rust twin [{}]",
                    show(g),
                    show(w)
                ));
            }
        }
    }
    None
}

/// Asserts that `got` matches the twin's `want` word by word as `kinds` says (see
/// [`twin_mismatch`]).
pub fn assert_twin(got: &[u32], want: &[u32], kinds: &[Word], what: &str) {
    if let Some(problem) = twin_mismatch(got, want, kinds) {
        panic!("{what}: {problem}");
    }
}

/// Asserts `got` matches `want` within `tol` relative to max(1, |want|), naming the first case
/// that does not.
pub fn assert_close(got: &[f32], want: &[f32], tol: f32, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: result count");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        let ok = (g - w).abs() <= tol * w.abs().max(1.0);
        assert!(
            ok,
            "{what}: case {i}: GPU {g} vs Rust twin {w} (tolerance {tol})"
        );
    }
}
