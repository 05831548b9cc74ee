//! Throughput of batch LOD selection: instances per second on one core, per transition mode.
//!
//! `cargo bench -p lodkit-cli --bench select`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use lodkit::select::*;
use lodkit_cli::demo::measures::host_cost::SelectionWorkload;

fn benches(c: &mut Criterion) {
    for n in [10_000, 100_000] {
        bench_size(c, n);
    }
}

fn bench_size(c: &mut Criterion, n: usize) {
    let w = SelectionWorkload::new(n);
    let batch = w.batch();
    let mut g = c.benchmark_group("select_batch");
    g.throughput(Throughput::Elements(n as u64));
    for (name, settings) in SelectionWorkload::modes() {
        let mut states = vec![LodState::NEW; n];
        let mut out = vec![LodSelection::default(); n];
        g.bench_with_input(BenchmarkId::new(name, n), &settings, |b, s| {
            b.iter(|| {
                select_batch(
                    &w.camera,
                    s,
                    &w.groups,
                    &batch,
                    black_box(0.016),
                    &mut states,
                    &mut out,
                )
                .unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(select_benches, benches);
criterion_main!(select_benches);
