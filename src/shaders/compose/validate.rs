//! Validation of composed modules, and the validator capabilities `lodkit check` takes.

use std::sync::Arc;

use crate::shaders::ShaderError;
use crate::shaders::diagnostic::validation_diagnostic;

/// Parses a list of naga validator capabilities, as `lodkit check --capabilities` takes it:
/// `all`, or names separated by commas, case-insensitive, `-` or `_` between words
/// (`immediates,float64,shader-int64`). `push-constants` is an alias of `IMMEDIATES`, `f64` of
/// `FLOAT64`, `int64` of `SHADER_INT64`, `f16` of `SHADER_FLOAT16`. An unknown name is an error
/// that lists the known ones.
pub fn parse_capabilities(list: &str) -> Result<naga::valid::Capabilities, String> {
    use naga::valid::Capabilities;
    let mut caps = Capabilities::empty();
    for raw in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let name = raw.to_ascii_uppercase().replace('-', "_");
        let flag = match name.as_str() {
            "ALL" => Capabilities::all(),
            "PUSH_CONSTANT" | "PUSH_CONSTANTS" => Capabilities::IMMEDIATES,
            "F64" => Capabilities::FLOAT64,
            "INT64" | "I64" => Capabilities::SHADER_INT64,
            "F16" => Capabilities::SHADER_FLOAT16,
            other => Capabilities::from_name(other).ok_or_else(|| {
                let known: Vec<String> = Capabilities::all()
                    .iter_names()
                    .map(|(n, _)| n.to_ascii_lowercase().replace('_', "-"))
                    .collect();
                format!(
                    "unknown capability `{raw}`; known: all, {} (aliases: push-constants, f64, int64, f16)",
                    known.join(", ")
                )
            })?,
        };
        caps |= flag;
    }
    Ok(caps)
}

/// Validates a naga module (one you built yourself) with `capabilities`.
pub fn validate(
    module: &naga::Module,
    capabilities: naga::valid::Capabilities,
) -> Result<naga::valid::ModuleInfo, ShaderError> {
    validate_with(module, capabilities, "<module>")
}

fn validate_with(
    module: &naga::Module,
    capabilities: naga::valid::Capabilities,
    file: &str,
) -> Result<naga::valid::ModuleInfo, ShaderError> {
    crate::shaders::memo::validate(None, module, capabilities)
        .map_err(|e| validation_error(&e, file))
}

pub(super) fn validation_error(
    e: &naga::WithSpan<naga::valid::ValidationError>,
    file: &str,
) -> ShaderError {
    ShaderError::Source(Box::new(validation_diagnostic(
        e,
        file.to_owned(),
        Arc::from(""),
        |_| 0..0,
    )))
}
