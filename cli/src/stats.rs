//! `lodkit check --stats` and `--budget FILE`: what each entry point fetches and computes,
//! counted from its IR by `lodkit::shaders::cost`, and a shader-cost budget that fails the check
//! when an entry point goes over it.
//!
//! A budget is a RON or TOML table (by extension) from entry points to maxima. A key is an entry
//! point's name, which applies in every file, or `FILE:ENTRY`, FILE as given on the command line
//! or its file name, which wins over the bare name. A key may end with shader defs, `-D NAME`
//! (or `-D NAME=VALUE`) as on the command line: it then holds only a check run with those defs
//! set, and among the keys of one name the one with the most defs set wins (a variant's own
//! budget over the default's; keys that tie all hold). Every maximum is optional and holds the
//! costliest path (what always runs plus the most that branches add):
//!
//! ```ron
//! {
//!     "fs_main": { "fetches": 9, "alu": 120 },
//!     "combine.wgsl:fs_main": { "texture_loads": 7, "conditional_fetches": 2 },
//!     "combine.wgsl:fs_main -D LODKIT_COMBINE_STILL": { "texture_loads": 6 },
//! }
//! ```
//!
//! or in TOML, `["combine.wgsl:fs_main"]` then `texture_loads = 7` on the next line.
//!
//! An entry point a key holds fails its budget when it has a loop whose trip count the counter
//! cannot bound (its counts are then no upper bound), unless the budget allows it:
//! `allow_unbounded_loops: true` in the entry, or at the top of the file for every entry (an
//! entry's own setting wins).

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use lodkit::shaders::ShaderDefValue;
use lodkit::shaders::cost::{Counts, EntryCost, FetchKind};
use serde::Deserialize;

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
    /// Whether a loop of unknown trip count is accepted (unset: the budget's global setting).
    pub allow_unbounded_loops: Option<bool>,
}

/// The setting that accepts loops of unknown trip count.
const ALLOW_UNBOUNDED: &str = "allow_unbounded_loops";

/// The names a budget entry may set.
const LIMITS: &[&str] = &[
    "fetches",
    "texture_loads",
    "samples",
    "gathers",
    "storage_reads",
    "conditional_fetches",
    "alu",
    ALLOW_UNBOUNDED,
];

/// A value in a budget entry: a maximum or a flag.
#[derive(Deserialize)]
#[serde(untagged)]
enum Value {
    Count(u64),
    Flag(bool),
}

/// A top-level value of a budget: an entry's table, or the global flag.
#[derive(Deserialize)]
#[serde(untagged)]
enum TopValue {
    Entry(BTreeMap<String, Value>),
    Flag(bool),
}

impl Limits {
    /// From a table of names and values (RON and TOML read alike); unknown names and values of
    /// the wrong kind are an error.
    fn from_table(key: &str, table: &BTreeMap<String, Value>) -> Result<Self, String> {
        let mut l = Self::default();
        for (name, value) in table {
            let slot = match name.as_str() {
                "fetches" => &mut l.fetches,
                "texture_loads" => &mut l.texture_loads,
                "samples" => &mut l.samples,
                "gathers" => &mut l.gathers,
                "storage_reads" => &mut l.storage_reads,
                "conditional_fetches" => &mut l.conditional_fetches,
                "alu" => &mut l.alu,
                ALLOW_UNBOUNDED => match value {
                    Value::Flag(allow) => {
                        l.allow_unbounded_loops = Some(*allow);
                        continue;
                    }
                    Value::Count(_) => {
                        return Err(format!(
                            "entry \"{key}\": `{ALLOW_UNBOUNDED}` is true or false"
                        ));
                    }
                },
                _ => {
                    return Err(format!(
                        "entry \"{key}\": unknown limit `{name}` (expected one of {})",
                        LIMITS.join(", ")
                    ));
                }
            };
            match value {
                Value::Count(max) => *slot = Some(*max),
                Value::Flag(_) => {
                    return Err(format!(
                        "entry \"{key}\": `{name}` is a whole number, not true or false"
                    ));
                }
            }
        }
        Ok(l)
    }
}

/// One key of a budget: the entry point it names, the defs it holds for, and its maxima.
struct Entry {
    key: String,
    name: String,
    defs: Vec<(String, ShaderDefValue)>,
    limits: Limits,
}

/// Splits a key into the entry point it names and its `-D NAME[=VALUE]` defs.
fn parse_key(key: &str) -> Result<(String, Vec<(String, ShaderDefValue)>), String> {
    let mut words = key.split_whitespace();
    let name = words.next().unwrap_or_default().to_owned();
    let mut defs = Vec::new();
    while let Some(word) = words.next() {
        let def = match word.strip_prefix("-D") {
            Some("") => words.next(),
            Some(rest) => Some(rest),
            None => None,
        };
        let def = def.ok_or_else(|| {
            format!(
                "key \"{key}\": expected `-D NAME[=VALUE]` after the entry point, found `{word}`"
            )
        })?;
        defs.push(crate::parse_def(def).map_err(|e| format!("key \"{key}\": {e}"))?);
    }
    Ok((name, defs))
}

