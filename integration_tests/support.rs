//! What every lodkit test crate shares (the library's integration tests and the CLI's): one
//! headless device, the skip rules, scratch folders and the headless-browser scripts.
//!
//! GPU tests start with `lodkit_test_gpu!()`. Without an adapter they fail when
//! `LODKIT_REQUIRE_GPU=1`, and otherwise return early after writing a SKIPPED line straight to
//! stderr (past the test harness's capture), so a skip is never silent. Browser checks follow the
//! same rule with `LODKIT_REQUIRE_BROWSER=1`. A device that lacks a capability the test needs
//! ([`Needs`]: lodkit's passes, or compute shaders) skips the test with a line that names the
//! capability, whatever `LODKIT_REQUIRE_GPU` says: such a device is no failure of the test.

#![allow(dead_code, unused_macros)] // each test crate uses its own part

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use lodkit::gpu::{GpuContext, GpuOptions};

/// The workspace root (where `shader_lib/` and `.ci/` are), from either package.
pub fn workspace_root() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    if here.join("shader_lib").is_dir() {
        here.to_path_buf()
    } else {
        here.parent()
            .expect("a package folder has a parent")
            .to_path_buf()
    }
}

/// Fails unless the files under `dir` that `keep` selects are exactly `generated` ((path, text)
/// pairs): none missing, none extra, none stale or edited by hand. `fix` says how to regenerate.
pub fn assert_folder_holds(
    dir: &Path,
    generated: &[(String, String)],
    keep: impl Fn(&str) -> bool,
    fix: &str,
) {
    let on_disk: Vec<String> = files_under(dir).into_iter().filter(|f| keep(f)).collect();
    let mut names: Vec<String> = generated.iter().map(|(p, _)| p.clone()).collect();
    names.sort();
    assert_eq!(on_disk, names, "files of {} differ; {fix}", dir.display());
    for (rel, text) in generated {
        let written = std::fs::read_to_string(dir.join(rel)).unwrap();
        assert!(
            written == *text,
            "{} is stale or was edited by hand; {fix}",
            dir.join(rel).display()
        );
    }
}

/// Every file under `dir`, as `/`-separated paths relative to it, sorted.
pub fn files_under(dir: &Path) -> Vec<String> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, root, out);
            } else {
                let rel = path.strip_prefix(root).unwrap().to_string_lossy();
                out.push(rel.replace('\\', "/"));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Runs `cmd` and returns its stdout and stderr; fails the test, showing both, unless it exits 0.
pub fn run_ok(cmd: &mut std::process::Command, what: &str) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{what}:\n{text}");
    text
}

/// A path inside a fresh temporary folder, which is removed with everything in it when the
/// `Scratch` is dropped (also when the test fails), so test runs leave nothing behind.
pub struct Scratch {
    folder: tempfile::TempDir,
    path: PathBuf,
}

impl Scratch {
    /// The new empty folder itself.
    pub fn folder() -> Self {
        let folder = tempfile::Builder::new()
            .prefix("lodkit-test-")
            .tempdir()
            .expect("a temporary folder");
        let path = folder.path().to_path_buf();
        Scratch { folder, path }
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.path.as_os_str()
    }
}

/// The path `name` inside a fresh temporary folder (nothing is created at `name` itself).
pub fn scratch(name: &str) -> Scratch {
    let mut scratch = Scratch::folder();
    scratch.path = scratch.folder.path().join(name);
    scratch
}

/// Whether missing GPU or reference tools are failures (`LODKIT_REQUIRE_GPU=1`, as CI sets it).
pub fn strict() -> bool {
    std::env::var("LODKIT_REQUIRE_GPU").is_ok_and(|v| v == "1")
}

/// Writes past libtest's output capture, so the line shows in a normal `cargo test` run.
pub fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

pub fn test_name() -> String {
    std::thread::current()
        .name()
        .unwrap_or("a GPU test")
        .to_owned()
}

/// The shared GPU, or why there is none.
pub fn gpu() -> Result<&'static GpuContext, String> {
    static GPU: OnceLock<Result<GpuContext, String>> = OnceLock::new();
    let gpu = GPU.get_or_init(|| {
        // Timestamps inside encoders where the adapter has them: the demo's timers read them.
        let options = GpuOptions {
            optional_features: wgpu::Features::TIMESTAMP_QUERY
                | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS,
            ..Default::default()
        };
        let gpu = GpuContext::new_headless(&options).map_err(|e| e.to_string());
        if let Ok(g) = &gpu {
            say(&format!("lodkit GPU tests run on: {}", g.adapter_summary()));
        }
        gpu
    });
    gpu.as_ref().map_err(Clone::clone)
}

/// On wgpu's GL backend, GPU tests run one at a time: each takes this lock in `gpu_or_skip` and
/// holds it until its thread ends. lodkit's own calls pass through the context's GL gate, but
/// the tests also drive the device directly (probes, fixtures), and a GL driver can hold wgpu's
/// GL context lock for seconds (a cold shader link): another test waiting in that lock would
/// panic after 6 s. `gl_threads` tests what lodkit promises to threads sharing a GL device.
static GL_TESTS: std::sync::Mutex<()> = std::sync::Mutex::new(());

thread_local! {
    /// The calling GPU test's hold of [`GL_TESTS`], released when the test's thread ends. (Only
    /// the lock: wgpu cannot be called from a thread-local destructor, its own thread-locals
    /// may be gone by then.)
    static GL_TEST_HOLD: std::cell::RefCell<Option<std::sync::MutexGuard<'static, ()>>> =
        const { std::cell::RefCell::new(None) };
}

