//! The quality and cost harness behind `lodkit demo`: renders the built-in
//! scenes (or a RON scene) headless with every technique, measures pop, see-through, cost, pass
//! time ratios and framebuffer-LOD quality, and writes images, PNG plots, `report.json` and a
//! browsable `index.html`; optionally regenerates `docs/benchmarks.md` and `docs/quality.md`.
//!
//! ```no_run
//! let options = lodkit_cli::demo::DemoOptions::default();
//! let report = lodkit_cli::demo::run(&options)?;
//! println!("{}", lodkit_cli::demo::report::terminal::summary(&report));
//! # Ok::<(), lodkit_cli::demo::DemoError>(())
//! ```
//!
//! Three layers, each importing only from those below it (`integration_tests/house.rs` checks):
//! - [`fixtures`]: the scenes, their renderers, the edge-scene frame the pass ratios, the frame
//!   cost and the closed loop read, the GPU clock;
//! - [`measures`]: each figure of the report, returned as a serializable struct;
//! - [`report`]: the HTML page, the Markdown pages, the plots, the tables and the terminal
//!   summary.
//!
//! [`error`] is beneath all three; this module runs them in order.

pub mod error;
pub mod fixtures;
pub mod measures;
pub mod report;

use std::path::PathBuf;

use lodkit::gpu::{GpuContext, GpuError, GpuOptions};

pub use error::{DemoError, save};
use fixtures::chain_scene;
use fixtures::clock::{self, RECORDINGS};
use fixtures::render;
use fixtures::scene::{DemoScene, SceneError};
pub use measures::DemoReport;
use measures::{
    closed_loop, combine_timing, controllers, frame_cost, host_cost, impostor_atlas, lod_chain,
    packed_upsample_timing, selection, transitions, upsample_quality, upsample_timing,
};
use report::{doc_pictures, framebuffer_lod, plots};

/// What `lodkit demo` renders and where it writes.
#[derive(Clone, Debug)]
pub struct DemoOptions {
    /// Output folder (created; files in it are overwritten).
    pub out: PathBuf,
    /// Image size of every rendering, 64..=4096 each way.
    pub size: (u32, u32),
    /// Frames a transition lasts, 4..=600.
    pub frames: usize,
    /// A RON scene to measure instead of the built-in ones.
    pub scene: Option<PathBuf>,
    /// Interleaved pairs per pass-time ratio (1..=10000); a quarter of it (at least 3) is the
    /// number of rounds of the frame-cost breakdown's pass timing, an eighth (at least 3) that
    /// of whole-frame timing (a whole frame is long and steady next to one pass).
    pub timing_pairs: usize,
    /// Folder to write `benchmarks.md`, `quality.md` and the guides' pictures (`img/`) into.
    pub docs: Option<PathBuf>,
    /// Size of the framebuffer-LOD frame-cost breakdown, shading-cost sweep and closed-loop
    /// controller runs (64..=4096 each way; default 1280x720, where a pass is not dominated by
    /// submission overhead).
    pub fb_size: (u32, u32),
    /// Show progress on stderr: a bar on a terminal, one line per scene and part elsewhere (a
    /// CI log, a pipe).
    pub progress: bool,
}

impl DemoOptions {
    /// The `lodkit demo` command line that runs these options.
    pub fn command_line(&self) -> String {
        let mut s = format!(
            "lodkit demo --size {}x{} --frames {} --pairs {} --fb-size {}x{}",
            self.size.0,
            self.size.1,
            self.frames,
            self.timing_pairs,
            self.fb_size.0,
            self.fb_size.1
        );
        if let Some(scene) = &self.scene {
            s.push_str(&format!(" --scene {}", scene.display()));
        }
        if let Some(docs) = &self.docs {
            s.push_str(&format!(" --docs {}", docs.display()));
        }
        s
    }
}

impl Default for DemoOptions {
    fn default() -> Self {
        Self {
            out: PathBuf::from("lodkit-demo"),
            size: (320, 180),
            frames: 24,
            scene: None,
            timing_pairs: 40,
            docs: None,
            fb_size: (1280, 720),
            progress: true,
        }
    }
}

/// The most memory the frames of one run may take.
pub const MAX_FRAME_MEMORY_MIB: u64 = 2048;

