//! The shader-def sets one file is checked under: the `-D` set alone; or, with `--permute`, the
//! combinations of the defs it and its imports test; or the sets a permutation file declares.

use std::collections::HashMap;
use std::path::Path;

use lodkit::shaders::ShaderDefValue;

use super::DefSet;
use super::discover::Sources;
use super::permfile::PermutationFile;
use super::sets::{self, Allowed, Coverage, Factor};

/// The sets of one file and how they were chosen.
pub struct Plan {
    /// The sets, the default first.
    pub sets: Vec<DefSet>,
    /// How they were chosen, said in the output (empty for the `-D` set alone).
    pub description: String,
    /// Defs the shader tests that its permutation-file entry leaves out (never set).
    pub undeclared: Vec<String>,
}

/// How `lodkit check` picks sets.
pub struct Planner {
    /// Defs given with `-D`: set in every set.
    pub fixed: HashMap<String, ShaderDefValue>,
    /// `--permute` or `--permutations`: vary the defs.
    pub permute: bool,
    /// `--max-sets`.
    pub max_sets: usize,
    /// `--permutations FILE`.
    pub file: Option<PermutationFile>,
    /// The user's modules, to follow imports.
    pub sources: Sources,
}

fn names(defs: &[String]) -> String {
    let shown: Vec<&str> = defs.iter().take(8).map(String::as_str).collect();
    let more = defs.len().saturating_sub(8);
    if more > 0 {
        format!("{} and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}

impl Planner {
    /// The sets `source` (the text of `path`) is checked under.
    pub fn plan(&self, path: &Path, source: &str) -> Plan {
        let single = |description: String| Plan {
            sets: vec![DefSet::from_map(&self.fixed)],
            description,
            undeclared: Vec::new(),
        };
        if !self.permute {
            return single(String::new());
        }
        let found = self.sources.defs_of(path, source);
        let entry = self.file.as_ref().and_then(|f| f.entry_for(path));
        let (factors, fixed, allowed, origin, undeclared): (
            Vec<Factor>,
            _,
            Box<Allowed>,
            String,
            Vec<String>,
        ) = match entry {
            Some(entry) => {
                let (factors, fixed) = entry.factors();
                let declared = entry.declared();
                let undeclared = found
                    .flags
                    .iter()
                    .chain(found.valued.keys())
                    .filter(|d| !declared.contains(&d.as_str()) && !self.fixed.contains_key(*d))
                    .cloned()
                    .collect();
                let origin = format!("the defs of permutation-file entry {}", entry.index);
                let entry = entry.clone();
                (
                    factors,
                    fixed,
                    Box::new(move |defs: &[(String, ShaderDefValue)]| entry.allows(defs)),
                    origin,
                    undeclared,
                )
            }
            None => {
                let mut factors = Vec::new();
                let mut varied = Vec::new();
                for name in &found.flags {
                    if self.fixed.contains_key(name) || found.valued.contains_key(name) {
                        continue;
                    }
                    varied.push(name.clone());
                    factors.push(Factor {
                        levels: vec![vec![], vec![(name.clone(), ShaderDefValue::Bool(true))]],
                    });
                }
                for (name, values) in &found.valued {
                    if self.fixed.contains_key(name) || values.is_empty() {
                        continue;
                    }
                    varied.push(name.clone());
                    let mut levels = vec![vec![]];
                    for v in values {
                        if let Ok(v) = i32::try_from(*v) {
                            levels.push(vec![(name.clone(), ShaderDefValue::Int(v))]);
                        }
                    }
                    factors.push(Factor { levels });
                }
                varied.sort();
                let origin = if varied.is_empty() {
                    "no defs tested".to_owned()
                } else {
                    format!(
                        "{} def{} ({})",
                        varied.len(),
                        if varied.len() == 1 { "" } else { "s" },
                        names(&varied)
                    )
                };
                (
                    factors,
                    Vec::new(),
                    Box::new(|_: &[(String, ShaderDefValue)]| true),
                    origin,
                    Vec::new(),
                )
            }
        };
        let (rows, coverage) = sets::choose(&factors, self.max_sets, &*allowed);
        let mut sets_out = Vec::new();
        for row in &rows {
            let mut map = self.fixed.clone();
            for (k, v) in fixed.iter().cloned().chain(sets::defs_of(&factors, row)) {
                map.entry(k).or_insert(v);
            }
            let set = DefSet::from_map(&map);
            if !sets_out.contains(&set) {
                sets_out.push(set);
            }
        }
        let n = sets_out.len();
        let description = match coverage {
            Coverage::All(total) => format!(
                "{n} set{}: every combination of {origin}{}",
                if n == 1 { "" } else { "s" },
                if total as usize != n {
                    format!(" that requires/excludes allow ({total} without them)")
                } else {
                    String::new()
                }
            ),
            Coverage::Pairwise {
                total,
                pairs,
                infeasible,
            } => format!(
                "{n} sets of {total} combinations of {origin} (over --max-sets {}): the default, \
                 each def alone and every pair of them ({pairs} pairs{})",
                self.max_sets,
                if infeasible > 0 {
                    format!(", {infeasible} more no allowed set has")
                } else {
                    String::new()
                }
            ),
        };
        Plan {
            sets: sets_out,
            description,
            undeclared,
        }
    }
}
