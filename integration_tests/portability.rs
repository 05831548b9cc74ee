//! Portability: every module and pass of the library, composed to plain WGSL, is accepted by a
//! second WGSL compiler — Tint, inside Chromium's WebGPU — as well as by naga; and what wgpu's GL
//! backend writes for a downlevel context (GLSL 3.30 core, GLSL ES 3.00) compiles with
//! glslangValidator.

use std::collections::BTreeSet;

use lodkit::shaders::{
    self, ComposeDescriptor, Composed, ExportOptions, ExportTarget, Exported, ModuleKind,
    ShaderDefValue, ShaderLibrary,
};

use crate::composition::{wgsl_harness, wgsl_modules};
use crate::harness::{render, tool};
use crate::support::browser_script;
use crate::support::{run_ok, scratch};

/// `source` composed with no shader defs and with each of `defs` switched on.
fn composed_variants(source: &str, file: &str, defs: &BTreeSet<String>) -> Vec<Composed> {
    let mut library = ShaderLibrary::new().unwrap();
    let on: Vec<Option<&String>> = std::iter::once(None).chain(defs.iter().map(Some)).collect();
    on.into_iter()
        .map(|def| {
            let shader_defs = def
                .map(|d| (d.clone(), ShaderDefValue::Bool(true)))
                .into_iter()
                .collect();
            library
                .compose(&ComposeDescriptor {
                    source,
                    file_path: file,
                    shader_defs,
                    ..Default::default()
                })
                .unwrap_or_else(|e| panic!("{file} ({def:?}) does not compose:\n{}", render(&e)))
        })
        .collect()
}

/// Composes `source` with no shader defs and with each of `defs` switched on, exports each
/// variant to plain WGSL and returns the distinct texts.
fn variants(source: &str, file: &str, defs: &BTreeSet<String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for composed in composed_variants(source, file, defs) {
        let text = match shaders::export(&composed, ExportTarget::Wgsl, &ExportOptions::default())
            .unwrap_or_else(|e| panic!("{file}: WGSL export failed: {e}"))
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
    let defs = all_defs();
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

/// Every shader def any module reads.
fn all_defs() -> BTreeSet<String> {
    shaders::modules()
        .iter()
        .flat_map(|m| m.shader_defs.iter().map(|d| d.name.clone()))
        .collect()
}

/// Each vertex and fragment entry point of `composed` as naga's GLSL back end writes it for
/// `version` with the options wgpu's GL backend uses (no binding points below GLSL 4.20 and
/// GLSL ES 3.10: wgpu binds by name there), with the glslangValidator stage name.
fn downlevel_glsl(
    composed: &Composed,
    version: naga::back::glsl::Version,
) -> Vec<(String, String)> {
    use naga::back::glsl;
    let options = glsl::Options {
        version,
        writer_flags: glsl::WriterFlags::ADJUST_COORDINATE_SPACE
            | glsl::WriterFlags::FORCE_POINT_SIZE,
        ..Default::default()
    };
    let mut out = Vec::new();
    for entry in &composed.module.entry_points {
        let stage = match entry.stage {
            naga::ShaderStage::Vertex => "vert",
            naga::ShaderStage::Fragment => "frag",
            // Compute needs GLSL 4.30 / GLSL ES 3.10: lodkit refuses it below (GpuCapabilities).
            _ => continue,
        };
        let pipeline = glsl::PipelineOptions {
            shader_stage: entry.stage,
            entry_point: entry.name.clone(),
            multiview: None,
        };
        let mut text = String::new();
        glsl::Writer::new(
            &mut text,
            &composed.module,
            &composed.info,
            &options,
            &pipeline,
            naga::proc::BoundsCheckPolicies::default(),
        )
        .and_then(|mut w| w.write())
        .unwrap_or_else(|e| panic!("naga cannot write {} as {version:?}: {e}", entry.name));
        out.push((stage.to_owned(), text));
    }
    out
}

/// GL 3.3 and GLES 3.0 / WebGL2 contexts get GLSL 3.30 and GLSL ES 3.00 from wgpu: every vertex
/// and fragment stage of every module and pass, in every shader-def variant, must compile there.
/// (naga writes a `select` with a vector condition as `mix(a, b, bvec)`, which these versions
/// have for float vectors only: the library keeps such selects to floats.)
#[test]
fn every_module_and_pass_compiles_as_glsl_330_and_glsl_es_300() {
    use naga::back::glsl::Version;
    let defs = all_defs();
    let mut sources: Vec<(String, &str)> = Vec::new();
    for module in wgsl_modules() {
        sources.push((wgsl_harness(module), module.path));
    }
    for pass in shaders::modules()
        .iter()
        .filter(|m| m.kind == ModuleKind::Pass)
    {
        sources.push((pass.source.to_owned(), pass.path));
    }
    let dir = scratch("glsl");
    std::fs::create_dir_all(&dir).unwrap();
    let mut files: Vec<(std::path::PathBuf, String, String)> = Vec::new();
    let mut seen = BTreeSet::new();
    for (source, path) in &sources {
        for composed in composed_variants(source, path, &defs) {
            for (version, tag) in [
                (Version::Desktop(330), "330"),
                (Version::new_gles(300), "es300"),
            ] {
                for (stage, text) in downlevel_glsl(&composed, version) {
                    if !seen.insert(text.clone()) {
                        continue;
                    }
                    let name = format!("{}-{tag}-{}.{stage}", path.replace('/', "_"), seen.len());
                    let file = dir.join(name);
                    std::fs::write(&file, &text).unwrap();
                    files.push((file, stage, path.to_string()));
                }
            }
        }
    }
    assert!(
        files.len() >= 40,
        "expected every stage of every module and pass, wrote {}",
        files.len()
    );
    for (file, stage, path) in &files {
        let Some(mut cmd) = tool("glslangValidator") else {
            return;
        };
        let out = cmd.args(["-S", stage]).arg(file).output().unwrap();
        assert!(
            out.status.success(),
            "{path}: wgpu's GL backend would hand the driver GLSL it rejects ({}):\n{}\n{}",
            file.display(),
            String::from_utf8_lossy(&out.stdout),
            std::fs::read_to_string(file).unwrap()
        );
    }
    crate::harness::say(&format!(
        "glsl 330 / es 300: {} distinct stages compile",
        files.len()
    ));
}
