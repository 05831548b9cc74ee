//! The GitHub Action (action.yml, its script scripts/check-action.sh) and the pre-commit hook
//! (.pre-commit-hooks.yaml) run on a small shader tree with the `lodkit` built here on PATH.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::cli::fixture;
use crate::support::{Scratch, workspace_root};

const GOOD: &[u8] = b"#import my::tone::tone

@fragment
fn main() -> @location(0) vec4<f32> {
    return vec4<f32>(tone(0.5));
}
";

const MODULE: &[u8] = b"#define_import_path my::tone

fn tone(x: f32) -> f32 {
    return x * x;
}
";

/// The function's `{` is missing: a parse error at the `return`, line 3, column 5 (after four
/// spaces).
const BAD: &[u8] = b"@fragment
fn main() -> @location(0) vec4<f32>
    return vec4<f32>(1.0);
}
";

/// shaders/ (one good, one broken in a subfolder), modules/ with the good one's import.
fn tree() -> Scratch {
    fixture(&[
        ("shaders/good.wgsl", GOOD),
        ("shaders/post/bad.wgsl", BAD),
        ("modules/tone.wgsl", MODULE),
        ("budget.ron", b"{ \"main\": { \"alu\": 100 } }"),
    ])
}

/// PATH with the `lodkit` under test first.
fn path_with_lodkit() -> String {
    let bin = Path::new(env!("CARGO_BIN_EXE_lodkit")).parent().unwrap();
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

/// Runs the action's script in `dir` with the inputs `env` (LODKIT_* variables).
fn action(dir: &Path, env: &[(&str, &str)]) -> (i32, String, String) {
    let script: PathBuf = workspace_root().join("scripts/check-action.sh");
    let mut cmd = Command::new("bash");
    cmd.arg(script)
        .current_dir(dir)
        .env("PATH", path_with_lodkit());
    for key in [
        "LODKIT_PATHS",
        "LODKIT_INCLUDE",
        "LODKIT_DEFS",
        "LODKIT_BUDGET",
        "LODKIT_CAPABILITIES",
        "LODKIT_PERMUTE",
        "LODKIT_PERMUTATIONS",
        "LODKIT_MAX_SETS",
        "LODKIT_FORMAT",
        "LODKIT_OUTPUT",
        "LODKIT_ARGS",
    ] {
        cmd.env_remove(key);
    }
    cmd.envs(env.iter().copied());
    let out = cmd.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn action_annotates_the_broken_shader_of_a_tree() {
    let dir = tree();
    let (code, stdout, stderr) = action(
        &dir,
        &[
            ("LODKIT_PATHS", "shaders/**/*.wgsl"),
            ("LODKIT_INCLUDE", "modules"),
            ("LODKIT_DEFS", "A\nB=3"),
            ("LODKIT_BUDGET", "budget.ron"),
        ],
    );
    assert_eq!(code, 1, "{stderr}");
    assert_eq!(
        stdout,
        "::error file=shaders/post/bad.wgsl,line=3,col=5,title=lodkit parse::expected `{`, \
         found \"return\" (shader defs {A, B=3})\n",
        "{stderr}"
    );
    assert!(stderr.contains("(2 files)"), "{stderr}");
}

#[test]
fn action_checks_the_permutation_tree_under_its_declared_sets() {
    let dir = workspace_root().join("cli/tests/permute_tree");
    let (code, stdout, stderr) = action(
        &dir,
        &[
            ("LODKIT_PATHS", "shaders/**/*.wgsl"),
            ("LODKIT_INCLUDE", "modules"),
            ("LODKIT_PERMUTATIONS", "lodkit-permutations.toml"),
        ],
    );
    assert_eq!(code, 1, "{stderr}");
    // The three broken shaders, each with the shortest set that breaks it (cli/tests/
    // permutations.rs derives them); the material and the prepass pass all 27 of theirs.
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    for (line, (file, shortest)) in lines.iter().zip([
        ("type_mismatch", "{PACKED, TONEMAP}"),
        ("unsubstituted", "{SHADOWS}"),
        ("uv_outside_ifdef", "{ALPHA_MASK}"),
    ]) {
        assert!(
            line.starts_with(&format!("::error file=shaders/broken/{file}.wgsl,")),
            "{line}"
        );
        assert!(
            line.ends_with(&format!("shortest failing set {shortest})")),
            "{line}"
        );
    }
    assert!(stderr.contains("under 150 shader-def sets"), "{stderr}");
}

#[test]
fn action_passes_a_clean_tree_and_writes_sarif_to_a_file() {
    let dir = tree();
    std::fs::remove_file(dir.join("shaders/post/bad.wgsl")).unwrap();
    let (code, stdout, stderr) = action(
        &dir,
        &[
            ("LODKIT_PATHS", "shaders/**/*.wgsl"),
            ("LODKIT_INCLUDE", "modules"),
            ("LODKIT_FORMAT", "sarif"),
            ("LODKIT_OUTPUT", "lodkit.sarif"),
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout, "");
    let log: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("lodkit.sarif")).unwrap()).unwrap();
    assert_eq!(log["version"], "2.1.0");
    assert_eq!(log["runs"][0]["results"], serde_json::json!([]));
}

#[test]
fn action_fails_on_a_glob_that_matches_nothing_and_on_no_paths() {
    let dir = tree();
    let (code, _, stderr) = action(&dir, &[("LODKIT_PATHS", "shaders/**/*.wesl")]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("no file matches `shaders/**/*.wesl`"),
        "{stderr}"
    );
    let (code, _, stderr) = action(&dir, &[("LODKIT_PATHS", " \n ")]);
    assert_eq!(code, 2);
    assert!(stderr.contains("names no shader"), "{stderr}");
    // A usage error from lodkit itself (a def that is not one) passes through as 2.
    let (code, _, stderr) = action(
        &dir,
        &[
            ("LODKIT_PATHS", "shaders/good.wgsl"),
            ("LODKIT_DEFS", "A=x"),
        ],
    );
    assert_eq!(code, 2, "{stderr}");
}

#[test]
fn action_yml_passes_every_input_to_its_script() {
    let root = workspace_root();
    let yml = std::fs::read_to_string(root.join("action.yml")).unwrap();
    let script = std::fs::read_to_string(root.join("scripts/check-action.sh")).unwrap();
    let inputs_block = &yml[yml.find("\ninputs:\n").unwrap()..yml.find("\nruns:\n").unwrap()];
    let inputs: Vec<&str> = inputs_block
        .lines()
        .filter_map(|l| l.strip_prefix("  ")?.strip_suffix(':'))
        .filter(|name| !name.starts_with(' '))
        .collect();
    assert!(inputs.len() >= 10, "{inputs:?}");
    let runs = &yml[yml.find("\nruns:\n").unwrap()..];
    for name in &inputs {
        assert!(
            runs.contains(&format!("${{{{ inputs.{name} }}}}"))
                || runs.contains(&format!("inputs.{name} ==")),
            "input `{name}` is not used by a step"
        );
    }
    // Each LODKIT_* variable the check step sets is one the script reads.
    for line in runs.lines() {
        if let Some((var, _)) = line.trim().split_once(": ${{ inputs.") {
            if var == "LODKIT_VERSION" {
                assert!(runs.contains("${LODKIT_VERSION:+--version"));
                continue;
            }
            assert!(script.contains(&format!("${{{var}")), "{var} unread");
        }
    }
    assert!(runs.contains("cargo install --locked lodkit-cli"));
    assert!(runs.contains("bash \"$GITHUB_ACTION_PATH/scripts/check-action.sh\""));
}

/// The hook's `entry` and `files` from .pre-commit-hooks.yaml.
fn hook() -> (String, Vec<String>) {
    let text = std::fs::read_to_string(workspace_root().join(".pre-commit-hooks.yaml")).unwrap();
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.trim().strip_prefix(&format!("{name}: ")))
            .unwrap_or_else(|| panic!("the hook has no `{name}`"))
            .to_owned()
    };
    // `files: \.(a|b|c)$`: the extensions the hook runs on.
    let files = field("files");
    let extensions = files
        .strip_prefix(r"\.(")
        .and_then(|f| f.strip_suffix(")$"))
        .unwrap_or_else(|| panic!("files `{files}` is not \\.(ext|...)$"))
        .split('|')
        .map(|e| format!(".{e}"))
        .collect();
    (field("entry"), extensions)
}

/// Runs the hook's entry as pre-commit does, the staged files appended.
fn run_hook(dir: &Path, args: &[&str], files: &[&str]) -> (i32, String) {
    let (entry, extensions) = hook();
    let chosen: Vec<&str> = files
        .iter()
        .copied()
        .filter(|f| extensions.iter().any(|e| f.ends_with(e.as_str())))
        .collect();
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!("{entry} \"$@\""))
        .arg("hook")
        .args(args)
        .args(&chosen)
        .current_dir(dir)
        .env("PATH", path_with_lodkit())
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn pre_commit_hook_checks_the_staged_shaders() {
    let dir = tree();
    std::fs::write(dir.join("README.md"), "not a shader").unwrap();
    let staged = ["README.md", "shaders/good.wgsl", "shaders/post/bad.wgsl"];
    let (code, stderr) = run_hook(&dir, &["-I", "modules"], &staged);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("shaders/post/bad.wgsl:3:5"), "{stderr}");
    assert!(
        stderr.contains("checked 2 files: 1 valid, 1 invalid"),
        "{stderr}"
    );
    let (code, stderr) = run_hook(&dir, &["-I", "modules"], &staged[..2]);
    assert_eq!(code, 0, "{stderr}");
}
