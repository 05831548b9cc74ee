//! LOD configuration in RON: global bias, hysteresis, transition mode and duration, and named
//! groups.
//!
//! ```ron
//! LodConfig(
//!     bias: 1.0,
//!     hysteresis: 10.0,
//!     transition: Time(seconds: 0.5),   // or Hard, or Distance
//!     groups: {
//!         "tree": (
//!             levels: [(distance: 0.0, mesh: "tree_lod0"), (distance: 40.0, mesh: "tree_lod1")],
//!             max_distance: Some(300.0),
//!         ),
//!     },
//! )
//! ```

use std::collections::BTreeMap;

use super::{LodError, LodGroup, LodLevel, LodSettings, TransitionMode};

/// A whole LOD configuration as written in RON.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LodConfig {
    /// Global LOD bias (default 1).
    #[serde(default = "one")]
    pub bias: f32,
    /// Hysteresis band width h (default 0).
    #[serde(default)]
    pub hysteresis: f32,
    /// How switches are staged (default `Distance`).
    #[serde(default)]
    pub transition: TransitionMode,
    /// Groups by name.
    pub groups: BTreeMap<String, GroupConfig>,
}

/// One named group in a [`LodConfig`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupConfig {
    /// Levels in any order.
    pub levels: Vec<LodLevel>,
    /// Max draw distance, if any.
    #[serde(default)]
    pub max_distance: Option<f32>,
}

fn one() -> f32 {
    1.0
}

/// Why a configuration could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// The text is not valid RON for a [`LodConfig`].
    #[error("{line}:{column}: {message}")]
    Ron {
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// The field the problem is about, when there is one.
        field: Option<String>,
        /// What RON said.
        message: String,
    },
    /// The RON parsed but a value is out of range.
    #[error("{path}: {source}")]
    Invalid {
        /// Where the value is, e.g. `groups["tree"].levels[1].distance`.
        path: String,
        /// What is wrong with it.
        source: LodError,
    },
}

impl LodConfig {
    /// Parses and validates a configuration.
    ///
    /// ```
    /// # use lodkit::select::config::{ConfigError, LodConfig};
    /// let err = LodConfig::from_ron("LodConfig(groups: {}, hysterisis: 2.0)").unwrap_err();
    /// match err {
    ///     ConfigError::Ron { line, column, field, .. } => {
    ///         assert_eq!((line, field.as_deref()), (1, Some("hysterisis")));
    ///         assert!(column > 1);
    ///     }
    ///     other => panic!("{other}"),
    /// }
    /// ```
    pub fn from_ron(text: &str) -> Result<Self, ConfigError> {
        let config: LodConfig = ron::from_str(text).map_err(|e| {
            let field = match &e.code {
                ron::Error::NoSuchStructField { found, .. } => Some(found.clone()),
                ron::Error::MissingStructField { field, .. }
                | ron::Error::DuplicateStructField { field, .. } => Some((*field).to_owned()),
                _ => None,
            };
            ConfigError::Ron {
                line: e.span.start.line,
                column: e.span.start.col,
                field,
                message: e.code.to_string(),
            }
        })?;
        config.groups()?;
        Ok(config)
    }

    /// The settings part (bias, hysteresis, transition), validated.
    pub fn settings(&self) -> Result<LodSettings, ConfigError> {
        let settings = LodSettings {
            bias: self.bias,
            hysteresis: self.hysteresis,
            transition: self.transition,
        };
        settings.validate().map_err(|source| ConfigError::Invalid {
            path: match source {
                LodError::BadBias(_) => "bias",
                LodError::BadHysteresis(_) => "hysteresis",
                _ => "transition",
            }
            .to_owned(),
            source,
        })?;
        Ok(settings)
    }

    /// The groups, built and validated, in name order.
    pub fn groups(&self) -> Result<Vec<(String, LodGroup)>, ConfigError> {
        self.settings()?;
        self.groups
            .iter()
            .map(|(name, g)| {
                let invalid = |field: String, source| ConfigError::Invalid {
                    path: format!("groups[{name:?}].{field}"),
                    source,
                };
                let group = LodGroup::new(g.levels.iter().cloned()).map_err(|e| match e {
                    LodError::BadDistance { index, .. } => {
                        invalid(format!("levels[{index}].distance"), e)
                    }
                    e => invalid("levels".to_owned(), e),
                })?;
                let group = match g.max_distance {
                    Some(max) => group
                        .with_max_distance(max)
                        .map_err(|e| invalid("max_distance".to_owned(), e))?,
                    None => group,
                };
                Ok((name.clone(), group))
            })
            .collect()
    }
}
