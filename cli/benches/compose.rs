//! Cost of the shader library on the host: a library with nothing loaded yet (naga_oil's
//! Composer), a cold library composing one shader (loading the lodkit modules it imports),
//! composing one user shader against a warm library, exporting it, and `lodkit check` of one
//! small shader end to end (process start included).
//!
//! `cargo bench -p lodkit-cli --bench compose`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use lodkit::shaders::{self, ExportOptions, ExportTarget, ShaderLibrary};
use lodkit_cli::demo::measures::host_cost::{USER_SHADER, compose_user_shader};

fn compose(library: &mut ShaderLibrary) -> shaders::Composed {
    compose_user_shader(library).expect("composes")
}

fn benches(c: &mut Criterion) {
    c.bench_function("library: new, nothing loaded", |b| {
        b.iter(|| black_box(ShaderLibrary::new().expect("library")))
    });
    c.bench_function(
        "library: cold composer + the modules one shader imports + it",
        |b| {
            b.iter(|| {
                let mut library = ShaderLibrary::new().expect("library");
                black_box(compose(&mut library))
            })
        },
    );
    let mut library = ShaderLibrary::new().expect("library");
    c.bench_function("compose one shader (warm library)", |b| {
        b.iter(|| black_box(compose(&mut library)))
    });
    let composed = compose(&mut library);
    c.bench_function("export SPIR-V", |b| {
        b.iter(|| {
            black_box(shaders::export(
                &composed,
                ExportTarget::SpirV,
                &ExportOptions::default(),
            ))
        })
    });
    let dir = std::env::temp_dir().join(format!("lodkit-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("user.wgsl");
    std::fs::write(&file, USER_SHADER).unwrap();
    c.bench_function(
        "`lodkit check` of one small shader (process wall time)",
        |b| {
            b.iter(|| {
                let status = std::process::Command::new(env!("CARGO_BIN_EXE_lodkit"))
                    .arg("check")
                    .arg(&file)
                    .stdout(std::process::Stdio::null())
                    .status()
                    .unwrap();
                assert!(status.success());
            })
        },
    );
}

criterion_group! {
    name = compose_benches;
    config = Criterion::default().sample_size(30);
    targets = benches
}
criterion_main!(compose_benches);
