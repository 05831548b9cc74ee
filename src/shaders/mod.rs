//! The shader library: every module under `shader_lib/` embedded and described, composition of
//! user shaders that import it (naga_oil), validation (naga) and export to every naga back end.
//!
//! - [`modules`] lists what the library holds: import path, language, functions with their doc
//!   line, shader defs.
//! - [`add_to_composer`] adds every lodkit module to a naga_oil `Composer` you already own.
//! - [`ShaderLibrary`] composes your WGSL (`#import lodkit::...`) or GLSL
//!   (`#include "lodkit/....glsl"`) into a validated `naga::Module`.
//! - [`export`] writes it as SPIR-V, MSL, HLSL, GLSL 450, GLSL ES or WGSL.
//!
//! Errors are [`ShaderError`]s; problems in source carry a [`Diagnostic`] with file, line and
//! column.
//!
//! Without the `compose` feature (`default-features = false`) this module is the embedded sources
//! and their descriptions only ([`modules`], [`find_module`], ...): no naga in the tree, so an
//! engine on another naga (Bevy's) registers the sources with its own composer.

#[cfg(feature = "compose")]
mod compose;
#[cfg(feature = "compose")]
mod diagnostic;
#[cfg(feature = "compose")]
mod export;
#[cfg(feature = "compose")]
mod glsl;
#[cfg(feature = "compose")]
mod imports;
#[cfg(feature = "compose")]
mod limits;
mod registry;

#[cfg(feature = "compose")]
mod errors;
#[cfg(feature = "compose")]
pub(crate) use errors::closest;
#[cfg(feature = "compose")]
pub use errors::{ShaderError, read_source};

#[cfg(feature = "compose")]
pub use compose::{
    ComposeDescriptor, Composed, LibraryDescriptor, ShaderDefs, ShaderLibrary, SourceLanguage,
    add_to_composer, validate,
};
#[cfg(feature = "compose")]
pub use diagnostic::{Diagnostic, DiagnosticKind, Location};
#[cfg(feature = "compose")]
pub use export::{ExportOptions, ExportTarget, Exported, export};
#[cfg(feature = "compose")]
pub use limits::MAX_NESTING;
#[cfg(feature = "compose")]
pub use naga;
#[cfg(feature = "compose")]
pub use naga_oil;
#[cfg(feature = "compose")]
pub use naga_oil::compose::ShaderDefValue;
pub use registry::{
    FunctionInfo, Language, ModuleInfo, ModuleKind, ShaderDefInfo, find_glsl_include, find_module,
    glsl_twin, import_paths, modules,
};

/// Source of the pass `shader_lib/passes/<name>.wgsl`, if there is one.
pub fn find_pass_source(name: &str) -> Option<&'static str> {
    let path = format!("passes/{name}.wgsl");
    modules().iter().find(|m| m.path == path).map(|m| m.source)
}
