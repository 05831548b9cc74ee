//! The WESL package: generated from the naga_oil modules and committed up to date, listed by the
//! registry with the paths Bevy 0.20 expects, and linked by wesl-js (npm `wesl`) into WGSL that
//! naga validates and Tint compiles, with every shader def off and on.

use std::collections::BTreeSet;
use std::path::Path;

use lodkit::shaders::{self, Language, ModuleKind, naga};

use crate::composition::{module_harness, wgsl_modules};
use crate::support::{
    Scratch, assert_folder_holds, browser_script, node_script, run_ok, scratch, workspace_root,
};

#[test]
fn committed_wesl_package_is_what_the_generator_writes() {
    let dir = workspace_root().join("shader_lib/wesl/lodkit");
    let generated = shaders::wesl_package().expect("every module converts to WESL");
    // The folder is also the npm package: its package.json, ES module, README and licences are
    // held to their generator by the CLI's test `committed_npm_package_is_what_the_generator_writes`.
    let fix = "regenerate with `cargo run -p lodkit-cli -- wesl --npm shader_lib/wesl/lodkit`";
    let wesl_files = |f: &str| f.ends_with(".wesl") || f == "wesl.toml";
    assert_folder_holds(&dir, &generated, wesl_files, fix);
}

#[test]
fn every_module_has_a_wesl_form_with_its_bevy_path() {
    let wgsl: Vec<&str> = wgsl_modules()
        .filter_map(|m| m.import_path.as_deref())
        .collect();
    let wesl: Vec<&str> = shaders::wesl_modules()
        .filter_map(|m| m.import_path.as_deref())
        .collect();
    assert_eq!(wgsl, wesl);
    for m in shaders::wesl_modules() {
        let topic = m
            .import_path
            .as_deref()
            .unwrap()
            .trim_start_matches("lodkit::");
        assert_eq!(m.language, Language::Wesl);
        assert_eq!(m.kind, ModuleKind::Module);
        assert_eq!(
            m.embedded_path.as_deref(),
            Some(format!("embedded://lodkit/{topic}.wesl").as_str())
        );
        assert!(!m.source.contains("#import") && !m.source.contains("#ifdef"));
        let twin = shaders::find_module(m.import_path.as_deref().unwrap()).unwrap();
        let names = |i: &shaders::ModuleInfo| -> Vec<String> {
            i.functions.iter().map(|f| f.name.clone()).collect()
        };
        assert_eq!(names(m), names(twin), "{}: same functions", m.path);
        let defs = |i: &shaders::ModuleInfo| -> Vec<String> {
            i.shader_defs.iter().map(|d| d.name.clone()).collect()
        };
        assert_eq!(defs(m), defs(twin), "{}: same shader defs", m.path);
    }
}

fn validate(wgsl: &str, what: &str) {
    let module = naga::front::wgsl::parse_str(wgsl).unwrap_or_else(|e| {
        panic!(
            "{what}: naga rejects the linked WGSL:\n{}\n{wgsl}",
            e.emit_to_string(wgsl)
        )
    });
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), Default::default())
        .validate(&module)
        .unwrap_or_else(|e| {
            panic!("{what}: naga's validator rejects the linked WGSL: {e:?}\n{wgsl}")
        });
}

/// One link job per module and condition set: a harness importing every item of the module,
/// with no condition set and with each one set. Returns the jobs, the file they are in, and the
/// temporary folder holding both (removed when dropped).
fn link_jobs(name: &str) -> (Vec<serde_json::Value>, std::path::PathBuf, Scratch) {
    let defs: BTreeSet<String> = shaders::wesl_modules()
        .flat_map(|m| m.shader_defs.iter().map(|d| d.name.clone()))
        .collect();
    assert!(defs.len() >= 2, "the modules read shader defs: {defs:?}");
    let dir = scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    let mut jobs = Vec::new();
    for m in wgsl_modules() {
        let root = module_harness(m, true);
        let topic = m
            .import_path
            .as_deref()
            .unwrap()
            .trim_start_matches("lodkit::");
        let on: Vec<Option<&String>> = std::iter::once(None).chain(defs.iter().map(Some)).collect();
        for def in on {
            let conditions: serde_json::Map<String, serde_json::Value> = def
                .map(|d| (d.clone(), serde_json::Value::Bool(true)))
                .into_iter()
                .collect();
            let out = dir.join(format!(
                "{topic}-{}.wgsl",
                def.map_or("none", |d| d.as_str())
            ));
            jobs.push(serde_json::json!({ "root": root, "conditions": conditions, "out": out }));
        }
    }
    let jobs_file = dir.with_extension("json");
    std::fs::write(&jobs_file, serde_json::to_string(&jobs).unwrap()).unwrap();
    (jobs, jobs_file, dir)
}

/// Runs a linker over the jobs (`PACKAGE_DIR JOBS.json`), then holds every linked file to naga's
/// validator and to Tint.
fn link_and_check(mut linker: std::process::Command, name: &str) {
    let (jobs, jobs_file, _scratch) = link_jobs(name);
    let text = run_ok(
        linker
            .arg(workspace_root().join("shader_lib/wesl/lodkit"))
            .arg(&jobs_file),
        &format!("{name} cannot link lodkit's WESL"),
    );
    crate::harness::say(&format!("{name}: {}", text.trim()));
    let mut dir = None;
    for job in &jobs {
        let path = Path::new(job["out"].as_str().unwrap());
        let wgsl = std::fs::read_to_string(path).unwrap();
        validate(&wgsl, &path.display().to_string());
        dir = path.parent().map(Path::to_path_buf);
    }
    // Tint (Chromium's WebGPU) compiles the same linked files.
    let Some(mut tint) = browser_script("tint.mjs") else {
        return;
    };
    run_ok(
        tint.arg(dir.unwrap()),
        &format!("Tint rejects WESL linked by {name}"),
    );
}

#[test]
fn every_wesl_module_links_with_wesl_js_and_validates_in_naga_and_tint() {
    if let Some(node) = node_script("wesl-link.mjs", "wesl") {
        link_and_check(node, "wesl-js");
    }
}

/// wesl-py bundles wesl-rs 0.6, the linker Bevy 0.20 runs. It needs Python >= 3.12:
/// `.ci/wesl-py/setup.sh` makes an environment where there is one and prints its python, which
/// CI passes as `LODKIT_WESL_PY` (and then requires it with `LODKIT_REQUIRE_WESL_PY=1`).
#[test]
fn every_wesl_module_links_with_wesl_rs_through_wesl_py() {
    let Some(python) = std::env::var_os("LODKIT_WESL_PY") else {
        let why =
            "LODKIT_WESL_PY is not set (bash .ci/wesl-py/setup.sh prints a python with wesl-py)";
        if std::env::var("LODKIT_REQUIRE_WESL_PY").is_ok_and(|v| v == "1") {
            panic!("LODKIT_REQUIRE_WESL_PY=1 but {why}");
        }
        crate::harness::say(&format!("SKIPPED {}: {why}", crate::harness::test_name()));
        return;
    };
    let mut cmd = std::process::Command::new(python);
    cmd.arg(workspace_root().join(".ci/wesl-py/link.py"));
    link_and_check(cmd, "wesl-py");
}
