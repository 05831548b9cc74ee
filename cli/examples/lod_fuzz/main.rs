//! A fuzz target for `lodkit lod`: mutated glTF files, each run through the `lodkit` binary
//! (built beside this example) with a time limit, counting panics (exit status 101 or a panic
//! message) and runs over the limit. Deterministic: the same seed mutates the same way.
//!
//! ```text
//! cargo build --release -p lodkit-cli --example lod_fuzz --bin lodkit
//! target/release/examples/lod_fuzz [--count N] [--seed S] [--jobs J] [--limit SECONDS]
//!     [--corpus DIR] [--keep DIR] [--first K]
//! ```
//!
//! The corpus: spheres and a terrain patch made here (indexed and not, `.gltf` and `.glb`, up
//! to 10^5 triangles), a quantized copy of one, and every `.gltf` / `.glb` file below `--corpus`
//! (Bevy's sample models, the files of lodkit's tests). Each input is one corpus file with 1-4
//! mutations: byte flips and truncation of the binary data (index values, NaN and huge
//! positions, chunk lengths of a GLB), and in the JSON accessor counts, offsets, component
//! types and types, buffer view offsets, lengths and strides, primitive modes, indices and
//! attributes, node children (cycles), mesh indices, buffer URIs and lengths, and `MSFT_lod`
//! ids. Inputs that panic or run over the limit are written to `--keep` (default
//! `lodkit-fuzz`) with what was done to them; `--first K --count K+1` makes input K alone
//! again. Exit status 1 when any did.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

mod corpus;
mod mutate;

use corpus::{load, quantized, sphere, terrain};
use mutate::{Rng, mutate, write};

/// What one run did.
enum Outcome {
    Ok,
    Panic(String),
    TooSlow(f64),
}