/// Serializes the calling test with the other GPU tests when the device is GL (see
/// [`GL_TESTS`]); already held when this thread has it.
fn serialize_on_gl(gpu: &GpuContext) {
    if gpu.adapter.get_info().backend != wgpu::Backend::Gl {
        return;
    }
    GL_TEST_HOLD.with(|hold| {
        let mut hold = hold.borrow_mut();
        if hold.is_none() {
            *hold = Some(
                GL_TESTS
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner),
            );
        }
    });
}

/// The shared GPU; with none, panics under `LODKIT_REQUIRE_GPU=1`, else returns `None` after
/// saying the calling test was skipped.
pub fn gpu_or_skip() -> Option<&'static GpuContext> {
    match gpu() {
        Ok(g) => {
            serialize_on_gl(g);
            Some(g)
        }
        Err(e) if strict() => panic!("LODKIT_REQUIRE_GPU=1 but there is no GPU adapter: {e}"),
        Err(e) => {
            say(&format!(
                "SKIPPED {}: {e}. Set LODKIT_REQUIRE_GPU=1 to make this a failure",
                test_name()
            ));
            None
        }
    }
}

/// What a GPU test needs of the device besides an adapter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Needs {
    /// Nothing more: probes without textures of their own, tests that look at the device's
    /// capabilities themselves.
    Device,
    /// lodkit's passes: pipelines with several textures and uniform buffers
    /// (`GpuCapabilities::binding_layout`).
    Passes,
    /// Compute shaders for the thing under test itself (GPU selection).
    Compute,
}

/// Why `gpu` cannot run a test that needs `needs`; `None` when it can.
pub fn lacks(gpu: &GpuContext, needs: Needs) -> Option<String> {
    let caps = gpu.capabilities();
    let missing = match needs {
        Needs::Device => None,
        Needs::Passes => (!caps.binding_layout).then_some("SHADER_BINDING_LAYOUT"),
        Needs::Compute => (!caps.compute_shaders()).then_some("COMPUTE_SHADERS"),
    }?;
    Some(format!("the device lacks {missing} ({caps})"))
}

/// The shared GPU when it has what the test needs; otherwise `None` after saying the calling test
/// was skipped and why (a missing adapter is a failure under `LODKIT_REQUIRE_GPU=1`).
pub fn gpu_for(needs: Needs) -> Option<&'static GpuContext> {
    let gpu = gpu_or_skip()?;
    match lacks(gpu, needs) {
        None => Some(gpu),
        Some(why) => {
            say(&format!("SKIPPED {}: {why}", test_name()));
            None
        }
    }
}

/// The shared GPU, or return from the test (see [`gpu_for`]): `lodkit_test_gpu!()` for a test
/// that renders through lodkit's passes, `lodkit_test_gpu!(device)` for one that needs only a
/// device (a probe without textures of its own), `lodkit_test_gpu!(compute)` for one that needs
/// compute shaders.
macro_rules! lodkit_test_gpu {
    () => {
        lodkit_test_gpu!(passes)
    };
    (passes) => {
        lodkit_test_gpu!(@ $crate::support::Needs::Passes)
    };
    (device) => {
        lodkit_test_gpu!(@ $crate::support::Needs::Device)
    };
    (compute) => {
        lodkit_test_gpu!(@ $crate::support::Needs::Compute)
    };
    (@ $needs:expr) => {
        match $crate::support::gpu_for($needs) {
            Some(gpu) => gpu,
            None => return,
        }
    };
}

/// `node .ci/browser/<script>` ready to take arguments, when node and the npm `package` the
/// script needs (`npm ci --prefix .ci/browser`) are installed. Otherwise fails under
/// `LODKIT_REQUIRE_BROWSER=1` (CI sets it) and skips loudly.
pub fn node_script(script: &str, package: &str) -> Option<std::process::Command> {
    let dir = workspace_root().join(".ci/browser");
    let node = std::process::Command::new("node")
        .arg("--version")
        .output()
        .is_ok();
    let missing = if !node {
        Some("node is not installed".to_owned())
    } else if !dir.join("node_modules").join(package).exists() {
        Some(format!(
            "npm package `{package}` is not installed (npm ci --prefix .ci/browser)"
        ))
    } else {
        None
    };
    match missing {
        None => {
            let mut cmd = std::process::Command::new("node");
            cmd.arg(dir.join(script));
            Some(cmd)
        }
        Some(why) => skip_browser(&why),
    }
}

fn skip_browser(why: &str) -> Option<std::process::Command> {
    if std::env::var("LODKIT_REQUIRE_BROWSER").is_ok_and(|v| v == "1") {
        panic!("LODKIT_REQUIRE_BROWSER=1 but {why}")
    }
    say(&format!(
        "SKIPPED {}: {why}. Set LODKIT_REQUIRE_BROWSER=1 to make this a failure",
        test_name()
    ));
    None
}

/// `node .ci/browser/<script>` ready to take arguments, when node, the scripts' npm packages and
/// Chromium are installed. Otherwise fails under `LODKIT_REQUIRE_BROWSER=1` (CI sets it) and
/// skips loudly.
pub fn browser_script(script: &str) -> Option<std::process::Command> {
    let chromium = std::env::var_os("LODKIT_CHROMIUM")
        .map_or_else(|| "/usr/bin/chromium".into(), std::path::PathBuf::from);
    if !chromium.exists() {
        return skip_browser("Chromium is not installed (apt-get install chromium)");
    }
    node_script(script, "playwright-core")
}
