//! The example a Bevy app copies: a glTF scene whose levels `lodkit lod` made (several objects
//! and materials; `examples/assets/lod_scene.glb`, written by `scripts/gltf-scene.sh` from the
//! repository's scene), loaded with Bevy's own glTF loader into an app whose only lodkit code is
//! `FrameSequentialLodPlugin` (the plugin gives the camera `FrameSequentialLod::default()`); the
//! camera keeps Bevy's default MSAA and walks back through the scene until every object shows
//! its last level.
//!
//! ```text
//! cargo run --example gltf_scene [-- [--out DIR] [--report FILE] [--gltf FILE] [--frames N]
//!     [--save-frames DIR]]
//! ```
//!
//! The same walk is rendered in one app once per level (each group's level k alone, as plain
//! Bevy meshes: the references), with Bevy's own `VisibilityRange` crossfade over the same
//! levels, distances and band, and with lodkit's frame-sequential LOD (on a camera with MSAA:
//! lodkit's complementary screen-door dither). Writes `DIR/strip_<run>.png` (8 frames of the
//! walk) and, with `--report`, JSON: per technique the pop and the flicker against the finest
//! and the coarsest reference (the frame_sequential example's metrics, `measure.rs`),
//! see-through pixel-frames (where every level alone covers and the frame shows the
//! background) and ghost pixel-frames (where no level covers and the frame shows something),
//! over the whole walk; and the groups the plugin made of the file with the
//! levels lodkit drew. `--gltf` loads another file (scene 0), `--frames` sets the walk's length
//! (default 120), `--save-frames DIR` writes every frame of every run as
//! `DIR/<run>/<frame>.png`, so anyone can recompute the figures, `--msaa-off` gives every run's
//! camera `Msaa::Off` (lodkit's frame-sequential combine instead of its dither).
//!
//! Exit codes: 0 done, 1 the scene did not load or render, 2 usage or I/O error.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/gltf_scene.rs"]
mod gltf_scene;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
#[path = "../frame_sequential/measure.rs"]
#[allow(dead_code, reason = "shared with the frame_sequential example")]
mod measure;
mod runs;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bevy::prelude::*;
use serde_json::{Value, json};

use frames::{Frame, strip};
use runs::{BACKGROUND, Failure, Run, Scene, Technique};

const USAGE: &str = "usage: gltf_scene [--out DIR] [--report FILE] [--gltf FILE] [--frames N] [--save-frames DIR] \
     [--msaa-off]";

struct Args {
    out: PathBuf,
    report: Option<PathBuf>,
    gltf: PathBuf,
    frames: usize,
    save_frames: Option<PathBuf>,
    msaa_off: bool,
}

fn parse() -> Result<Option<Args>, String> {
    let mut args = Args {
        out: PathBuf::from("lodkit-bevy-gltf-scene"),
        report: None,
        gltf: Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assets/lod_scene.glb"),
        frames: 120,
        save_frames: None,
        msaa_off: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("`{arg}` needs a value"));
        match arg.as_str() {
            "-h" | "--help" => return Ok(None),
            "--out" => args.out = PathBuf::from(value()?),
            "--report" => args.report = Some(PathBuf::from(value()?)),
            "--gltf" => args.gltf = PathBuf::from(value()?),
            "--save-frames" => args.save_frames = Some(PathBuf::from(value()?)),
            "--msaa-off" => args.msaa_off = true,
            "--frames" => {
                let v = value()?;
                args.frames = match v.parse() {
                    Ok(n) if n >= 8 => n,
                    _ => return Err(format!("--frames {v}: a whole number, at least 8")),
                };
            }
            _ => return Err(format!("unexpected argument `{arg}`")),
        }
    }
    Ok(Some(args))
}

