//! `lodkit check --stats` and `--budget FILE`: what each entry point fetches and computes,
//! counted from its IR by `lodkit::shaders::cost`, and a shader-cost budget that fails the check
//! when an entry point goes over it.
//!
//! A budget is a RON or TOML table (by extension) from entry points to maxima. A key is an entry
//! point's name, which applies in every file, or `FILE:ENTRY`, FILE as given on the command line
//! or its file name, which wins over the bare name. Every maximum is optional and holds the
//! costliest path (what always runs plus the most that branches add):
//!
//! ```ron
//! {
//!     "fs_main": { "fetches": 9, "alu": 120 },
//!     "combine.wgsl:fs_main": { "texture_loads": 7, "conditional_fetches": 2 },
//! }
//! ```
//!
//! or in TOML, `["combine.wgsl:fs_main"]` then `texture_loads = 7` on the next line.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use lodkit::shaders::cost::{Counts, EntryCost, FetchKind};

/// Maxima for one entry point; unset ones are not checked.
#[derive(Clone, Debug, Default)]
pub struct Limits {
    /// All fetches: texture loads, samples, gathers and storage reads.
    pub fetches: Option<u64>,
    /// `textureLoad` calls.
    pub texture_loads: Option<u64>,
    /// `textureSample*` calls.
    pub samples: Option<u64>,
    /// `textureGather*` calls.
    pub gathers: Option<u64>,
    /// Storage-buffer loads.
    pub storage_reads: Option<u64>,
    /// Fetches under branches, at most.
    pub conditional_fetches: Option<u64>,
    /// ALU operations.
    pub alu: Option<u64>,
}

/// The names a budget entry may set.
const LIMITS: &[&str] = &[
    "fetches",
    "texture_loads",
    "samples",
    "gathers",
    "storage_reads",
    "conditional_fetches",
    "alu",
];

impl Limits {
    /// From a table of names and maxima (RON and TOML read alike); unknown names are an error.
    fn from_table(key: &str, table: &BTreeMap<String, u64>) -> Result<Self, String> {
        let mut l = Self::default();
        for (name, &max) in table {
            let slot = match name.as_str() {
                "fetches" => &mut l.fetches,
                "texture_loads" => &mut l.texture_loads,
                "samples" => &mut l.samples,
                "gathers" => &mut l.gathers,
                "storage_reads" => &mut l.storage_reads,
                "conditional_fetches" => &mut l.conditional_fetches,
                "alu" => &mut l.alu,
                _ => {
                    return Err(format!(
                        "entry \"{key}\": unknown limit `{name}` (expected one of {})",
                        LIMITS.join(", ")
                    ));
                }
            };
            *slot = Some(max);
        }
        Ok(l)
    }
}

/// A loaded budget file.
pub struct Budget {
    path: PathBuf,
    entries: BTreeMap<String, Limits>,
    used: BTreeSet<String>,
}

impl Budget {
    /// Reads a `.ron` or `.toml` budget; the error names the file and, for syntax, the line.
    pub fn load(path: &Path) -> Result<Self, String> {
        let shown = path.display();
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{shown}: cannot read: {e}"))?;
        let tables: BTreeMap<String, BTreeMap<String, u64>> =
            match path.extension().and_then(|e| e.to_str()) {
                Some("ron") => ron::from_str(&text).map_err(|e| {
                    format!(
                        "{shown}:{}:{}: {}",
                        e.span.start.line, e.span.start.col, e.code
                    )
                })?,
                Some("toml") => toml::from_str(&text).map_err(|e| {
                    let line = e
                        .span()
                        .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
                    match line {
                        Some(line) => format!("{shown}:{line}: {}", e.message()),
                        None => format!("{shown}: {}", e.message()),
                    }
                })?,
                _ => return Err(format!("{shown}: a budget is a .ron or .toml file")),
            };
        let entries = tables
            .iter()
            .map(|(key, table)| Ok((key.clone(), Limits::from_table(key, table)?)))
            .collect::<Result<_, String>>()
            .map_err(|e| format!("{shown}: {e}"))?;
        Ok(Self {
            path: path.to_owned(),
            entries,
            used: BTreeSet::new(),
        })
    }

