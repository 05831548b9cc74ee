//! `lodkit check --stats` and `--budget`: a shader of known cost prints its counts (text and
//! JSON), a budget it exceeds makes the check exit 1 (RON and TOML), one it meets exits 0, and a
//! malformed budget is an error that names the file and the line (exit 2).

use crate::cli::{fixture, run};

/// Hand-counted: 2 texture loads and 1 sample always; under the branch at most 2 more loads
/// (a loop of 2 trips); 1 storage read in the other branch.
const SHADER: &[u8] = b"
@group(0) @binding(0) var color: texture_2d<f32>;
@group(0) @binding(1) var s: sampler;
@group(0) @binding(2) var<storage, read> weights: array<f32>;
@fragment
fn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    var c = textureLoad(color, vec2<u32>(p.xy), 0) + textureLoad(color, vec2<u32>(0u), 0);
    c += textureSample(color, s, p.xy);
    if c.w > 0.5 {
        for (var i = 0u; i < 2u; i++) {
            c += textureLoad(color, vec2<u32>(i), 0);
        }
    } else {
        c *= weights[0];
    }
    return c;
}
";

#[test]
fn stats_print_the_counts_of_each_entry_point() {
    let dir = fixture(&[("pass.wgsl", SHADER)]);
    let (code, stdout, stderr) = run(&dir, &["check", "--stats", "pass.wgsl"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("fs_main (fragment): 3 fetches (2 texture loads, 1 sample)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("branches add at most 3 fetches (2 texture loads, 1 storage read)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("color @group(0) @binding(0): 2 texture loads + 2 under branches"),
        "{stdout}"
    );
    let (code, stdout, _) = run(&dir, &["check", "--stats", "--format", "json", "pass.wgsl"]);
    assert_eq!(code, 0);
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let fs = &doc["files"][0]["stats"][0];
    assert_eq!(fs["name"], "fs_main");
    assert_eq!(fs["always"]["texture_loads"], 2);
    assert_eq!(fs["always"]["samples"], 1);
    assert_eq!(fs["conditional"]["texture_loads"], 2);
    assert_eq!(fs["conditional"]["storage_reads"], 1);
    assert_eq!(fs["worst"]["texture_loads"], 4);
    assert_eq!(fs["unknown_loops"], 0);
}

#[test]
fn a_shader_over_its_budget_exits_1() {
    let dir = fixture(&[
        ("pass.wgsl", SHADER),
        ("tight.ron", b"{ \"fs_main\": { \"fetches\": 5 } }"),
        (
            "tight.toml",
            b"[\"pass.wgsl:fs_main\"]\ntexture_loads = 3\n",
        ),
        (
            "enough.ron",
            b"{ \"fs_main\": { \"fetches\": 6, \"conditional_fetches\": 3 } }",
        ),
    ]);
    // Worst path: 2 + 2 loads, 1 sample, 1 storage read: 6 fetches, 4 of them loads.
    let (code, _, stderr) = run(&dir, &["check", "--budget", "tight.ron", "pass.wgsl"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains(
            "`fs_main` makes 6 fetches, over its budget of 5 (tight.ron, key \"fs_main\")"
        ),
        "{stderr}"
    );
    let (code, _, stderr) = run(&dir, &["check", "--budget", "tight.toml", "pass.wgsl"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("makes 4 texture loads, over its budget of 3"),
        "{stderr}"
    );
    let (code, stdout, _) = run(
        &dir,
        &[
            "check",
            "--format",
            "json",
            "--budget",
            "tight.toml",
            "pass.wgsl",
        ],
    );
    assert_eq!(code, 1);
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(doc["valid"], true);
    assert_eq!(doc["within_budget"], false);
    let (code, _, stderr) = run(&dir, &["check", "--budget", "enough.ron", "pass.wgsl"]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn a_malformed_budget_names_its_file_and_line() {
    let dir = fixture(&[
        ("pass.wgsl", SHADER),
        ("typo.ron", b"{\n  \"fs_main\": { \"fetchez\": 5 },\n}"),
        (
            "broken.ron",
            b"{\n  \"fs_main\": { \"fetches\": 5 }\n  \"x\": {}\n}",
        ),
        ("budget.txt", b"fs_main 5"),
    ]);
    let (code, _, stderr) = run(&dir, &["check", "--budget", "typo.ron", "pass.wgsl"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("typo.ron: entry \"fs_main\": unknown limit `fetchez`"),
        "{stderr}"
    );
    let (code, _, stderr) = run(&dir, &["check", "--budget", "broken.ron", "pass.wgsl"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("broken.ron:3:"), "{stderr}");
    let (code, _, stderr) = run(&dir, &["check", "--budget", "budget.txt", "pass.wgsl"]);
    assert_eq!(code, 2, "{stderr}");
    let (code, _, stderr) = run(&dir, &["check", "--budget", "missing.ron", "pass.wgsl"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// lodkit's own passes stay within `cli/tests/passes-budget.ron`: the budget CI holds them to.
#[test]
fn lodkits_passes_meet_their_budget() {
    let root = crate::support::workspace_root();
    let mut args = vec![
        "check".to_owned(),
        "--budget".to_owned(),
        root.join("cli/tests/passes-budget.ron")
            .display()
            .to_string(),
    ];
    let passes = root.join("shader_lib/passes");
    let mut files: Vec<String> = std::fs::read_dir(&passes)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| p.ends_with(".wgsl"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 6, "a new pass needs a budget: {files:?}");
    args.extend(files);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, stderr) = run(&root, &args);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("warning[budget]"), "{stderr}");
}
