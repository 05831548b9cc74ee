//! What a [`ShaderLibrary`] does on demand: loading the lodkit modules a shader imports, and
//! validating each distinct composed module once for a check of many shader-def sets.

use std::sync::Arc;

use super::{
    ComposeDescriptor, Composed, ShaderError, ShaderLibrary, add_modules, composer_in,
    declared_imports, longest_prefix, registry, validation_error,
};

impl ShaderLibrary {
    /// Adds to the composer the lodkit modules that `sources` import or redeclare, and the
    /// modules those import: a library loads lodkit's modules when a shader or a user module
    /// first names them, so checking one file costs only the modules it uses.
    pub(super) fn load_lodkit_for<'s>(
        &mut self,
        sources: impl IntoIterator<Item = &'s str>,
    ) -> Result<(), ShaderError> {
        let mut wanted: Vec<String> = Vec::new();
        for source in sources {
            wanted.extend(declared_imports(source).into_iter().map(|(p, _)| p));
            wanted.extend(registry::define_import_path(source));
        }
        let mut needed: Vec<(&'static str, &'static str)> = Vec::new();
        while let Some(import) = wanted.pop() {
            let Some((import_path, (path, source))) =
                longest_prefix(&import, registry::find_module_source)
            else {
                continue;
            };
            let loaded = self.contains_module(import_path);
            if loaded || needed.iter().any(|(p, _)| *p == path) {
                continue;
            }
            needed.push((path, source));
            wanted.extend(declared_imports(source).into_iter().map(|(p, _)| p));
        }
        if needed.is_empty() {
            return Ok(());
        }
        let sources = needed
            .iter()
            .map(|(path, source)| (format!("shader_lib/{path}"), Arc::from(*source)))
            .collect();
        let composer = composer_in(&mut self.composer, self.capabilities);
        add_modules(composer, sources, true, None)
    }

    /// From now on, validates each distinct composed module once: a composition whose module
    /// is identical to one validated before (the same IR, hashed) takes that verdict. For a
    /// check of one shader under many shader-def sets.
    pub fn remember_validations(&mut self) {
        self.memo.get_or_insert_with(Default::default);
    }

    /// Modules validated and validations reused since [`remember_validations`](Self::remember_validations)
    /// (`None` before it).
    pub fn validation_counts(&self) -> Option<crate::shaders::memo::ValidationCounts> {
        self.memo.as_ref().map(|m| m.counts)
    }

    /// Composes WGSL with naga_oil's own validation off and validates the module once (each
    /// distinct module once after [`remember_validations`](Self::remember_validations)). A
    /// shader that fails is composed again with naga_oil validating, which places the error in
    /// the user's source; with the memo, that diagnostic is remembered too.
    pub(super) fn compose_wgsl_validated(
        &mut self,
        desc: &ComposeDescriptor,
    ) -> Result<Composed, ShaderError> {
        composer_in(&mut self.composer, self.capabilities).validate = false;
        let module = self.compose_wgsl(desc);
        composer_in(&mut self.composer, self.capabilities).validate = true;
        let module = match module {
            Ok(module) => module,
            // naga_oil's checks of its own (identifiers its WGSL writer renamed) run only when
            // it validates: the diagnostic comes from that composition.
            Err(first) => return Err(self.compose_wgsl(desc).err().unwrap_or(first)),
        };
        let key = self
            .memo
            .as_ref()
            .map(|_| crate::shaders::memo::key(&module));
        let verdict = match (self.memo.as_mut(), key) {
            (Some(memo), Some(key)) => {
                crate::shaders::memo::validate_keyed(memo, key, &module, self.capabilities)
            }
            _ => crate::shaders::memo::validate(None, &module, self.capabilities),
        };
        let e = match verdict {
            Ok(info) => return Ok(Composed { module, info }),
            Err(e) => e,
        };
        let located = key.map(|key| (key, desc.file_path.to_owned()));
        if let (Some(memo), Some(located)) = (&self.memo, &located)
            && let Some(d) = memo.located.get(located)
        {
            return Err(ShaderError::Source(Box::new(d.clone())));
        }
        let d = match self.compose_wgsl(desc) {
            Err(ShaderError::Source(d)) => *d,
            _ => match validation_error(&e, desc.file_path) {
                ShaderError::Source(d) => *d,
                other => return Err(other),
            },
        };
        if let (Some(memo), Some(located)) = (self.memo.as_mut(), located) {
            memo.located.insert(located, d.clone());
        }
        Err(ShaderError::Source(Box::new(d)))
    }
}
