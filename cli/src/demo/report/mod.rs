//! The demo's outputs from a [`DemoReport`]: PNG plots, `report.json`, `index.html` and the two
//! generated docs pages (the terminal summary is in [`terminal`]).

pub mod closed_loop;
pub mod doc_pictures;
pub mod frame_cost;
pub mod framebuffer_lod;
pub mod gpu_report;
pub mod lod_chain;
pub mod plots;
pub mod selection;
pub mod table;
pub mod terminal;

use std::fmt::Write as _;
use std::path::Path;

use crate::demo::error::DemoError;
use crate::demo::fixtures::technique::Technique;
use crate::demo::measures::DemoReport;
use crate::demo::measures::controllers::{CONTROLLER_SEEDS, TARGET_MS};
use crate::demo::measures::upsample_quality::{METHODS, ROUTES, SHADING_WORK};
use crate::demo::report::plots::{Chart, Series, line_chart};
use crate::demo::report::table::{Table, esc, img, pct, reads, times};

fn write(path: &Path, text: &str) -> Result<(), DemoError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| DemoError::io(dir, e))?;
    }
    std::fs::write(path, text).map_err(|e| DemoError::io(path, e))
}

/// Writes the plots under `out/plots/`.
pub fn write_plots(report: &DemoReport, out: &Path) -> Result<(), DemoError> {
    for scene in &report.scenes {
        for moving in [false, true] {
            let camera = if moving { "moving" } else { "static" };
            let series = report
                .transitions
                .iter()
                .filter(|t| &t.scene == scene)
                .map(|t| Series {
                    name: t.technique.clone(),
                    points: (if moving {
                        &t.change_moving
                    } else {
                        &t.change_static
                    })
                    .iter()
                    .enumerate()
                    .map(|(f, &c)| ((f + 1) as f32, c * 100.0))
                    .collect(),
                })
                .collect();
            let chart = Chart {
                title: format!("{scene}, {camera} camera: image change per frame"),
                x_label: "frame".to_owned(),
                y_label: "change from the transition (% of full scale)".to_owned(),
                series,
                markers: false,
                reference: None,
                y_from_zero: true,
            };
            line_chart(
                &out.join(format!("plots/change-{scene}-{camera}.png")),
                &chart,
            )?;
        }
    }
    let u = &report.upsampling;
    let by_r = (0..METHODS.len())
        .map(|k| Series {
            name: METHODS[k].to_owned(),
            points: u.iter().map(|row| (row.r, row.psnr[k])).collect(),
        })
        .collect();
    line_chart(
        &out.join("plots/psnr-vs-r.png"),
        &Chart {
            title: "Framebuffer LOD: PSNR against the full-resolution frame".to_owned(),
            x_label: "resize factor r".to_owned(),
            y_label: "PSNR (dB)".to_owned(),
            series: by_r,
            markers: true,
            reference: None,
            y_from_zero: false,
        },
    )?;
    let by_speed = ROUTES
        .iter()
        .enumerate()
        .map(|(s, &(_, k))| Series {
            name: METHODS[k].to_owned(),
            points: u
                .iter()
                .map(|row| (row.speedup[s] as f32, row.psnr[k]))
                .collect(),
        })
        .collect();
    line_chart(
        &out.join("plots/psnr-vs-speedup.png"),
        &Chart {
            title: "Framebuffer LOD: quality against whole-frame speed-up".to_owned(),
            x_label: "speed-up over full resolution".to_owned(),
            y_label: "PSNR (dB)".to_owned(),
            series: by_speed,
            markers: true,
            reference: None,
            y_from_zero: false,
        },
    )?;
    let curves = report
        .controllers
        .iter()
        .map(|c| Series {
            name: c.name.clone(),
            points: c
                .curve
                .iter()
                .enumerate()
                .map(|(f, &t)| (f as f32, t))
                .collect(),
        })
        .collect();
    line_chart(
        &out.join("plots/controllers.png"),
        &Chart {
            title: "Frame time under a 2x workload step (frames 60-160)".to_owned(),
            x_label: "frame".to_owned(),
            y_label: "frame time (ms)".to_owned(),
            series: curves,
            markers: false,
            reference: Some(TARGET_MS),
            y_from_zero: true,
        },
    )
}