/// A loaded budget file.
pub struct Budget {
    path: PathBuf,
    entries: Vec<Entry>,
    /// `allow_unbounded_loops` at the top of the file.
    allow_unbounded_loops: bool,
    /// The shader defs of this check run.
    defs: HashMap<String, ShaderDefValue>,
    used: BTreeSet<String>,
}

impl Budget {
    /// Reads a `.ron` or `.toml` budget for a check run with `defs` set; the error names the
    /// file and, for syntax, the line.
    pub fn load(path: &Path, defs: &HashMap<String, ShaderDefValue>) -> Result<Self, String> {
        let shown = path.display();
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{shown}: cannot read: {e}"))?;
        let tables: BTreeMap<String, TopValue> = match path.extension().and_then(|e| e.to_str()) {
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
        let mut budget = Self {
            path: path.to_owned(),
            entries: Vec::new(),
            allow_unbounded_loops: false,
            defs: defs.clone(),
            used: BTreeSet::new(),
        };
        for (key, value) in &tables {
            match value {
                TopValue::Flag(allow) if key == ALLOW_UNBOUNDED => {
                    budget.allow_unbounded_loops = *allow;
                }
                TopValue::Flag(_) => {
                    return Err(format!(
                        "{shown}: entry \"{key}\" is a table of limits \
                         (only `{ALLOW_UNBOUNDED}` is true or false at the top)"
                    ));
                }
                TopValue::Entry(table) => {
                    let (name, defs) = parse_key(key).map_err(|e| format!("{shown}: {e}"))?;
                    let limits =
                        Limits::from_table(key, table).map_err(|e| format!("{shown}: {e}"))?;
                    budget.entries.push(Entry {
                        key: key.clone(),
                        name,
                        defs,
                        limits,
                    });
                }
            }
        }
        Ok(budget)
    }

    /// The shader defs of the set checked next (a check of many sets changes them per set).
    pub fn set_defs(&mut self, defs: &HashMap<String, ShaderDefValue>) {
        self.defs = defs.clone();
    }

    /// Whether every def `entry` names is set so in this run.
    fn holds_defs(&self, entry: &Entry) -> bool {
        entry
            .defs
            .iter()
            .all(|(name, value)| self.defs.get(name) == Some(value))
    }

    /// Checks `cost` of an entry point of `file`; returns what is over, one line each.
    pub fn check(&mut self, file: &Path, cost: &EntryCost) -> Vec<String> {
        let file_name = file.file_name().map(|n| n.to_string_lossy().into_owned());
        let names = [
            Some(format!("{}:{}", file.display(), cost.name)),
            file_name.map(|n| format!("{n}:{}", cost.name)),
            Some(cost.name.clone()),
        ];
        // Keys that name this entry point and whose defs this run sets, ranked: the file
        // named wins over the bare name, then the most defs.
        let candidates: Vec<(usize, (usize, std::cmp::Reverse<usize>))> = self
            .entries
            .iter()
            .enumerate()
            .filter(|(_, e)| self.holds_defs(e))
            .filter_map(|(i, e)| {
                let rank = names.iter().position(|n| n.as_deref() == Some(&e.name))?;
                Some((i, (rank, std::cmp::Reverse(e.defs.len()))))
            })
            .collect();
        let Some(best) = candidates.iter().map(|(_, r)| *r).min() else {
            return Vec::new();
        };
        let mut over = Vec::new();
        for &(i, rank) in &candidates {
            self.used.insert(self.entries[i].key.clone());
            if rank == best {
                over.extend(self.over(file, cost, &self.entries[i]));
            }
        }
        over
    }

    /// What `cost` exceeds of `entry`'s limits, one line each.
    fn over(&self, file: &Path, cost: &EntryCost, entry: &Entry) -> Vec<String> {
        let (limits, key) = (&entry.limits, &entry.key);
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
        let mut over: Vec<String> = measured
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
            .collect();
        let allowed = limits
            .allow_unbounded_loops
            .unwrap_or(self.allow_unbounded_loops);
        if cost.unknown_loops > 0 && !allowed {
            let mut places: Vec<&str> = Vec::new();
            for f in &cost.unknown_loops_in {
                if !places.contains(&f.as_str()) {
                    places.push(f);
                }
            }
            let places: Vec<String> = places.iter().map(|f| format!("`{f}`")).collect();
            over.push(format!(
                "{}: `{}` has {} loop{} of unknown trip count (in {}), counted once: its counts \
                 are no upper bound ({}, key \"{key}\"; `{ALLOW_UNBOUNDED}: true` accepts it)",
                file.display(),
                cost.name,
                cost.unknown_loops,
                if cost.unknown_loops == 1 { "" } else { "s" },
                places.join(", "),
                self.path.display()
            ));
        }
        over
    }

    /// Keys that matched no entry point of the files checked (likely misspelt); a key for
    /// defs this run does not set is for another run, and not listed.
    pub fn unused(&self) -> Vec<&str> {
        self.entries
            .iter()
            .filter(|e| self.holds_defs(e) && !self.used.contains(&e.key))
            .map(|e| e.key.as_str())
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
