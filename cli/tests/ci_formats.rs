//! `lodkit check --format sarif` and `--format github`: the SARIF log validates against the
//! SARIF 2.1.0 JSON schema and names each failure's rule, place and shader defs; the workflow
//! commands are exact for hand-made broken shaders; neither panics on closed pipes.

use std::path::PathBuf;
use std::process::Stdio;

use crate::cli::{fixture, lodkit, run};

/// A parse error at line 3, column 18 (4 spaces and `let x = 1.0 +` are 17 characters).
const SYNTAX: &[u8] = b"@fragment\nfn main() -> @location(0) vec4<f32> {\n    let x = 1.0 +;\n    return vec4<f32>(x);\n}\n";

/// An unknown import at line 1, column 9 (after `#import `).
const UNKNOWN_IMPORT: &[u8] = b"#import lodkit::no_such_module::f\n@fragment\nfn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }\n";

/// Two texture loads: over a budget of one.
const TWO_LOADS: &[u8] = b"@group(0) @binding(0) var t: texture_2d<f32>;
@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return textureLoad(t, vec2<u32>(0u), 0) + textureLoad(t, vec2<u32>(1u), 0);
}
";

const GOOD: &[u8] = b"@fragment\nfn main() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }\n";

/// The SARIF 2.1.0 schema that serde-sarif's types are generated from (the OASIS schema, in
/// draft-07 form), read from the package cargo fetched: `cargo metadata` says where it is.
fn sarif_schema() -> serde_json::Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let out = std::process::Command::new(cargo)
        .current_dir(crate::support::workspace_root())
        .args(["metadata", "--format-version", "1", "--locked"])
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let manifest = meta["packages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "serde-sarif")
        .expect("serde-sarif is in the workspace's tree")["manifest_path"]
        .as_str()
        .unwrap()
        .to_owned();
    let schema = PathBuf::from(manifest).with_file_name("src/schema.json");
    let text = std::fs::read_to_string(&schema).unwrap();
    // Two `language` patterns end `{2}]?$`: a lone `]` is a literal in ECMA-262's non-Unicode
    // regexes, which the schema's own meta-schema check (format `regex`, Unicode mode) rejects.
    // Escaping it keeps the meaning and lets the schema compile.
    let text = text.replace(r#"{2}]?$"#, r#"{2}\\]?$"#);
    let schema: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        schema["title"],
        "Static Analysis Results Format (SARIF) Version 2.1.0 JSON Schema"
    );
    schema
}

fn assert_valid_sarif(doc: &serde_json::Value) {
    let validator = jsonschema::options()
        .should_validate_formats(true)
        .build(&sarif_schema())
        .expect("the SARIF schema compiles");
    let errors: Vec<String> = validator
        .iter_errors(doc)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect();
    assert!(errors.is_empty(), "not SARIF 2.1.0: {errors:#?}\n{doc:#}");
}

#[test]
fn sarif_validates_against_the_2_1_0_schema_and_names_rule_place_and_defs() {
    let dir = fixture(&[
        ("bad syntax.wgsl", SYNTAX),
        ("unknown.wgsl", UNKNOWN_IMPORT),
        ("loads.wgsl", TWO_LOADS),
        ("good.wgsl", GOOD),
        ("budget.ron", b"{ \"fs_main\": { \"texture_loads\": 1 } }"),
    ]);
    let args = [
        "check",
        "--format",
        "sarif",
        "-D",
        "B=3",
        "-D",
        "A",
        "--budget",
        "budget.ron",
        "bad syntax.wgsl",
        "unknown.wgsl",
        "loads.wgsl",
        "good.wgsl",
        "missing.wgsl",
    ];
    let (code, stdout, stderr) = run(&dir, &args);
    assert_eq!(code, 2, "a file is missing: {stderr}");
    let doc: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON document");
    assert_valid_sarif(&doc);

    let run = &doc["runs"][0];
    let rules: Vec<&str> = run["tool"]["driver"]["rules"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["id"].as_str().unwrap())
        .collect();
    let results = run["results"].as_array().unwrap();
    let got: Vec<(&str, &str, Option<i64>, Option<i64>)> = results
        .iter()
        .map(|r| {
            let loc = &r["locations"][0]["physicalLocation"];
            (
                r["ruleId"].as_str().unwrap(),
                loc["artifactLocation"]["uri"].as_str().unwrap(),
                loc["region"]["startLine"].as_i64(),
                loc["region"]["startColumn"].as_i64(),
            )
        })
        .collect();
    assert_eq!(
        got,
        [
            ("parse", "bad%20syntax.wgsl", Some(3), Some(18)),
            ("unknown-import", "unknown.wgsl", Some(1), Some(9)),
            ("budget", "loads.wgsl", None, None),
            ("io", "missing.wgsl", None, None),
        ]
    );
    for r in results {
        let index = r["ruleIndex"].as_u64().unwrap() as usize;
        assert_eq!(rules[index], r["ruleId"], "ruleIndex points at its rule");
        assert_eq!(r["level"], "error");
        let text = r["message"]["text"].as_str().unwrap();
        assert!(text.ends_with("(shader defs {A, B=3})"), "{text}");
        assert_eq!(
            r["properties"]["shaderDefs"],
            serde_json::json!(["A", "B=3"])
        );
    }
    // One rule per kind of error, each id once.
    let mut unique = rules.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), rules.len(), "{rules:?}");
}