/// The transition metrics of `scene`: quality (pop, see-through) or cost.
fn transition_table(report: &DemoReport, scene: &str, cost: bool) -> Table {
    let rows = report.transitions.iter().filter(|t| t.scene == scene);
    if cost {
        Table {
            header: &[
                "technique",
                "triangles",
                "vs hard switch",
                "fragments",
                "vs hard switch",
                "frames without a t-instance, vs hard switch",
            ],
            rows: rows
                .map(|t| {
                    vec![
                        t.technique.clone(),
                        t.triangles.to_string(),
                        format!("{:.3}x", t.triangles_vs_hard),
                        t.fragments.map_or("n/a".to_owned(), |f| f.to_string()),
                        times(t.fragments_vs_hard),
                        times(t.idle_fragments_vs_hard),
                    ]
                })
                .collect(),
        }
    } else {
        Table {
            header: &[
                "technique",
                "pop (static)",
                "pop (moving)",
                "see-through",
                "silhouette error (moving)",
                "flicker (static)",
                "flicker (moving)",
                "flicker vs coarse (static)",
                "flicker vs coarse (moving)",
                "see-through / ghosts (pixel-frames)",
            ],
            rows: rows
                .map(|t| {
                    vec![
                        t.technique.clone(),
                        format!("{:.3}", t.pop_static),
                        format!("{:.3}", t.pop_moving),
                        pct(t.see_through),
                        pct(t.silhouette_error),
                        format!("{:.2} ({} rev.)", t.flicker_static, t.reversals_static),
                        format!("{:.2} ({} rev.)", t.flicker_moving, t.reversals_moving),
                        format!(
                            "{:.2} ({} rev.)",
                            t.flicker_static_coarse, t.reversals_static_coarse
                        ),
                        format!(
                            "{:.2} ({} rev.)",
                            t.flicker_moving_coarse, t.reversals_moving_coarse
                        ),
                        format!("{} / {}", t.see_through_pixel_frames, t.ghost_pixel_frames),
                    ]
                })
                .collect(),
        }
    }
}

/// Markdown tables of the transition metrics, one per scene.
fn transition_tables(report: &DemoReport, cost: bool) -> String {
    let mut s = String::new();
    for scene in &report.scenes {
        let _ = writeln!(s, "\n### Scene `{scene}`\n");
        s.push_str(&transition_table(report, scene, cost).markdown());
    }
    s
}

fn upsample_table(report: &DemoReport) -> Table {
    Table {
        header: &[
            "r",
            "PSNR bilinear",
            "PSNR bilateral",
            "PSNR fine-grained",
            "PSNR bilateral, packed L",
            "PSNR fine-grained, packed L",
            "SSIM bilinear",
            "SSIM bilateral",
            "SSIM fine-grained",
            "SSIM bilateral, packed L",
            "SSIM fine-grained, packed L",
        ],
        rows: report
            .upsampling
            .iter()
            .map(|u| {
                let mut row = vec![u.r.to_string()];
                row.extend(u.psnr.iter().map(|p| format!("{p:.2} dB")));
                row.extend(u.ssim.iter().map(|v| format!("{v:.4}")));
                row
            })
            .collect(),
    }
}

fn speed_table(report: &DemoReport) -> Table {
    Table {
        header: &[
            "r",
            "whole frame, bilateral route",
            "whole frame, fine-grained route",
            "whole frame, bilateral route, packed L",
            "whole frame, fine-grained route, packed L",
        ],
        rows: report
            .upsampling
            .iter()
            .map(|u| {
                let mut row = vec![u.r.to_string()];
                row.extend(u.speedup.iter().map(|x| format!("{x:.2}x")));
                row
            })
            .collect(),
    }
}

pub(crate) fn ratio_table(ratios: &[crate::demo::measures::upsample_timing::PassRatio]) -> Table {
    Table {
        header: &[
            "pass",
            "baseline",
            "size",
            "pass ms",
            "baseline ms",
            "median ratio",
            "pairs",
            "clock",
            "fetches / texels / bytes per pixel, pass vs baseline",
        ],
        rows: ratios
            .iter()
            .map(|p| {
                vec![
                    p.pass.clone(),
                    p.baseline.clone(),
                    format!("{}x{}", p.size.0, p.size.1),
                    format!("{:.3}", p.pass_ms),
                    format!("{:.3}", p.baseline_ms),
                    format!("{:.3}", p.ratio),
                    p.pairs.to_string(),
                    p.clock.label().to_owned(),
                    format!("{} vs {}", reads(&p.pass_reads), reads(&p.baseline_reads)),
                ]
            })
            .collect(),
    }
}

