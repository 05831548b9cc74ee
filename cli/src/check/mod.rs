//! `lodkit check`: compose each shader against the lodkit modules (and the user's), validate it,
//! count its cost (`--stats`, `--budget`), and report what failed for people, as JSON, as SARIF
//! 2.1.0 or as GitHub workflow commands.

mod defs;
mod report;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::ValueEnum;
use lodkit::shaders::{self, Location, ShaderDefValue, ShaderError};

use crate::compose::{self, Outcome};
use crate::output::{self, Output};
use crate::{ComposeArgs, stats};

pub use defs::DefSet;

/// How `lodkit check` reports.
#[derive(Clone, Copy, Default, ValueEnum)]
pub enum CheckFormat {
    /// Diagnostics for people: file:line:col, the source line, a caret.
    #[default]
    Human,
    /// One JSON document on stdout, for CI tools.
    Json,
    /// One SARIF 2.1.0 log on stdout (GitHub code scanning, IDE viewers): a rule per kind of
    /// error, each result with its file, line, column and shader defs.
    Sarif,
    /// One GitHub Actions workflow command per error on stdout
    /// (`::error file=F,line=L,col=C::message`), shown on the pull request's lines.
    Github,
}

/// One thing that failed: an invalid or unreadable shader, or an entry point over budget.
#[derive(Clone, Debug)]
pub struct Finding {
    /// Stable rule id (a [`report::RULES`] id): the diagnostic's kind, `io` or `budget`.
    pub rule: &'static str,
    /// What is wrong, with the hint when there is one.
    pub message: String,
    /// The file, as given on the command line (or the lodkit module the error is in).
    pub file: String,
    /// Line and column, when the problem has one.
    pub location: Option<Location>,
    /// The shader defs the file was composed with.
    pub defs: DefSet,
}

impl Finding {
    fn from_error(file: &Path, e: &ShaderError, defs: &DefSet) -> Self {
        match e.diagnostic() {
            Some(d) => Self {
                rule: report::rule_of(d.kind),
                message: match &d.hint {
                    Some(hint) => format!("{} ({hint})", d.message),
                    None => d.message.clone(),
                },
                file: d.file.clone(),
                location: d.location,
                defs: defs.clone(),
            },
            None => Self {
                rule: match e {
                    ShaderError::Io { .. } => "io",
                    _ => "export",
                },
                message: e.to_string(),
                file: file.display().to_string(),
                location: None,
                defs: defs.clone(),
            },
        }
    }
}

/// What `lodkit check` was asked to do.
pub struct CheckRun<'a> {
    /// `-I`, `-D`, `--stage`, `--capabilities`, `--exclude`.
    pub compose: &'a ComposeArgs,
    /// How to report.
    pub format: CheckFormat,
    /// `--stats`.
    pub stats: bool,
    /// `--budget FILE`.
    pub budget: Option<&'a Path>,
    /// The shaders.
    pub files: &'a [PathBuf],
}

