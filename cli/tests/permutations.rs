//! `lodkit check --permute` and `--permutations FILE` on the Bevy-style tree in
//! cli/tests/permute_tree: three shaders with a bug that shows under one def combination only
//! pass in their default configuration and fail with that combination named, and reduced to
//! the shortest set that still fails; the tree's permutation file declares the sets of its
//! material and prepass, which pass under every one of them. Every count below is derived by
//! hand from the shaders' `#ifdef`s and the permutation file.

use std::path::PathBuf;

use crate::cli::{fixture, run};

fn tree() -> PathBuf {
    crate::support::workspace_root().join("cli/tests/permute_tree")
}

const BROKEN: [&str; 3] = [
    "shaders/broken/type_mismatch.wgsl",
    "shaders/broken/unsubstituted.wgsl",
    "shaders/broken/uv_outside_ifdef.wgsl",
];

fn json(args: &[&str]) -> (i32, serde_json::Value, String) {
    let mut all = vec!["check", "--format", "json", "-I", "modules"];
    all.extend_from_slice(args);
    let (code, stdout, stderr) = run(&tree(), &all);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let doc = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}\n{stderr}"));
    (code, doc, stderr)
}

/// (file, line, column, kind, first failing set, failing sets, sets, shortest failing set) of
/// each file's one failure.
type Failure = (String, u64, u64, String, Vec<String>, u64, u64, Vec<String>);

fn failures(doc: &serde_json::Value) -> Vec<Failure> {
    let strings = |v: &serde_json::Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_owned())
            .collect()
    };
    doc["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["valid"] == false)
        .map(|f| {
            let d = &f["diagnostics"][0];
            assert_eq!(f["diagnostics"].as_array().unwrap().len(), 1, "{f:#}");
            (
                f["file"].as_str().unwrap().to_owned(),
                d["line"].as_u64().unwrap(),
                d["column"].as_u64().unwrap(),
                d["kind"].as_str().unwrap().to_owned(),
                strings(&d["defs"]),
                d["failing_sets"].as_u64().unwrap(),
                f["sets"].as_u64().unwrap(),
                strings(&d["shortest_failing_defs"]),
            )
        })
        .collect()
}

fn v(items: &[&str]) -> Vec<String> {
    items.iter().map(|s| s.to_string()).collect()
}

#[test]
fn the_broken_shaders_pass_in_their_default_configuration() {
    let mut args = vec!["check", "-I", "modules"];
    args.extend(BROKEN);
    let (code, stdout, stderr) = run(&tree(), &args);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout.matches("ok: ").count(), 3, "{stdout}");
}

#[test]
fn permute_names_the_one_combination_each_bug_needs() {
    let mut args = vec!["--permute"];
    args.extend(BROKEN);
    let (code, doc, stderr) = json(&args);
    assert_eq!(code, 1, "{stderr}");
    // type_mismatch tests PACKED and TONEMAP: 4 sets, only both on fails, at `v = v * 0.5;`.
    // unsubstituted tests SHADOWS (MAX_CASCADES_PER_LIGHT has no value to vary): 2 sets.
    // uv_outside_ifdef tests ALPHA_MASK, VERTEX_UVS and, through sample::mesh_types, SKINNED:
    // 8 sets; ALPHA_MASK without VERTEX_UVS fails, SKINNED either way: 2 sets.
    assert_eq!(
        failures(&doc),
        [
            (
                BROKEN[0].into(),
                11,
                5,
                "parse".into(),
                v(&["PACKED", "TONEMAP"]),
                1,
                4,
                v(&["PACKED", "TONEMAP"])
            ),
            (
                BROKEN[1].into(),
                7,
                20,
                "preprocessor".into(),
                v(&["SHADOWS"]),
                1,
                2,
                v(&["SHADOWS"])
            ),
            (
                BROKEN[2].into(),
                13,
                15,
                "parse".into(),
                v(&["ALPHA_MASK"]),
                2,
                8,
                v(&["ALPHA_MASK"])
            ),
        ]
    );
    // naga sees a stray `#` where the def has no value: the diagnostic says which def.
    assert_eq!(
        doc["files"][1]["diagnostics"][0]["message"],
        "shader def `MAX_CASCADES_PER_LIGHT` has no value here, so `#{MAX_CASCADES_PER_LIGHT}` \
         is left in the source"
    );
    assert_eq!(doc["sets_checked"], 14);
    assert!(
        stderr.contains("checked 3 files under 14 shader-def sets: 0 valid, 3 invalid"),
        "{stderr}"
    );
}