fn controller_table(report: &DemoReport) -> Table {
    Table {
        header: &["controller", "settling frames", "overshoot", "spread"],
        rows: report
            .controllers
            .iter()
            .map(|c| {
                vec![
                    c.name.clone(),
                    c.settling_frames
                        .map_or("never".to_owned(), |f| format!("{f}")),
                    pct(c.overshoot),
                    pct(c.spread),
                ]
            })
            .collect(),
    }
}

fn cpu_table(report: &DemoReport) -> Table {
    Table {
        header: &["what", "median", "runs"],
        rows: report
            .cpu
            .iter()
            .map(|c| {
                vec![
                    c.what.clone(),
                    format!("{:.2} {}", c.median, c.unit),
                    c.runs.to_string(),
                ]
            })
            .collect(),
    }
}

fn header(report: &DemoReport, what: &str) -> String {
    let (width, height) = report.size;
    format!(
        "# {what}\n\nGenerated by `{command}` on {date} (do not edit by hand; run it again). \
         Adapter: {adapter} — backend {backend}, device type {device}, driver {driver}. Clock: \
         {clock}. Images {width}x{height}, transitions of {frames} frames; fragment counts are \
         {counter}. The demo's own report (`index.html` in its output folder) shows the images \
         behind these figures. Timings are per recording of a pass, read from the clock named: \
         GPU timestamps around a run of {recordings} recordings in one encoder (fewer where \
         one recording lasts {min_run} ms or more: as many as make the run last that long; the \
         GPU's own time, no submission or wait), or, where the device has none, the wall clock \
         around the run's submission and wait; on a software rasterizer (device type Cpu) read \
         the ratios, not the milliseconds.\n",
        command = report.command,
        date = report.date,
        adapter = report.adapter,
        backend = report.backend,
        device = report.device_type,
        driver = report.driver,
        clock = report.clock.label(),
        frames = report.frames,
        counter = report.counter,
        recordings = crate::demo::fixtures::clock::RECORDINGS,
        min_run = crate::demo::fixtures::clock::MIN_RUN_MS,
    )
}

const POP_TEXT: &str = "Pop is the largest single-frame share of the image change a transition \
causes (1.0: all of it in one frame, as a hard switch; 1/N: spread evenly over N frames). With \
the moving camera, the change of a run without transition is subtracted frame by frame. \
See-through is the share of the transitioning objects' interior (pixels both LODs cover) where \
the background contributes to the static camera's middle frame: the frame is rendered over black \
and over white scenery and the pixels that differ are counted. Silhouette error is measured at \
the middle frame of the moving camera: pixels both LODs cover that show the background, plus \
pixels neither covers that show a transitioning object, as a share of the pixels either covers. \
The last column counts both kinds on every frame of the transition with both cameras, against \
what each LOD alone covers at that frame: see-through / ghost pixel-frames. \
`frame-seq-default` is frame-sequential LOD with the library's defaults, nothing else chosen: \
`TransitionScheduler::new()` (the complementary schedule), `CombinePassDescriptor::default()`, \
`LodBuffers::new`, the pattern on the screen, and the default route to the older levels' \
coverage: the t-instances' older levels drawn again each frame, whole and depth only, into \
`LodBuffers::level_depth` (its fragments and triangles counted in the row), and the frame's data \
from `CombineData::depth_pass` with a default `DepthPassFrame`; `frame-seq-silhouettes` the same \
with the route that draws no extra pass: each level registered once in `CoverageLevels` (a closed \
mesh by its surface, an impostor card by its mask's outline) and the frame's data from \
`CoverageLevels::data` (a scene with a swaying impostor card, which has no exact silhouette, \
names the estimate for it).\n";

