//! `lodkit check --stats` and `--budget`: a shader of known cost prints its counts (text and
//! JSON), a budget it exceeds makes the check exit 1 (RON and TOML), one it meets exits 0, and a
//! malformed budget is an error that names the file and the line (exit 2).

use std::collections::{BTreeMap, BTreeSet};

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

/// One loop of a trip count the shader does not fix (`n` comes from a uniform): 1 load counted,
/// for however many the loop makes.
const UNBOUNDED: &[u8] = b"
@group(0) @binding(0) var color: texture_2d<f32>;
@group(0) @binding(1) var<uniform> n: u32;
@fragment
fn fs_main() -> @location(0) vec4<f32> {
    var c = vec4<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        c += textureLoad(color, vec2<u32>(i, 0u), 0);
    }
    return c;
}
";

#[test]
fn a_loop_the_counter_cannot_bound_fails_the_budget_unless_allowed() {
    let dir = fixture(&[
        ("pass.wgsl", UNBOUNDED),
        ("budget.ron", b"{ \"fs_main\": { \"fetches\": 100 } }"),
        (
            "entry.ron",
            b"{ \"fs_main\": { \"fetches\": 100, \"allow_unbounded_loops\": true } }",
        ),
        (
            "global.ron",
            b"{ \"allow_unbounded_loops\": true, \"fs_main\": { \"fetches\": 100 } }",
        ),
        (
            "global.toml",
            b"allow_unbounded_loops = true\n[fs_main]\nfetches = 100\n",
        ),
        (
            "overridden.ron",
            b"{ \"allow_unbounded_loops\": true, \"fs_main\": { \"allow_unbounded_loops\": false } }",
        ),
        ("not_a_flag.ron", b"{ \"fs_main\": { \"allow_unbounded_loops\": 1 } }"),
    ]);
    // 1 fetch counted is far under 100, but the count is no bound: the budget fails.
    let (code, _, stderr) = run(&dir, &["check", "--budget", "budget.ron", "pass.wgsl"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains(
            "error[budget]: pass.wgsl: `fs_main` has 1 loop of unknown trip count (in `fs_main`)"
        ),
        "{stderr}"
    );
    assert!(stderr.contains("allow_unbounded_loops"), "{stderr}");
    let (code, stdout, _) = run(
        &dir,
        &[
            "check",
            "--format",
            "json",
            "--budget",
            "budget.ron",
            "pass.wgsl",
        ],
    );
    assert_eq!(code, 1);
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(doc["within_budget"], false);
    assert_eq!(doc["files"][0]["stats"][0]["unknown_loops"], 1);
    for allowed in ["entry.ron", "global.ron", "global.toml"] {
        let (code, _, stderr) = run(&dir, &["check", "--budget", allowed, "pass.wgsl"]);
        assert_eq!(code, 0, "{allowed}: {stderr}");
    }
    let (code, _, stderr) = run(&dir, &["check", "--budget", "overridden.ron", "pass.wgsl"]);
    assert_eq!(
        code, 1,
        "an entry's own `false` wins over the global: {stderr}"
    );
    let (code, _, stderr) = run(&dir, &["check", "--budget", "not_a_flag.ron", "pass.wgsl"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("`allow_unbounded_loops` is true or false"),
        "{stderr}"
    );
}

/// The shader defs a pass reads: its own and those of the lodkit modules it imports, in the
/// order they are first read.
fn pass_defs(module: &lodkit::shaders::ModuleInfo, defs: &mut Vec<String>) {
    for d in &module.shader_defs {
        if !defs.contains(&d.name) {
            defs.push(d.name.clone());
        }
    }
    for line in module.source.lines() {
        let Some(rest) = line.trim().strip_prefix("#import lodkit::") else {
            continue;
        };
        let topic: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let import = lodkit::shaders::find_module(&format!("lodkit::{topic}"))
            .unwrap_or_else(|| panic!("no module lodkit::{topic}"));
        pass_defs(import, defs);
    }
}

/// A budget key's entry name and the defs it names (`-D NAME` after the name).
fn key_parts(key: &str) -> (&str, BTreeSet<&str>) {
    let mut words = key.split_whitespace();
    let name = words.next().unwrap_or_default();
    (name, words.filter(|w| *w != "-D").collect())
}

/// lodkit's own passes stay within `cli/tests/passes-budget.ron`, the budget CI holds them to,
/// in every shader-def variant: every subset of the defs each pass reads (through the modules
/// it imports too) has its own key, which holds the fetches exactly.
#[test]
fn lodkits_passes_meet_their_budget_in_every_variant() {
    let root = crate::support::workspace_root();
    let budget_path = root.join("cli/tests/passes-budget.ron");
    let budget: BTreeMap<String, BTreeMap<String, serde_json::Value>> =
        ron::from_str(&std::fs::read_to_string(&budget_path).unwrap()).unwrap();
    let passes = root.join("shader_lib/passes");
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(&passes)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 9, "a new pass needs a budget: {files:?}");
    // Per pass, its file name and every subset of its defs.
    let mut variants: Vec<(String, Vec<Vec<String>>, Vec<String>)> = Vec::new();
    for file in &files {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let module = lodkit::shaders::modules()
            .iter()
            .find(|m| m.path == format!("passes/{name}"))
            .unwrap_or_else(|| panic!("{name} is not in the registry"));
        let mut defs = Vec::new();
        pass_defs(module, &mut defs);
        let subsets = (0..1usize << defs.len())
            .map(|bits| {
                (0..defs.len())
                    .filter(|i| bits & (1 << i) != 0)
                    .map(|i| defs[i].clone())
                    .collect()
            })
            .collect();
        variants.push((name, subsets, defs));
    }
    let runs = variants.iter().map(|(_, s, _)| s.len()).max().unwrap();
    // Runs set several passes' defs at once: a def two passes read (a module's, such as the
    // screen-door pattern's) reaches both, so each pass is held to the variant the run's defs
    // make of it. Run `i` sets each pass's `i`-th subset; a variant no such run made of some
    // pass gets a run of its own afterwards, so every variant of every pass is measured.
    assert!(runs > 1, "the passes read shader defs: {variants:?}");
    let mut checked: BTreeSet<(String, Vec<String>)> = BTreeSet::new();
    let check_run = |run_defs: &BTreeSet<String>| -> Vec<(String, Vec<String>)> {
        let mut args = vec![
            "check".to_owned(),
            "--format=json".to_owned(),
            "--budget".to_owned(),
            budget_path.display().to_string(),
        ];
        for d in run_defs {
            args.extend(["-D".to_owned(), d.clone()]);
        }
        let mut expected = Vec::new();
        for ((name, _, all), file) in variants.iter().zip(&files) {
            let defs: Vec<String> = all
                .iter()
                .filter(|d| run_defs.contains(*d))
                .cloned()
                .collect();
            let key = budget
                .iter()
                .find(|(k, _)| {
                    let (entry, key_defs) = key_parts(k);
                    entry
                        .strip_prefix(name.as_str())
                        .is_some_and(|e| e.starts_with(':'))
                        && key_defs == defs.iter().map(String::as_str).collect()
                })
                .unwrap_or_else(|| panic!("no budget key for {name} with {defs:?}"));
            // The entry point the key holds: `fs_main` of the render passes, the compute entry
            // of the selection pass.
            let entry = key_parts(key.0).0.split_once(':').unwrap().1.to_owned();
            let fetches = key.1.get("fetches").and_then(serde_json::Value::as_u64);
            expected.push((
                file.display().to_string(),
                name.clone(),
                defs,
                fetches,
                entry,
            ));
        }
        args.extend(files.iter().map(|f| f.display().to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, stdout, stderr) = run(&root, &args);
        assert_eq!(code, 0, "{args:?}: {stdout}{stderr}");
        assert!(!stderr.contains("warning[budget]"), "{args:?}: {stderr}");
        let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let reported = doc["files"].as_array().unwrap();
        assert_eq!(reported.len(), expected.len(), "{args:?}: a file per pass");
        let mut measured_variants = Vec::new();
        for (path, name, defs, fetches, entry) in expected {
            let file = reported
                .iter()
                .find(|f| f["file"] == path.as_str())
                .unwrap_or_else(|| panic!("{name} is not in the report"));
            let fs = file["stats"]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s["name"] == entry.as_str())
                .unwrap_or_else(|| panic!("{name} has no entry point {entry}"));
            let w = &fs["worst"];
            let measured: u64 = ["texture_loads", "samples", "gathers", "storage_reads"]
                .iter()
                .map(|k| w[k].as_u64().unwrap())
                .sum();
            assert_eq!(
                Some(measured),
                fetches,
                "{name} with {defs:?}: the budget holds fetches exactly"
            );
            measured_variants.push((name, defs));
        }
        measured_variants
    };
    for run_index in 0..runs {
        let run_defs: BTreeSet<String> = variants
            .iter()
            .flat_map(|(_, subsets, _)| subsets[run_index % subsets.len()].clone())
            .collect();
        checked.extend(check_run(&run_defs));
    }
    for (name, subsets, _) in &variants {
        for defs in subsets {
            if !checked.contains(&(name.clone(), defs.clone())) {
                let ran = check_run(&defs.iter().cloned().collect());
                checked.extend(ran);
            }
        }
    }
    for (name, subsets, _) in &variants {
        for defs in subsets {
            assert!(
                checked.contains(&(name.clone(), defs.clone())),
                "{name} with {defs:?} came up in no run"
            );
        }
    }
}