#[test]
fn the_permutation_file_declares_the_sets_of_the_tree() {
    let mut args = vec![
        "--permutations",
        "lodkit-permutations.toml",
        "shaders/pbr.wgsl",
        "shaders/prepass.wgsl",
    ];
    args.extend(BROKEN);
    let (code, doc, stderr) = json(&args);
    assert_eq!(code, 1, "{stderr}");
    // Entry 1: 2 pipelines x 2^5 optional = 64; MORPH_TARGETS without SKINNED goes (48 left),
    // ALPHA_MASK without VERTEX_UVS goes (36), PREPASS_PIPELINE with SHADOWS goes (27).
    for f in &doc["files"].as_array().unwrap()[..2] {
        assert_eq!(f["valid"], true, "{f:#}");
        assert_eq!(f["sets"], 27, "{f:#}");
    }
    // Entry 2: 2^5 = 32 sets each; PACKED and TONEMAP both on in 8, SHADOWS on in 16,
    // ALPHA_MASK on and VERTEX_UVS off in 8.
    let got = failures(&doc);
    let counts: Vec<(u64, u64, Vec<String>)> =
        got.iter().map(|f| (f.5, f.6, f.7.clone())).collect();
    assert_eq!(
        counts,
        [
            (8, 32, v(&["PACKED", "TONEMAP"])),
            (16, 32, v(&["SHADOWS"])),
            (8, 32, v(&["ALPHA_MASK"])),
        ]
    );
    assert_eq!(doc["sets_checked"], 27 + 27 + 3 * 32);
    // The entry leaves MAX_CASCADES_PER_LIGHT unset, and says so.
    assert!(
        stderr.contains(
            "note: shaders/broken/unsubstituted.wgsl tests defs its permutation-file entry \
             leaves out (never set): MAX_CASCADES_PER_LIGHT"
        ),
        "{stderr}"
    );
}

#[test]
fn the_same_sets_in_ron_give_the_same_verdicts() {
    let ron = br#"(shaders: [(
        files: ["shaders/pbr.wgsl", "shaders/prepass.wgsl"],
        one_of: [["MESH_PIPELINE", "PREPASS_PIPELINE"]],
        optional: ["VERTEX_UVS", "ALPHA_MASK", "SHADOWS", "SKINNED", "MORPH_TARGETS"],
        values: {"MAX_LIGHTS": 8, "MAX_CASCADES_PER_LIGHT": 4},
        requires: {"MORPH_TARGETS": ["SKINNED"], "ALPHA_MASK": ["VERTEX_UVS"]},
        excludes: [["PREPASS_PIPELINE", "SHADOWS"]],
    )])"#;
    let dir = fixture(&[("sets.ron", ron)]);
    let file = dir.join("sets.ron");
    let shaders = tree().join("shaders");
    let (pbr, prepass) = (shaders.join("pbr.wgsl"), shaders.join("prepass.wgsl"));
    // The globs are relative to the permutation file: point it at the tree by copying.
    std::fs::create_dir_all(dir.join("shaders")).unwrap();
    std::fs::copy(&pbr, dir.join("shaders/pbr.wgsl")).unwrap();
    std::fs::copy(&prepass, dir.join("shaders/prepass.wgsl")).unwrap();
    let modules = tree().join("modules");
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "check",
            "--format=json",
            "-I",
            modules.to_str().unwrap(),
            "--permutations",
            file.to_str().unwrap(),
            "shaders/pbr.wgsl",
            "shaders/prepass.wgsl",
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(doc["sets_checked"], 54);
}

