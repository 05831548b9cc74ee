//! Loading user modules into the composer: ordering them by their imports, and keeping a broken
//! or doubly declared module from failing shaders that never import it.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use naga_oil::compose::{ComposableModuleDescriptor, Composer, ShaderLanguage};

use super::ShaderError;
use super::diagnostic::{Diagnostic, DiagnosticKind, from_composer_error};
use super::imports::{declared_imports, import_site, longest_prefix};
use super::registry;

/// Every `.<extension>` file under `dir` whose path contains none of `exclude`.
pub(super) fn collect_files(
    dir: &Path,
    extension: &str,
    exclude: &[String],
    out: &mut Vec<PathBuf>,
) -> Result<(), ShaderError> {
    let entries = std::fs::read_dir(dir).map_err(|source| ShaderError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            collect_files(&path, extension, exclude, out)?;
        } else if path.extension().is_some_and(|e| e == extension) && !excluded(&path, exclude) {
            out.push(path);
        }
    }
    Ok(())
}

/// Whether `path` contains one of the `exclude` strings (compared on `/`-separated paths).
fn excluded(path: &Path, exclude: &[String]) -> bool {
    let text = path.to_string_lossy().replace('\\', "/");
    exclude
        .iter()
        .any(|x| !x.is_empty() && text.contains(x.as_str()))
}

/// User modules that could not be added, by import path: the diagnostic to give a shader that
/// imports one (two files declaring the path, or the module's own error).
pub(super) type Unavailable = HashMap<String, Diagnostic>;

/// Takes out of `sources` every import path declared by more than one file (an engine may ship
/// a stand-in and the real module under one path, picked by a build feature): each becomes
/// unavailable with a diagnostic naming all its files.
pub(super) fn split_duplicates(
    sources: &mut Vec<(String, Arc<str>)>,
    unavailable: &mut Unavailable,
) {
    let mut files: HashMap<String, Vec<String>> = HashMap::new();
    for (file, source) in sources.iter() {
        let name = registry::define_import_path(source).unwrap_or_default();
        files.entry(name).or_default().push(file.clone());
    }
    sources.retain(|(file, source)| {
        let name = registry::define_import_path(source).unwrap_or_default();
        let all = &files[&name];
        if all.len() < 2 {
            return true;
        }
        if all[0] == *file {
            let d = Diagnostic::new(
                DiagnosticKind::DuplicateModule,
                file.clone(),
                format!(
                    "`{name}` is declared by {} files: {}",
                    all.len(),
                    all.join(", ")
                ),
            )
            .with_span(source.clone(), import_site_define(source))
            .with_hint("leave out the ones you do not use (`lodkit check --exclude PATTERN`)");
            unavailable.insert(name, d);
        }
        false
    });
}

/// Every path a module names: its `#import`s, and the `module::item` paths it writes in full
/// without importing them (naga_oil resolves those too), outside `//` comments. What
/// naga_oil's own scan finds, without building a second preprocessor (its regular
/// expressions cost more than composing a small shader).
fn named_paths(source: &str) -> Vec<String> {
    let mut out: Vec<String> = declared_imports(source)
        .into_iter()
        .map(|(p, _)| p)
        .collect();
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    for line in source.lines() {
        let code = line.split("//").next().unwrap_or_default();
        if code.trim_start().starts_with('#') {
            continue;
        }
        let bytes = code.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            if !(bytes[i].is_ascii_alphabetic() || bytes[i] == b'_') {
                i += 1;
                continue;
            }
            let start = i;
            loop {
                while i < bytes.len() && word(bytes[i]) {
                    i += 1;
                }
                if bytes[i..].starts_with(b"::") && bytes.get(i + 2).is_some_and(|&b| word(b)) {
                    i += 2;
                } else {
                    break;
                }
            }
            let path = &code[start..i];
            if path.contains("::") {
                out.push(path.to_owned());
            }
        }
    }
    out
}

