//! Permutation files (`lodkit check --permutations FILE`, TOML or RON): the shader-def sets a
//! group of shaders is used with, in the style engines declare them.
//!
//! ```toml
//! [[shaders]]
//! files = ["pbr/*.wgsl", "prepass.wgsl"]   # globs, relative to the permutation file
//! one_of = [["MESH_PIPELINE", "PREPASS_PIPELINE"]]   # exactly one of each group is on
//! optional = ["VERTEX_UVS", "SKINNED", "MORPH_TARGETS"]   # each on or off
//! values = { MAX_CASCADES_PER_LIGHT = 4, MAX_LIGHTS = "8u" }   # set in every set
//! requires = { MORPH_TARGETS = ["SKINNED"] }   # on only with these on
//! excludes = [["SKINNED", "PREPASS_PIPELINE"]]   # never all on together
//! ```
//!
//! A shader takes the first entry whose `files` match it; a shader no entry matches has its
//! defs found in its source, as without a permutation file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use lodkit::shaders::ShaderDefValue;
use serde::Deserialize;

use super::sets::Factor;

/// A value in `values`: a number (an int), `true`/`false`, or a string as `-D` takes it
/// (`"8u"` for a uint).
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
enum Value {
    Int(i64),
    Bool(bool),
    Text(String),
}

/// One `[[shaders]]` entry as written.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct EntryText {
    files: Vec<String>,
    one_of: Vec<Vec<String>>,
    optional: Vec<String>,
    values: BTreeMap<String, Value>,
    requires: BTreeMap<String, Vec<String>>,
    excludes: Vec<Vec<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileText {
    shaders: Vec<EntryText>,
}

/// One entry, checked.
#[derive(Clone, Debug)]
pub struct Entry {
    /// Index in the file, from 1, for messages.
    pub index: usize,
    files: Vec<glob::Pattern>,
    one_of: Vec<Vec<String>>,
    optional: Vec<String>,
    values: Vec<(String, ShaderDefValue)>,
    requires: BTreeMap<String, Vec<String>>,
    excludes: Vec<Vec<String>>,
}

/// A loaded permutation file.
pub struct PermutationFile {
    /// The folder its globs are relative to.
    dir: PathBuf,
    entries: Vec<Entry>,
}

fn value_of(name: &str, v: &Value) -> Result<ShaderDefValue, String> {
    match v {
        Value::Bool(b) => Ok(ShaderDefValue::Bool(*b)),
        Value::Int(i) => i32::try_from(*i)
            .map(ShaderDefValue::Int)
            .map_err(|_| format!("value {i} of `{name}` is not an i32 (write \"{i}u\" for a u32)")),
        Value::Text(t) => crate::parse_def(&format!("{name}={t}")).map(|(_, v)| v),
    }
}