#[test]
fn past_max_sets_every_pair_is_covered_and_the_pair_bug_is_still_found() {
    let mut args = vec![
        "--permutations",
        "lodkit-permutations.toml",
        "--max-sets",
        "10",
    ];
    args.extend(BROKEN);
    let (code, doc, stderr) = json(&args);
    assert_eq!(code, 1, "{stderr}");
    let files = doc["files"].as_array().unwrap();
    for f in files {
        let sets = f["sets"].as_u64().unwrap();
        assert!(sets < 32, "{f:#}");
        let said = f["sets_described"].as_str().unwrap();
        assert!(said.contains("of 32 combinations"), "{said}");
        assert!(said.contains("every pair of them"), "{said}");
    }
    // Each bug needs at most two defs on: pairwise sets still find all three, and the shortest
    // failing sets are the same as with all 32 sets.
    let shortest: Vec<Vec<String>> = failures(&doc).into_iter().map(|f| f.7).collect();
    assert_eq!(
        shortest,
        [
            v(&["PACKED", "TONEMAP"]),
            v(&["SHADOWS"]),
            v(&["ALPHA_MASK"])
        ]
    );
}

/// `sample::shading` defines `shade` under FAST and `shade_slow` otherwise; the shader calls
/// the one its defs select. SECOND_TEXTURE binds a second texture at a taken slot, which only
/// naga's validator rejects. UNUSED_A and UNUSED_B change nothing.
const SHADING: &[u8] = b"#define_import_path sample::shading

#ifdef FAST
fn shade(x: f32) -> f32 {
    return x;
}
#else
fn shade_slow(x: f32) -> f32 {
    return x * 0.5;
}
#endif
";

const SWITCHING: &[u8] = b"#import sample::shading

@group(0) @binding(0) var t: texture_2d<f32>;
@group(0) @binding(1) var s: sampler;
#ifdef SECOND_TEXTURE
@group(0) @binding(0) var second: texture_2d<f32>;
#endif

@fragment
fn main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
#ifdef FAST
    var c = vec4<f32>(shading::shade(uv.x));
#else
    var c = vec4<f32>(shading::shade_slow(uv.x));
#endif
    c *= textureSample(t, s, uv);
#ifdef SECOND_TEXTURE
    c += textureSample(second, s, uv);
#endif
#ifdef UNUSED_A
#endif
#ifdef UNUSED_B
#endif
    return c;
}
";

#[test]
fn identical_modules_are_validated_once_and_no_set_gets_another_sets_module() {
    // Two copies: the second starts with FAST off right after the first ended with it on, so
    // an imported module cached across sets would be the wrong one in both directions.
    let dir = fixture(&[
        ("mods/shading.wgsl", SHADING),
        ("a.wgsl", SWITCHING),
        ("b.wgsl", SWITCHING),
    ]);
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "check",
            "--format=json",
            "-I",
            "mods",
            "--permute",
            "a.wgsl",
            "b.wgsl",
        ],
    );
    assert_eq!(code, 1, "{stderr}");
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    for (f, name) in doc["files"]
        .as_array()
        .unwrap()
        .iter()
        .zip(["a.wgsl", "b.wgsl"])
    {
        // 16 sets; every set with FAST off calls shade_slow, with FAST on shade: a stale
        // sample::shading would fail one of them with an unknown function. Only the 8 sets
        // with SECOND_TEXTURE fail, in validation, at the second binding (line 6).
        assert_eq!(f["sets"], 16);
        let diags = f["diagnostics"].as_array().unwrap();
        assert_eq!(diags.len(), 1, "{f:#}");
        assert_eq!(diags[0]["kind"], "validation");
        assert_eq!(diags[0]["file"], name);
        assert_eq!(diags[0]["line"], 6);
        assert_eq!(diags[0]["failing_sets"], 8);
        assert_eq!(
            diags[0]["shortest_failing_defs"],
            serde_json::json!(["SECOND_TEXTURE"])
        );
    }
    // The module depends on FAST and SECOND_TEXTURE only: 4 distinct modules, validated once
    // each; the 16 + 16 sets and the 2 reductions (dropping SECOND_TEXTURE) reuse the rest.
    assert_eq!(doc["modules_validated"], 4);
    assert!(
        stderr.contains("4 distinct modules validated, 30 reused"),
        "{stderr}"
    );
}

