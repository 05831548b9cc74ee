//! WGSL that needs no composition: a shader without naga_oil's directives (`#import`,
//! `#define_import_path`, `#ifdef`, `#{NAME}`, ...), `module::item` paths, `virtual`/`override`
//! functions, `@binding(auto)` or decorated names is read by naga's WGSL front end as it is
//! written. Such a shader is parsed and validated by naga alone, without building naga_oil's
//! composer, with the diagnostics the composer would have given.

use std::sync::Arc;

use super::{ComposeDescriptor, Composed, ShaderError, ShaderLibrary};
use crate::shaders::diagnostic::{validation_diagnostic, wgsl_parse_diagnostic};
use crate::shaders::memo;

/// Whether naga_oil has to read `source` before naga can: it has a `#` or a `::` outside
/// comments, the word `virtual`, `@binding(auto)`, or a naga_oil decoration (which naga_oil
/// rejects in source). Errs on the side of the composer: it is never wrong to compose.
pub(super) fn needs_composer(source: &str) -> bool {
    if source.contains("X_naga_oil_") || source.contains("@binding(auto)") {
        return true;
    }
    let code = crate::shaders::blank_comments(source, crate::shaders::CommentSyntax::Wgsl);
    let bytes = code.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let rest = &bytes[i..];
        match bytes[i] {
            b'#' => return true,
            b':' if rest.starts_with(b"::") => return true,
            b if b.is_ascii_alphabetic() || b == b'_' => {
                let len = rest
                    .iter()
                    .position(|&b| !(b.is_ascii_alphanumeric() || b == b'_'))
                    .unwrap_or(rest.len());
                if &rest[..len] == b"virtual" {
                    return true;
                }
                i += len;
            }
            _ => i += 1,
        }
    }
    false
}

impl ShaderLibrary {
    /// Parses and validates a WGSL shader that [`needs_composer`] says naga reads as written.
    pub(super) fn compose_plain(
        &mut self,
        desc: &ComposeDescriptor,
    ) -> Result<Composed, ShaderError> {
        let source = || Arc::<str>::from(desc.source);
        let module = naga::front::wgsl::parse_str(desc.source).map_err(|e| {
            let d = wgsl_parse_diagnostic(&e, desc.file_path.to_owned(), source(), |r| r);
            ShaderError::Source(Box::new(d))
        })?;
        match memo::validate(self.memo.as_mut(), &module, self.capabilities) {
            Ok(info) => Ok(Composed { module, info }),
            Err(remembered) => {
                // A remembered verdict may come from another file with the same IR: its spans
                // are that file's. Validate this module again to place the error in this one.
                let e = match memo::validate(None, &module, self.capabilities) {
                    Err(e) => e,
                    Ok(_) => remembered,
                };
                let d = validation_diagnostic(&e, desc.file_path.to_owned(), source(), |r| r);
                Err(ShaderError::Source(Box::new(d)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::needs_composer;
    use crate::shaders::{ComposeDescriptor, ShaderError, ShaderLibrary};

    /// Broken shaders without directives: a parse error, an unknown name (caught while
    /// lowering), a missing return, a uniform array with a bad stride, an `f32 + i32` (caught
    /// by the validator, with notes).
    const BROKEN: &[&str] = &[
        "fn f() -> f32 {\n    return 1.0\n}\n",
        "@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(undefined_name);\n}\n",
        "fn f() -> f32 {\n    let x = 1.0;\n}\n",
        "@group(0) @binding(0) var<uniform> u: array<f32>;\n@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(u[0]);\n}\n",
        "struct S { a: f32 }\nfn g(s: S) -> f32 { return s.a; }\nfn f(a: f32, b: i32) -> f32 {\n    return a + b;\n}\n",
    ];

    fn rendered(e: ShaderError) -> String {
        e.diagnostic().expect("a diagnostic").render()
    }

    #[test]
    fn naga_alone_reports_what_the_composer_reports() {
        for source in BROKEN {
            let desc = ComposeDescriptor {
                source,
                file_path: "broken.wgsl",
                ..Default::default()
            };
            let mut library = ShaderLibrary::new().unwrap();
            let plain = rendered(library.compose(&desc).unwrap_err());
            assert!(!library.has_composer(), "{source:?} took the composer");
            let composed = rendered(library.compose_wgsl_validated(&desc).unwrap_err());
            assert!(library.has_composer());
            assert_eq!(plain, composed, "{source:?}");
        }
    }

    #[test]
    fn a_shader_with_directives_is_composed() {
        let mut library = ShaderLibrary::new().unwrap();
        let plain =
            "@fragment\nfn main() -> @location(0) vec4<f32> {\n    return vec4<f32>(1.0);\n}\n";
        let desc = |source| ComposeDescriptor {
            source,
            file_path: "s.wgsl",
            ..Default::default()
        };
        library.compose(&desc(plain)).unwrap();
        assert!(!library.has_composer());
        let with_ifdef = format!("#ifdef NEVER_SET\n#endif\n{plain}");
        library.compose(&desc(&with_ifdef)).unwrap();
        assert!(library.has_composer());
        // A def only the composer knows: `#ifdef` takes the branch that fails.
        let broken_under_def = format!("#ifdef BREAK\nfn f() -> f32 {{ }}\n#endif\n{plain}");
        let mut set = ComposeDescriptor {
            shader_defs: [(
                "BREAK".to_owned(),
                naga_oil::compose::ShaderDefValue::Bool(true),
            )]
            .into(),
            ..desc(&broken_under_def)
        };
        assert!(library.compose(&set).is_err());
        set.shader_defs.clear();
        library.compose(&set).unwrap();
    }

    #[test]
    fn directives_paths_and_naga_oil_syntax_need_the_composer() {
        for source in [
            "#import a::b\nfn f() {}",
            "fn f() {}\n#ifdef X\n#endif",
            "  #define_import_path my::mod",
            "fn f() -> f32 { return #{N}.0; }",
            "fn f() -> f32 { return a::b::c(); }",
            "virtual fn f() {}",
            "override fn a::f() {}",
            "@group(0) @binding(auto) var<uniform> u: f32;",
            "// X_naga_oil_mod_X in a comment is still rejected by naga_oil",
        ] {
            assert!(needs_composer(source), "{source:?}");
        }
    }

    #[test]
    fn plain_wgsl_and_comments_do_not() {
        for source in [
            "fn f() -> f32 { return 1.0; }",
            "// see #import and a::b in a comment\nfn f() {}",
            "/* #ifdef X /* nested a::b */ still comment # */ fn f() {}",
            "override scale: f32 = 1.0;\nfn virtuality() {}",
            "@group(0) @binding(0) var<uniform> u: f32;",
            "",
        ] {
            assert!(!needs_composer(source), "{source:?}");
        }
    }
}
