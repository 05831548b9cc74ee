//! Names the versions of the shader tools the command is built with (naga, naga_oil, wesl, wgpu)
//! for `lodkit --version`: read from the Cargo.lock of the build, the workspace's in the
//! repository or the package's own under `cargo install --locked`.

use std::path::{Path, PathBuf};

#[derive(serde::Deserialize)]
struct Lock {
    #[serde(default)]
    package: Vec<Locked>,
}

#[derive(serde::Deserialize)]
struct Locked {
    name: String,
    version: String,
}

/// The nearest Cargo.lock from the manifest's folder up.
fn find_lock(start: &Path) -> Option<PathBuf> {
    start
        .ancestors()
        .map(|dir| dir.join("Cargo.lock"))
        .find(|lock| lock.is_file())
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let lock = find_lock(&manifest);
    let packages = lock
        .as_ref()
        .and_then(|path| {
            println!("cargo:rerun-if-changed={}", path.display());
            std::fs::read_to_string(path).ok()
        })
        .and_then(|text| toml::from_str::<Lock>(&text).ok())
        .map(|lock| lock.package)
        .unwrap_or_default();
    let versions: Vec<String> = ["naga", "naga_oil", "wesl", "wgpu"]
        .iter()
        .map(|name| {
            let found: Vec<&str> = packages
                .iter()
                .filter(|p| p.name == *name)
                .map(|p| p.version.as_str())
                .collect();
            match found.as_slice() {
                [] => format!("{name} (not in Cargo.lock)"),
                many => format!("{name} {}", many.join(" + ")),
            }
        })
        .collect();
    println!(
        "cargo:rustc-env=LODKIT_TOOL_VERSIONS={}",
        versions.join(", ")
    );
}