#[test]
fn a_bad_permutation_file_is_an_error_that_names_it() {
    let dir = fixture(&[
        (
            "p.toml",
            b"[[shaders]]\nfiles = [\"*.wgsl\"]\none_of = [[\"A\"]]\n",
        ),
        (
            "q.toml",
            b"[[shaders]]\nfiles = [\"*.wgsl\"]\noptional = 3\n",
        ),
        ("r.ron", b"(shaders: [(files: [\"*.wgsl\"], optionl: [])])"),
        ("a.wgsl", b"@fragment fn main() {}\n"),
    ]);
    let cases = [
        (
            "p.toml",
            "p.toml: shaders entry 1: one_of group [\"A\"] needs two defs or more",
        ),
        ("q.toml", "q.toml:3:"),
        ("r.ron", "r.ron:1:"),
    ];
    for (file, want) in cases {
        let (code, _, stderr) = run(&dir, &["check", "--permutations", file, "a.wgsl"]);
        assert_eq!(code, 2, "{file}: {stderr}");
        assert!(stderr.contains(want), "{file}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

/// Two texture loads, and one more under EXTRA (hand-counted).
const LOADS: &[u8] = b"@group(0) @binding(0) var t: texture_2d<f32>;
@fragment
fn fs_main() -> @location(0) vec4<f32> {
    var c = textureLoad(t, vec2<u32>(0u), 0) + textureLoad(t, vec2<u32>(1u), 0);
#ifdef EXTRA
    c += textureLoad(t, vec2<u32>(2u), 0);
#endif
    return c;
}
";

#[test]
fn budget_holds_each_set_and_names_the_set_over_it() {
    let dir = fixture(&[
        ("loads.wgsl", LOADS),
        ("budget.ron", b"{ \"fs_main\": { \"texture_loads\": 2 } }"),
        (
            "variants.ron",
            b"{ \"fs_main\": { \"texture_loads\": 2 }, \"fs_main -D EXTRA\": { \"texture_loads\": 3 } }",
        ),
    ]);
    let (code, _, stderr) = run(
        &dir,
        &["check", "--permute", "--budget", "budget.ron", "loads.wgsl"],
    );
    assert_eq!(code, 1, "{stderr}");
    let over: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("error[budget]"))
        .collect();
    assert_eq!(over.len(), 1, "{stderr}");
    assert!(
        over[0].contains("makes 3 texture loads, over its budget of 2"),
        "{stderr}"
    );
    assert!(over[0].ends_with("under shader defs {EXTRA}"), "{stderr}");
    // A key for the EXTRA variant holds that set only.
    let (code, stdout, stderr) = run(
        &dir,
        &[
            "check",
            "--permute",
            "--stats",
            "--budget",
            "variants.ron",
            "loads.wgsl",
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("  shader defs {}:\n"), "{stdout}");
    assert!(stdout.contains("  shader defs {EXTRA}:\n"), "{stdout}");
}

/// The permutation file `scripts/check-bevy-tree.sh` uses (Bevy's shaders are not in the
/// repository) reads: a misspelt key or a bad value fails the load with exit 2. Its globs match
/// nothing here, so the shader is checked as with --permute.
#[test]
fn bevy_permutation_file_loads() {
    let file = crate::support::workspace_root().join("cli/tests/bevy/permutations-0.19.toml");
    let shader =
        "@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(1.0);\n}\n";
    let dir = fixture(&[("s.wgsl", shader.as_bytes())]);
    let (code, _, err) = run(
        &dir,
        &["check", "--permutations", file.to_str().unwrap(), "s.wgsl"],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("checked 1 file under 1 shader-def set"),
        "{err}"
    );
}
