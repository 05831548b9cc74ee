//! A reader that stops early (`lodkit check --stats shader_lib/passes/*.wgsl | head -1`) is no
//! crash for any subcommand: what is left to print is dropped and the command exits as it would
//! have with the whole output read (never 101, the code of a panic, and no panic on stderr).

use std::io::BufRead as _;
use std::path::Path;
use std::process::Stdio;

use crate::cli::{fixture, lodkit, run};

/// Runs `lodkit args` in `dir`, reads `lines` lines of its stdout (0: none), then closes the
/// pipe. Returns the exit code and stderr.
fn run_closing_early(dir: &Path, args: &[&str], lines: usize) -> (i32, String) {
    let mut child = lodkit()
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = std::io::BufReader::new(child.stdout.take().unwrap());
    for _ in 0..lines {
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        assert!(
            !line.is_empty(),
            "{args:?}: stdout ended before line {lines}"
        );
    }
    drop(stdout);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code().unwrap_or(-1), stderr)
}

/// The command exits as it does when its whole output is read, and does not panic.
fn assert_pipe_safe(dir: &Path, args: &[&str], lines: usize) {
    let (want, _, _) = run(dir, args);
    let (code, stderr) = run_closing_early(dir, args, lines);
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    assert_ne!(code, 101, "{args:?}: {stderr}");
    assert_eq!(code, want, "{args:?}: {stderr}");
}

fn passes() -> Vec<String> {
    let dir = crate::support::workspace_root().join("shader_lib/passes");
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| p.ends_with(".wgsl"))
        .collect();
    files.sort();
    files
}

#[test]
fn check_survives_a_reader_that_stops_early() {
    // Human output: one line read, then each later file's lines meet a closed pipe.
    let files = passes();
    let mut args = vec!["check", "--stats"];
    args.extend(files.iter().map(String::as_str));
    assert_pipe_safe(Path::new("."), &args, 1);
    // JSON: one document at the end, printed after the pipe closed.
    args.insert(1, "--format=json");
    assert_pipe_safe(Path::new("."), &args, 0);
}

#[test]
fn modules_survives_a_reader_that_stops_early() {
    assert_pipe_safe(Path::new("."), &["modules"], 1);
    assert_pipe_safe(Path::new("."), &["modules", "--format", "json"], 0);
}

#[test]
fn export_to_stdout_survives_a_reader_that_stops_early() {
    let good = b"@fragment fn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }\n";
    let dir = fixture(&[("good.wgsl", good)]);
    assert_pipe_safe(&dir, &["export", "--to", "wgsl", "good.wgsl", "-o", "-"], 0);
    assert_pipe_safe(&dir, &["export", "--to", "spv", "good.wgsl", "-o", "-"], 0);
}

#[test]
fn wesl_survives_a_reader_that_stops_early() {
    let dir = fixture(&[]);
    assert_pipe_safe(&dir, &["wesl", "--out", "pkg"], 0);
}

#[test]
fn adapter_survives_a_reader_that_stops_early() {
    // Exits 0 with an adapter and 1 without one; either way as it does with the output read.
    assert_pipe_safe(Path::new("."), &["adapter"], 0);
}

#[test]
fn demo_survives_a_reader_that_stops_early() {
    // The demo's first line comes before it reads its scene; a missing scene then exits 2.
    let dir = fixture(&[]);
    assert_pipe_safe(&dir, &["demo", "--scene", "missing.ron", "--out", "out"], 0);
}
