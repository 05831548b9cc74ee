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

use serde_json::{Value, json};

/// xorshift64*: the mutations' random numbers.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// A corpus file: its name's extension, and the JSON and binary chunk (a `.gltf`'s buffer is
/// written as `<name>.bin` beside it).
#[derive(Clone)]
struct Sample {
    glb: bool,
    json: Value,
    bin: Vec<u8>,
}

fn sphere(rings: u32, segments: u32, indexed: bool, glb: bool) -> Sample {
    let (positions, indices) = lodkit::lod_chain::uv_sphere(rings, segments);
    let (positions, indices) = if indexed {
        (positions, Some(indices))
    } else {
        (
            indices.iter().map(|&i| positions[i as usize]).collect(),
            None,
        )
    };
    mesh_sample(&positions, indices.as_deref(), glb)
}

fn terrain(n: u32) -> Sample {
    let mut positions = Vec::new();
    for z in 0..=n {
        for x in 0..=n {
            let (fx, fz) = (x as f32 / n as f32, z as f32 / n as f32);
            positions.push([fx, 0.1 * (7.0 * fx).sin() * (5.0 * fz).cos(), fz]);
        }
    }
    let mut indices = Vec::new();
    for z in 0..n {
        for x in 0..n {
            let a = z * (n + 1) + x;
            indices.extend([a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2]);
        }
    }
    mesh_sample(&positions, Some(&indices), true)
}

