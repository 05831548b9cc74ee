//! Portability: every module and pass of the library, composed to plain WGSL, is accepted by a
//! second WGSL compiler — Tint, inside Chromium's WebGPU — as well as by naga.

use std::collections::BTreeSet;

use lodkit::shaders::{
    self, ComposeDescriptor, ExportOptions, ExportTarget, Exported, ModuleKind, ShaderDefValue,
    ShaderLibrary,
};

use crate::composition::{wgsl_harness, wgsl_modules};
use crate::harness::render;
use crate::support::browser_script;
use crate::support::{run_ok, scratch};

/// Composes `source` with no shader defs and with each of `defs` switched on, exports each
/// variant to plain WGSL and returns the distinct texts.
fn variants(source: &str, file: &str, defs: &BTreeSet<String>) -> Vec<String> {
    let mut library = ShaderLibrary::new().unwrap();
    let on: Vec<Option<&String>> = std::iter::once(None).chain(defs.iter().map(Some)).collect();
    let mut out: Vec<String> = Vec::new();
    for def in on {
        let shader_defs = def
            .map(|d| (d.clone(), ShaderDefValue::Bool(true)))
            .into_iter()
            .collect();
        let composed = library
            .compose(&ComposeDescriptor {
                source,
                file_path: file,
                shader_defs,
                ..Default::default()
            })
            .unwrap_or_else(|e| panic!("{file} ({def:?}) does not compose:\n{}", render(&e)));
        let text = match shaders::export(&composed, ExportTarget::Wgsl, &ExportOptions::default())
            .unwrap_or_else(|e| panic!("{file} ({def:?}): WGSL export failed: {e}"))
        {
            Exported::Text(t) => t,
            Exported::SpirV(_) => unreachable!("WGSL export is text"),
        };
        if !out.contains(&text) {
            out.push(text);
        }
    }
    out
}

#[test]
fn every_module_and_pass_compiles_in_tint() {
    let defs: BTreeSet<String> = shaders::modules()
        .iter()
        .flat_map(|m| m.shader_defs.iter().map(|d| d.name.clone()))
        .collect();
    let dir = scratch("tint");
    std::fs::create_dir_all(&dir).unwrap();
    let mut files = 0;
    let mut write = |name: &str, texts: Vec<String>| {
        for (k, text) in texts.into_iter().enumerate() {
            let file = dir.join(format!("{}-{k}.wgsl", name.replace('/', "_")));
            std::fs::write(file, text).unwrap();
            files += 1;
        }
    };
    for module in wgsl_modules() {
        write(
            module.path,
            variants(&wgsl_harness(module), module.path, &defs),
        );
    }
    for pass in shaders::modules()
        .iter()
        .filter(|m| m.kind == ModuleKind::Pass)
    {
        write(pass.path, variants(pass.source, pass.path, &defs));
    }
    assert!(
        files >= 16,
        "expected every module and pass, wrote {files} files"
    );
    let Some(mut node) = browser_script("tint.mjs") else {
        return;
    };
    let text = run_ok(
        node.arg(&dir),
        &format!("Tint rejects composed lodkit WGSL ({})", dir.display()),
    );
    crate::harness::say(&format!(
        "tint: {}",
        text.lines().last().unwrap_or_default()
    ));
}
