//! Validating each distinct composed module once: a check that composes one shader under many
//! shader-def sets ([`ShaderLibrary::remember_validations`](super::ShaderLibrary::remember_validations))
//! gets the same module from many sets, and naga's validator is the larger part of the cost.

use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash as _, Hasher as _};

use naga::WithSpan;
use naga::valid::{Capabilities, ModuleInfo, ValidationError, ValidationFlags, Validator};

/// What the validator said about a module.
pub(crate) type Verdict = Result<ModuleInfo, Box<WithSpan<ValidationError>>>;

/// How many modules a library validated and how many validations it reused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ValidationCounts {
    /// Distinct modules validated.
    pub validated: usize,
    /// Compositions whose module was identical to one validated before.
    pub reused: usize,
}

/// Verdicts by the hash of the module's content (its IR as `Debug` prints it: every arena's
/// items, not their source spans).
#[derive(Default)]
pub(crate) struct ValidationMemo {
    verdicts: HashMap<Key, Verdict>,
    /// The diagnostic of an invalid module of a file, where finding its place took more work
    /// (naga_oil validating it again to map the error into the user's source).
    pub(crate) located: HashMap<(Key, String), super::Diagnostic>,
    pub(crate) counts: ValidationCounts,
}

/// A module's content key.
pub(crate) type Key = (u64, usize);

/// The content key of `module`: a hash of its IR and the IR's length as printed.
pub(crate) fn key(module: &naga::Module) -> Key {
    let text = format!("{module:?}");
    let mut hasher = DefaultHasher::new();
    text.hash(&mut hasher);
    (hasher.finish(), text.len())
}

/// Validates `module` with `capabilities`, or returns the verdict on an identical module from
/// `memo`.
pub(crate) fn validate(
    memo: Option<&mut ValidationMemo>,
    module: &naga::Module,
    capabilities: Capabilities,
) -> Verdict {
    let Some(memo) = memo else {
        return run_validator(module, capabilities);
    };
    validate_keyed(memo, key(module), module, capabilities)
}

/// naga's validator on `module`, every check on.
fn run_validator(module: &naga::Module, capabilities: Capabilities) -> Verdict {
    Validator::new(ValidationFlags::all(), capabilities)
        .validate(module)
        .map_err(Box::new)
}

/// [`validate`] with the module's key computed already.
pub(crate) fn validate_keyed(
    memo: &mut ValidationMemo,
    key: Key,
    module: &naga::Module,
    capabilities: Capabilities,
) -> Verdict {
    if let Some(verdict) = memo.verdicts.get(&key) {
        memo.counts.reused += 1;
        return verdict.clone();
    }
    let verdict = run_validator(module, capabilities);
    memo.counts.validated += 1;
    memo.verdicts.insert(key, verdict.clone());
    verdict
}
