//! Costs counted from the IR (`lodkit::shaders::cost`): hand-counted shaders give their counts,
//! loops of constant trip count multiply out, branches count apart as conditional, calls are
//! inlined, and lodkit's own passes give the fetches their headers state. The counts never
//! undercount: GLSL `for` loops, switch fall-through and counters set under branches are
//! counted on their costliest path (`cost_bounds`), or the loop is reported as unbounded.

use lodkit::shaders::cost::{Counts, EntryCost, FetchKind, entry_point_costs};
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary, SourceLanguage, find_module};

/// The cost of every entry point of `source`, composed as `language`.
pub(crate) fn costs_in(source: &str, language: SourceLanguage) -> Vec<EntryCost> {
    let file_path = match language {
        SourceLanguage::Wgsl => "cost.wgsl",
        SourceLanguage::Wesl => "cost.wesl",
        SourceLanguage::Glsl(_) => "cost.frag",
    };
    let composed = ShaderLibrary::new()
        .unwrap()
        .compose(&ComposeDescriptor {
            source,
            file_path,
            language,
            ..Default::default()
        })
        .unwrap_or_else(|e| panic!("{e}"));
    entry_point_costs(&composed.module)
}

fn costs(source: &str) -> Vec<EntryCost> {
    costs_in(source, SourceLanguage::Wgsl)
}

fn only(source: &str) -> EntryCost {
    let mut all = costs(source);
    assert_eq!(all.len(), 1);
    all.remove(0)
}

const HEAD: &str = "
@group(0) @binding(0) var t: texture_2d<f32>;
@group(0) @binding(1) var s: sampler;
@group(0) @binding(2) var<storage, read> buf: array<f32>;
@group(0) @binding(3) var<uniform> n: u32;
";

#[test]
fn straight_line_fetches_and_alu_are_counted_one_by_one() {
    let c = only(&format!(
        "{HEAD}
@fragment fn main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {{
    let a = textureLoad(t, vec2<u32>(1u, 2u), 0);
    let b = textureSample(t, s, p.xy);
    let g = textureGather(0, t, s, p.xy);
    let x = buf[3];
    return a * b + g * x;
}}"
    ));
    // Fetches: 1 load, 1 sample, 1 gather, 1 storage read. ALU: a * b, g * x, + : 3.
    assert_eq!(
        c.always,
        Counts {
            texture_loads: 1,
            samples: 1,
            gathers: 1,
            storage_reads: 1,
            alu: 3
        }
    );
    assert_eq!(c.conditional, Counts::default());
    assert_eq!(c.unknown_loops, 0);
    let t: Vec<_> = c
        .resources
        .iter()
        .map(|r| (r.resource.as_str(), r.binding, r.kind, r.always))
        .collect();
    assert_eq!(
        t,
        [
            ("t", Some((0, 0)), FetchKind::TextureLoad, 1),
            ("t", Some((0, 0)), FetchKind::Sample, 1),
            ("t", Some((0, 0)), FetchKind::Gather, 1),
            ("buf", Some((0, 2)), FetchKind::StorageRead, 1),
        ]
    );
}

#[test]
fn counted_loops_multiply_their_bodies() {
    let c = only(&format!(
        "{HEAD}
@fragment fn main() -> @location(0) vec4<f32> {{
    var sum = vec4<f32>(0.0);
    for (var i = 0u; i < 4u; i++) {{
        sum += textureLoad(t, vec2<u32>(i, 0u), 0);
    }}
    for (var j = 8; j > 0; j -= 2) {{
        sum += textureLoad(t, vec2<i32>(j, 1), 0);
    }}
    var k = 0u;
    loop {{
        sum += textureLoad(t, vec2<u32>(k, 2u), 0);
        continuing {{
            k += 1u;
            break if k >= 3u;
        }}
    }}
    return sum;
}}"
    ));
    // 4 + 4 (8, 6, 4, 2) + 3 (k = 0, 1, 2).
    assert_eq!(c.always.texture_loads, 11, "{c:?}");
    assert_eq!(c.unknown_loops, 0);
}

#[test]
fn a_loop_the_ir_does_not_fix_counts_once_and_is_reported() {
    let c = only(&format!(
        "{HEAD}
@fragment fn main() -> @location(0) vec4<f32> {{
    var sum = vec4<f32>(0.0);
    for (var i = 0u; i < n; i++) {{
        sum += textureLoad(t, vec2<u32>(i, 0u), 0);
    }}
    return sum;
}}"
    ));
    assert_eq!(c.always.texture_loads, 1);
    assert_eq!(c.unknown_loops, 1);
}

#[test]
fn branches_count_apart_at_their_costliest_path() {
    let c = only(&format!(
        "{HEAD}
@fragment fn main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {{
    var c = textureLoad(t, vec2<u32>(p.xy), 0);
    if c.x > 0.5 {{
        c += textureLoad(t, vec2<u32>(0u), 0) + textureLoad(t, vec2<u32>(1u), 0);
    }} else {{
        c += buf[0];
    }}
    switch n {{
        case 0u: {{ c += textureLoad(t, vec2<u32>(2u), 0); }}
        default: {{ }}
    }}
    return c;
}}"
    ));
    assert_eq!(c.always.texture_loads, 1);
    // if: at most 2 loads (accept) and 1 storage read (reject); switch: at most 1 load.
    assert_eq!(c.conditional.texture_loads, 3, "{c:?}");
    assert_eq!(c.conditional.storage_reads, 1);
    assert_eq!(c.worst().fetches(), 5);
    let load = c
        .resources
        .iter()
        .find(|r| r.kind == FetchKind::TextureLoad)
        .unwrap();
    assert_eq!((load.always, load.conditional), (1, 3));
}

#[test]
fn calls_are_inlined_as_often_as_they_run() {
    let c = only(&format!(
        "{HEAD}
fn two(p: vec2<u32>) -> vec4<f32> {{
    return textureLoad(t, p, 0) + textureLoad(t, p + 1u, 0);
}}
@fragment fn main() -> @location(0) vec4<f32> {{
    var s = vec4<f32>(0.0);
    for (var i = 0u; i < 3u; i++) {{
        s += two(vec2<u32>(i));
    }}
    return s + two(vec2<u32>(9u));
}}"
    ));
    assert_eq!(c.always.texture_loads, 8);
}

/// lodkit's bilateral upsample: one full-resolution geometry load and eq. 1's 2x2 color and
/// geometry loads (its header: "Eight texel loads"), nothing conditional.
#[test]
fn the_bilateral_upsample_pass_makes_nine_loads() {
    let pass = find_module("passes/upsample.wgsl")
        .or_else(|| {
            lodkit::shaders::modules()
                .iter()
                .find(|m| m.path == "passes/upsample.wgsl")
        })
        .expect("the upsample pass is embedded");
    let all = costs(pass.source);
    let fs = all.iter().find(|c| c.name == "fs_main").unwrap();
    assert_eq!(fs.worst().fetches(), 9, "{fs:?}");
    assert_eq!(fs.conditional.fetches(), 0);
    let per: Vec<(&str, u64)> = fs
        .resources
        .iter()
        .map(|r| (r.resource.as_str(), r.always))
        .collect();
    assert_eq!(
        per,
        [("low_color", 4), ("low_geometry", 4), ("full_geometry", 1)]
    );
    let vs = all.iter().find(|c| c.name == "vs_main").unwrap();
    assert_eq!(vs.worst().fetches(), 0);
}
