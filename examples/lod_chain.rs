//! What a LOD chain costs: builds the chain of a bumpy sphere of about 100k and 1M triangles
//! with `lodkit::lod_chain` (meshoptimizer's simplifier plus the Hausdorff bound of every level)
//! and times meshoptimizer's own `simplify` making the same cascade of levels on the same mesh,
//! in one run. Prints one table per mesh.
//!
//! ```sh
//! cargo run --release --features lod_chain --example lod_chain -- [--sizes 100000,1000000] [--tolerance 0.05]
//! ```

use std::time::Instant;

use lodkit::lod_chain::{LodChain, LodChainDescriptor, MeshData, PixelErrorCamera, uv_sphere};

/// A unit sphere with smooth bumps, about `triangles` triangles, with normals.
fn bumpy_sphere(triangles: usize) -> (Vec<[f32; 3]>, Vec<u32>, Vec<[f32; 3]>) {
    let side = ((triangles / 2) as f64).sqrt().round() as u32;
    let (mut positions, indices) = uv_sphere(side, side);
    for p in &mut positions {
        let bump = 1.0 + 0.04 * (7.0 * p[0]).sin() * (5.0 * p[1]).sin() * (3.0 * p[2] + 1.0).sin();
        *p = p.map(|c| c * bump);
    }
    let mut normals = vec![[0.0f32; 3]; positions.len()];
    for t in indices.chunks_exact(3) {
        let v = |i: u32| glam::Vec3::from(positions[i as usize]);
        let n = (v(t[1]) - v(t[0])).cross(v(t[2]) - v(t[0]));
        for &i in t {
            let m = glam::Vec3::from(normals[i as usize]) + n;
            normals[i as usize] = m.to_array();
        }
    }
    for n in &mut normals {
        *n = glam::Vec3::from(*n).normalize_or_zero().to_array();
    }
    (positions, indices, normals)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sizes: Vec<usize> = args
        .iter()
        .position(|a| a == "--sizes")
        .and_then(|i| args.get(i + 1))
        .map_or(vec![100_000, 1_000_000], |s| {
            s.split(',').map(|x| x.parse().expect("a size")).collect()
        });
    let tolerance: f32 = args
        .iter()
        .position(|a| a == "--tolerance")
        .and_then(|i| args.get(i + 1))
        .map_or(LodChainDescriptor::default().bound_tolerance, |s| {
            s.parse().expect("a tolerance")
        });
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("lod_chain cost, {threads} threads for the bound, bound tolerance {tolerance}");
    for size in sizes {
        let (positions, indices, normals) = bumpy_sphere(size);
        let triangles = indices.len() / 3;
        let descriptor = LodChainDescriptor {
            bound_tolerance: tolerance,
            ..Default::default()
        };

        // meshoptimizer alone: the same cascade (each level from the one before).
        let started = Instant::now();
        let mut current = indices.clone();
        let mut plain = Vec::new();
        for i in 1..descriptor.levels {
            let target = (triangles as f64 * 0.5f64.powi(i as i32)).round() as usize * 3;
            let level_started = Instant::now();
            current = meshopt::simplify_decoder(
                &current,
                &positions,
                target,
                1.0,
                meshopt::SimplifyOptions::None,
                None,
            );
            plain.push((current.len() / 3, level_started.elapsed()));
        }
        let meshopt_time = started.elapsed();

        let started = Instant::now();
        let chain = LodChain::build(
            &MeshData {
                positions: &positions,
                indices: &indices,
                normals: Some(&normals),
                uvs: None,
            },
            &descriptor,
        )
        .expect("the chain builds");
        let chain_time = started.elapsed();
        let distances = chain
            .switch_distances(&PixelErrorCamera::default())
            .expect("distances");

        println!(
            "\n{triangles} triangles: lodkit LodChain::build {:.2} s, meshopt::simplify {:.2} s ({:.1}x)",
            chain_time.as_secs_f64(),
            meshopt_time.as_secs_f64(),
            chain_time.as_secs_f64() / meshopt_time.as_secs_f64()
        );
        println!(
            "level  triangles  lodkit (s)  bound (object units)  meshopt estimate  switch distance (1 px, 60°, 1080 p)  meshopt::simplify triangles  (s)"
        );
        for (i, level) in chain.levels().iter().enumerate() {
            let (t, s) = if i == 0 {
                (triangles, 0.0)
            } else {
                plain
                    .get(i - 1)
                    .map_or((0, 0.0), |(t, d)| (*t, d.as_secs_f64()))
            };
            println!(
                "{i:>5}  {:>9}  {:>10.3}  {:>20.6}  {:>16.6}  {:>35.3}  {t:>27}  {s:.3}",
                level.triangles(),
                level.time().as_secs_f64(),
                level.error(),
                level.simplifier_error(),
                distances[i],
            );
        }
    }
}
