//! What `lodkit check` found, in the forms CI shows: a SARIF 2.1.0 log (GitHub code scanning,
//! IDE viewers) and GitHub Actions workflow commands (annotations on a pull request's lines).

use percent_encoding::{AsciiSet, NON_ALPHANUMERIC, utf8_percent_encode};
use serde_sarif::sarif;

use super::Finding;
use lodkit::shaders::DiagnosticKind;

/// Every rule `lodkit check` reports under, id then description: one per kind of diagnostic,
/// then `io` (a file that cannot be read), `export` (a back end that failed) and `budget` (an
/// entry point over its `--budget`).
pub const RULES: &[(&str, &str)] = &[
    (
        "parse",
        "The source does not parse, or the front end rejects a name or a call.",
    ),
    (
        "unknown-import",
        "An #import, import or #include names a module that does not exist.",
    ),
    ("import-cycle", "Modules import each other in a cycle."),
    (
        "duplicate-module",
        "Two modules declare the same import path.",
    ),
    ("invalid-utf8", "The file is not valid UTF-8."),
    (
        "preprocessor",
        "A preprocessor directive or shader def is malformed or left unsubstituted.",
    ),
    (
        "validation",
        "The module parses but naga's validator rejects it (types, uniformity, layout).",
    ),
    (
        "limit",
        "The source goes past a nesting or size limit lodkit sets.",
    ),
    ("io", "A file cannot be read, or its language is unknown."),
    ("export", "A back end could not write the module."),
    (
        "budget",
        "An entry point goes over its shader-cost budget, or has a loop it cannot bound.",
    ),
];

/// The rule id of each diagnostic kind; the match makes a new kind a compile error here until
/// it has a rule.
pub fn rule_of(kind: DiagnosticKind) -> &'static str {
    match kind {
        DiagnosticKind::Parse
        | DiagnosticKind::UnknownImport
        | DiagnosticKind::ImportCycle
        | DiagnosticKind::DuplicateModule
        | DiagnosticKind::InvalidUtf8
        | DiagnosticKind::Preprocessor
        | DiagnosticKind::Validation
        | DiagnosticKind::Limit => kind.code(),
    }
}

/// Characters kept as they are in a path made a URI reference: RFC 3986's unreserved ones and `/`.
const PATH: &AsciiSet = &NON_ALPHANUMERIC
    .remove(b'-')
    .remove(b'.')
    .remove(b'_')
    .remove(b'~')
    .remove(b'/');

/// `file` as a SARIF artifact URI: a relative path stays relative (GitHub resolves it from the
/// repository root), an absolute one becomes `file:///...`; `\` becomes `/`.
pub fn artifact_uri(file: &str) -> String {
    let slashed = file.replace('\\', "/");
    let encoded = utf8_percent_encode(&slashed, PATH).to_string();
    if slashed.starts_with('/') {
        format!("file://{encoded}")
    } else if slashed.as_bytes().get(1) == Some(&b':') {
        // A Windows drive (C:/...): the colon stays.
        let (drive, rest) = slashed.split_at(2);
        format!("file:///{drive}{}", utf8_percent_encode(rest, PATH))
    } else {
        encoded
    }
}

/// The text of a finding: the message, then the shader defs it was composed with (and, from a
/// check of many sets, in how many it fails and the shortest set that still fails).
pub fn message_text(f: &Finding) -> String {
    let mut text = format!("{} (shader defs {}", f.message, f.defs);
    if let Some((failing, of)) = f.failing {
        text.push_str(&format!("; fails in {failing} of {of} sets"));
    }
    if let Some(shortest) = &f.shortest {
        text.push_str(&format!("; shortest failing set {shortest}"));
    }
    text.push(')');
    text
}

/// The SARIF 2.1.0 log of `findings`, one result per finding at level `error`.
/// `completed` is false when the check stopped before the first file.
pub fn sarif(findings: &[Finding], completed: bool) -> String {
    let rules: Vec<sarif::ReportingDescriptor> = RULES
        .iter()
        .map(|(id, text)| {
            sarif::ReportingDescriptor::builder()
                .id(*id)
                .short_description(
                    sarif::MultiformatMessageString::builder()
                        .text(*text)
                        .build(),
                )
                .build()
        })
        .collect();
    let results: Vec<sarif::Result> = findings.iter().map(result).collect();
    let driver = sarif::ToolComponent::builder()
        .name("lodkit")
        .version(env!("CARGO_PKG_VERSION"))
        .semantic_version(env!("CARGO_PKG_VERSION"))
        .information_uri(env!("CARGO_PKG_HOMEPAGE"))
        .rules(rules)
        .build();
    let run = sarif::Run::builder()
        .tool(sarif::Tool::builder().driver(driver).build())
        .invocations(vec![
            sarif::Invocation::builder()
                .execution_successful(completed)
                .build(),
        ])
        // lodkit's columns count characters, not UTF-16 code units (SARIF's default).
        .column_kind(serde_json::json!("unicodeCodePoints"))
        .results(results)
        .build();
    let log = sarif::Sarif::builder()
        .schema(sarif::SCHEMA_URL)
        .version(serde_json::json!("2.1.0"))
        .runs(vec![run])
        .build();
    // A log of strings and numbers always serializes.
    serde_json::to_string_pretty(&log).unwrap_or_default()
}