/// Adds `(file, source)` modules to `composer` so that every module comes after those it imports.
/// A module whose import path the composer already has is skipped when `skip_existing` (adding
/// the lodkit modules twice is harmless) and an error otherwise. With `unavailable`, a module
/// that fails to add is recorded there (and reported where it is imported) instead of failing
/// the batch; without it, the first failure is the error. An import cycle is always an error.
pub(super) fn add_modules(
    composer: &mut Composer,
    sources: Vec<(String, Arc<str>)>,
    skip_existing: bool,
    mut unavailable: Option<&mut Unavailable>,
) -> Result<(), ShaderError> {
    let mut by_name: HashMap<String, usize> = HashMap::new();
    let mut deps: Vec<Vec<String>> = Vec::new();
    for (i, (file, source)) in sources.iter().enumerate() {
        // The declared path as written: naga_oil gives none for a module whose preprocessor
        // directives are malformed, and two such modules must not look like duplicates.
        let imports = named_paths(source);
        let name = registry::define_import_path(source).unwrap_or_else(|| file.clone());
        if let Some(&j) = by_name.get(&name) {
            let d = Diagnostic::new(
                DiagnosticKind::DuplicateModule,
                file.clone(),
                format!("`{name}` is also defined in {}", sources[j].0),
            )
            .with_span(source.clone(), import_site_define(source));
            return Err(ShaderError::Source(Box::new(d)));
        }
        by_name.insert(name, i);
        deps.push(imports);
    }
    // Resolve each import to a module of this batch (the longest matching prefix).
    let resolve = |import: &str| -> Option<usize> {
        longest_prefix(import, |p| by_name.get(p).copied()).map(|(_, i)| i)
    };
    let n = sources.len();
    let mut state = vec![0u8; n]; // 0 new, 1 on stack, 2 done
    let mut order = Vec::with_capacity(n);
    fn visit(
        i: usize,
        deps: &[Vec<String>],
        resolve: &dyn Fn(&str) -> Option<usize>,
        state: &mut [u8],
        stack: &mut Vec<(usize, String)>,
        order: &mut Vec<usize>,
    ) -> Result<(), (usize, Vec<(usize, String)>)> {
        state[i] = 1;
        for import in &deps[i] {
            let Some(j) = resolve(import) else { continue };
            stack.push((i, import.clone()));
            match state[j] {
                1 => return Err((j, stack.clone())),
                0 => visit(j, deps, resolve, state, stack, order)?,
                _ => {}
            }
            stack.pop();
        }
        state[i] = 2;
        order.push(i);
        Ok(())
    }
    for i in 0..n {
        if state[i] == 0 {
            let mut stack = Vec::new();
            if let Err((start, stack)) =
                visit(i, &deps, &resolve, &mut state, &mut stack, &mut order)
            {
                let cycle: Vec<&(usize, String)> =
                    stack.iter().skip_while(|(m, _)| *m != start).collect();
                let (first, import) = cycle[0];
                let names: Vec<String> = cycle
                    .iter()
                    .map(|(m, _)| registry::define_import_path(&sources[*m].1).unwrap_or_default())
                    .chain(registry::define_import_path(&sources[start].1))
                    .collect();
                let (file, source) = &sources[*first];
                let d = Diagnostic::new(
                    DiagnosticKind::ImportCycle,
                    file.clone(),
                    format!("import cycle: {}", names.join(" -> ")),
                )
                .with_span(
                    source.clone(),
                    import_site(source, module_prefix_of(import, &by_name)),
                )
                .with_label("the cycle starts with this import")
                .with_hint("move what both modules need into a third module that imports neither");
                return Err(ShaderError::Source(Box::new(d)));
            }
        }
    }
    for i in order {
        let (file, source) = &sources[i];
        let name = registry::define_import_path(source).unwrap_or_default();
        if composer.contains_module(&name) {
            if skip_existing {
                continue;
            }
            let owner = if registry::find_module(&name).is_some() {
                "a lodkit module"
            } else {
                "a module added earlier"
            };
            let d = Diagnostic::new(
                DiagnosticKind::DuplicateModule,
                file.clone(),
                format!("`{name}` is already {owner}"),
            )
            .with_span(source.clone(), import_site_define(source))
            .with_hint("give the module another #define_import_path");
            return Err(ShaderError::Source(Box::new(d)));
        }
        let added = composer.add_composable_module(ComposableModuleDescriptor {
            source,
            file_path: file,
            language: ShaderLanguage::Wgsl,
            ..Default::default()
        });
        if let Err(e) = added {
            let d = from_composer_error(&e, composer, None);
            match unavailable.as_deref_mut() {
                Some(map) => {
                    map.insert(name, d);
                }
                None => return Err(ShaderError::Source(Box::new(d))),
            }
        }
    }
    Ok(())
}

fn module_prefix_of<'a>(import: &'a str, by_name: &HashMap<String, usize>) -> &'a str {
    longest_prefix(import, |p| by_name.get(p)).map_or(import, |(prefix, _)| prefix)
}

pub(super) fn import_site_define(source: &str) -> std::ops::Range<usize> {
    source
        .find("#define_import_path")
        .map(|i| i..i + "#define_import_path".len())
        .unwrap_or(0..0)
}
