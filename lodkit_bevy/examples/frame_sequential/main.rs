//! Frame-sequential LOD in Bevy 0.20 side by side with Bevy's own `VisibilityRange` crossfade:
//! the same scene, meshes and transition distances, rendered headless in one app, one run after
//! the other, every frame read back. Each run has a camera of its own with only what its
//! technique needs, in two kinds of app: one without a prepass (neither technique needs one),
//! and one that runs Bevy's depth and motion-vector prepass anyway (TAA, motion blur; names
//! suffixed `_with_prepass`).
//!
//! ```text
//! cargo run --example frame_sequential [-- [--out DIR] [--report FILE] [--frames DIR]
//!     [--schedule paper|complementary] [--anchor screen|object] [--no-reprojection]
//!     [--coverage estimated|silhouette|depth-pass] [--combine-region hulls|rectangles]
//!     [--without-prepass-only] [--chain] [--msaa]]
//! ```
//!
//! Writes into DIR (default `lodkit-bevy-frame-sequential`) `strip_<run>.png` (7 frames over the
//! moving camera's transitions), with `--report` the figures as JSON (pop, flicker, reversals,
//! see-through, ghosts, coverage, fragments per pass), with `--frames DIR` every frame of every run as
//! `DIR/<run>_<static|moving>/<frame>.png` (the references as `reference_fine` and
//! `reference_coarse`), so anyone can recompute the figures. `--schedule` picks how the two
//! levels share the pattern (default `paper`, the plugin's default). `--no-reprojection` breaks the
//! combine on purpose (the older frame read at the same pixel): the moving camera then shows the
//! background through the objects. `--coverage` sets `FrameSequentialLod::coverage` (default
//! `silhouette`; with `depth-pass` the older-level depth pass's samples are the report's
//! `fragments_<run>_older_depth`). `--combine-region` sets
//! `FrameSequentialLod::combine_region` (default `hulls`; `rectangles`, the groups' screen
//! rectangles, draws the same picture with more of the combine's fragments:
//! `fragments_<run>_combine`). `--without-prepass-only` skips the app with a prepass.
//! `--msaa` gives every camera Bevy's default `Msaa::Sample4`: the frame-sequential runs then take
//! the plugin's fallback, lodkit's complementary screen-door dither (in the app with a prepass
//! too: the levels' prepass drops the same pixels).
//! Exit codes: 0 done, 1 nothing rendered, 2 usage or I/O error.
//!
//! The scene is `scene.rs` (what a Bevy app writes to use the plugin is there, in
//! `spawn_groups`), the metrics `measure.rs`, one run `run.rs`, the comparison `report.rs`.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
#[allow(dead_code, reason = "shared with the other examples; each uses a part")]
mod measure;
mod report;
mod run;
mod scene;

use std::path::PathBuf;
use std::process::ExitCode;

use lodkit::frame_sequential::Schedule;
use lodkit_bevy::FrameSequentialLod;
use lodkit_bevy::frame_sequential::{CombineRegion, OlderCoverage, VisibilitySpace};

/// Parsed command line.
pub struct Args {
    out: PathBuf,
    report: Option<PathBuf>,
    frames: Option<PathBuf>,
    with_prepass: bool,
    schedule: Schedule,
    anchor: VisibilitySpace,
    reprojection: bool,
    coverage: OlderCoverage,
    combine_region: CombineRegion,
    msaa: bool,
}

const USAGE: &str = "usage: frame_sequential [--out DIR] [--report FILE] [--frames DIR] \
[--schedule paper|complementary] [--anchor screen|object] [--no-reprojection] \
[--coverage estimated|silhouette|depth-pass] [--combine-region hulls|rectangles] \
[--without-prepass-only] [--chain] [--msaa]";

fn parse() -> Result<Option<Args>, String> {
    let mut args = Args {
        out: PathBuf::from("lodkit-bevy-frame-sequential"),
        report: None,
        frames: None,
        with_prepass: true,
        schedule: FrameSequentialLod::default().schedule,
        anchor: VisibilitySpace::Screen,
        reprojection: true,
        coverage: OlderCoverage::default(),
        combine_region: CombineRegion::default(),
        msaa: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("`{arg}` needs a value"));
        match arg.as_str() {
            "-h" | "--help" => return Ok(None),
            "--out" => args.out = PathBuf::from(value()?),
            "--report" => args.report = Some(PathBuf::from(value()?)),
            "--frames" => args.frames = Some(PathBuf::from(value()?)),
            "--without-prepass-only" => args.with_prepass = false,
            "--schedule" => {
                args.schedule = match value()?.as_str() {
                    "complementary" => Schedule::Complementary,
                    "paper" => Schedule::Paper,
                    other => return Err(format!("unknown schedule `{other}`")),
                }
            }
            "--anchor" => {
                args.anchor = match value()?.as_str() {
                    "screen" => VisibilitySpace::Screen,
                    "object" => VisibilitySpace::Object,
                    other => return Err(format!("unknown anchor `{other}`")),
                }
            }
            "--no-reprojection" => args.reprojection = false,
            "--chain" => scene::use_chain(),
            "--msaa" => args.msaa = true,
            "--coverage" => {
                args.coverage = match value()?.as_str() {
                    "estimated" => OlderCoverage::Estimated,
                    "silhouette" => OlderCoverage::Silhouette,
                    "depth-pass" => OlderCoverage::DepthPass,
                    other => return Err(format!("unknown coverage `{other}`")),
                }
            }
            "--combine-region" => {
                args.combine_region = match value()?.as_str() {
                    "hulls" => CombineRegion::Hulls,
                    "rectangles" => CombineRegion::Rectangles,
                    other => return Err(format!("unknown combine region `{other}`")),
                }
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
    match report::run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(run::Failure(code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}