fn main() -> ExitCode {
    let args = match parse() {
        Ok(Some(args)) => args,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}

/// The camera at each of `frames` frames: from 2.5 world units off the scene's centre back to
/// `far`, a little above, evenly in the square root of the distance (slower near, where the
/// first switches are close together, faster far).
fn walk((centre, _): (Vec3, f32), far: f32, frames: usize) -> Vec<Transform> {
    let (near, far) = (2.5f32.sqrt(), far.sqrt());
    (0..frames)
        .map(|f| {
            let t = f as f32 / (frames - 1) as f32;
            let distance = (near + t * (far - near)).powi(2);
            let eye = centre + distance * Vec3::new(0.0, 0.3, 1.0).normalize();
            Transform::from_translation(eye).looking_at(centre, Vec3::Y)
        })
        .collect()
}

/// Per frame, the pixels every reference covers (`all`), or any covers (not `all`), as a frame
/// of `background` with white where they do.
fn covered(references: &[Run], all: bool, background: [u8; 3]) -> Vec<Frame> {
    let first = &references[0].frames;
    (0..first.len())
        .map(|i| {
            let mut out = Frame::filled(first[i].width, first[i].height, background);
            let masks: Vec<Vec<bool>> = references
                .iter()
                .map(|r| r.frames[i].coverage(background))
                .collect();
            for p in 0..masks[0].len() {
                let mut covers = masks.iter().map(|m| m[p]);
                let shown = if all {
                    covers.all(|c| c)
                } else {
                    covers.any(|c| c)
                };
                if shown {
                    out.set_rgb(p as u32 % out.width, p as u32 / out.width, [255; 3]);
                }
            }
            out
        })
        .collect()
}

/// A technique's figures (`measure::Figures`): see-through where every level alone covers
/// (`all`) and the frame shows the background; ghosts where no level covers (outside `any`) and
/// the frame shows something.
fn figures(
    run: &Run,
    references: &[Run],
    [all, any]: [&[Frame]; 2],
    background: [u8; 3],
) -> Result<measure::Figures, Failure> {
    let (fine, coarse) = (&references[0], &references[references.len() - 1]);
    measure::Figures::of(
        &run.frames,
        [&fine.frames, &coarse.frames],
        [all, all],
        [any, any],
        background,
    )
    .map_err(|e| Failure(1, e.to_string()))
}

fn run(args: &Args) -> Result<(), Failure> {
    let io = |e: std::io::Error| Failure(2, e.to_string());
    let gltf = std::fs::canonicalize(&args.gltf)
        .map_err(|e| Failure(2, format!("{}: {e}", args.gltf.display())))?;
    let assets = gltf.parent().map(Path::to_path_buf).unwrap_or_default();
    let file = gltf
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    std::fs::create_dir_all(&args.out).map_err(io)?;
    let mut scene = Scene::load(&assets, &file)?;
    if args.msaa_off {
        scene.msaa = Msaa::Off;
    }
    let poses = walk(scene.sphere, 1.1 * scene.farthest_switch(), args.frames);
    let background = Frame::filled(1, 1, BACKGROUND.to_srgba().to_u8_array_no_alpha()).rgb(0, 0);
    let levels = scene
        .groups
        .iter()
        .map(|g| g.levels.len())
        .max()
        .unwrap_or(1);
    let references = (0..levels)
        .map(|k| scene.run(Technique::Level(k), &poses))
        .collect::<Result<Vec<Run>, Failure>>()?;
    if references[0]
        .frames
        .iter()
        .all(|f| f.object_pixels(background) == 0)
    {
        return Err(Failure(
            1,
            "nothing rendered: the reference frames are empty".into(),
        ));
    }
    let crossfade = scene.run(Technique::BevyCrossfade, &poses)?;
    let lodkit = scene.run(Technique::FrameSequential, &poses)?;
    let all = covered(&references, true, background);
    let any = covered(&references, false, background);
    let mut report = serde_json::Map::new();
    let named = references
        .iter()
        .enumerate()
        .map(|(k, r)| (format!("reference_level{k}"), r));
    for (name, run) in named.chain([
        ("bevy_crossfade".to_owned(), &crossfade),
        ("frame_sequential".to_owned(), &lodkit),
    ]) {
        let picks: Vec<Frame> = (0..8)
            .map(|k| run.frames[k * (run.frames.len() - 1) / 7].clone())
            .collect();
        let path = args.out.join(format!("strip_{name}.png"));
        headless::save_png(&strip(&picks), &path).map_err(|e| Failure(2, e))?;
        if let Some(dir) = &args.save_frames {
            let folder = dir.join(&name);
            std::fs::create_dir_all(&folder).map_err(io)?;
            for (i, frame) in run.frames.iter().enumerate() {
                let path = folder.join(format!("{i:03}.png"));
                headless::save_png(frame, &path).map_err(|e| Failure(2, e))?;
            }
        }
        if !name.starts_with("reference") {
            let f = figures(run, &references, [&all, &any], background)?;
            println!("{name:18} {}", f.line());
            report.insert(name, f.json());
        }
    }
    let groups: Vec<Value> = scene
        .groups
        .iter()
        .zip(&lodkit.drawn)
        .map(|(g, drawn)| {
            json!({
                "name": g.name,
                "levels": g.levels.len(),
                "impostor": matches!(g.levels.last(), Some((_, runs::LevelDraw::Impostor(_)))),
                "distances": g.distances,
                "max_distance": g.max_distance,
                "drawn": drawn,
            })
        })
        .collect();
    println!(
        "{} groups from {file}, {} meshes without levels; levels lodkit drew per group: {}",
        groups.len(),
        scene.plain_meshes,
        lodkit
            .drawn
            .iter()
            .map(|d| format!("{d:?}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    if let Some(path) = &args.report {
        report.insert("file".into(), json!(file));
        report.insert("frames".into(), json!(args.frames));
        report.insert("size".into(), json!([runs::WIDTH, runs::HEIGHT]));
        report.insert("groups".into(), json!(groups));
        report.insert("plain_meshes".into(), json!(scene.plain_meshes));
        report.insert("msaa_off".into(), json!(args.msaa_off));
        let text = serde_json::to_string_pretty(&Value::Object(report)).expect("JSON");
        std::fs::write(path, text).map_err(io)?;
    }
    Ok(())
}
