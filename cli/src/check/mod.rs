//! `lodkit check`: compose each shader against the lodkit modules (and the user's), validate it,
//! count its cost (`--stats`, `--budget`), and report what failed for people, as JSON, as SARIF
//! 2.1.0 or as GitHub workflow commands. With `--permute` or `--permutations FILE` each shader
//! is checked under many shader-def sets ([`plan`]), each distinct composed module validated
//! once, and each failure reduced to the shortest def set that still fails.

mod defs;
mod discover;
mod file;
mod permfile;
mod plan;
mod report;
mod sets;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::ValueEnum;
use lodkit::shaders::{Location, ShaderDefValue, ShaderError};

use crate::compose;
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
    /// The shader defs the file was composed with (the first set that failed).
    pub defs: DefSet,
    /// In a check of many sets: the sets that fail this way, of the sets checked.
    pub failing: Option<(usize, usize)>,
    /// In a check of many sets: the shortest def set that still fails this way.
    pub shortest: Option<DefSet>,
}

impl Finding {
    fn from_error(file: &Path, e: &ShaderError, defs: &DefSet) -> Self {
        let (rule, message, file, location) = match e.diagnostic() {
            Some(d) => (
                report::rule_of(d.kind),
                match &d.hint {
                    Some(hint) => format!("{} ({hint})", d.message),
                    None => d.message.clone(),
                },
                d.file.clone(),
                d.location,
            ),
            None => (
                match e {
                    ShaderError::Io { .. } => "io",
                    _ => "export",
                },
                e.to_string(),
                file.display().to_string(),
                None,
            ),
        };
        Self {
            rule,
            message,
            file,
            location,
            defs: defs.clone(),
            failing: None,
            shortest: None,
        }
    }

    /// The same failure: same rule, place and message (under whichever defs).
    fn same_as(&self, other: &Finding) -> bool {
        (self.rule, &self.message, &self.file, self.location)
            == (other.rule, &other.message, &other.file, other.location)
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
    /// `--permute`: check the combinations of the defs each shader tests.
    pub permute: bool,
    /// `--permutations FILE`: the sets a permutation file declares.
    pub permutations: Option<&'a Path>,
    /// `--max-sets N`.
    pub max_sets: usize,
    /// The shaders.
    pub files: &'a [PathBuf],
}

/// What the files of a check came to.
#[derive(Default)]
struct Totals {
    invalid: usize,
    unreadable: usize,
    sets: usize,
    over: Vec<String>,
    findings: Vec<Finding>,
    reports: Vec<serde_json::Value>,
}

/// Runs `lodkit check`: exit 0 all valid and within budget, 1 a shader invalid or over budget,
/// 2 a file unreadable or a usage error.
pub fn run(run: &CheckRun) -> ExitCode {
    let started = Instant::now();
    let (args, format) = (run.compose, run.format);
    let fixed: std::collections::HashMap<String, ShaderDefValue> =
        args.define.iter().cloned().collect();
    let def_set = DefSet::from_map(&fixed);
    let mut budget = match run
        .budget
        .map(|b| stats::Budget::load(b, &fixed))
        .transpose()
    {
        Ok(b) => b,
        Err(e) => {
            output::eprintln(&format!("error[budget]: {e}"));
            return ExitCode::from(2);
        }
    };
    let file = match run
        .permutations
        .map(permfile::PermutationFile::load)
        .transpose()
    {
        Ok(f) => f,
        Err(e) => {
            output::eprintln(&format!("error[permutations]: {e}"));
            return ExitCode::from(2);
        }
    };
    let permute = run.permute || file.is_some();
    if run.max_sets == 0 {
        output::eprintln("error: --max-sets must be 1 or more");
        return ExitCode::from(2);
    }
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
    if permute {
        library.remember_validations();
    }
    let planner = plan::Planner {
        fixed,
        permute,
        max_sets: run.max_sets,
        file,
        sources: if permute {
            discover::Sources::scan(&args.include, &args.exclude)
        } else {
            discover::Sources::scan(&[], &[])
        },
    };
    let mut totals = Totals::default();
    let mut ctx = file::FileCheck {
        library: &mut library,
        planner: &planner,
        stage: args.stage,
        format,
        stats: run.stats,
        budget: budget.as_mut(),
        out: &mut out,
    };
    for path in run.files {
        ctx.check(path, &mut totals);
    }
    if let Some(b) = &budget {
        for key in b.unused() {
            output::eprintln(&format!(
                "warning[budget]: no entry point of the files checked matches \"{key}\""
            ));
        }
    }
    let files = run.files.len();
    let Totals {
        invalid,
        unreadable,
        over,
        findings,
        reports,
        sets,
    } = totals;
    let counts = library.validation_counts().unwrap_or_default();
    let closing = format!(
        "checked {files} file{} under {sets} shader-def set{}: {} valid, {invalid} invalid, \
         {unreadable} unreadable{}; {} distinct modules validated, {} reused; {:.2} s",
        if files == 1 { "" } else { "s" },
        if sets == 1 { "" } else { "s" },
        files - invalid - unreadable,
        if budget.is_some() {
            format!(", {} over budget", over.len())
        } else {
            String::new()
        },
        counts.validated,
        counts.reused,
        started.elapsed().as_secs_f64()
    );
    match format {
        CheckFormat::Json => {
            let mut doc = serde_json::json!({"valid": invalid + unreadable == 0, "files": reports});
            if budget.is_some() {
                doc["within_budget"] = over.is_empty().into();
                doc["over_budget"] = over.clone().into();
            }
            if permute {
                doc["sets_checked"] = sets.into();
                doc["modules_validated"] = counts.validated.into();
            }
            out.println(&doc.to_string())
        }
        CheckFormat::Sarif => out.println(&report::sarif(&findings, true)),
        CheckFormat::Github => out.print(&report::github(&findings)),
        CheckFormat::Human => {
            for line in &over {
                output::eprintln(&format!("error[budget]: {line}"));
            }
            if permute {
                output::eprintln(&closing);
            } else if files > 1 {
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
    if permute && !matches!(format, CheckFormat::Human) {
        output::eprintln(&closing);
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