/// Runs `lodkit lod` on `input` with a time limit.
fn run(lodkit: &Path, input: &Path, out: &Path, limit: Duration) -> (Outcome, f64) {
    let start = Instant::now();
    let child = Command::new(lodkit)
        .args([
            "lod".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn();
    let Ok(mut child) = child else {
        return (Outcome::Panic("could not start lodkit".into()), 0.0);
    };
    loop {
        match child.try_wait() {
            Ok(Some(status)) => {
                let seconds = start.elapsed().as_secs_f64();
                let mut stderr = String::new();
                if let Some(mut e) = child.stderr.take() {
                    use std::io::Read;
                    let _ = e.read_to_string(&mut stderr);
                }
                if status.code() == Some(101) || stderr.contains("panicked") {
                    return (Outcome::Panic(stderr), seconds);
                }
                if status.code().is_none() {
                    return (
                        Outcome::Panic(format!("killed by a signal: {stderr}")),
                        seconds,
                    );
                }
                return (Outcome::Ok, seconds);
            }
            Ok(None) if start.elapsed() > limit => {
                let _ = child.kill();
                let _ = child.wait();
                return (Outcome::TooSlow(start.elapsed().as_secs_f64()), 0.0);
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(2)),
            Err(e) => return (Outcome::Panic(e.to_string()), 0.0),
        }
    }
}

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let (mut count, mut seed, mut limit) = (1000usize, 1u64, 10.0f64);
    let mut jobs = std::thread::available_parallelism().map_or(1, |n| n.get());
    let (mut corpus_dir, mut keep) = (None, PathBuf::from("lodkit-fuzz"));
    let mut first = 0usize;
    while let Some(a) = args.next() {
        let v = args.next().unwrap_or_default();
        match a.as_str() {
            "--count" => count = v.parse().unwrap_or(count),
            "--seed" => seed = v.parse().unwrap_or(seed),
            "--jobs" => jobs = v.parse().unwrap_or(jobs).max(1),
            "--limit" => limit = v.parse().unwrap_or(limit),
            "--corpus" => corpus_dir = Some(PathBuf::from(v)),
            "--keep" => keep = PathBuf::from(v),
            "--first" => first = v.parse().unwrap_or(first),
            _ => {
                eprintln!(
                    "usage: lod_fuzz [--count N] [--seed S] [--jobs J] [--limit SECONDS] [--corpus DIR] [--keep DIR] [--first K]"
                );
                return ExitCode::from(2);
            }
        }
    }
    let exe = std::env::current_exe().expect("this example's path");
    let lodkit = exe
        .parent()
        .and_then(Path::parent)
        .map(|p| p.join(format!("lodkit{}", std::env::consts::EXE_SUFFIX)))
        .filter(|p| p.exists());
    let Some(lodkit) = lodkit else {
        eprintln!("error: build the lodkit binary beside this example (--bin lodkit)");
        return ExitCode::from(2);
    };
    let mut corpus = vec![
        sphere(8, 16, true, false),
        sphere(12, 24, true, true),
        sphere(10, 20, false, false),
        sphere(160, 320, true, true), // 101,760 triangles: the largest
        terrain(64),
        quantized(sphere(16, 32, true, true)),
    ];
    if let Some(dir) = &corpus_dir {
        let mut stack = vec![dir.clone()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
                let p = e.path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|e| {
                    e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf")
                }) && let Some(s) = load(&p)
                {
                    corpus.push(s);
                }
            }
        }
    }
    println!(
        "corpus: {} files; {count} inputs, seed {seed}, {jobs} jobs, limit {limit} s",
        corpus.len()
    );
    let scratch = tempfile::tempdir().expect("a temporary folder");
    let next = AtomicUsize::new(first);
    let found = Arc::new(Mutex::new(Vec::new()));
    let times = Arc::new(Mutex::new(Vec::new()));
    let started = Instant::now();
    std::thread::scope(|scope| {
        for job in 0..jobs {
            let dir = scratch.path().join(format!("job{job}"));
            std::fs::create_dir_all(&dir).expect("a job folder");
            let (corpus, next, found, times, lodkit, keep) =
                (&corpus, &next, found.clone(), times.clone(), &lodkit, &keep);
            scope.spawn(move || {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= count {
                        break;
                    }
                    let mut rng = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (k as u64 + 1));
                    let _ = rng.next();
                    let mut s = corpus[rng.below(corpus.len())].clone();
                    let done: Vec<String> = (0..1 + rng.below(4))
                        .map(|_| mutate(&mut rng, &mut s))
                        .collect();
                    for f in ["in.glb", "in.gltf", "in.bin", "out.glb"] {
                        let _ = std::fs::remove_file(dir.join(f));
                    }
                    let Ok(input) = write(&s, &dir, &mut rng) else {
                        continue;
                    };
                    let (outcome, seconds) = run(
                        lodkit,
                        &input,
                        &dir.join("out.glb"),
                        Duration::from_secs_f64(limit),
                    );
                    times
                        .lock()
                        .expect("times")
                        .push((seconds, k, done.join("; ")));
                    let what = match outcome {
                        Outcome::Ok => None,
                        Outcome::Panic(e) => Some(format!(
                            "panic: {}",
                            e.lines().find(|l| l.contains("panicked")).unwrap_or(&e)
                        )),
                        Outcome::TooSlow(t) => Some(format!("over the limit: {t:.1} s")),
                    };
                    if let Some(what) = what {
                        let case = keep.join(format!("case{k}"));
                        let _ = std::fs::create_dir_all(&case);
                        for f in ["in.glb", "in.gltf", "in.bin"] {
                            let _ = std::fs::copy(dir.join(f), case.join(f));
                        }
                        let _ = std::fs::write(
                            case.join("what.txt"),
                            format!("{what}\ninput {}\n{}\n", input.display(), done.join("\n")),
                        );
                        println!("input {k}: {what} ({})", done.join("; "));
                        found.lock().expect("found").push(k);
                    }
                    if k > 0 && k % 1000 == 0 {
                        eprintln!("[{:7.1} s] {k} inputs", started.elapsed().as_secs_f64());
                    }
                }
            });
        }
    });
    let mut times = times.lock().expect("times").clone();
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let found = found.lock().expect("found").len();
    let (slowest, at, what) = times.last().cloned().unwrap_or_default();
    println!(
        "{count} inputs in {:.0} s: {found} panics or runs over {limit} s; slowest run {slowest:.2} s \
         (input {at}: {what}), median {:.3} s",
        started.elapsed().as_secs_f64(),
        times.get(times.len() / 2).map_or(0.0, |t| t.0)
    );
    ExitCode::from(u8::from(found > 0))
}
