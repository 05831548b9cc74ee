//! The demo's outputs from a [`DemoReport`]: PNG plots, `report.json`, `index.html`, the two
//! generated docs pages and the terminal summary.

use std::fmt::Write as _;
use std::path::Path;

use super::plots::{Chart, Series, line_chart};
use super::upsampling::{CONTROLLER_SEEDS, METHODS, SHADING_WORK, SIGMA_N, SIGMA_Z, TARGET_MS};
use super::{DemoError, DemoReport};

fn write(path: &Path, text: &str) -> Result<(), DemoError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| DemoError::io(dir, e))?;
    }
    std::fs::write(path, text).map_err(|e| DemoError::io(path, e))
}

fn pct(v: f32) -> String {
    format!("{:.1} %", v * 100.0)
}

fn times(v: Option<f64>) -> String {
    v.map_or("n/a".to_owned(), |v| format!("{v:.3}x"))
}

/// Escapes text for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
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
    let by_r = (0..3)
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
    let by_speed = [(1usize, 0usize), (2, 1)]
        .iter()
        .map(|&(k, s)| Series {
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

/// Markdown tables of the transition metrics, one per scene.
fn transition_tables(report: &DemoReport, cost: bool) -> String {
    let mut s = String::new();
    for scene in &report.scenes {
        let _ = writeln!(s, "\n### Scene `{scene}`\n");
        if cost {
            s.push_str("| technique | triangles | vs hard switch | fragments | vs hard switch |\n|---|---|---|---|---|\n");
        } else {
            s.push_str(
                "| technique | pop (static) | pop (moving) | see-through |\n|---|---|---|---|\n",
            );
        }
        for t in report.transitions.iter().filter(|t| &t.scene == scene) {
            if cost {
                let _ = writeln!(
                    s,
                    "| {} | {} | {:.3}x | {} | {} |",
                    t.technique,
                    t.triangles,
                    t.triangles_vs_hard,
                    t.fragments.map_or("n/a".to_owned(), |f| f.to_string()),
                    times(t.fragments_vs_hard)
                );
            } else {
                let _ = writeln!(
                    s,
                    "| {} | {:.3} | {:.3} | {} |",
                    t.technique,
                    t.pop_static,
                    t.pop_moving,
                    pct(t.see_through)
                );
            }
        }
    }
    s
}

fn upsample_table(report: &DemoReport) -> String {
    let mut s = String::from(
        "| r | PSNR bilinear | PSNR bilateral | PSNR fine-grained | SSIM bilinear | SSIM bilateral | SSIM fine-grained |\n|---|---|---|---|---|---|---|\n",
    );
    for u in &report.upsampling {
        let _ = writeln!(
            s,
            "| {} | {:.2} dB | {:.2} dB | {:.2} dB | {:.4} | {:.4} | {:.4} |",
            u.r, u.psnr[0], u.psnr[1], u.psnr[2], u.ssim[0], u.ssim[1], u.ssim[2]
        );
    }
    s
}

fn speed_table(report: &DemoReport) -> String {
    let mut s = String::from(
        "| r | whole frame, bilateral route | whole frame, fine-grained route |\n|---|---|---|\n",
    );
    for u in &report.upsampling {
        let _ = writeln!(
            s,
            "| {} | {:.2}x | {:.2}x |",
            u.r, u.speedup[0], u.speedup[1]
        );
    }
    s
}

fn ratio_table(report: &DemoReport) -> String {
    let mut s = String::from(
        "| pass | baseline | size | pass ms | baseline ms | median ratio | pairs |\n|---|---|---|---|---|---|---|\n",
    );
    for p in &report.pass_ratios {
        let _ = writeln!(
            s,
            "| {} | {} | {}x{} | {:.3} | {:.3} | {:.3} | {} |",
            p.pass, p.baseline, p.size.0, p.size.1, p.pass_ms, p.baseline_ms, p.ratio, p.pairs
        );
    }
    s
}

fn controller_table(report: &DemoReport) -> String {
    let mut s =
        String::from("| controller | settling frames | overshoot | spread |\n|---|---|---|---|\n");
    for c in &report.controllers {
        let settle = c
            .settling_frames
            .map_or("never".to_owned(), |f| format!("{f}"));
        let _ = writeln!(
            s,
            "| {} | {settle} | {} | {} |",
            c.name,
            pct(c.overshoot),
            pct(c.spread)
        );
    }
    s
}

fn cpu_table(report: &DemoReport) -> String {
    let mut s = String::from("| what | median | runs |\n|---|---|---|\n");
    for c in &report.cpu {
        let _ = writeln!(
            s,
            "| {} | {:.2} {} | {} |",
            c.what, c.median, c.unit, c.runs
        );
    }
    s
}

fn header(report: &DemoReport, what: &str) -> String {
    format!(
        "# {what}\n\nGenerated by `{}` on {} (do not edit by hand; run it again). Adapter: {} — \
         backend {}, device type {}. Images {}x{}, transitions of {} frames; fragment counts \
         are {}. The demo's own report (`index.html` in its output folder) shows the images \
         behind these figures. Timings are wall time per pass including submit and wait; on a \
         software rasterizer (device type Cpu) read the ratios, not the milliseconds.\n",
        report.command,
        report.date,
        report.adapter,
        report.backend,
        report.device_type,
        report.size.0,
        report.size.1,
        report.frames,
        report.counter
    )
}

const POP_TEXT: &str = "Pop is the largest single-frame share of the image change a transition \
causes (1.0: all of it in one frame, as a hard switch; 1/N: spread evenly over N frames). With \
the moving camera, the change of a run without transition is subtracted frame by frame. \
See-through is the share of the transitioning objects' interior (pixels both LODs cover) where \
the background contributes to the middle frame: the frame is rendered over black and over white \
scenery and the pixels that differ are counted.\n";

/// Writes `benchmarks.md` and `quality.md` into `docs`.
pub fn write_docs(report: &DemoReport, docs: &Path) -> Result<(), DemoError> {
    let mut q = header(report, "Quality");
    q.push_str("\n## Transitions\n\n");
    q.push_str(POP_TEXT);
    q.push_str(&transition_tables(report, false));
    q.push_str("\n## Framebuffer LOD\n\n");
    let _ = writeln!(
        q,
        "Edge scene with synthetic shading work (a smooth sky term summed over {SHADING_WORK} directions per fragment, the expensive low-frequency shading framebuffer LOD is for), full-resolution frame as reference; bilateral sigma_z = {SIGMA_Z}, sigma_n = {SIGMA_N}; fine-grained resizing sends only the lighting through the low-res buffer and multiplies by full-resolution albedo.\n"
    );
    q.push_str(&upsample_table(report));
    q.push_str("\n## Framerate control\n\nSimulated frame time t = K workload / r^2 + C with 3 % noise (K = 40 ms, C = 3 ms), ");
    let _ = writeln!(
        q,
        "target {TARGET_MS} ms, workload doubling at frame 60; medians over {CONTROLLER_SEEDS} seeds.\n"
    );
    q.push_str(&controller_table(report));
    write(&docs.join("quality.md"), &q)?;
    let mut b = header(report, "Benchmarks");
    b.push_str("\n## Cost of a transition\n\nTriangles submitted and fragments counted over the transition's frames, static camera. Frame-sequential adds one fullscreen combine pass (one fragment per pixel, included).\n");
    b.push_str(&transition_tables(report, true));
    b.push_str("\n## Pass time ratios\n\nEach pass against the plainest pass with the same memory traffic, timed in interleaved pairs; the figure is the median of the per-pair ratios.\n\n");
    b.push_str(&ratio_table(report));
    b.push_str("\n## Framebuffer LOD: whole-frame speed-up\n\n");
    let _ = writeln!(
        b,
        "Median wall time of a full-resolution frame over a framebuffer-LOD frame: the full-resolution geometry prepass the upsampling needs (depth and normals, with the cheap albedo), the low-res shading pass and the upsample pass (fine-grained: the low-res lighting pass, the full-resolution albedo pass that also writes the geometry, and the upsample). Edge scene with {SHADING_WORK} sky directions of shading work per fragment.\n"
    );
    b.push_str(&speed_table(report));
    b.push_str("\n## Host side (CPU)\n\nMedians of repeated runs in the same process (the machine's CPU, not the GPU). The criterion benches measure the same workloads more thoroughly: `cargo bench --bench compose`, `cargo bench --bench select`; `cargo bench --bench combine` and `--bench upsample` print the pass ratios above on their own.\n\n");
    b.push_str(&cpu_table(report));
    write(&docs.join("benchmarks.md"), &b)
}

fn img(src: &str, alt: &str) -> String {
    format!("<figure><img src=\"{src}\" alt=\"{alt}\"><figcaption>{alt}</figcaption></figure>\n")
}

fn md_table_to_html(md: &str) -> String {
    let mut s = String::from("<table>\n");
    for (i, line) in md.lines().filter(|l| l.starts_with('|')).enumerate() {
        if i == 1 {
            continue;
        }
        let tag = if i == 0 { "th" } else { "td" };
        s.push_str("<tr>");
        for cell in line.trim_matches('|').split('|') {
            let _ = write!(s, "<{tag}>{}</{tag}>", esc(&cell.trim().replace('`', "")));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
    s
}

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
        "<p>{} · adapter {} · {}x{} · transitions of {} frames · fragments: {} · {:.0} s</p>",
        report.date,
        esc(&report.adapter),
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
        let rows: Vec<_> = report
            .transitions
            .iter()
            .filter(|t| &t.scene == scene)
            .collect();
        let mut md = String::from(
            "| technique | pop (static) | pop (moving) | see-through | triangles vs hard | fragments vs hard |\n|---|---|---|---|---|---|\n",
        );
        for t in &rows {
            let _ = writeln!(
                md,
                "| {} | {:.3} | {:.3} | {} | {:.3}x | {} |",
                t.technique,
                t.pop_static,
                t.pop_moving,
                pct(t.see_through),
                t.triangles_vs_hard,
                times(t.fragments_vs_hard)
            );
        }
        h.push_str(&md_table_to_html(&md));
        for camera in ["static", "moving"] {
            h.push_str(&img(
                &format!("plots/change-{scene}-{camera}.png"),
                &format!("image change per frame, {camera} camera"),
            ));
        }
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
            if name.starts_with("frame-seq") {
                h.push_str(&img(
                    &format!("sources/{scene}-{name}.png"),
                    "combine rule per pixel, middle frame, moving camera: gray newer, orange older, magenta average of both LODs, cyan outside the older view",
                ));
            }
        }
    }
    h.push_str("<h2>Framebuffer LOD</h2>\n");
    h.push_str(&md_table_to_html(&upsample_table(report)));
    h.push_str(&md_table_to_html(&speed_table(report)));
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
    h.push_str("<h2>Pass time ratios</h2>\n");
    h.push_str(&md_table_to_html(&ratio_table(report)));
    h.push_str("<h2>Host side (CPU)</h2>\n");
    h.push_str(&md_table_to_html(&cpu_table(report)));
    h.push_str("<h2>Framerate control</h2>\n");
    h.push_str(&md_table_to_html(&controller_table(report)));
    h.push_str(&img(
        "plots/controllers.png",
        "frame time of each controller",
    ));
    h.push_str("</body></html>\n");
    write(&out.join("index.html"), &h)
}

/// The summary table printed on the terminal.
pub fn summary(report: &DemoReport) -> String {
    let mut s = format!(
        "adapter: {}\n{}x{}, transitions of {} frames, {:.0} s\n",
        report.adapter, report.size.0, report.size.1, report.frames, report.seconds
    );
    for scene in &report.scenes {
        let _ = writeln!(
            s,
            "\n{scene:<24} {:>8} {:>8} {:>12} {:>10} {:>10}",
            "pop", "pop mov", "see-through", "tris", "frags"
        );
        for t in report.transitions.iter().filter(|t| &t.scene == scene) {
            let _ = writeln!(
                s,
                "  {:<22} {:>8.3} {:>8.3} {:>12} {:>9.3}x {:>10}",
                t.technique,
                t.pop_static,
                t.pop_moving,
                pct(t.see_through),
                t.triangles_vs_hard,
                times(t.fragments_vs_hard)
            );
        }
    }
    let _ = writeln!(
        s,
        "\n{:<6} {:>10} {:>10} {:>12} {:>10}",
        "r", "bilinear", "bilateral", "fine-grained", "speed-up"
    );
    for u in &report.upsampling {
        let _ = writeln!(
            s,
            "{:<6} {:>7.2} dB {:>7.2} dB {:>9.2} dB {:>9.2}x",
            u.r, u.psnr[0], u.psnr[1], u.psnr[2], u.speedup[0]
        );
    }
    s.push('\n');
    for p in &report.pass_ratios {
        let _ = writeln!(s, "{} / {}: {:.3}x", p.pass, p.baseline, p.ratio);
    }
    s
}
