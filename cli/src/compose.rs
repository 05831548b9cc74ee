//! Reading and composing one shader file the way `lodkit check` and `lodkit export` do: the
//! library with the user's folders, the language from the file name, the defs from `-D`.

use std::collections::HashMap;
use std::path::Path;

use lodkit::shaders::{
    self, ComposeDescriptor, ShaderDefValue, ShaderError, ShaderLibrary, SourceLanguage,
};

use crate::{ComposeArgs, Stage};

/// What happened to one file.
pub enum Outcome {
    /// It composed and validated.
    Valid(Box<shaders::Composed>),
    /// Its source has a problem.
    Invalid(ShaderError),
    /// It could not be read, or its language is unknown.
    Unreadable(ShaderError),
}

/// The lodkit library plus the `-I` folders (less `--exclude`), with the capabilities asked for.
pub fn library(args: &ComposeArgs) -> Result<ShaderLibrary, ShaderError> {
    let mut library = ShaderLibrary::with_descriptor(&shaders::LibraryDescriptor {
        capabilities: args
            .capabilities
            .map_or_else(Default::default, |c| c | Default::default()),
    })?;
    library.add_import_dirs_excluding(&args.include, &args.exclude)?;
    Ok(library)
}

/// The language of `path`: from its extension, or `--stage` for GLSL.
pub fn language_of(path: &Path, stage: Option<Stage>) -> Result<SourceLanguage, String> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    if name.ends_with(".wgsl") {
        return Ok(SourceLanguage::Wgsl);
    }
    if name.ends_with(".wesl") {
        return Ok(SourceLanguage::Wesl);
    }
    let from_name = [
        (".vert", naga::ShaderStage::Vertex),
        (".frag", naga::ShaderStage::Fragment),
        (".comp", naga::ShaderStage::Compute),
    ]
    .into_iter()
    .find(|(ext, _)| name.ends_with(ext) || name.contains(&format!("{ext}.")))
    .map(|(_, s)| s);
    let stage = stage.map(|s| match s {
        Stage::Vertex => naga::ShaderStage::Vertex,
        Stage::Fragment => naga::ShaderStage::Fragment,
        Stage::Compute => naga::ShaderStage::Compute,
    });
    match stage.or(from_name) {
        Some(stage) => Ok(SourceLanguage::Glsl(stage)),
        None if name.ends_with(".glsl") => Err(format!(
            "{}: a GLSL file needs a stage: pass --stage or name it .vert/.frag/.comp",
            path.display()
        )),
        None => Err(format!(
            "{}: unknown shader language (expected .wgsl, .wesl, .glsl, .vert, .frag or .comp)",
            path.display()
        )),
    }
}

/// Reads `path` and its language, or says why it cannot be checked.
pub fn read(path: &Path, stage: Option<Stage>) -> Result<(String, SourceLanguage), Outcome> {
    let language = language_of(path, stage).map_err(|message| {
        Outcome::Unreadable(ShaderError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
        })
    })?;
    match shaders::read_source(path) {
        Ok(s) => Ok((s, language)),
        Err(e @ ShaderError::Io { .. }) => Err(Outcome::Unreadable(e)),
        Err(e) => Err(Outcome::Invalid(e)),
    }
}

/// Composes `source` (the text of `path`) with `defs` set.
pub fn compose_source(
    library: &mut ShaderLibrary,
    path: &Path,
    source: &str,
    language: SourceLanguage,
    defs: HashMap<String, ShaderDefValue>,
) -> Outcome {
    let file_path = path.display().to_string();
    match library.compose(&ComposeDescriptor {
        source,
        file_path: &file_path,
        language,
        shader_defs: defs,
    }) {
        Ok(c) => Outcome::Valid(Box::new(c)),
        Err(e) => Outcome::Invalid(e),
    }
}

/// Reads and composes `path` with the `-D` defs of `args`.
pub fn compose_file(library: &mut ShaderLibrary, args: &ComposeArgs, path: &Path) -> Outcome {
    let (source, language) = match read(path, args.stage) {
        Ok(x) => x,
        Err(outcome) => return outcome,
    };
    let defs: HashMap<String, ShaderDefValue> = args.define.iter().cloned().collect();
    compose_source(library, path, &source, language, defs)
}

/// The JSON form of an error (`lodkit check --format json`).
pub fn error_json(file: &Path, e: &ShaderError) -> serde_json::Value {
    match e.diagnostic() {
        Some(d) => serde_json::to_value(d).unwrap_or_default(),
        None => serde_json::json!({
            "kind": match e { ShaderError::Io { .. } => "io", _ => "export" },
            "message": e.to_string(),
            "file": file.display().to_string(),
            "hint": null,
            "notes": [],
        }),
    }
}

/// Prints an error for people on stderr: the diagnostic with its source line, or one line.
pub fn print_error(e: &ShaderError) {
    match e.diagnostic() {
        Some(d) => crate::output::eprint(&d.render()),
        None => crate::output::eprint(&format!("error: {e}\n")),
    }
}
