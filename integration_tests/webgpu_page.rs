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

/// The probe jobs: `combine_samples` (standard and reversed Z) and `screen_door_keep` (Bayer and
/// blue noise), on the tables the native GPU tests use.
fn probe_jobs() -> Vec<serde_json::Value> {
    let (combine, screen_door) = (COMBINE_PROBE, SCREEN_DOOR_PROBE);
    let combine_in = combine_inputs(&combine_cases());
    let (_, door_in) = screen_door_cases();
    vec![
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
    ]
}

/// Holds the page's output words (webgpu-probe.mjs's stdout) to the Rust twins.
fn assert_matches_the_rust_twins(stdout: &str, what: &str) {
    let json = stdout
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_default();
    let doc: serde_json::Value = serde_json::from_str(json).expect("the page prints JSON");
    say(&format!("{what}: adapter {}", doc["adapter"]));
    let words = |name: &str| -> Vec<u32> {
        doc["results"][name]
            .as_array()
            .unwrap_or_else(|| panic!("no result for {name}: {stdout}"))
            .iter()
            .map(|v| v.as_u64().unwrap() as u32)
            .collect()
    };
    let cases = combine_cases();
    for (name, convention) in [
        ("combine", DepthConvention::Standard),
        ("combine-reversed-z", DepthConvention::Reversed),
    ] {
        let want: Vec<f32> = cases
            .iter()
            .flat_map(|(n, o)| combine_samples(*n, *o, convention).to_array())
            .collect();
        assert_eq!(floats(&words(name)), want, "{name} ({what})");
    }
    let (ts, _) = screen_door_cases();
    for (name, pattern) in [
        ("screen-door", DitherPattern::Bayer4x4),
        ("screen-door-blue-noise", DitherPattern::BlueNoise16x16),
    ] {
        assert_eq!(words(name), rust_bits(pattern, &ts), "{name} ({what})");
    }
}

#[test]
fn webgpu_page_links_wesl_and_matches_the_rust_twins() {
    let file = scratch("webgpu-probe.json");
    std::fs::write(&file, serde_json::to_string(&probe_jobs()).unwrap()).unwrap();
    let Some(mut node) = browser_script("webgpu-probe.mjs") else {
        return;
    };
    let stdout = run_ok(
        node.arg(workspace_root().join("shader_lib/wesl/lodkit"))
            .arg(&file),
        "the WebGPU page failed",
    );
    assert_matches_the_rust_twins(&stdout, "webgpu page");
}

/// What a WebGPU developer does: `npm pack` the package folder, install the tarball and npm
/// `wesl` into a fresh node project, import the bundle from the package and link with it, and
/// run the result on Chromium's WebGPU.
#[test]
fn npm_package_installs_links_and_runs_in_chromium() {
    let Some(mut probe) = browser_script("webgpu-probe.mjs") else {
        return;
    };
    let work = scratch("npm");
    let app = work.join("app");
    std::fs::create_dir_all(&app).unwrap();
    let package = workspace_root().join("shader_lib/wesl/lodkit");
    let packed = std::process::Command::new("npm")
        .args(["pack", "--json", "--pack-destination"])
        .arg(&work)
        .arg(&package)
        .output()
        .expect("npm runs");
    assert!(packed.status.success(), "npm pack: {packed:?}");
    let packed: serde_json::Value =
        serde_json::from_slice(&packed.stdout).expect("npm pack --json prints JSON");
    let mut shipped: Vec<String> = packed[0]["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["path"].as_str().unwrap().to_owned())
        .collect();
    shipped.sort();
    assert_eq!(
        shipped,
        crate::support::files_under(&package),
        "npm pack ships exactly the package folder"
    );
    let tarball = work.join(packed[0]["filename"].as_str().unwrap());
    say(&format!(
        "npm pack: {} ({} bytes, {} unpacked)",
        tarball.display(),
        packed[0]["size"],
        packed[0]["unpackedSize"]
    ));
    std::fs::write(
        app.join("package.json"),
        r#"{ "name": "lodkit-user", "version": "0.0.0", "private": true, "type": "module" }"#,
    )
    .unwrap();
    let browser = workspace_root().join(".ci/browser");
    let pinned: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(browser.join("package.json")).unwrap())
            .unwrap();
    let wesl = format!("wesl@{}", pinned["dependencies"]["wesl"].as_str().unwrap());
    run_ok(
        std::process::Command::new("npm")
            .current_dir(&app)
            .args(["install", "--no-audit", "--no-fund", "--prefer-offline"])
            .arg(&tarball)
            .arg(&wesl),
        "npm install of the packed tarball",
    );
    std::fs::copy(browser.join("npm-user.mjs"), app.join("link.mjs")).unwrap();
    let (jobs, linked) = (work.join("jobs.json"), work.join("linked.json"));
    std::fs::write(&jobs, serde_json::to_string(&probe_jobs()).unwrap()).unwrap();
    let said = run_ok(
        std::process::Command::new("node")
            .current_dir(&app)
            .arg("link.mjs")
            .arg(&jobs)
            .arg(&linked),
        "linking with the installed package",
    );
    say(said.trim());
    let stdout = run_ok(
        probe.arg("-").arg(&linked),
        "the WebGPU page failed on the linked shaders",
    );
    assert_matches_the_rust_twins(&stdout, "npm package in a WebGPU page");
}
