//! Deterministic dither and noise patterns: void-and-cluster blue noise (Ulichney 1993) and
//! uniform white noise, both seeded. Used by the screen-door dither (`lodkit::screen_door`) and
//! the visibility textures of frame-sequential LOD.

use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;

/// Standard deviation of the Gaussian energy filter of void-and-cluster (Ulichney's 1.5).
const SIGMA: f32 = 1.5;

/// A `size` x `size` void-and-cluster dither array: each pixel gets a distinct rank in
/// `0..size*size`, ranks are spread so that every prefix (every threshold) is a blue-noise point
/// set. Row-major, toroidal (tiles seamlessly). Deterministic for a given `seed`.
///
/// ```
/// # use lodkit::noise::void_and_cluster;
/// let ranks = void_and_cluster(8, 1);
/// let mut sorted = ranks.clone();
/// sorted.sort();
/// assert_eq!(sorted, (0..64).collect::<Vec<u32>>());
/// ```
pub fn void_and_cluster(size: usize, seed: u64) -> Vec<u32> {
    let n = size * size;
    if n == 0 {
        return Vec::new();
    }
    // Toroidal Gaussian kernel by offset.
    let kernel: Vec<f32> = (0..n)
        .map(|i| {
            let (dx, dy) = ((i % size) as f32, (i / size) as f32);
            let dx = dx.min(size as f32 - dx);
            let dy = dy.min(size as f32 - dy);
            (-(dx * dx + dy * dy) / (2.0 * SIGMA * SIGMA)).exp()
        })
        .collect();
    // The Gaussian is below 1e-3 of its peak beyond 4 sigma: update only that window (the whole
    // array when it is smaller), which keeps a 64x64 array fast.
    let reach = ((4.0 * SIGMA).ceil() as usize).min(size / 2);
    let toggle = |energy: &mut [f32], p: usize, sign: f32| {
        let (px, py) = (p % size, p / size);
        let span = if size < 32 { 0..size } else { 0..2 * reach + 1 };
        for oy in span.clone() {
            let dy = if span.len() == size {
                oy
            } else {
                (oy + size - reach) % size
            };
            let qy = (py + dy) % size;
            for ox in span.clone() {
                let dx = if span.len() == size {
                    ox
                } else {
                    (ox + size - reach) % size
                };
                let qx = (px + dx) % size;
                energy[qy * size + qx] += sign * kernel[dy * size + dx];
            }
        }
    };
    let tightest = |pattern: &[bool], energy: &[f32]| {
        (0..n)
            .filter(|&p| pattern[p])
            .max_by(|&a, &b| energy[a].total_cmp(&energy[b]).then(b.cmp(&a)))
    };
    let largest_void = |pattern: &[bool], energy: &[f32]| {
        (0..n)
            .filter(|&p| !pattern[p])
            .min_by(|&a, &b| energy[a].total_cmp(&energy[b]).then(a.cmp(&b)))
    };

    // Initial pattern: about 10% of the pixels, at random.
    let mut rng = Pcg32::seed_from_u64(seed);
    let ones = (n / 10).max(1);
    let mut pattern = vec![false; n];
    let mut energy = vec![0.0f32; n];
    let mut placed = 0;
    while placed < ones {
        let p = (rng.next_u32() as usize) % n;
        if !pattern[p] {
            pattern[p] = true;
            toggle(&mut energy, p, 1.0);
            placed += 1;
        }
    }
    // Relax: move the tightest cluster into the largest void until that changes nothing.
    for _ in 0..(4 * n) {
        let Some(cluster) = tightest(&pattern, &energy) else {
            break;
        };
        pattern[cluster] = false;
        toggle(&mut energy, cluster, -1.0);
        let Some(void) = largest_void(&pattern, &energy) else {
            break;
        };
        pattern[void] = true;
        toggle(&mut energy, void, 1.0);
        if void == cluster {
            break;
        }
    }
    let mut ranks = vec![0u32; n];
    // Phase 1: rank the initial points by removing the tightest cluster.
    let (mut p1, mut e1) = (pattern.clone(), energy.clone());
    for rank in (0..ones).rev() {
        let Some(c) = tightest(&p1, &e1) else { break };
        p1[c] = false;
        toggle(&mut e1, c, -1.0);
        ranks[c] = rank as u32;
    }
    // Phases 2 and 3: fill the largest void. (The tightest cluster of zeros is the zero with the
    // least energy of ones, so both phases are the same step.)
    for rank in ones..n {
        let Some(v) = largest_void(&pattern, &energy) else {
            break;
        };
        pattern[v] = true;
        toggle(&mut energy, v, 1.0);
        ranks[v] = rank as u32;
    }
    ranks
}

/// `count` uniform values in [0, 1), deterministic for a given `seed`.
pub fn white_noise(count: usize, seed: u64) -> Vec<f32> {
    let mut rng = Pcg32::seed_from_u64(seed);
    (0..count)
        .map(|_| (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32)
        .collect()
}

/// Radially averaged power spectrum of a `size` x `size` pattern (mean removed), in `size / 2`
/// rings of integer radius 1..=size/2. Blue noise has little power in the low rings.
pub fn radial_power_spectrum(values: &[f32], size: usize) -> Vec<f32> {
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64;
    let tau = std::f64::consts::TAU;
    let (cos, sin): (Vec<f64>, Vec<f64>) = (0..size)
        .map(|k| {
            let a = tau * k as f64 / size as f64;
            (a.cos(), a.sin())
        })
        .unzip();
    // Separable DFT: rows, then columns.
    let mut rows = vec![(0.0f64, 0.0f64); size * size];
    for y in 0..size {
        for u in 0..size {
            let (mut re, mut im) = (0.0, 0.0);
            for x in 0..size {
                let s = f64::from(values[y * size + x]) - mean;
                let k = (u * x) % size;
                re += s * cos[k];
                im -= s * sin[k];
            }
            rows[y * size + u] = (re, im);
        }
    }
    let half = size / 2;
    let mut power = vec![0.0f64; half + 1];
    let mut count = vec![0usize; half + 1];
    for u in 0..size {
        for v in 0..size {
            let (mut re, mut im) = (0.0, 0.0);
            for y in 0..size {
                let (a, b) = rows[y * size + u];
                let k = (v * y) % size;
                re += a * cos[k] + b * sin[k];
                im += b * cos[k] - a * sin[k];
            }
            let fu = u.min(size - u) as f64;
            let fv = v.min(size - v) as f64;
            let r = (fu * fu + fv * fv).sqrt().round() as usize;
            if (1..=half).contains(&r) {
                power[r] += (re * re + im * im) / (size * size) as f64;
                count[r] += 1;
            }
        }
    }
    (1..=half)
        .map(|r| {
            if count[r] > 0 {
                (power[r] / count[r] as f64) as f32
            } else {
                0.0
            }
        })
        .collect()
}