fn check_options(o: &DemoOptions) -> Result<(), DemoError> {
    for (flag, (w, h)) in [("--size", o.size), ("--fb-size", o.fb_size)] {
        if !(64..=4096).contains(&w) || !(64..=4096).contains(&h) {
            return Err(DemoError::Options(format!(
                "{flag} {w}x{h}: each side must be within 64..=4096"
            )));
        }
    }
    let (w, h) = o.size;
    if !(4..=600).contains(&o.frames) {
        return Err(DemoError::Options(format!(
            "--frames {}: must be within 4..=600",
            o.frames
        )));
    }
    if !(1..=10_000).contains(&o.timing_pairs) {
        return Err(DemoError::Options(format!(
            "--pairs {}: must be within 1..=10000",
            o.timing_pairs
        )));
    }
    // A moving-camera reference run is kept whole (RGBA8 frames).
    let frames = o.frames as u64 + 2 * render::LEAD_FRAMES as u64 + 1;
    let mib = (u64::from(w) * u64::from(h) * 4 * frames) >> 20;
    if mib > MAX_FRAME_MEMORY_MIB {
        return Err(DemoError::Options(format!(
            "--size {w}x{h} with --frames {} keeps {mib} MiB of frames, more than \
             {MAX_FRAME_MEMORY_MIB} MiB: lower one of them",
            o.frames
        )));
    }
    Ok(())
}

/// UTC date of `secs` seconds after the Unix epoch as YYYY-MM-DD (civil-from-days).
pub fn utc_date(secs: u64) -> String {
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// Opens the GPU the demo runs on: the first adapter of `LODKIT_BACKEND` or Vulkan then GL,
/// with pipeline statistics and timestamps inside encoders when the adapter has them.
pub fn open_gpu() -> Result<GpuContext, DemoError> {
    let options = GpuOptions {
        optional_features: wgpu::Features::PIPELINE_STATISTICS_QUERY | clock::TIMESTAMP_FEATURES,
        ..Default::default()
    };
    GpuContext::new_headless(&options).map_err(|e| match e {
        GpuError::NoAdapter { .. } => DemoError::NoAdapter { source: e },
        other => DemoError::Gpu(other),
    })
}

/// Runs the whole demo on a GPU of its own (see [`open_gpu`]).
pub fn run(options: &DemoOptions) -> Result<DemoReport, DemoError> {
    check_options(options)?;
    let scenes = match &options.scene {
        Some(path) => vec![DemoScene::from_file(path)?],
        None => DemoScene::built_in(),
    };
    let gpu = open_gpu()?;
    run_on(&gpu, options, &scenes)
}

/// Most scenes whose transitions are measured at once.
const MAX_SCENE_WORKERS: usize = 4;

/// The transitions' rows, what the fragment counts count, and the scenes' impostor atlases.
type Transitions = (
    Vec<transitions::TransitionMetrics>,
    String,
    Vec<impostor_atlas::AtlasFigure>,
);

/// The transitions of every scene, in `scenes`' order, the fragment counter's description and
/// the scenes' octahedral impostor atlases (their pictures written into the output folder).
///
/// Scenes are measured side by side, one thread each, up to the machine's cores (at most
/// [`MAX_SCENE_WORKERS`]): a scene's metrics are CPU work between its GPU runs, so a second
/// scene's runs keep the cores busy meanwhile. The scene with the most objects starts first.
/// Nothing a scene measures depends on another's (its own renderer, counters and files; no
/// figure here is a time), so the rows are the same as one by one.
fn measure_transitions(
    gpu: &GpuContext,
    options: &DemoOptions,
    scenes: &[DemoScene],
    bar: &crate::progress::Progress,
) -> Result<Transitions, DemoError> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    for scene in scenes {
        scene.check().map_err(|message| SceneError::Invalid {
            path: format!("scene `{}`", scene.name),
            message,
        })?;
    }
    let measure = |scene: &DemoScene| {
        bar.set_message(format!("scene {}", scene.name));
        let renderer = render::SceneRenderer::new(gpu, scene, options.size, options.frames)?;
        let counter = renderer.counter().kind().describe().to_owned();
        let atlas = impostor_atlas::write(&renderer, &scene.name, &options.out)?;
        let mut tick = |name: &str| bar.done(format!("scene {}: {name}", scene.name));
        let rows = transitions::measure_scene(
            gpu,
            &renderer,
            &scene.name,
            options.size,
            &options.out,
            &mut tick,
        )?;
        Ok::<_, DemoError>((rows, counter, atlas))
    };
    let mut order: Vec<usize> = (0..scenes.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(scenes[i].objects.len()));
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, MAX_SCENE_WORKERS)
        .min(scenes.len());
    let next = AtomicUsize::new(0);
    let results: Vec<Mutex<Option<Result<_, DemoError>>>> =
        scenes.iter().map(|_| Mutex::new(None)).collect();
    // The first scene to fail, in time: a scene running beside it may fail because of it (a
    // lost device), and the first failure is the one to report.
    let first_failure: Mutex<Option<usize>> = Mutex::new(None);
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let result = measure(&scenes[i]);
                    if result.is_err() {
                        // The run fails: no other scene starts.
                        next.store(order.len(), Ordering::Relaxed);
                        let mut first = first_failure
                            .lock()
                            .unwrap_or_else(std::sync::PoisonError::into_inner);
                        first.get_or_insert(i);
                    }
                    *results[i]
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(result);
                }
            });
        }
    });
    let mut results: Vec<Option<Result<_, DemoError>>> = results
        .into_iter()
        .map(|slot| {
            slot.into_inner()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        })
        .collect();
    let first = first_failure
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(Some(Err(e))) = first.and_then(|i| results.get_mut(i)).map(Option::take) {
        return Err(e);
    }
    let (mut rows, mut counter, mut atlases) = (Vec::new(), String::new(), Vec::new());
    for result in results.into_iter().flatten() {
        let (scene_rows, scene_counter, atlas) = result?;
        rows.extend(scene_rows);
        counter = scene_counter;
        atlases.extend(atlas);
    }
    Ok((rows, counter, atlases))
}

