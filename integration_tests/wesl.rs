//! The WESL package: generated from the naga_oil modules and committed up to date, listed by the
//! registry with the paths Bevy 0.20 expects, and linked by wesl-js (npm `wesl`) into WGSL that
//! naga validates and Tint compiles, with every shader def off and on.

use std::collections::BTreeSet;
use std::path::Path;

use lodkit::shaders::{self, Language, ModuleKind, naga};

use crate::composition::{module_harness, wgsl_modules};
use crate::support::{browser_script, node_script, scratch, workspace_root};

/// Every file under `dir`, relative to it, sorted.
fn files_under(dir: &Path, base: &Path, out: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            files_under(&path, base, out);
        } else {
            let rel = path.strip_prefix(base).unwrap().to_string_lossy();
            out.push(rel.replace('\\', "/"));
        }
    }
    out.sort();
}

#[test]
fn committed_wesl_package_is_what_the_generator_writes() {
    let dir = workspace_root().join("shader_lib/wesl");
    let generated = shaders::wesl_package().expect("every module converts to WESL");
    let mut on_disk = Vec::new();
    files_under(&dir, &dir, &mut on_disk);
    let names: Vec<String> = generated.iter().map(|(p, _)| p.clone()).collect();
    let mut sorted = names.clone();
    sorted.sort();
    let fix = "regenerate with `cargo run -p lodkit-cli -- wesl --out shader_lib/wesl`";
    assert_eq!(on_disk, sorted, "files of shader_lib/wesl differ; {fix}");
    for (rel, text) in &generated {
        let committed = std::fs::read_to_string(dir.join(rel)).unwrap();
        assert!(
            committed == *text,
            "shader_lib/wesl/{rel} is stale or was edited by hand; {fix}"
        );
    }
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

#[test]
fn every_wesl_module_links_with_wesl_js_and_validates_in_naga_and_tint() {
    let defs: BTreeSet<String> = shaders::wesl_modules()
        .flat_map(|m| m.shader_defs.iter().map(|d| d.name.clone()))
        .collect();
    assert!(defs.len() >= 2, "the modules read shader defs: {defs:?}");
    let dir = scratch("wesl-link");
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
    let jobs_file = dir.join("jobs.json");
    std::fs::write(&jobs_file, serde_json::to_string(&jobs).unwrap()).unwrap();
    let Some(mut node) = node_script("wesl-link.mjs", "wesl") else {
        return;
    };
    let out = node
        .arg(workspace_root().join("shader_lib/wesl"))
        .arg(&jobs_file)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success(),
        "wesl-js cannot link lodkit's WESL:\n{text}"
    );
    crate::harness::say(&format!("wesl-js: {}", text.trim()));
    std::fs::remove_file(&jobs_file).unwrap();
    for job in &jobs {
        let path = job["out"].as_str().unwrap();
        let wgsl = std::fs::read_to_string(path).unwrap();
        validate(&wgsl, path);
    }
    // Tint (Chromium's WebGPU) compiles the same linked files.
    let Some(mut tint) = browser_script("tint.mjs") else {
        return;
    };
    let out = tint.arg(&dir).output().unwrap();
    assert!(
        out.status.success(),
        "Tint rejects WESL linked by wesl-js:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
