//! Running the examples from the tests. `cargo test` builds every example before the tests run;
//! they sit in `examples/` beside the directory of the test binary.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::SystemTime;

/// The built example `name`.
pub fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let profile = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("tests run from target/<profile>/deps");
    profile
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX))
}

/// Runs example `name` with `args`. Without a GPU adapter it says SKIPPED and returns `None`,
/// unless `LODKIT_REQUIRE_GPU=1` (lodkit's CI), where that fails the test.
pub fn run_example(name: &str, args: &[&OsStr]) -> Option<Output> {
    let path = example(name);
    assert!(
        path.exists(),
        "{} is missing: run `cargo test` (which builds the examples), not only `--test`",
        path.display()
    );
    let built = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
    let sources = newest_source(Path::new(env!("CARGO_MANIFEST_DIR")), &path, name);
    assert!(
        built >= sources,
        "{} is older than the sources: run `cargo test` (which rebuilds the examples), not only \
         `--test`",
        path.display()
    );
    let output = Command::new(&path)
        .args(args)
        .output()
        .expect("run the example");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let strict = std::env::var("LODKIT_REQUIRE_GPU").is_ok_and(|v| v == "1");
    // Bevy's words, or lodkit's where an example opens a device of its own (the impostor's bake).
    let no_gpu = stderr.contains("Unable to find a GPU") || stderr.contains("no GPU adapter found");
    if !output.status.success() && no_gpu && !strict {
        eprintln!("SKIPPED: no GPU adapter (install mesa-vulkan-drivers for lavapipe)");
        return None;
    }
    Some(output)
}

/// Runs example `name` with `--out DIR --report DIR/report.json` in a temporary folder, and
/// returns its report (None where the GPU test is skipped, as [`run_example`] says). Fails the
/// test where the example fails or logs a wgpu validation error.
#[allow(dead_code, reason = "not every test reads a report")]
pub fn example_report(name: &str) -> Option<serde_json::Value> {
    example_report_with(name, &[])
}

/// [`example_report`] with `extra` arguments after `--out` and `--report`.
#[allow(dead_code, reason = "not every test reads a report")]
pub fn example_report_with(name: &str, extra: &[&OsStr]) -> Option<serde_json::Value> {
    let folder = tempfile::Builder::new()
        .prefix(&format!("lodkit-bevy-{name}-"))
        .tempdir()
        .expect("a temporary folder");
    let report = folder.path().join("report.json");
    let args = [
        OsStr::new("--out"),
        folder.path().as_os_str(),
        OsStr::new("--report"),
        report.as_os_str(),
    ];
    let args: Vec<&OsStr> = args.iter().chain(extra).copied().collect();
    let output = run_example(name, &args)?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{name} failed: {stderr}");
    assert!(
        !stderr.contains("Validation Error") && !stderr.contains("wgpu error"),
        "{stderr}"
    );
    let text = std::fs::read_to_string(&report).expect("the report");
    Some(serde_json::from_str(&text).expect("the report is JSON"))
}

/// The newest modification time of the files the example at `path` is built from, as cargo's
/// dep-info file beside it (`<name>.d`) lists them: the same files that make cargo rebuild it,
/// so a test-only module edited since does not count. Without that file: everything under
/// `src/`, `examples/<example>/` and `examples/common/`.
fn newest_source(root: &Path, path: &Path, example: &str) -> Option<SystemTime> {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    if let Ok(info) = std::fs::read_to_string(path.with_extension("d")) {
        let deps = info.split_once(": ").map_or("", |(_, deps)| deps);
        // Make's syntax: spaces separate the files; a space inside a name is escaped.
        let deps = deps.replace("\\ ", "\u{0}");
        return deps
            .split_whitespace()
            .map(|d| PathBuf::from(d.replace('\u{0}', " ")))
            .filter_map(|d| modified(&d))
            .max();
    }
    fn walk(dir: &Path, newest: &mut Option<SystemTime>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, newest);
            } else if let Ok(modified) = entry.metadata().and_then(|m| m.modified()) {
                *newest = (*newest).max(Some(modified));
            }
        }
    }
    let mut newest = None;
    walk(&root.join("src"), &mut newest);
    // The example's own folder and what the examples share: another example's edit does not
    // rebuild this one.
    walk(&root.join("examples").join(example), &mut newest);
    walk(&root.join("examples/common"), &mut newest);
    newest
}

/// Holds one transition run of an example's report (`measure::Figures` as JSON, with the levels
/// each group drew) to what every smooth lodkit transition shows: no background where every
/// level covers, nothing drawn where none does, the levels `drawn`, each pixel changed one way
/// (flicker against the finest level at most 1.1) and a pop at most `share` of switching at
/// once (`hard`).
#[allow(dead_code, reason = "not every test reads a transition")]
pub fn assert_smooth_transition(
    name: &str,
    run: &serde_json::Value,
    drawn: serde_json::Value,
    hard: f64,
    share: f64,
) {
    assert_eq!(run["see_through"], 0, "{name}: {run}");
    assert_eq!(run["ghosts"], 0, "{name}: {run}");
    assert_eq!(run["drawn"], drawn, "{name}: {run}");
    let flicker = run["flicker_vs_fine"].as_f64().unwrap();
    assert!(flicker <= 1.1, "{name}: flicker {flicker}: {run}");
    let pop = run["pop"].as_f64().unwrap();
    assert!(
        pop <= share * hard,
        "{name}: pop {pop} against switching at once {hard}"
    );
}
