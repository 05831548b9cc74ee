//! A set of shader defs as `lodkit check` names it in its reports: `{A, B=3, C=false}`.

use std::collections::HashMap;
use std::fmt;

use lodkit::shaders::ShaderDefValue;

/// Shader defs with their values, sorted by name.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct DefSet(Vec<(String, ShaderDefValue)>);

impl DefSet {
    /// The defs of `map`, sorted by name.
    pub fn from_map(map: &HashMap<String, ShaderDefValue>) -> Self {
        let mut defs: Vec<_> = map.iter().map(|(k, v)| (k.clone(), *v)).collect();
        defs.sort_by(|a, b| a.0.cmp(&b.0));
        Self(defs)
    }

    /// The defs of `pairs`, sorted by name.
    pub fn from_pairs(mut pairs: Vec<(String, ShaderDefValue)>) -> Self {
        pairs.sort_by(|a, b| a.0.cmp(&b.0));
        Self(pairs)
    }

    /// The defs, sorted by name.
    pub fn pairs(&self) -> &[(String, ShaderDefValue)] {
        &self.0
    }

    /// The defs as the composer takes them.
    pub fn to_map(&self) -> HashMap<String, ShaderDefValue> {
        self.0.iter().cloned().collect()
    }

    /// Each def as `-D` takes it (`A`, `B=3`, `C=3u`, `D=false`).
    pub fn args(&self) -> Vec<String> {
        self.0.iter().map(|(k, v)| def_arg(k, v)).collect()
    }
}

/// `NAME` for true, else `NAME=VALUE` as `-D` takes it.
pub fn def_arg(name: &str, value: &ShaderDefValue) -> String {
    match value {
        ShaderDefValue::Bool(true) => name.to_owned(),
        ShaderDefValue::Bool(false) => format!("{name}=false"),
        ShaderDefValue::Int(i) => format!("{name}={i}"),
        ShaderDefValue::UInt(u) => format!("{name}={u}u"),
    }
}

impl fmt::Display for DefSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{{{}}}", self.args().join(", "))
    }
}
