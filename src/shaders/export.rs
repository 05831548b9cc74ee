//! Export a composed module through naga's back ends: SPIR-V, MSL, HLSL, GLSL 450, GLSL ES, WGSL.

use std::fmt;
use std::str::FromStr;

use naga::back;

use super::{Composed, ShaderError};

/// A back end to export to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ExportTarget {
    /// SPIR-V 1.0 binary (all entry points).
    SpirV,
    /// Metal Shading Language 2.0 (all entry points).
    Msl,
    /// HLSL shader model 5.1 (all entry points).
    Hlsl,
    /// GLSL 450 core (one entry point).
    Glsl,
    /// GLSL ES 3.00, or 3.10 for compute (one entry point).
    GlslEs,
    /// WGSL with every import inlined (all entry points).
    Wgsl,
}

impl ExportTarget {
    /// Every target, in the order the CLI lists them.
    pub const ALL: [ExportTarget; 6] = [
        Self::SpirV,
        Self::Msl,
        Self::Hlsl,
        Self::Glsl,
        Self::GlslEs,
        Self::Wgsl,
    ];

    /// The name the CLI takes (`spv`, `msl`, `hlsl`, `glsl`, `glsl-es`, `wgsl`).
    pub fn name(self) -> &'static str {
        match self {
            Self::SpirV => "spv",
            Self::Msl => "msl",
            Self::Hlsl => "hlsl",
            Self::Glsl => "glsl",
            Self::GlslEs => "glsl-es",
            Self::Wgsl => "wgsl",
        }
    }

    /// Whether this back end writes one entry point per output.
    pub fn one_entry_point(self) -> bool {
        matches!(self, Self::Glsl | Self::GlslEs)
    }
}

impl fmt::Display for ExportTarget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ExportTarget {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| {
                format!("unknown target `{s}` (expected spv, msl, hlsl, glsl, glsl-es or wgsl)")
            })
    }
}

/// Options for [`export`].
#[derive(Clone, Debug, Default)]
pub struct ExportOptions {
    /// Entry point to write for the GLSL targets; may be left out when the module has exactly one.
    pub entry_point: Option<String>,
}

/// What a back end wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Exported {
    /// Source text (MSL, HLSL, GLSL, WGSL).
    Text(String),
    /// SPIR-V words.
    SpirV(Vec<u32>),
}

impl Exported {
    /// The bytes to write to a file (SPIR-V little-endian).
    pub fn to_bytes(&self) -> Vec<u8> {
        match self {
            Self::Text(s) => s.as_bytes().to_vec(),
            Self::SpirV(words) => words.iter().flat_map(|w| w.to_le_bytes()).collect(),
        }
    }
}

/// Writes `composed` with the back end `target`. The back ends recurse once per nested block
/// and expression, which composed GLSL may nest thousands deep: they run on a deep-stack thread.
pub fn export(
    composed: &Composed,
    target: ExportTarget,
    options: &ExportOptions,
) -> Result<Exported, ShaderError> {
    super::limits::on_deep_stack(|| write(composed, target, options)).unwrap_or_else(|()| {
        Err(ShaderError::Export {
            target,
            message: "naga's back end panicked on this module".into(),
        })
    })
}

fn write(
    composed: &Composed,
    target: ExportTarget,
    options: &ExportOptions,
) -> Result<Exported, ShaderError> {
    let (module, info) = (&composed.module, &composed.info);
    let fail = |message: String| ShaderError::Export { target, message };
    match target {
        ExportTarget::SpirV => {
            back::spv::write_vec(module, info, &back::spv::Options::default(), None)
                .map(Exported::SpirV)
                .map_err(|e| fail(e.to_string()))
        }
        ExportTarget::Msl => {
            let options = back::msl::Options {
                lang_version: (2, 0),
                ..Default::default()
            };
            back::msl::write_string(module, info, &options, &Default::default())
                .map(|(s, _)| Exported::Text(s))
                .map_err(|e| fail(e.to_string()))
        }
        ExportTarget::Hlsl => {
            let mut out = String::new();
            let options = back::hlsl::Options::default();
            let pipeline = back::hlsl::PipelineOptions::default();
            back::hlsl::Writer::new(&mut out, &options, &pipeline)
                .write(module, info, None)
                .map_err(|e| fail(e.to_string()))?;
            Ok(Exported::Text(out))
        }
        ExportTarget::Glsl | ExportTarget::GlslEs => {
            let entry = pick_entry_point(module, options.entry_point.as_deref())
                .map_err(ShaderError::EntryPoint)?;
            let version = match (target, entry.stage) {
                (ExportTarget::Glsl, _) => back::glsl::Version::Desktop(450),
                (_, naga::ShaderStage::Compute) => back::glsl::Version::new_gles(310),
                _ => back::glsl::Version::new_gles(300),
            };
            let glsl_options = back::glsl::Options {
                version,
                ..Default::default()
            };
            let pipeline = back::glsl::PipelineOptions {
                shader_stage: entry.stage,
                entry_point: entry.name.clone(),
                multiview: None,
            };
            let mut out = String::new();
            back::glsl::Writer::new(
                &mut out,
                module,
                info,
                &glsl_options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .and_then(|mut w| w.write())
            .map_err(|e| fail(e.to_string()))?;
            Ok(Exported::Text(out))
        }
        ExportTarget::Wgsl => {
            back::wgsl::write_string(module, info, back::wgsl::WriterFlags::empty())
                .map(Exported::Text)
                .map_err(|e| fail(e.to_string()))
        }
    }
}

fn pick_entry_point<'m>(
    module: &'m naga::Module,
    wanted: Option<&str>,
) -> Result<&'m naga::ir::EntryPoint, String> {
    let names = || {
        module
            .entry_points
            .iter()
            .map(|e| e.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    match wanted {
        Some(name) => module
            .entry_points
            .iter()
            .find(|e| e.name == name)
            .ok_or_else(|| format!("no entry point `{name}` (the module has: {})", names())),
        None => match module.entry_points.as_slice() {
            [one] => Ok(one),
            [] => Err("the module has no entry point; GLSL output needs one".to_owned()),
            _ => Err(format!(
                "the module has several entry points ({}); choose one with --entry",
                names()
            )),
        },
    }
}