impl PermutationFile {
    /// Reads a `.toml` or `.ron` permutation file; an error names the file, and the line where
    /// the syntax is wrong.
    pub fn load(path: &Path) -> Result<Self, String> {
        let shown = path.display();
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{shown}: cannot read: {e}"))?;
        let parsed: FileText = match path.extension().and_then(|e| e.to_str()) {
            Some("toml") => toml::from_str(&text).map_err(|e| {
                let line = e
                    .span()
                    .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
                match line {
                    Some(line) => format!("{shown}:{line}: {}", e.message().trim()),
                    None => format!("{shown}: {}", e.message().trim()),
                }
            })?,
            Some("ron") => ron::from_str(&text).map_err(|e| {
                format!(
                    "{shown}:{}:{}: {}",
                    e.span.start.line, e.span.start.col, e.code
                )
            })?,
            _ => {
                return Err(format!(
                    "{shown}: a permutation file is a .toml or .ron file"
                ));
            }
        };
        let mut entries = Vec::new();
        for (i, e) in parsed.shaders.into_iter().enumerate() {
            let index = i + 1;
            let at = |m: String| format!("{shown}: shaders entry {index}: {m}");
            if e.files.is_empty() {
                return Err(at("`files` names no shader (a list of globs)".into()));
            }
            let files = e
                .files
                .iter()
                .map(|g| glob::Pattern::new(g).map_err(|err| at(format!("glob `{g}`: {err}"))))
                .collect::<Result<Vec<_>, _>>()?;
            let names = e
                .one_of
                .iter()
                .flatten()
                .chain(&e.optional)
                .chain(e.values.keys())
                .chain(e.requires.keys())
                .chain(e.requires.values().flatten())
                .chain(e.excludes.iter().flatten());
            for name in names {
                crate::parse_def(name).map_err(|m| at(m.to_string()))?;
                if name.contains('=') {
                    return Err(at(format!("`{name}`: give values under `values`")));
                }
            }
            if let Some(g) = e.one_of.iter().find(|g| g.len() < 2) {
                return Err(at(format!("one_of group {g:?} needs two defs or more")));
            }
            let values = e
                .values
                .iter()
                .map(|(k, v)| value_of(k, v).map(|v| (k.clone(), v)).map_err(at))
                .collect::<Result<Vec<_>, _>>()?;
            entries.push(Entry {
                index,
                files,
                one_of: e.one_of,
                optional: e.optional,
                values,
                requires: e.requires,
                excludes: e.excludes,
            });
        }
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Ok(Self { dir, entries })
    }

    /// The first entry whose globs match `file` (relative to the permutation file's folder).
    pub fn entry_for(&self, file: &Path) -> Option<&Entry> {
        let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let (file, dir) = (abs(file), abs(&self.dir));
        let rel = file.strip_prefix(&dir).unwrap_or(&file);
        let options = glob::MatchOptions {
            require_literal_separator: true,
            ..Default::default()
        };
        self.entries
            .iter()
            .find(|e| e.files.iter().any(|g| g.matches_path_with(rel, options)))
    }
}

impl Entry {
    /// The factors: each `one_of` group, then each optional def (with its value when `values`
    /// gives one); and the defs set in every set (`values` of defs that are not optional).
    pub fn factors(&self) -> (Vec<Factor>, Vec<(String, ShaderDefValue)>) {
        let value = |name: &str| {
            self.values
                .iter()
                .find(|(k, _)| k == name)
                .map_or(ShaderDefValue::Bool(true), |(_, v)| *v)
        };
        let mut factors: Vec<Factor> = self
            .one_of
            .iter()
            .map(|g| Factor {
                levels: g.iter().map(|d| vec![(d.clone(), value(d))]).collect(),
            })
            .collect();
        factors.extend(self.optional.iter().map(|d| Factor {
            levels: vec![vec![], vec![(d.clone(), value(d))]],
        }));
        let fixed = self
            .values
            .iter()
            .filter(|(k, _)| {
                !self.optional.contains(k) && !self.one_of.iter().flatten().any(|d| d == k)
            })
            .cloned()
            .collect();
        (factors, fixed)
    }

    /// Whether a set satisfies `requires` and `excludes`.
    pub fn allows(&self, defs: &[(String, ShaderDefValue)]) -> bool {
        let on = |name: &str| {
            defs.iter()
                .any(|(k, v)| k == name && *v != ShaderDefValue::Bool(false))
        };
        self.requires
            .iter()
            .all(|(d, needs)| !on(d) || needs.iter().all(|n| on(n)))
            && self
                .excludes
                .iter()
                .all(|group| !group.iter().all(|d| on(d)))
    }

    /// The defs the entry declares (to tell which defs a shader tests that it leaves out).
    pub fn declared(&self) -> Vec<&str> {
        self.one_of
            .iter()
            .flatten()
            .chain(&self.optional)
            .map(String::as_str)
            .chain(self.values.iter().map(|(k, _)| k.as_str()))
            .collect()
    }
}
