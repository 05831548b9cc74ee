//! Every module and pass of the library composes, validates, exports through every back end, and
//! passes the independent tools (spirv-val, glslangValidator); the GLSL twins match the WGSL
//! modules name for name.

use std::path::Path;

use lodkit::shaders::{
    self, ComposeDescriptor, Composed, ExportOptions, ExportTarget, Exported, Language, ModuleInfo,
    ModuleKind, ShaderDefValue, ShaderLibrary, SourceLanguage,
};

use crate::harness::{render, tool};
use crate::support::{files_under, scratch, workspace_root};

pub(crate) fn wgsl_modules() -> impl Iterator<Item = &'static ModuleInfo> {
    shaders::modules()
        .iter()
        .filter(|m| m.language == Language::Wgsl && m.kind == ModuleKind::Module)
}

/// Splits a parameter list at top-level commas (generic arguments contain commas too).
fn params(signature: &str) -> Vec<(String, String)> {
    let open = signature.find('(').unwrap();
    let close = signature.rfind(')').unwrap();
    let (mut depth, mut start, mut out) = (0, open + 1, Vec::new());
    let inner_end = close;
    for (i, c) in signature.char_indices().take(inner_end).skip(open + 1) {
        match c {
            '<' | '(' => depth += 1,
            '>' | ')' => depth -= 1,
            ',' if depth == 0 => {
                out.push(signature[start..i].to_owned());
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(signature[start..inner_end].to_owned());
    out.into_iter()
        .filter(|p| !p.trim().is_empty())
        .map(|p| {
            let (name, ty) = p.split_once(':').expect("typed parameter");
            (name.trim().to_owned(), ty.trim().to_owned())
        })
        .collect()
}

/// A fragment shader that imports `module` and calls every function it exports (textures as
/// bindings, other arguments zero-valued), in naga_oil WGSL or in WESL.
pub(crate) fn module_harness(module: &ModuleInfo, wesl: bool) -> String {
    let path = module.import_path.as_deref().unwrap();
    // naga_oil: `#import lodkit::t` and qualified calls; WESL: an import list and plain names.
    let prefix = if wesl {
        String::new()
    } else {
        format!("{path}::")
    };
    let mut items: Vec<String> = Vec::new();
    let mut globals = String::new();
    let mut calls = String::new();
    for (i, f) in module.functions.iter().enumerate() {
        let mut args = Vec::new();
        for (j, (_, ty)) in params(&f.signature).into_iter().enumerate() {
            if ty.starts_with("texture") || ty.starts_with("sampler") {
                let binding = i * 8 + j;
                globals.push_str(&format!(
                    "@group(0) @binding({binding}) var g{binding}: {ty};\n"
                ));
                args.push(format!("g{binding}"));
            } else if module.source.contains(&format!("struct {ty} ")) {
                args.push(format!("{prefix}{ty}()"));
                if !items.contains(&ty) {
                    items.push(ty.clone());
                }
            } else {
                args.push(format!("{ty}()"));
            }
        }
        items.push(f.name.clone());
        let call = format!("{prefix}{}({})", f.name, args.join(", "));
        if f.signature.contains("->") {
            calls.push_str(&format!("    _ = {call};\n"));
        } else {
            calls.push_str(&format!("    {call};\n"));
        }
    }
    let import = if wesl {
        format!("import {path}::{{{}}};", items.join(", "))
    } else {
        format!("#import {path}")
    };
    format!(
        "{import}\n{globals}\n@fragment\nfn lodkit_harness() -> @location(0) vec4<f32> {{\n{calls}    return vec4<f32>(0.0);\n}}\n"
    )
}

/// [`module_harness`] in naga_oil WGSL.
pub(crate) fn wgsl_harness(module: &ModuleInfo) -> String {
    module_harness(module, false)
}

fn compose(source: &str, file: &str, language: SourceLanguage) -> Composed {
    ShaderLibrary::new()
        .unwrap()
        .compose(&ComposeDescriptor {
            source,
            file_path: file,
            language,
            ..Default::default()
        })
        .unwrap_or_else(|e| panic!("{file} does not compose:\n{}\n{source}", render(&e)))
}

/// Exports to every back end (GLSL once per entry point); SPIR-V goes through spirv-val.
fn export_everywhere(composed: &Composed, what: &str) {
    for target in ExportTarget::ALL {
        let entries: Vec<Option<String>> = if target.one_entry_point() {
            composed
                .module
                .entry_points
                .iter()
                .map(|e| Some(e.name.clone()))
                .collect()
        } else {
            vec![None]
        };
        for entry in entries {
            let out = shaders::export(
                composed,
                target,
                &ExportOptions {
                    entry_point: entry.clone(),
                },
            )
            .unwrap_or_else(|e| panic!("{what}: export to {target} ({entry:?}) failed: {e}"));
            match out {
                Exported::Text(t) => assert!(!t.trim().is_empty(), "{what}: empty {target}"),
                Exported::SpirV(words) => spirv_val(&words, what),
            }
        }
    }
}

fn spirv_val(words: &[u32], what: &str) {
    assert_eq!(words.first(), Some(&0x0723_0203), "{what}: SPIR-V magic");
    let Some(mut cmd) = tool("spirv-val") else {
        return;
    };
    let path = scratch("module.spv");
    std::fs::write(&path, Exported::SpirV(words.to_vec()).to_bytes()).unwrap();
    let out = cmd.arg(&path).output().unwrap();
    assert!(
        out.status.success(),
        "{what}: spirv-val rejects the SPIR-V export:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn every_file_under_shader_lib_is_embedded() {
    let mut on_disk = files_under(&workspace_root().join("shader_lib"));
    // Shaders only: the WESL package's manifest is `shaders::WESL_TOML`, and the npm files
    // beside it (package.json, the bundle, README, licences) are the CLI's `npm_package()`.
    on_disk.retain(|p| [".wgsl", ".glsl", ".wesl"].iter().any(|e| p.ends_with(e)));
    on_disk.sort();
    let mut embedded: Vec<String> = shaders::modules()
        .iter()
        .map(|m| m.path.to_owned())
        .collect();
    embedded.sort();
    assert_eq!(on_disk, embedded);
}

#[test]
fn every_wgsl_module_composes_validates_and_exports() {
    let mut count = 0;
    for module in wgsl_modules() {
        let harness = wgsl_harness(module);
        let composed = compose(&harness, module.path, SourceLanguage::Wgsl);
        export_everywhere(&composed, module.path);
        count += 1;
    }
    assert!(count >= 2, "expected the library's modules, found {count}");
}

#[test]
fn every_pass_composes_validates_and_exports() {
    let passes: Vec<_> = shaders::modules()
        .iter()
        .filter(|m| m.kind == ModuleKind::Pass)
        .collect();
    assert!(!passes.is_empty());
    for pass in passes {
        let composed = compose(pass.source, pass.path, SourceLanguage::Wgsl);
        assert!(
            !composed.module.entry_points.is_empty(),
            "{}: no entry point",
            pass.path
        );
        export_everywhere(&composed, pass.path);
        // And with each of its shader defs switched on.
        for def in &pass.shader_defs {
            let composed = ShaderLibrary::new()
                .unwrap()
                .compose(&ComposeDescriptor {
                    source: pass.source,
                    file_path: pass.path,
                    shader_defs: [(def.name.clone(), ShaderDefValue::Bool(true))].into(),
                    ..Default::default()
                })
                .unwrap_or_else(|e| panic!("{} with {}:\n{}", pass.path, def.name, render(&e)));
            export_everywhere(&composed, &format!("{} with {}", pass.path, def.name));
        }
    }
}

fn glsl_harness(twin: &ModuleInfo) -> String {
    // A twin's hook functions (under `LODKIT_<TOPIC>_HOOKS`) are switched on: every function is
    // compiled, its hooks declared and not called.
    let include = twin.include_path.as_deref().unwrap();
    let topic = include
        .trim_start_matches("lodkit/")
        .trim_end_matches(".glsl")
        .to_ascii_uppercase();
    let hooks = format!("LODKIT_{topic}_HOOKS");
    let switch = if twin.source.contains(&format!("#ifdef {hooks}")) {
        format!("#define {hooks}\n")
    } else {
        String::new()
    };
    format!(
        "#version 450\n#extension GL_GOOGLE_include_directive : require\n{switch}#include \"{include}\"\nlayout(location = 0) out vec4 lodkit_color;\nvoid main() {{ lodkit_color = vec4(0.0); }}\n",
    )
}

/// Compiles a fragment shader with glslangValidator (lodkit's GLSL folder on the include path)
/// and returns the SPIR-V words, failing the test with glslang's output when it rejects it.
fn glslang_spirv(name: &str, source: &str, what: &str) -> Vec<u32> {
    let include_root = Path::new(env!("CARGO_MANIFEST_DIR")).join("shader_lib/glsl");
    let frag = scratch(name);
    std::fs::write(&frag, source).unwrap();
    let spv = frag.with_extension("spv");
    let out = std::process::Command::new("glslangValidator")
        .args(["-V", "-S", "frag"])
        .arg(format!("-I{}", include_root.display()))
        .arg(&frag)
        .arg("-o")
        .arg(&spv)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{what}: glslangValidator rejects it:\n{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let bytes = std::fs::read(&spv).unwrap();
    bytes
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn every_glsl_twin_compiles_with_glslang_and_passes_spirv_val() {
    let Some(_) = tool("glslangValidator") else {
        return;
    };
    for twin in shaders::modules()
        .iter()
        .filter(|m| m.language == Language::Glsl)
    {
        let words = glslang_spirv("harness.frag", &glsl_harness(twin), twin.path);
        spirv_val(&words, twin.path);
    }
}

#[test]
fn every_glsl_twin_composes_through_naga() {
    for twin in shaders::modules()
        .iter()
        .filter(|m| m.language == Language::Glsl)
    {
        let composed = compose(
            &glsl_harness(twin),
            "harness.frag",
            SourceLanguage::Glsl(naga::ShaderStage::Fragment),
        );
        let names: Vec<&str> = composed
            .module
            .functions
            .iter()
            .filter_map(|(_, f)| f.name.as_deref())
            .collect();
        // Macros (GLSL twins that take textures) leave no function behind; the GPU tests use them.
        for f in twin
            .functions
            .iter()
            .filter(|f| !f.signature.starts_with("#define"))
        {
            assert!(
                names.contains(&f.name.as_str()),
                "{}: {} missing after compose",
                twin.path,
                f.name
            );
        }
    }
}

#[test]
fn glsl_twins_match_wgsl_modules_name_for_name() {
    for module in wgsl_modules() {
        let twin = shaders::glsl_twin(module)
            .unwrap_or_else(|| panic!("{} has no GLSL twin", module.path));
        let want: Vec<String> = module
            .functions
            .iter()
            .map(|f| format!("lodkit_{}", f.name))
            .collect();
        let got: Vec<String> = twin.functions.iter().map(|f| f.name.clone()).collect();
        assert_eq!(got, want, "functions of {} vs {}", twin.path, module.path);
        let want: Vec<String> = module
            .constants
            .iter()
            .map(|c| format!("LODKIT_{c}"))
            .collect();
        assert_eq!(
            twin.constants, want,
            "constants of {} vs {}",
            twin.path, module.path
        );
        let defs = |m: &ModuleInfo| {
            m.shader_defs
                .iter()
                .map(|d| d.name.clone())
                .collect::<Vec<_>>()
        };
        assert_eq!(
            defs(twin),
            defs(module),
            "shader defs of {} vs {}",
            twin.path,
            module.path
        );
    }
}

#[test]
fn every_wgsl_function_has_a_rust_twin_of_the_same_name() {
    for module in wgsl_modules() {
        let topic = module
            .import_path
            .as_deref()
            .unwrap()
            .trim_start_matches("lodkit::");
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut rust =
            std::fs::read_to_string(src.join(format!("{topic}.rs"))).unwrap_or_else(|_| {
                panic!(
                    "src/{topic}.rs (the Rust twins of {}) is missing",
                    module.path
                )
            });
        // A topic's file may keep some twins in files of its folder (src/<topic>/*.rs).
        if let Ok(dir) = std::fs::read_dir(src.join(topic)) {
            for entry in dir.flatten() {
                rust.push_str(&std::fs::read_to_string(entry.path()).unwrap_or_default());
            }
        }
        for f in &module.functions {
            assert!(
                rust.contains(&format!("pub fn {}(", f.name)),
                "src/{topic}.rs (or src/{topic}/) has no twin of {}",
                f.name
            );
        }
    }
}

#[test]
fn every_shader_file_documents_itself() {
    for m in shaders::modules() {
        let header: String = m
            .source
            .lines()
            .take_while(|l| l.starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        assert!(
            header.contains("Shader defs:"),
            "{}: header has no `Shader defs:` line",
            m.path
        );
        let section = if m.kind == ModuleKind::Pass {
            "Entry points:"
        } else {
            "Exports:"
        };
        assert!(
            header.contains(section),
            "{}: header has no `{section}` section",
            m.path
        );
        assert!(
            !m.summary.is_empty(),
            "{}: header has no summary line",
            m.path
        );
        for f in &m.functions {
            assert!(
                !f.doc.is_empty(),
                "{}: `{}` has no /// doc comment",
                m.path,
                f.name
            );
            assert!(
                header.contains(&f.name),
                "{}: header does not list `{}`",
                m.path,
                f.name
            );
        }
        for d in &m.shader_defs {
            assert!(
                !d.doc.is_empty(),
                "{}: shader def {} is not documented in the header",
                m.path,
                d.name
            );
        }
    }
}

#[test]
fn add_to_composer_lets_a_foreign_composer_import_lodkit() {
    let mut composer = naga_oil::compose::Composer::default();
    shaders::add_to_composer(&mut composer).unwrap();
    // Adding twice is harmless (an engine may call it from several plugins).
    shaders::add_to_composer(&mut composer).unwrap();
    let module = composer
        .make_naga_module(naga_oil::compose::NagaModuleDescriptor {
            source: "#import lodkit::normal_distance::foreshortened_normal_distance\n\
                     #import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}\n\
                     @vertex fn vs(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }\n\
                     @fragment fn fs(v: FullscreenVertex) -> @location(0) vec4<f32> {\n\
                       return vec4<f32>(foreshortened_normal_distance(vec3(v.uv, 1.0), vec3(0.0, 0.0, 1.0)));\n}\n",
            file_path: "engine.wgsl",
            ..Default::default()
        })
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
    assert_eq!(module.entry_points.len(), 2);
}

#[test]
fn rust_uniform_mirrors_match_the_wgsl_layout() {
    use lodkit_scenes::lod_buffer::{LodCameraUniform, LodDrawUniform};
    use lodkit_scenes::mesh::{CameraUniform, DrawUniform};
    let mirrors: [(&str, &str, usize); 4] = [
        ("lod_mesh", "Camera", std::mem::size_of::<CameraUniform>()),
        ("lod_mesh", "Draw", std::mem::size_of::<DrawUniform>()),
        (
            "lod_buffer_mesh",
            "LodCamera",
            std::mem::size_of::<LodCameraUniform>(),
        ),
        (
            "lod_buffer_mesh",
            "LodDraw",
            std::mem::size_of::<LodDrawUniform>(),
        ),
    ];
    for (pass_name, name, rust_size) in mirrors {
        let pass = shaders::find_pass_source(pass_name).unwrap();
        let composed = compose(pass, &format!("{pass_name}.wgsl"), SourceLanguage::Wgsl);
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(composed.module.to_ctx()).unwrap();
        let (handle, _) = composed
            .module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{pass_name}: no struct {name}"));
        assert_eq!(
            layouter[handle].size as usize, rust_size,
            "{pass_name}: {name}"
        );
    }
}

#[test]
fn glsl_texture_macros_compile_with_glslang() {
    let Some(_) = tool("glslangValidator") else {
        return;
    };
    let source = "#version 450
#extension GL_GOOGLE_include_directive : require
#include \"lodkit/visibility.glsl\"
#include \"lodkit/bilateral.glsl\"
#include \"lodkit/alpha_mask.glsl\"
layout(set = 0, binding = 0) uniform sampler2D vis_tex;
layout(set = 0, binding = 3) uniform sampler2D alpha_tex;
layout(set = 0, binding = 1) uniform sampler2D low_color;
layout(set = 0, binding = 2) uniform sampler2D low_geometry;
layout(location = 0) in vec3 object_pos;
layout(location = 0) out vec4 color;
void main() {
    if (!lodkit_check_visibility(vis_tex, object_pos, 0.5)) discard;
    if (!lodkit_alpha_mask_keep(alpha_tex, object_pos, vec4(0.5, -0.5, 0.5, 0.5))) discard;
    color = lodkit_bilateral_upsample_at(low_color, low_geometry, vec2(320.0, 180.0), vec2(640.0, 360.0),
                                         gl_FragCoord.xy, 4.0, vec3(0.0, 0.0, 1.0), 0.25, 0.4);
}
";
    let words = glslang_spirv("macros.frag", source, "macros.frag");
    spirv_val(&words, "macros.frag");
}