#[test]
fn sarif_of_a_clean_run_has_no_results() {
    let dir = fixture(&[("good.wgsl", GOOD)]);
    let (code, stdout, stderr) = run(&dir, &["check", "--format=sarif", "good.wgsl"]);
    assert_eq!(code, 0, "{stderr}");
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_valid_sarif(&doc);
    assert_eq!(doc["runs"][0]["results"], serde_json::json!([]));
}

#[test]
fn github_prints_one_workflow_command_per_error() {
    let dir = fixture(&[
        ("bad.wgsl", SYNTAX),
        ("odd, name.wgsl", SYNTAX),
        ("unknown.wgsl", UNKNOWN_IMPORT),
        ("good.wgsl", GOOD),
    ]);
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "check",
            "--format",
            "github",
            "-D",
            "LODKIT_REVERSE_Z",
            "bad.wgsl",
            "odd, name.wgsl",
            "good.wgsl",
            "unknown.wgsl",
        ],
    );
    assert_eq!(code, 1, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    assert_eq!(
        lines[0],
        "::error file=bad.wgsl,line=3,col=18,title=lodkit parse::expected expression, \
         found \";\" (shader defs {LODKIT_REVERSE_Z})"
    );
    // `,` and `:` in a property are escaped.
    assert_eq!(
        lines[1],
        "::error file=odd%2C name.wgsl,line=3,col=18,title=lodkit parse::expected expression, \
         found \";\" (shader defs {LODKIT_REVERSE_Z})"
    );
    assert!(
        lines[2].starts_with(
            "::error file=unknown.wgsl,line=1,col=9,title=lodkit unknown-import::unknown import \
             `lodkit::no_such_module`"
        ),
        "{}",
        lines[2]
    );
    assert!(
        lines[2].ends_with("(shader defs {LODKIT_REVERSE_Z})"),
        "{}",
        lines[2]
    );
}

#[test]
fn formats_survive_closed_stdout_and_stderr() {
    let dir = fixture(&[("bad.wgsl", SYNTAX), ("good.wgsl", GOOD)]);
    for format in ["human", "json", "sarif", "github"] {
        let args = [
            "check",
            "--format",
            format,
            "--stats",
            "good.wgsl",
            "bad.wgsl",
        ];
        let (want, _, _) = run(&dir, &args);
        assert_eq!(want, 1, "{format}");
        // Both pipes have lost their reader before the command starts: every write fails.
        let (out_reader, out_writer) = std::io::pipe().unwrap();
        let (err_reader, err_writer) = std::io::pipe().unwrap();
        drop((out_reader, err_reader));
        let status = lodkit()
            .current_dir(&dir)
            .args(args)
            .stdout(Stdio::from(out_writer))
            .stderr(Stdio::from(err_writer))
            .status()
            .unwrap();
        assert_eq!(status.code(), Some(want), "{format}: 101 is a panic");
    }
}
