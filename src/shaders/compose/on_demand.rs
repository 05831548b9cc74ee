//! What a [`ShaderLibrary`] does on demand: loading the lodkit modules a shader imports, and
//! validating each distinct composed module once for a check of many shader-def sets.

use std::sync::Arc;

use super::{
    ComposeDescriptor, Composed, ShaderError, ShaderLibrary, add_modules, declared_imports,
    deep_stack_failed, longest_prefix, registry, validation_error,
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
        let mut needed: Vec<&'static registry::ModuleInfo> = Vec::new();
        while let Some(import) = wanted.pop() {
            let Some((_, m)) = longest_prefix(&import, registry::find_module) else {
                continue;
            };
            let loaded = m
                .import_path
                .as_deref()
                .is_some_and(|p| self.composer.contains_module(p));
            if loaded || needed.iter().any(|n| std::ptr::eq(*n, m)) {
                continue;
            }
            needed.push(m);
            wanted.extend(declared_imports(m.source).into_iter().map(|(p, _)| p));
        }
        if needed.is_empty() {
            return Ok(());
        }
        let sources = needed
            .iter()
            .map(|m| (format!("shader_lib/{}", m.path), Arc::from(m.source)))
            .collect();
        add_modules(&mut self.composer, sources, true, None)
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

    /// Composes WGSL with naga_oil's own validation off and validates each distinct module
    /// once ([`remember_validations`](Self::remember_validations)). An invalid module is
    /// composed again with naga_oil validating, which places the error in the user's source;
    /// that diagnostic is remembered too.
    pub(super) fn compose_wgsl_once(
        &mut self,
        desc: &ComposeDescriptor,
    ) -> Result<Composed, ShaderError> {
        self.composer.validate = false;
        let module = self.compose_wgsl(desc);
        self.composer.validate = true;
        let module = module?;
        let key = crate::shaders::memo::key(&module);
        let Some(memo) = self.memo.as_mut() else {
            return Err(deep_stack_failed(desc.file_path));
        };
        let e = match crate::shaders::memo::validate_keyed(memo, key, &module, self.capabilities) {
            Ok(info) => return Ok(Composed { module, info }),
            Err(e) => e,
        };
        let located = (key, desc.file_path.to_owned());
        if let Some(d) = memo.located.get(&located) {
            return Err(ShaderError::Source(Box::new(d.clone())));
        }
        let d = match self.compose_wgsl(desc) {
            Err(ShaderError::Source(d)) => *d,
            _ => match validation_error(&e, desc.file_path) {
                ShaderError::Source(d) => *d,
                other => return Err(other),
            },
        };
        if let Some(memo) = self.memo.as_mut() {
            memo.located.insert(located, d.clone());
        }
        Err(ShaderError::Source(Box::new(d)))
    }
}
