//! Checking one file under each of its shader-def sets: compose, validate (each distinct module
//! once), count, and reduce each failure to the shortest def set that still fails.

use std::path::Path;

use lodkit::shaders::{self, ShaderDefValue, ShaderError, ShaderLibrary, SourceLanguage};

use super::plan::Planner;
use super::{CheckFormat, DefSet, Finding, Totals};
use crate::compose::{self, Outcome};
use crate::output::{self, Output};
use crate::{Stage, stats};

/// What one file is checked with.
pub struct FileCheck<'a> {
    /// The composer (remembering validations when sets are many).
    pub library: &'a mut ShaderLibrary,
    /// Picks the sets.
    pub planner: &'a Planner,
    /// `--stage`.
    pub stage: Option<Stage>,
    /// How to report.
    pub format: CheckFormat,
    /// `--stats`.
    pub stats: bool,
    /// `--budget`.
    pub budget: Option<&'a mut stats::Budget>,
    /// Stdout.
    pub out: &'a mut Output,
}

/// One way a file fails, with the first error and how many sets fail so.
struct Failure {
    error: ShaderError,
    finding: Finding,
    sets: usize,
}

impl FileCheck<'_> {
    fn compose(
        &mut self,
        path: &Path,
        source: &str,
        language: SourceLanguage,
        set: &DefSet,
    ) -> Outcome {
        match compose::compose_source(self.library, path, source, language, set.to_map()) {
            Outcome::Invalid(e) => Outcome::Invalid(unsubstituted(e, path, source)),
            other => other,
        }
    }

    /// Checks `path` under its sets and adds what it found to `totals`.
    pub fn check(&mut self, path: &Path, totals: &mut Totals) {
        let file = path.display().to_string();
        let human = matches!(self.format, CheckFormat::Human);
        let fixed = DefSet::from_map(&self.planner.fixed);
        let (source, language) = match compose::read(path, self.stage) {
            Ok(x) => x,
            Err(Outcome::Invalid(e) | Outcome::Unreadable(e)) => {
                let unreadable = matches!(e, ShaderError::Io { .. });
                if unreadable {
                    totals.unreadable += 1;
                } else {
                    totals.invalid += 1;
                }
                if human {
                    compose::print_error(&e);
                }
                totals.findings.push(Finding::from_error(path, &e, &fixed));
                totals.reports.push(serde_json::json!({"file": file, "valid": false, "entry_points": [], "diagnostics": [compose::error_json(path, &e)]}));
                return;
            }
            Err(Outcome::Valid(_)) => unreachable!("read() gives no composed module"),
        };
        let plan = self.planner.plan(path, &source);
        let permute = self.planner.permute;
        let count = plan.sets.len();
        totals.sets += count;
        let mut failures: Vec<Failure> = Vec::new();
        let mut entry_points: Option<Vec<String>> = None;
        let mut stats_json = Vec::new();
        for set in &plan.sets {
            match self.compose(path, &source, language, set) {
                Outcome::Valid(c) => {
                    entry_points.get_or_insert_with(|| {
                        c.module
                            .entry_points
                            .iter()
                            .map(|e| e.name.clone())
                            .collect()
                    });
                    if self.stats || self.budget.is_some() {
                        let costs = shaders::cost::entry_point_costs(&c.module);
                        if self.stats && human && permute {
                            self.out.println(&format!("  shader defs {set}:"));
                        }
                        for cost in &costs {
                            if let Some(b) = self.budget.as_deref_mut() {
                                b.set_defs(&set.to_map());
                                for line in b.check(path, cost) {
                                    let line = if permute {
                                        format!("{line} under shader defs {set}")
                                    } else {
                                        line
                                    };
                                    totals.findings.push(Finding {
                                        rule: "budget",
                                        message: line.clone(),
                                        file: file.clone(),
                                        location: None,
                                        defs: set.clone(),
                                        failing: None,
                                        shortest: None,
                                    });
                                    totals.over.push(line);
                                }
                            }
                            if self.stats && human {
                                self.out.print(&stats::human(cost));
                            }
                        }
                        let json: Vec<serde_json::Value> = costs.iter().map(stats::json).collect();
                        stats_json.push(if permute {
                            serde_json::json!({"defs": set.args(), "entry_points": json})
                        } else {
                            serde_json::Value::Array(json)
                        });
                    }
                }
                Outcome::Invalid(e) | Outcome::Unreadable(e) => {
                    let finding = Finding::from_error(path, &e, set);
                    match failures.iter_mut().find(|f| f.finding.same_as(&finding)) {
                        Some(f) => f.sets += 1,
                        None => failures.push(Failure {
                            error: e,
                            finding,
                            sets: 1,
                        }),
                    }
                }
            }
        }
        if permute {
            for f in &mut failures {
                let shortest = self.shortest(path, &source, language, &f.finding);
                f.finding.failing = Some((f.sets, count));
                f.finding.shortest = Some(shortest);
            }
        }
        let entry_points = entry_points.unwrap_or_default();
        if failures.is_empty() && human {
            let what = if plan.description.is_empty() {
                String::new()
            } else {
                format!("; {}", plan.description)
            };
            self.out.println(&format!(
                "ok: {file} ({} entry point{}{what})",
                entry_points.len(),
                if entry_points.len() == 1 { "" } else { "s" }
            ));
        }
        if !plan.undeclared.is_empty() {
            output::eprintln(&format!(
                "note: {file} tests defs its permutation-file entry leaves out (never set): {}",
                plan.undeclared.join(", ")
            ));
        }
        for f in &failures {
            if human {
                compose::print_error(&f.error);
                if permute {
                    output::eprintln(&format!(
                        "  = shader defs {}: fails in {} of {count} sets ({}); shortest failing set {}\n",
                        f.finding.defs,
                        f.sets,
                        plan.description,
                        f.finding.shortest.as_ref().unwrap_or(&f.finding.defs)
                    ));
                }
            }
            totals.findings.push(f.finding.clone());
        }
        if failures.is_empty() {
        } else if failures
            .iter()
            .all(|f| matches!(f.error, ShaderError::Io { .. }))
        {
            totals.unreadable += 1;
        } else {
            totals.invalid += 1;
        }
        let diagnostics: Vec<serde_json::Value> = failures
            .iter()
            .map(|f| {
                let mut d = compose::error_json(path, &f.error);
                if permute {
                    d["defs"] = f.finding.defs.args().into();
                    d["failing_sets"] = f.sets.into();
                    d["shortest_failing_defs"] =
                        f.finding.shortest.as_ref().map(DefSet::args).into();
                }
                d
            })
            .collect();
        let mut report = serde_json::json!({"file": file, "valid": failures.is_empty(), "entry_points": entry_points, "diagnostics": diagnostics});
        if self.stats || self.budget.is_some() {
            report["stats"] = if permute {
                serde_json::Value::Array(stats_json)
            } else {
                stats_json
                    .into_iter()
                    .next()
                    .unwrap_or_else(|| serde_json::json!([]))
            };
        }
        if permute {
            report["sets"] = count.into();
            report["sets_described"] = plan.description.clone().into();
        }
        totals.reports.push(report);
    }

    /// The shortest set that still fails as `failure` does: drop one def at a time (never a
    /// `-D` one) while the failure stays, until no def can go.
    fn shortest(
        &mut self,
        path: &Path,
        source: &str,
        language: SourceLanguage,
        failure: &Finding,
    ) -> DefSet {
        let fixed = &self.planner.fixed;
        let mut current: Vec<(String, ShaderDefValue)> = failure.defs.pairs().to_vec();
        'shrink: loop {
            for i in 0..current.len() {
                if fixed.contains_key(&current[i].0) {
                    continue;
                }
                let mut fewer = current.clone();
                fewer.remove(i);
                let set = DefSet::from_pairs(fewer.clone());
                if let Outcome::Invalid(e) | Outcome::Unreadable(e) =
                    self.compose(path, source, language, &set)
                    && Finding::from_error(path, &e, &set).same_as(failure)
                {
                    current = fewer;
                    continue 'shrink;
                }
            }
            return DefSet::from_pairs(current);
        }
    }
}

