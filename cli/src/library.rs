//! What the command writes about the library itself: `lodkit modules` (the registry, for people
//! or as JSON) and `lodkit wesl` (the WESL package, or the npm package).

use std::path::Path;
use std::process::ExitCode;

use lodkit::shaders;

use crate::output::{Output, emit};

/// `lodkit modules`: every module with its functions and shader defs.
pub fn modules(json: bool) -> ExitCode {
    use std::fmt::Write as _;
    let modules = shaders::modules();
    if json {
        let json = serde_json::to_string_pretty(modules).unwrap_or_default();
        return emit(&format!("{json}\n"));
    }
    // Writing into a String cannot fail.
    let mut out = String::new();
    for m in modules {
        let name = m.import_path.clone().unwrap_or_else(|| m.path.to_owned());
        let kind = match (m.kind, m.language) {
            (shaders::ModuleKind::Pass, _) => "pass",
            (_, shaders::Language::Wgsl) => "wgsl",
            (_, shaders::Language::Glsl) => "glsl twin",
            (_, shaders::Language::Wesl) => "wesl",
        };
        let _ = writeln!(out, "{name}  [{kind}: shader_lib/{}]", m.path);
        if let Some(path) = &m.embedded_path {
            let _ = writeln!(out, "    Bevy 0.20: Shader::from_wesl(source, \"{path}\")");
        }
        let _ = writeln!(out, "    {}", m.summary);
        for f in &m.functions {
            let _ = writeln!(out, "    {}", f.signature);
            if !f.doc.is_empty() {
                let _ = writeln!(out, "        {}", f.doc);
            }
        }
        if m.shader_defs.is_empty() {
            let _ = writeln!(out, "    shader defs: none");
        }
        for d in &m.shader_defs {
            let _ = writeln!(out, "    shader def {} {}", d.name, d.doc);
        }
        out.push('\n');
    }
    emit(&out)
}

/// `lodkit wesl --out DIR` (the WESL package) or `--npm DIR` (the npm package).
pub fn write_wesl(out: &Path, npm: bool) -> ExitCode {
    let files = if npm {
        lodkit_cli::npm::npm_package()
    } else {
        shaders::wesl_package()
    };
    let files = match files {
        Ok(files) => files,
        Err(e) => {
            crate::output::eprintln(&format!("error: a lodkit module has no WESL form: {e}"));
            return ExitCode::from(1);
        }
    };
    for (rel, text) in &files {
        let path = out.join(rel);
        let written = path
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .and_then(|()| std::fs::write(&path, text));
        if let Err(e) = written {
            crate::output::eprintln(&format!("error: cannot write `{}`: {e}", path.display()));
            return ExitCode::from(2);
        }
    }
    let what = if npm { "npm package" } else { "WESL package" };
    let mut stdout = Output::default();
    stdout.println(&format!(
        "wrote {} files of the {what} `lodkit` into {}",
        files.len(),
        out.display()
    ));
    stdout.finish(ExitCode::SUCCESS)
}
