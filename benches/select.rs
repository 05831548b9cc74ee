//! Throughput of batch LOD selection: instances per second on one core, per transition mode.
//!
//! `cargo bench --bench select`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use lodkit::select::*;

fn benches(c: &mut Criterion) {
    for n in [10_000, 100_000] {
        bench_size(c, n);
    }
}

fn bench_size(c: &mut Criterion, n: usize) {
    let proj = glam::camera::rh::proj::directx::perspective(1.0, 16.0 / 9.0, 0.1, 2000.0);
    let camera = LodCamera::new(Vec3::new(0.0, 2.0, 0.0), proj);
    let groups = vec![
        LodGroup::from_distances(&[0.0, 20.0, 60.0, 150.0])
            .unwrap()
            .with_max_distance(600.0)
            .unwrap(),
        LodGroup::from_distances(&[0.0, 40.0, 120.0]).unwrap(),
    ];
    // Instances scattered over a 1 km square, deterministic.
    let noise = lodkit::noise::white_noise(3 * n, 11);
    let positions: Vec<Vec3> = noise
        .chunks(3)
        .map(|v| Vec3::new(v[0] * 1000.0 - 500.0, 0.0, v[1] * 1000.0 - 500.0))
        .collect();
    let max_scales: Vec<f32> = noise.chunks(3).map(|v| 0.5 + v[2]).collect();
    let group_ids: Vec<u32> = (0..n as u32).map(|i| i % 2).collect();
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &max_scales,
        groups: &group_ids,
    };
    let mut g = c.benchmark_group("select_batch");
    g.throughput(Throughput::Elements(n as u64));
    for (name, transition) in [
        ("hard", TransitionMode::Hard),
        ("distance", TransitionMode::Distance),
        ("time", TransitionMode::Time { seconds: 0.5 }),
    ] {
        let settings = LodSettings {
            hysteresis: 8.0,
            transition,
            ..Default::default()
        };
        let mut states = vec![LodState::NEW; n];
        let mut out = vec![LodSelection::default(); n];
        g.bench_with_input(BenchmarkId::new(name, n), &settings, |b, s| {
            b.iter(|| {
                select_batch(
                    &camera,
                    s,
                    &groups,
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