/// Writes `benchmarks.md` and `quality.md` into `docs`.
pub fn write_docs(report: &DemoReport, docs: &Path) -> Result<(), DemoError> {
    let mut q = header(report, "Quality");
    q.push_str("\n## Transitions\n\n");
    q.push_str(POP_TEXT);
    q.push_str(&transition_tables(report, false));
    q.push_str("\n## Framebuffer LOD\n\n");
    let lodkit::bilateral::RangeSigmas {
        depth: depth_sigma,
        normal: normal_sigma,
    } = lodkit::bilateral::RangeSigmas::default();
    let _ = writeln!(
        q,
        "Edge scene with synthetic shading work (a smooth sky term summed over {SHADING_WORK} directions per fragment, the expensive low-frequency shading framebuffer LOD is for), full-resolution frame as reference; bilateral sigmas (`RangeSigmas`, the defaults): depth {depth_sigma} of the view depth, normal {normal_sigma}; fine-grained resizing sends only the lighting through the low-res buffer, and its upsample pass multiplies by the full-resolution albedo (the image measured is the one the timed frame produces); \"packed L\" reads lodkit::gbuffer's packed texel (HDR color as halves, depth, normal: 4 low-res loads per pixel instead of 8).\n"
    );
    q.push_str(&upsample_table(report).markdown());
    // The controllers on the real frame are the headline; the simulation stands beside them.
    q.push_str(&framebuffer_lod::quality_markdown(report));
    q.push_str("\n### Beside it: the simulation\n\nSimulated frame time t = K workload / r^2 + C with 3 % noise (K = 40 ms, C = 3 ms), ");
    let _ = writeln!(
        q,
        "target {TARGET_MS} ms, workload doubling at frame 60 and back at 160; settling counted over frames 60 to 160; medians over {CONTROLLER_SEEDS} seeds.\n"
    );
    q.push_str(&controller_table(report).markdown());
    write(&docs.join("quality.md"), &q)?;
    let mut b = header(report, "Benchmarks");
    b.push_str("\n## Cost of a transition\n\nTriangles submitted and fragments counted over the transition's frames, static camera. Frame-sequential adds the combine pass over the screen rectangles of the objects in transition (one fragment per pixel of the rectangles, included; the rest of the frame is a copy). The last column compares the frames before and after the transition, with no object in transition.\n");
    b.push_str(&transition_tables(report, true));
    b.push_str(&format!("\n## Pass time ratios\n\nEach pass against the plainest pass with the same memory traffic, timed in interleaved pairs; the figure is the median of the per-pair ratios, on the clock each row names. Host work is the same on both sides: {}. Fetches, texels and bytes per pixel are counted from each shader (`lodkit check --stats`), weighed by the formats bound.\n\n", crate::demo::measures::upsample_timing::HOST_WORK));
    b.push_str(&ratio_table(&report.pass_ratios).markdown());
    b.push_str("\n## Framebuffer LOD: whole-frame speed-up\n\n");
    let _ = writeln!(
        b,
        "Median time of a full-resolution frame over a framebuffer-LOD frame (per recording, on the report's clock: {clock}): the full-resolution geometry prepass the upsampling needs (depth and normals, with the cheap albedo), the low-res shading pass and the upsample pass (fine-grained: the low-res lighting pass, the full-resolution albedo pass that also writes the geometry, and the upsample, which multiplies by that albedo: no composite pass left out). Edge scene with {SHADING_WORK} sky directions of shading work per fragment.\n",
        clock = report.clock.label()
    );
    b.push_str(&speed_table(report).markdown());
    b.push_str(&framebuffer_lod::benchmarks_markdown(report));
    b.push_str("\n## Host side (CPU)\n\nMedians of repeated runs in the same process (the machine's CPU, not the GPU). The criterion benches measure the same workloads more thoroughly: `cargo bench -p lodkit-cli --bench compose`, `cargo bench -p lodkit-cli --bench select`; `cargo bench -p lodkit-cli --bench combine` and `--bench upsample` print the pass ratios above on their own.\n\n");
    b.push_str(&cpu_table(report).markdown());
    let sel = &report.selection;
    let _ = write!(b, "\n## GPU LOD selection\n\n{}\n\n", selection::text(sel));
    b.push_str(&selection::table(sel).markdown());
    // Sections the demo does not measure (`lodkit check` against naga-cli) follow a marker in
    // the file; they are kept as they are.
    let path = docs.join("benchmarks.md");
    if let Ok(old) = std::fs::read_to_string(&path)
        && let Some(at) = old.find(HAND_WRITTEN)
    {
        b.push('\n');
        b.push_str(&old[at..]);
    }
    write(&path, &b)
}

/// The line in `benchmarks.md` after which the text is written by hand, and kept by
/// `lodkit demo --docs`.
pub const HAND_WRITTEN: &str =
    "<!-- Written by hand from here on; `lodkit demo --docs` keeps this part. -->";