fn mesh_sample(positions: &[[f32; 3]], indices: Option<&[u32]>, glb: bool) -> Sample {
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let (lo, hi) = positions.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(mut lo, mut hi), p| {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
            (lo, hi)
        },
    );
    let mut views = vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": bin.len()})];
    let mut accessors = vec![json!({"bufferView": 0, "componentType": 5126,
        "count": positions.len(), "type": "VEC3", "min": lo, "max": hi})];
    let mut primitive = json!({"attributes": {"POSITION": 0}});
    if let Some(indices) = indices {
        let at = bin.len();
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": bin.len() - at}));
        accessors.push(json!({"bufferView": 1, "componentType": 5125,
            "count": indices.len(), "type": "SCALAR"}));
        primitive["indices"] = json!(1);
    }
    let json = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [2.0, 0.0, 0.0]}],
        "meshes": [{"primitives": [primitive]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    Sample { glb, json, bin }
}

/// The sample with 16-bit normalized positions (`KHR_mesh_quantization`).
fn quantized(mut s: Sample) -> Sample {
    let count = s.json["accessors"][0]["count"].as_u64().unwrap_or(0) as usize;
    let mut q = Vec::with_capacity(count * 8);
    for k in 0..count {
        for c in 0..3 {
            let at = 12 * k + 4 * c;
            let x = f32::from_le_bytes(s.bin[at..at + 4].try_into().expect("4 bytes"));
            q.extend(((x.clamp(-1.0, 1.0) * 32767.0) as i16).to_le_bytes());
        }
        q.extend([0, 0]);
    }
    let rest = s.bin[12 * count..].to_vec();
    let at = q.len();
    s.bin = q;
    s.bin.extend(rest);
    s.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    s.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    s.json["bufferViews"][0] = json!({"buffer": 0, "byteOffset": 0, "byteLength": at,
        "byteStride": 8});
    if s.json["bufferViews"].get(1).is_some() {
        s.json["bufferViews"][1]["byteOffset"] = json!(at);
    }
    s.json["accessors"][0]["componentType"] = json!(5122);
    s.json["accessors"][0]["normalized"] = json!(true);
    s.json["accessors"][0]["min"] = json!([-32767, -32767, -32767]);
    s.json["accessors"][0]["max"] = json!([32767, 32767, 32767]);
    s.json["buffers"][0]["byteLength"] = json!(s.bin.len());
    s
}

/// A corpus file from disk (its external buffers inlined as the binary chunk when there is
/// one; images are dropped).
fn load(path: &Path) -> Option<Sample> {
    let bytes = std::fs::read(path).ok()?;
    if bytes.starts_with(b"glTF") {
        let glb = gltf::Glb::from_slice(&bytes).ok()?;
        let json = serde_json::from_slice(&glb.json).ok()?;
        let bin = glb.bin.map(|b| b.into_owned()).unwrap_or_default();
        return Some(Sample {
            glb: true,
            json,
            bin,
        });
    }
    let mut json: Value = serde_json::from_slice(&bytes).ok()?;
    let buffers = json["buffers"].as_array()?.clone();
    if buffers.len() != 1 {
        return None;
    }
    let uri = buffers[0]["uri"].as_str()?;
    let bin = std::fs::read(path.parent()?.join(percent(uri))).ok()?;
    json["buffers"][0].as_object_mut()?.remove("uri");
    if let Some(images) = json.as_object_mut()?.remove("images") {
        let _ = images;
        json.as_object_mut()?.remove("textures");
        strip_textures(&mut json);
    }
    Some(Sample {
        glb: false,
        json,
        bin,
    })
}

fn percent(uri: &str) -> String {
    percent_encoding::percent_decode_str(uri)
        .decode_utf8_lossy()
        .into_owned()
}

/// Drops every `*Texture` member of the materials (their textures are gone).
fn strip_textures(json: &mut Value) {
    if let Some(materials) = json["materials"].as_array_mut() {
        for m in materials {
            strip_texture_members(m);
        }
    }
}

fn strip_texture_members(v: &mut Value) {
    if let Some(o) = v.as_object_mut() {
        o.retain(|k, _| !k.ends_with("Texture"));
        for v in o.values_mut() {
            strip_texture_members(v);
        }
    }
}

/// Values a number in the JSON is set to.
fn interesting(rng: &mut Rng, was: &Value) -> Value {
    let n = was.as_i64().unwrap_or(1);
    match rng.below(12) {
        0 => json!(0),
        1 => json!(-1),
        2 => json!(n + 1),
        3 => json!(n - 1),
        4 => json!(n * 2),
        5 => json!(u32::MAX),
        6 => json!(i64::from(i32::MAX) + 1),
        7 => json!(1e308),
        8 => json!(3),
        9 => json!("x"),
        10 => Value::Null,
        _ => json!(rng.below(70_000)),
    }
}

/// One mutation; returns what it did.
fn mutate(rng: &mut Rng, s: &mut Sample) -> String {
    let pick = |rng: &mut Rng, s: &Sample, key: &str| {
        let n = s.json[key].as_array().map_or(0, Vec::len);
        (n > 0).then(|| rng.below(n))
    };
    match rng.below(14) {
        0 | 1 => {
            let flips = 1 + rng.below(8);
            for _ in 0..flips {
                if !s.bin.is_empty() {
                    let at = rng.below(s.bin.len());
                    s.bin[at] ^= 1 << rng.below(8);
                }
            }
            format!("{flips} bit flips in the binary data")
        }
        2 => {
            // A whole float: NaN, infinity, huge; or an index past the end.
            let at = rng.below(s.bin.len().max(4) / 4) * 4;
            let value: u32 = match rng.below(4) {
                0 => f32::NAN.to_bits(),
                1 => f32::INFINITY.to_bits(),
                2 => 1e30f32.to_bits(),
                _ => u32::MAX,
            };
            if at + 4 <= s.bin.len() {
                s.bin[at..at + 4].copy_from_slice(&value.to_le_bytes());
            }
            format!("word at {at} set to {value:#x}")
        }
        3 => {
            let keep = rng.below(s.bin.len() + 1);
            s.bin.truncate(keep);
            format!("binary data cut to {keep} bytes")
        }
        4 | 5 => {
            let Some(k) = pick(rng, s, "accessors") else {
                return "no accessor".into();
            };
            let key = [
                "count",
                "byteOffset",
                "componentType",
                "bufferView",
                "normalized",
            ][rng.below(5)];
            let was = s.json["accessors"][k][key].clone();
            s.json["accessors"][k][key] = match key {
                "componentType" => json!([5120, 5121, 5122, 5123, 5125, 5126, 5124][rng.below(7)]),
                _ => interesting(rng, &was),
            };
            if rng.below(4) == 0 {
                s.json["accessors"][k]["type"] =
                    json!(["SCALAR", "VEC2", "VEC3", "VEC4", "MAT4", "MAT2"][rng.below(6)]);
            }
            format!("accessors[{k}].{key}")
        }
        6 => {
            let Some(k) = pick(rng, s, "bufferViews") else {
                return "no view".into();
            };
            let key = ["byteOffset", "byteLength", "byteStride", "buffer"][rng.below(4)];
            let was = s.json["bufferViews"][k][key].clone();
            s.json["bufferViews"][k][key] = interesting(rng, &was);
            format!("bufferViews[{k}].{key}")
        }
        7 => {
            let Some(m) = pick(rng, s, "meshes") else {
                return "no mesh".into();
            };
            let Some(p) = s.json.pointer_mut(&format!("/meshes/{m}/primitives/0")) else {
                return "no primitive".into();
            };
            if !p.is_object() {
                return "no primitive".into();
            }
            match rng.below(3) {
                0 => p["mode"] = json!(rng.below(8)),
                1 => p["indices"] = json!(rng.below(4)),
                _ => p["attributes"]["POSITION"] = json!(rng.below(4)),
            }
            format!("meshes[{m}].primitives[0]")
        }
        8 => {
            let Some(n) = pick(rng, s, "nodes") else {
                return "no node".into();
            };
            let child = rng.below(s.json["nodes"].as_array().map_or(1, Vec::len) + 1);
            s.json["nodes"][n]["children"] = json!([child, n]);
            format!("nodes[{n}].children = [{child}, {n}]")
        }
        9 => {
            let Some(n) = pick(rng, s, "nodes") else {
                return "no node".into();
            };
            s.json["nodes"][n]["mesh"] = json!(rng.below(4));
            format!("nodes[{n}].mesh")
        }
        10 => {
            let length = interesting(rng, &json!(s.bin.len()));
            let uri_too = rng.below(2) == 0;
            let Some(buffer) = s.json.pointer_mut("/buffers/0").filter(|b| b.is_object()) else {
                return "no buffer".into();
            };
            buffer["byteLength"] = length;
            if uri_too {
                buffer["uri"] = json!(
                    [
                        "../../etc/passwd",
                        "data:application/octet-stream;base64,AAA",
                        "x.bin"
                    ][rng.below(3)]
                );
            }
            "buffers[0]".into()
        }
        11 => {
            let Some(n) = pick(rng, s, "nodes") else {
                return "no node".into();
            };
            let count = s.json["nodes"].as_array().map_or(1, Vec::len);
            let ids: Vec<usize> = (0..1 + rng.below(3))
                .map(|_| rng.below(count + 2))
                .collect();
            s.json["nodes"][n]["extensions"] = json!({"MSFT_lod": {"ids": ids}});
            s.json["extensionsUsed"] = json!(["MSFT_lod"]);
            format!("nodes[{n}] MSFT_lod ids {ids:?}")
        }
        12 => {
            // A member removed.
            let key = [
                "accessors",
                "bufferViews",
                "buffers",
                "meshes",
                "scenes",
                "asset",
            ][rng.below(6)];
            s.json.as_object_mut().map(|o| o.remove(key));
            format!("{key} removed")
        }
        _ => {
            let names = [
                "KHR_draco_mesh_compression",
                "EXT_meshopt_compression",
                "KHR_mesh_quantization",
                "X_unknown",
            ];
            let name = names[rng.below(names.len())];
            s.json["extensionsRequired"] = json!([name]);
            "extensionsRequired".into()
        }
    }
}

/// Writes `s` as `dir/in.glb` or `dir/in.gltf` (+ `in.bin`); the GLB's chunk length may be
/// forged by a mutation of the container (a quarter of GLB inputs).
fn write(s: &Sample, dir: &Path, rng: &mut Rng) -> std::io::Result<PathBuf> {
    let json = serde_json::to_vec(&s.json).expect("JSON");
    if s.glb {
        let mut json = json;
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = s.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut out = Vec::new();
        let total = 12 + 8 + json.len() + 8 + bin.len();
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
        if rng.below(4) == 0 {
            let at = [8, 12, 20 + json.len()][rng.below(3)];
            let forged = [0u32, 1, u32::MAX, (total * 2) as u32][rng.below(4)];
            out[at..at + 4].copy_from_slice(&forged.to_le_bytes());
        }
        let path = dir.join("in.glb");
        std::fs::write(&path, out)?;
        Ok(path)
    } else {
        let mut json_value = s.json.clone();
        if json_value["buffers"][0].get("uri").is_none()
            && let Some(b) = json_value["buffers"].get_mut(0)
        {
            b["uri"] = json!("in.bin");
        }
        std::fs::write(dir.join("in.bin"), &s.bin)?;
        let path = dir.join("in.gltf");
        std::fs::write(&path, serde_json::to_vec(&json_value).expect("JSON"))?;
        Ok(path)
    }
}

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