    /// Checks `cost` of an entry point of `file`; returns what is over, one line each.
    pub fn check(&mut self, file: &Path, cost: &EntryCost) -> Vec<String> {
        let name = file.file_name().map(|n| n.to_string_lossy().into_owned());
        let keys = [
            Some(format!("{}:{}", file.display(), cost.name)),
            name.map(|n| format!("{n}:{}", cost.name)),
            Some(cost.name.clone()),
        ];
        let Some((key, limits)) = keys
            .into_iter()
            .flatten()
            .find_map(|k| self.entries.get(&k).map(|l| (k, l.clone())))
        else {
            return Vec::new();
        };
        self.used.insert(key.clone());
        let worst = cost.worst();
        let measured = [
            ("fetches", limits.fetches, worst.fetches()),
            ("texture loads", limits.texture_loads, worst.texture_loads),
            ("samples", limits.samples, worst.samples),
            ("gathers", limits.gathers, worst.gathers),
            ("storage reads", limits.storage_reads, worst.storage_reads),
            (
                "conditional fetches",
                limits.conditional_fetches,
                cost.conditional.fetches(),
            ),
            ("ALU ops", limits.alu, worst.alu),
        ];
        measured
            .into_iter()
            .filter_map(|(what, max, n)| {
                let max = max?;
                (n > max).then(|| {
                    format!(
                        "{}: `{}` makes {n} {what}, over its budget of {max} ({}, key \"{key}\")",
                        file.display(),
                        cost.name,
                        self.path.display()
                    )
                })
            })
            .collect()
    }

    /// Keys that matched no entry point of the files checked (likely misspelt).
    pub fn unused(&self) -> Vec<&str> {
        self.entries
            .keys()
            .filter(|k| !self.used.contains(*k))
            .map(String::as_str)
            .collect()
    }
}

fn counts_text(c: &Counts) -> String {
    let parts: Vec<String> = [
        (c.texture_loads, "texture load"),
        (c.samples, "sample"),
        (c.gathers, "gather"),
        (c.storage_reads, "storage read"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}{}", if *n == 1 { "" } else { "s" }))
    .collect();
    match parts.len() {
        0 => format!("{} ALU ops", c.alu),
        _ => format!(
            "{} fetch{} ({}), {} ALU ops",
            c.fetches(),
            if c.fetches() == 1 { "" } else { "es" },
            parts.join(", "),
            c.alu
        ),
    }
}

/// The human listing of one entry point's cost, indented under the file's `ok:` line.
pub fn human(cost: &EntryCost) -> String {
    let mut out = format!(
        "  {} ({}): {}",
        cost.name,
        cost.stage,
        counts_text(&cost.always)
    );
    if cost.conditional != Counts::default() {
        let _ = write!(
            out,
            "; branches add at most {}",
            counts_text(&cost.conditional)
        );
    }
    if cost.unknown_loops > 0 {
        let _ = write!(
            out,
            "; {} loop{} of unknown trip count counted once",
            cost.unknown_loops,
            if cost.unknown_loops == 1 { "" } else { "s" }
        );
    }
    out.push('\n');
    for r in &cost.resources {
        let kind = match r.kind {
            FetchKind::TextureLoad => "texture load",
            FetchKind::Sample => "sample",
            FetchKind::Gather => "gather",
            FetchKind::StorageRead => "storage read",
        };
        let plural = if r.always == 1 { "" } else { "s" };
        let binding = r.binding.map_or(String::new(), |(g, b)| {
            format!(" @group({g}) @binding({b})")
        });
        let _ = write!(
            out,
            "    {}{binding}: {} {kind}{plural}",
            r.resource, r.always
        );
        if r.conditional > 0 {
            let _ = write!(out, " + {} under branches", r.conditional);
        }
        out.push('\n');
    }
    out
}

/// One entry point's cost as JSON: the counts, per resource, and the costliest path (`worst`).
pub fn json(cost: &EntryCost) -> serde_json::Value {
    let mut v = serde_json::to_value(cost).unwrap_or_default();
    v["worst"] = serde_json::to_value(cost.worst()).unwrap_or_default();
    v
}