/// Writes `report.json` and `index.html` into `out`.
pub fn write_report(report: &DemoReport, out: &Path) -> Result<(), DemoError> {
    let json =
        serde_json::to_string_pretty(report).map_err(|e| DemoError::Internal(e.to_string()))?;
    write(&out.join("report.json"), &json)?;
    let mut h = String::from(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>lodkit demo</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:1400px}img{max-width:100%;image-rendering:pixelated}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}th{background:#eee}figure{margin:1em 0}figcaption{color:#555;font-size:90%}</style></head><body>\n<h1>lodkit demo</h1>\n",
    );
    let _ = writeln!(
        h,
        "<p>{} · adapter {} · driver {} · clock: {} · {}x{} · transitions of {} frames · fragments: {} · {:.0} s</p>",
        report.date,
        esc(&report.adapter),
        esc(&report.driver),
        report.clock.label(),
        report.size.0,
        report.size.1,
        report.frames,
        esc(&report.counter),
        report.seconds
    );
    h.push_str("<h2>Transitions</h2>\n<p>");
    h.push_str(POP_TEXT);
    h.push_str("</p>\n");
    for scene in &report.scenes {
        let _ = writeln!(h, "<h3>Scene {scene}</h3>");
        if let Some(chain) = report.chain.as_ref().filter(|c| &c.scene == scene) {
            h.push_str(&lod_chain::html(chain));
        }
        for atlas in report.atlases.iter().filter(|a| &a.scene == scene) {
            h.push_str(&img(
                &atlas.picture,
                &format!(
                    "the octahedral impostor's colour atlas (lodkit::gpu::impostor, baked when \
                     the scene is loaded): {f} x {f} frames of {} texels, {} sphere of \
                     directions",
                    atlas.frame_size,
                    if atlas.hemi {
                        "upper half of the"
                    } else {
                        "the whole"
                    },
                    f = atlas.frames
                ),
            ));
        }
        let rows: Vec<_> = report
            .transitions
            .iter()
            .filter(|t| &t.scene == scene)
            .collect();
        h.push_str(&transition_table(report, scene, false).html());
        h.push_str(&transition_table(report, scene, true).html());
        for camera in ["static", "moving"] {
            h.push_str(&img(
                &format!("plots/change-{scene}-{camera}.png"),
                &format!("image change per frame, {camera} camera"),
            ));
        }
        let order: Vec<&str> = rows.iter().map(|t| t.technique.as_str()).collect();
        h.push_str(&img(
            &format!("close-ups/{scene}.png"),
            &format!(
                "the objects in transition at the middle frame, static camera, enlarged twice; rows: {}",
                order.join(", ")
            ),
        ));
        for t in &rows {
            let name = &t.technique;
            let _ = writeln!(h, "<h4>{name}</h4>");
            for camera in ["static", "moving"] {
                h.push_str(&img(
                    &format!("strips/{scene}-{name}-{camera}.png"),
                    &format!(
                        "{name}, {camera} camera: 7 frames from start to end of the transition"
                    ),
                ));
            }
            h.push_str(&img(
                &format!("see-through/{scene}-{name}.png"),
                "middle frame: interior of the transitioning objects (gray) and where the background shows through (red)",
            ));
            let sourced = Technique::ALL
                .iter()
                .any(|t| t.name() == name && t.maps_sources());
            if sourced {
                h.push_str(&img(
                    &format!("sources/{scene}-{name}.png"),
                    "combine rule per pixel, middle frame, moving camera: gray newer, orange older, magenta average of both LODs, cyan outside the older view",
                ));
            }
        }
    }
    h.push_str("<h2>Framebuffer LOD</h2>\n");
    h.push_str(&upsample_table(report).html());
    h.push_str(&speed_table(report).html());
    h.push_str(&img(
        "plots/psnr-vs-r.png",
        "PSNR against the resize factor",
    ));
    h.push_str(&img(
        "plots/psnr-vs-speedup.png",
        "PSNR against the whole-frame speed-up",
    ));
    for u in &report.upsampling {
        h.push_str(&img(
            &format!("upsample/r{}.png", u.r),
            &format!(
                "r = {}: reference, bilinear, bilateral, fine-grained; below, |error| x 4",
                u.r
            ),
        ));
    }
    h.push_str(&framebuffer_lod::html(report));
    h.push_str("<h2>Pass time ratios</h2>\n");
    h.push_str(&ratio_table(&report.pass_ratios).html());
    h.push_str("<h2>Host side (CPU)</h2>\n");
    h.push_str(&cpu_table(report).html());
    let sel = &report.selection;
    let _ = write!(
        h,
        "<h2>GPU LOD selection</h2>\n<p>{}</p>\n",
        esc(&selection::text(sel))
    );
    h.push_str(&selection::table(sel).html());
    h.push_str("<h2>Framerate control</h2>\n");
    h.push_str(&controller_table(report).html());
    h.push_str(&img(
        "plots/controllers.png",
        "frame time of each controller",
    ));
    h.push_str("</body></html>\n");
    write(&out.join("index.html"), &h)
}