/// Runs the demo on `gpu` over `scenes`.
pub fn run_on(
    gpu: &GpuContext,
    options: &DemoOptions,
    scenes: &[DemoScene],
) -> Result<DemoReport, DemoError> {
    check_options(options)?;
    let start = std::time::Instant::now();
    let out = &options.out;
    std::fs::create_dir_all(out).map_err(|e| DemoError::io(out, e))?;
    let steps =
        scenes.len() * render::Technique::ALL.len() + upsample_quality::RESIZE_FACTORS.len() + 7;
    let bar = crate::progress::Progress::new(options.progress, steps);
    let (transitions, counter, atlases) = measure_transitions(gpu, options, scenes, &bar)?;
    bar.set_message("framebuffer LOD");
    let mut tick = |name: &str| bar.done(format!("framebuffer LOD: {name}"));
    let rounds = (options.timing_pairs / 4).max(3);
    let frame_rounds = (options.timing_pairs / 8).max(3);
    let timer = clock::Timer::new(gpu, RECORDINGS)?;
    let upsampling = upsample_quality::measure_upsampling(
        gpu,
        &timer,
        options.size,
        frame_rounds,
        out,
        &mut tick,
    )?;
    bar.set_message("framebuffer LOD: frame cost and shading sweep");
    let frame_cost =
        frame_cost::measure_frame_cost(gpu, &timer, options.fb_size, rounds, frame_rounds)?;
    bar.inc(1);
    bar.set_message("framebuffer LOD: controllers on the real frame");
    let closed_loop = closed_loop::measure_closed_loop(gpu, options.fb_size)?;
    bar.inc(1);
    bar.set_message("pass time ratios");
    let pairs = options.timing_pairs;
    let combine_size = options.size.0.min(1024);
    let mut pass_ratios =
        combine_timing::combine_vs_copy(gpu, &timer, combine_size, pairs)?.to_vec();
    let fb_size = options.fb_size;
    pass_ratios.extend(upsample_timing::upsample_vs_bilinear(
        gpu, &timer, fb_size, 2.0, pairs,
    )?);
    pass_ratios.extend(packed_upsample_timing::packed_upsample_vs_bilinear(
        gpu, &timer, fb_size, 2.0, pairs,
    )?);
    bar.inc(1);
    bar.set_message("controllers and host-side figures");
    let controllers = controllers::measure_controllers(controllers::CONTROLLER_SEEDS);
    let cpu = host_cost::cpu_figures(15)?;
    bar.inc(1);
    bar.set_message("GPU LOD selection against select_batch");
    let selection = selection::measure(gpu, &timer, 5, &selection::SIZES)?;
    bar.inc(1);
    let chain = if scenes.iter().any(|s| s.name == chain_scene::SCENE) {
        Some(lod_chain::report(out)?)
    } else {
        None
    };
    let info = gpu.adapter.get_info();
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let mut report = DemoReport {
        adapter: gpu.adapter_summary(),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_owned(),
        clock: timer.clock(),
        backend: format!("{:?}", info.backend),
        device_type: format!("{:?}", info.device_type),
        date: utc_date(now),
        command: options.command_line(),
        size: options.size,
        frames: options.frames,
        counter,
        scenes: scenes.iter().map(|s| s.name.clone()).collect(),
        transitions,
        upsampling,
        pass_ratios,
        frame_cost,
        closed_loop,
        controllers,
        selection,
        cpu,
        atlases,
        chain,
        plot_text: plots::plot_font().is_some(),
        seconds: 0.0,
    };
    bar.set_message("plots and report");
    report::write_plots(&report, out)?;
    framebuffer_lod::write_plots(&report, out)?;
    report.seconds = start.elapsed().as_secs_f64();
    report::write_report(&report, out)?;
    if let Some(docs) = &options.docs {
        report::write_docs(&report, docs)?;
        doc_pictures::write_doc_pictures(&report, out, docs)?;
    }
    bar.inc(1);
    bar.finish();
    Ok(report)
}