/// Runs `lodkit check`: exit 0 all valid and within budget, 1 a shader invalid or over budget,
/// 2 a file unreadable or a usage error.
pub fn run(run: &CheckRun) -> ExitCode {
    let (args, format) = (run.compose, run.format);
    let defs: HashMap<String, ShaderDefValue> = args.define.iter().cloned().collect();
    let def_set = DefSet::from_map(&defs);
    let mut budget = match run
        .budget
        .map(|b| stats::Budget::load(b, &defs))
        .transpose()
    {
        Ok(b) => b,
        Err(e) => {
            output::eprintln(&format!("error[budget]: {e}"));
            return ExitCode::from(2);
        }
    };
    let mut out = Output::default();
    let mut library = match compose::library(args) {
        Ok(l) => l,
        Err(e) => {
            let code = if matches!(e, ShaderError::Io { .. }) {
                2
            } else {
                1
            };
            let finding = Finding::from_error(Path::new(""), &e, &def_set);
            report_setup_error(&mut out, format, &e, &finding);
            return out.finish(ExitCode::from(code));
        }
    };
    let (mut invalid, mut unreadable) = (0, 0);
    let mut over = Vec::new();
    let mut findings = Vec::new();
    let mut reports = Vec::new();
    for path in run.files {
        let outcome = compose::compose_file(&mut library, args, path);
        let file = path.display().to_string();
        match &outcome {
            Outcome::Valid(c) => {
                let entry_points: Vec<String> = c
                    .module
                    .entry_points
                    .iter()
                    .map(|e| e.name.clone())
                    .collect();
                if let CheckFormat::Human = format {
                    out.println(&format!(
                        "ok: {file} ({} entry point{})",
                        entry_points.len(),
                        if entry_points.len() == 1 { "" } else { "s" }
                    ));
                }
                let mut report = serde_json::json!({"file": file, "valid": true, "entry_points": entry_points, "diagnostics": []});
                if run.stats || budget.is_some() {
                    let costs = shaders::cost::entry_point_costs(&c.module);
                    for cost in &costs {
                        if let Some(b) = budget.as_mut() {
                            for line in b.check(path, cost) {
                                findings.push(Finding {
                                    rule: "budget",
                                    message: line.clone(),
                                    file: file.clone(),
                                    location: None,
                                    defs: def_set.clone(),
                                });
                                over.push(line);
                            }
                        }
                        if run.stats && matches!(format, CheckFormat::Human) {
                            out.print(&stats::human(cost));
                        }
                    }
                    report["stats"] = costs.iter().map(stats::json).collect();
                }
                reports.push(report);
            }
            Outcome::Invalid(e) | Outcome::Unreadable(e) => {
                if matches!(outcome, Outcome::Invalid(_)) {
                    invalid += 1
                } else {
                    unreadable += 1
                }
                if let CheckFormat::Human = format {
                    compose::print_error(e);
                }
                findings.push(Finding::from_error(path, e, &def_set));
                reports.push(serde_json::json!({"file": file, "valid": false, "entry_points": [], "diagnostics": [compose::error_json(path, e)]}));
            }
        }
    }
    if let Some(b) = &budget {
        for key in b.unused() {
            output::eprintln(&format!(
                "warning[budget]: no entry point of the files checked matches \"{key}\""
            ));
        }
    }
    let files = run.files.len();
    match format {
        CheckFormat::Json => {
            let mut doc = serde_json::json!({"valid": invalid + unreadable == 0, "files": reports});
            if budget.is_some() {
                doc["within_budget"] = over.is_empty().into();
                doc["over_budget"] = over.clone().into();
            }
            out.println(&doc.to_string())
        }
        CheckFormat::Sarif => out.println(&report::sarif(&findings, true)),
        CheckFormat::Github => out.print(&report::github(&findings)),
        CheckFormat::Human => {
            for line in &over {
                output::eprintln(&format!("error[budget]: {line}"));
            }
            if files > 1 {
                output::eprintln(&format!(
                    "checked {files} files: {} valid, {invalid} invalid, {unreadable} unreadable{}",
                    files - invalid - unreadable,
                    if budget.is_some() {
                        format!(", {} over budget", over.len())
                    } else {
                        String::new()
                    }
                ));
            }
        }
    }
    out.finish(ExitCode::from(if unreadable > 0 {
        2
    } else if invalid > 0 || !over.is_empty() {
        1
    } else {
        0
    }))
}

/// Reports an error that stopped the check before the first file (an `-I` folder).
fn report_setup_error(out: &mut Output, format: CheckFormat, e: &ShaderError, finding: &Finding) {
    match format {
        CheckFormat::Human => compose::print_error(e),
        CheckFormat::Json => out.println(
            &serde_json::json!({"valid": false, "files": [], "diagnostics": [compose::error_json(Path::new(""), e)]})
                .to_string(),
        ),
        CheckFormat::Sarif => out.println(&report::sarif(std::slice::from_ref(finding), false)),
        CheckFormat::Github => out.print(&report::github(std::slice::from_ref(finding))),
    }
}
