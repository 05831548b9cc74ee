//! WebGPU in the browser: a page in headless Chromium links lodkit's WESL package with wesl-js
//! (npm `wesl`, loaded into the page), runs probes of `combine_samples` and `screen_door_keep`
//! on the page's WebGPU adapter (SwiftShader without a GPU), and the results must equal what the
//! Rust twins compute on the same tables the native GPU tests use.

use lodkit::combine::{DepthConvention, combine_samples};
use lodkit::screen_door::DitherPattern;
use lodkit::shaders::naga_oil_to_wesl;

use crate::frame_sequential::{COMBINE_PROBE, combine_cases, combine_inputs};
use crate::harness::{Probe, floats, say, wgsl_probe};
use crate::single_frame::{SCREEN_DOOR_PROBE, rust_bits, screen_door_cases};
use crate::support::{browser_script, run_ok, scratch, workspace_root};

/// A probe job for `.ci/browser/webgpu-probe.mjs`: the naga_oil probe converted to WESL.
fn job(name: &str, probe: &Probe, condition: Option<&str>, input: &[u32]) -> serde_json::Value {
    let root = naga_oil_to_wesl(&wgsl_probe(probe), "", "").expect("the probe converts to WESL");
    let conditions: serde_json::Map<String, serde_json::Value> = condition
        .map(|c| (c.to_owned(), serde_json::Value::Bool(true)))
        .into_iter()
        .collect();
    serde_json::json!({
        "name": name,
        "root": root,
        "conditions": conditions,
        "input": input,
        "cases": input.len() / probe.inputs,
        "outputs": probe.outputs,
    })
}

#[test]
fn webgpu_page_links_wesl_and_matches_the_rust_twins() {
    let (combine, screen_door) = (COMBINE_PROBE, SCREEN_DOOR_PROBE);
    let cases = combine_cases();
    let combine_in = combine_inputs(&cases);
    let (ts, door_in) = screen_door_cases();
    let jobs = vec![
        job("combine", &combine, None, &combine_in),
        job(
            "combine-reversed-z",
            &combine,
            Some("LODKIT_REVERSE_Z"),
            &combine_in,
        ),
        job("screen-door", &screen_door, None, &door_in),
        job(
            "screen-door-blue-noise",
            &screen_door,
            Some("LODKIT_SCREEN_DOOR_BLUE_NOISE"),
            &door_in,
        ),
    ];
    let file = scratch("webgpu-probe.json");
    std::fs::write(&file, serde_json::to_string(&jobs).unwrap()).unwrap();
    let Some(mut node) = browser_script("webgpu-probe.mjs") else {
        return;
    };
    let stdout = run_ok(
        node.arg(workspace_root().join("shader_lib/wesl/lodkit"))
            .arg(&file),
        "the WebGPU page failed",
    );
    let json = stdout
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_default();
    let doc: serde_json::Value = serde_json::from_str(json).expect("the page prints JSON");
    say(&format!("webgpu page: adapter {}", doc["adapter"]));
    let words = |name: &str| -> Vec<u32> {
        doc["results"][name]
            .as_array()
            .unwrap_or_else(|| panic!("no result for {name}: {stdout}"))
            .iter()
            .map(|v| v.as_u64().unwrap() as u32)
            .collect()
    };
    for (name, convention) in [
        ("combine", DepthConvention::Standard),
        ("combine-reversed-z", DepthConvention::Reversed),
    ] {
        let want: Vec<f32> = cases
            .iter()
            .flat_map(|(n, o)| combine_samples(*n, *o, convention).to_array())
            .collect();
        assert_eq!(floats(&words(name)), want, "{name} in the browser");
    }
    for (name, pattern) in [
        ("screen-door", DitherPattern::Bayer4x4),
        ("screen-door-blue-noise", DitherPattern::BlueNoise16x16),
    ] {
        assert_eq!(
            words(name),
            rust_bits(pattern, &ts),
            "{name} in the browser"
        );
    }
}