/// A parse error at a `#{NAME}` the preprocessor left in place (the def has no value in this
/// set) becomes a `preprocessor` diagnostic that says so; naga only sees a stray `#`.
fn unsubstituted(e: ShaderError, path: &Path, source: &str) -> ShaderError {
    let ShaderError::Source(d) = &e else {
        return e;
    };
    let (Some(at), shaders::DiagnosticKind::Parse) = (d.location, d.kind) else {
        return e;
    };
    let text = if d.file == path.display().to_string() {
        Some(source.to_owned())
    } else {
        std::fs::read_to_string(&d.file).ok()
    };
    let name = text.as_deref().and_then(|t| {
        let line = t.lines().nth(at.line.checked_sub(1)?)?;
        let rest: String = line.chars().skip(at.column.checked_sub(1)?).collect();
        let inner = rest.strip_prefix("#{")?;
        Some(inner[..inner.find('}')?].to_owned())
    });
    let Some(name) = name else {
        return e;
    };
    let mut d = (**d).clone();
    d.notes.insert(0, d.message.clone());
    d.kind = shaders::DiagnosticKind::Preprocessor;
    d.message =
        format!("shader def `{name}` has no value here, so `#{{{name}}}` is left in the source");
    ShaderError::Source(Box::new(d.with_hint(format!(
        "give it one: -D {name}=VALUE, or `values` in a permutation file"
    ))))
}