fn result(f: &Finding) -> sarif::Result {
    let mut physical = sarif::PhysicalLocation::builder()
        .artifact_location(
            sarif::ArtifactLocation::builder()
                .uri(artifact_uri(&f.file))
                .build(),
        )
        .build();
    if let Some(l) = f.location {
        physical.region = Some(
            sarif::Region::builder()
                .start_line(l.line as i64)
                .start_column(l.column as i64)
                .build(),
        );
    }
    let properties = sarif::PropertyBag::builder()
        .additional_properties(
            [
                Some(("shaderDefs".to_owned(), serde_json::json!(f.defs.args()))),
                f.shortest.as_ref().map(|s| {
                    (
                        "shortestFailingShaderDefs".to_owned(),
                        serde_json::json!(s.args()),
                    )
                }),
            ]
            .into_iter()
            .flatten()
            .collect::<std::collections::BTreeMap<_, _>>(),
        )
        .build();
    let mut result = sarif::Result::builder()
        .rule_id(f.rule)
        .level(sarif::ResultLevel::Error)
        .message(sarif::Message::builder().text(message_text(f)).build())
        .properties(properties)
        .build();
    if !f.file.is_empty() {
        result.locations = Some(vec![
            sarif::Location::builder()
                .physical_location(physical)
                .build(),
        ]);
    }
    if let Some(i) = RULES.iter().position(|(id, _)| *id == f.rule) {
        result.rule_index = Some(i as i64);
    }
    result
}

/// Escapes workflow-command data: `%`, CR and LF.
fn escape_data(s: &str) -> String {
    s.replace('%', "%25")
        .replace('\r', "%0D")
        .replace('\n', "%0A")
}

/// Escapes a workflow-command property value: as data, plus `:` and `,`.
fn escape_property(s: &str) -> String {
    escape_data(s).replace(':', "%3A").replace(',', "%2C")
}

/// One `::error file=F,line=L,col=C,title=lodkit RULE::MESSAGE` line per finding.
pub fn github(findings: &[Finding]) -> String {
    let mut out = String::new();
    for f in findings {
        let mut props = Vec::new();
        if !f.file.is_empty() {
            props.push(format!("file={}", escape_property(&f.file)));
        }
        if let Some(l) = f.location {
            props.push(format!("line={}", l.line));
            props.push(format!("col={}", l.column));
        }
        props.push(format!("title=lodkit {}", f.rule));
        out.push_str(&format!(
            "::error {}::{}\n",
            props.join(","),
            escape_data(&message_text(f))
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn artifact_uris_are_uri_references() {
        assert_eq!(artifact_uri("shaders/a b.wgsl"), "shaders/a%20b.wgsl");
        assert_eq!(artifact_uri("/srv/x/%.wgsl"), "file:///srv/x/%25.wgsl");
        assert_eq!(artifact_uri(r"C:\src\é.wgsl"), "file:///C:/src/%C3%A9.wgsl");
    }

    #[test]
    fn workflow_command_escapes() {
        assert_eq!(escape_data("50%\r\nnext"), "50%25%0D%0Anext");
        assert_eq!(escape_property("a:b,c%"), "a%3Ab%2Cc%25");
    }

    #[test]
    fn every_diagnostic_kind_has_a_rule() {
        for kind in [
            DiagnosticKind::Parse,
            DiagnosticKind::UnknownImport,
            DiagnosticKind::ImportCycle,
            DiagnosticKind::DuplicateModule,
            DiagnosticKind::InvalidUtf8,
            DiagnosticKind::Preprocessor,
            DiagnosticKind::Validation,
            DiagnosticKind::Limit,
        ] {
            assert!(RULES.iter().any(|(id, _)| *id == rule_of(kind)), "{kind:?}");
        }
    }
}
