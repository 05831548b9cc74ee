//! The npm package of the WESL modules: the committed `shader_lib/wesl/lodkit/` is exactly what
//! `lodkit wesl --npm` writes (a stale or hand-edited file fails), and its manifest and bundle
//! hold what npm and wesl-js need. `integration_tests/webgpu_page.rs` packs, installs, links and
//! runs it in Chromium.

use crate::support::{assert_folder_holds, run_ok, scratch, workspace_root};

const FIX: &str = "regenerate with `cargo run -p lodkit-cli -- wesl --npm shader_lib/wesl/lodkit`";

#[test]
fn committed_npm_package_is_what_the_generator_writes() {
    let dir = workspace_root().join("shader_lib/wesl/lodkit");
    let generated = lodkit_cli::npm::npm_package().expect("every module converts to WESL");
    assert_folder_holds(&dir, &generated, |_| true, FIX);
}

#[test]
fn lodkit_wesl_npm_writes_the_package() {
    let out = scratch("npm");
    let said = run_ok(
        std::process::Command::new(env!("CARGO_BIN_EXE_lodkit"))
            .args(["wesl", "--npm"])
            .arg(&out),
        "lodkit wesl --npm",
    );
    assert!(said.contains("npm package `lodkit`"), "{said}");
    let generated = lodkit_cli::npm::npm_package().unwrap();
    assert_folder_holds(
        &out,
        &generated,
        |_| true,
        "lodkit wesl --npm wrote another package",
    );
}

#[test]
fn manifest_names_every_file_and_the_bundle_every_module() {
    let generated = lodkit_cli::npm::npm_package().unwrap();
    let file = |name: &str| -> &str {
        &generated
            .iter()
            .find(|(p, _)| p == name)
            .unwrap_or_else(|| panic!("no {name}"))
            .1
    };
    let manifest: serde_json::Value = serde_json::from_str(file("package.json")).unwrap();
    assert_eq!(manifest["name"], "lodkit");
    assert_eq!(manifest["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(manifest["type"], "module");
    assert_eq!(manifest["exports"]["."]["import"], "./index.js");
    for keyword in ["WGSL", "WESL", "WebGPU"] {
        assert!(
            manifest["keywords"]
                .as_array()
                .unwrap()
                .iter()
                .any(|k| k == keyword),
            "keyword {keyword}"
        );
    }
    let listed: Vec<&str> = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    // npm adds package.json and README.md by itself; everything else must be listed.
    for (path, _) in &generated {
        assert!(
            listed.contains(&path.as_str()) || path == "package.json" || path == "README.md",
            "package.json's files leave out {path}"
        );
    }
    let bundle = file("index.js");
    for (path, source) in generated.iter().filter(|(p, _)| p.ends_with(".wesl")) {
        let entry = format!(
            "    {}: {},\n",
            serde_json::to_string(path).unwrap(),
            serde_json::to_string(source).unwrap()
        );
        assert!(
            bundle.contains(&entry),
            "index.js does not carry {path} as written"
        );
    }
    assert!(bundle.contains("  name: \"lodkit\",\n  edition: \"unstable_2025\",\n"));
    assert!(bundle.ends_with("export default weslBundle;\n"));
}

#[test]
fn version_names_the_shader_tools() {
    let said = run_ok(
        std::process::Command::new(env!("CARGO_BIN_EXE_lodkit")).arg("--version"),
        "lodkit --version",
    );
    let lock = std::fs::read_to_string(workspace_root().join("Cargo.lock")).unwrap();
    for name in ["naga", "naga_oil", "wesl", "wgpu"] {
        let version = lock
            .split("[[package]]")
            .find_map(|p| {
                let mut lines = p.lines().map(str::trim);
                lines.find(|l| *l == format!("name = \"{name}\""))?;
                lines.next()?.strip_prefix("version = ")
            })
            .unwrap_or_else(|| panic!("{name} is not in Cargo.lock"))
            .trim_matches('"');
        assert!(
            said.contains(&format!("{name} {version}")),
            "`lodkit --version` should name {name} {version}: {said}"
        );
    }
    assert!(
        said.starts_with(&format!("lodkit {}\n", env!("CARGO_PKG_VERSION"))),
        "{said}"
    );
}
