//! The demo harness on the GPU: every technique measured on the built-in scenes, the counts
//! held to hand-derived expectations, and its report opened in headless Chromium.

use lodkit_cli::demo::fixtures::render::Technique;
use lodkit_cli::demo::fixtures::scene::DemoScene;
use lodkit_cli::demo::measures::transitions::TransitionMetrics;
use lodkit_cli::demo::measures::upsample_quality::METHODS;
use lodkit_cli::demo::{DemoOptions, run_on};

use crate::support::{browser_script, say, scratch};

/// Triangles a run submits over the transition's frames (LEAD ..= LEAD + N), computed from the
/// scene's meshes: `both` draws both LODs of each transitioning object on every frame strictly
/// inside the transition and only the visible one at t = 0 and t = 1, otherwise the fine LOD
/// until t = 0.5 and the coarse one from there (a hard switch).
fn expected_triangles(scene: &DemoScene, frames: usize, both: bool) -> u64 {
    let mut total = 0u64;
    for f in 0..=frames {
        let t = f as f32 / frames as f32;
        for o in &scene.objects {
            let fine = o.fine.triangles();
            let coarse = o.coarse.triangles();
            let inside = t > 0.0 && t < 1.0;
            total += match (o.transition, both && inside) {
                (false, _) => fine,
                (true, true) => fine + coarse,
                (true, false) if t < 0.5 => fine,
                (true, false) => coarse,
            };
        }
    }
    total
}

/// Bounds on the triangles of drawing exactly one LOD of every object per frame over the
/// transition: all the smaller LODs, all the larger ones.
fn one_lod_per_frame(scene: &DemoScene, frames: usize) -> (u64, u64) {
    let (mut lo, mut hi) = (0u64, 0u64);
    for o in &scene.objects {
        let (a, b) = (o.fine.triangles(), o.coarse.triangles());
        let (small, large) = if o.transition {
            (a.min(b), a.max(b))
        } else {
            (a, a)
        };
        lo += small * (frames as u64 + 1);
        hi += large * (frames as u64 + 1);
    }
    (lo, hi)
}

/// The most triangles the older-level depth pass draws over a transition of `frames` frames: the
/// larger level of each object in transition, once a frame.
fn older_level_depth_pass(scene: &DemoScene, frames: usize) -> u64 {
    let objects = scene.objects.iter().filter(|o| o.transition);
    let larger = objects.map(|o| o.fine.triangles().max(o.coarse.triangles()));
    larger.sum::<u64>() * (frames as u64 + 1)
}

#[test]
fn demo_measures_every_technique_and_its_report_opens_in_chromium() {
    let gpu = lodkit_test_gpu!();
    let out = scratch("demo");
    let frames = 8;
    let options = DemoOptions {
        out: out.to_path_buf(),
        size: (96, 64),
        frames,
        scene: None,
        timing_pairs: 3,
        docs: Some(out.join("docs")),
        fb_size: (128, 72),
        progress: false,
    };
    let scenes = DemoScene::built_in();
    let report = run_on(gpu, &options, &scenes).unwrap();
    for t in &report.transitions {
        say(&format!(
            "demo figure {} {}: pop {:.3}/{:.3} flicker {:.2}/{:.2} reversals {}/{} vs coarse {:.2}/{:.2} reversals {}/{} see-through {:.4} silhouette {:.4} ({} / {} px) outside {}",
            t.scene,
            t.technique,
            t.pop_static,
            t.pop_moving,
            t.flicker_static,
            t.flicker_moving,
            t.reversals_static,
            t.reversals_moving,
            t.flicker_static_coarse,
            t.flicker_moving_coarse,
            t.reversals_static_coarse,
            t.reversals_moving_coarse,
            t.see_through,
            t.silhouette_error,
            t.see_through_pixel_frames,
            t.ghost_pixel_frames,
            t.outside_rects
        ));
    }
    // Scenes are measured side by side (the most objects first); the rows still come in the
    // scenes' order, each scene's techniques in `Technique::ALL`'s.
    let rows: Vec<(&str, &str)> = report
        .transitions
        .iter()
        .map(|t| (t.scene.as_str(), t.technique.as_str()))
        .collect();
    let expected: Vec<(&str, &str)> = scenes
        .iter()
        .flat_map(|s| Technique::ALL.map(|t| (s.name.as_str(), t.name())))
        .collect();
    assert_eq!(rows, expected);
    for u in &report.upsampling {
        say(&format!(
            "demo figure upsampling r={}: psnr {:?} ssim {:?}",
            u.r, u.psnr, u.ssim
        ));
    }
    for c in &report.controllers {
        say(&format!(
            "demo figure controller {}: {:?}",
            c.name, c.settling_frames
        ));
    }
    // GPU selection: every size measured on both selectors; the bytes it writes per instance
    // are the 8-byte state and, per list it joins, a 16-byte entry and its 4-byte count.
    let sel = &report.selection;
    assert_eq!(
        sel.rows.iter().map(|r| r.instances).collect::<Vec<_>>(),
        lodkit_cli::demo::measures::selection::SIZES
    );
    assert!(
        sel.rows
            .iter()
            .all(|r| r.gpu_per_second > 0.0 && r.cpu_per_second > 0.0),
        "{sel:?}"
    );
    assert_eq!(sel.bytes_written, (8 + 16 + 4, 8 + 2 * (16 + 4)));
    assert!(sel.bytes_read.0 > sel.group_table_bytes && sel.bytes_read.0 <= sel.bytes_read.1);
    say(&format!("demo figure selection: {sel:?}"));
    for run in report.closed_loop.runs() {
        say(&format!(
            "demo figure closed loop {}: settled {:?} within {:.2} overshoot {:.2} spread {:.2}",
            run.name, run.settling_frames, run.frames_within, run.overshoot, run.spread
        ));
    }
    // wgpu's GL backend answers occlusion queries with any-samples-passed, not a count: the
    // fragment ratios are measured on every other backend, and their absence there is a failure.
    let counts = gpu.adapter.get_info().backend != wgpu::Backend::Gl;
    if !counts {
        say(&format!(
            "demo test on {}: no fragment counts on GL, so the fragment-ratio assertions did not run",
            gpu.adapter_summary()
        ));
    }
    assert_eq!(
        report.transitions.len(),
        scenes.len() * Technique::ALL.len()
    );
    // The scene with an octahedral impostor shows its atlas: one picture of its layout's side.
    let atlases: Vec<_> = report.atlases.iter().map(|a| a.scene.as_str()).collect();
    assert_eq!(atlases, ["impostors"], "scenes with an atlas picture");
    let atlas = &report.atlases[0];
    let picture = image::open(out.join(&atlas.picture)).unwrap();
    assert_eq!(
        (picture.width(), picture.height()),
        (
            atlas.frames * atlas.frame_size,
            atlas.frames * atlas.frame_size
        ),
        "the atlas picture's size"
    );
    for scene in &scenes {
        let row = |name: &str| {
            report
                .transitions
                .iter()
                .find(|t| t.scene == scene.name && t.technique == name)
                .unwrap_or_else(|| panic!("no {name} row for {}", scene.name))
        };
        // A swaying object keeps changing after a hard switch (its LODs sway differently from the
        // reference run's fine LOD), so only a still scene puts all of the change in one frame.
        let animated = scene.objects.iter().any(|o| o.sway != 0.0);
        let hard = row("hard-switch");
        if animated {
            assert!(hard.pop_static > 0.3, "a hard switch: {}", hard.pop_static);
        } else {
            assert_eq!(hard.pop_static, 1.0, "a hard switch changes in one frame");
            // ... once, in one direction: no flicker, whatever the scene.
            assert_eq!(
                (hard.flicker_static, hard.reversals_static),
                (1.0, 0),
                "a hard switch in {}",
                scene.name
            );
            assert_eq!(
                (hard.flicker_static_coarse, hard.reversals_static_coarse),
                (1.0, 0),
                "a hard switch against the coarse level in {}",
                scene.name
            );
        }
        assert_eq!(hard.triangles, expected_triangles(scene, frames, false));
        let fade = row("cross-fade");
        assert_eq!(fade.triangles, expected_triangles(scene, frames, true));
        assert!(fade.see_through > 0.5, "cross-fade: {}", fade.see_through);
        // Half-transparent LODs show the background inside the silhouette: the metric sees it.
        assert!(
            fade.silhouette_error > 0.3,
            "cross-fade: silhouette error {}",
            fade.silhouette_error
        );
        // The silhouette error's parts: the cross-fade's is see-through.
        assert!(
            fade.see_through_pixel_frames > 0,
            "cross-fade: no see-through pixel"
        );
        // Flicker against the coarse level's run is its own figure: a reference that fell back
        // to the fine level would repeat the fine figures exactly.
        let seq = row("frame-seq-complementary");
        assert_ne!(
            (seq.flicker_moving, seq.reversals_moving),
            (seq.flicker_moving_coarse, seq.reversals_moving_coarse),
            "frame-seq-complementary in {}: the coarse reference repeats the fine one",
            scene.name
        );
        assert_eq!(fade.fragments_vs_hard.is_some(), counts, "fragment counts");
        if let Some(f) = fade.fragments_vs_hard {
            assert!(f > 1.05, "drawing both LODs must shade more: {f}");
        }
        // With a still camera the combine that knows the levels' coverage (their silhouettes,
        // or the older-level depth pass) reverses no pixel where the one that estimates them
        // reverses none: where another object hides a level that its silhouette says covers the
        // pixel, it shows that object, as last frame did (`combine_hidden`). Without that test,
        // 7,830 pixel reversals in `simple` at 320x180.
        for (estimated, known) in [
            ("frame-seq-complementary", "frame-seq-silhouettes"),
            ("frame-seq-complementary", "frame-seq-default"),
        ] {
            if row(estimated).reversals_static == 0 {
                assert_eq!(
                    row(known).reversals_static,
                    0,
                    "{known} in {}: a still camera reverses pixels",
                    scene.name
                );
            }
        }
        // Single-frame techniques draw the frame's own geometry: no silhouette error.
        assert_eq!(hard.silhouette_error, 0.0, "hard switch in {}", scene.name);
        for name in ["dither-bayer", "dither-blue-noise", "unpopping"] {
            let r = row(name);
            assert_eq!(r.see_through, 0.0, "{name} in {}", scene.name);
            assert_eq!(r.silhouette_error, 0.0, "{name} in {}", scene.name);
            // At this size and length (96x64, 8 frames) the dithers measured 0.126-0.141 and
            // unpopping 0.171-0.285 over the three scenes: limits about 12 % above.
            let limit = if name == "unpopping" { 0.32 } else { 0.16 };
            assert!(
                r.pop_static < limit,
                "{name} in {} pops: {}",
                scene.name,
                r.pop_static
            );
        }
        for name in [
            "frame-seq-white-noise",
            "frame-seq-blue-noise",
            "frame-seq-complementary",
            "frame-seq-object-space",
            "frame-seq-silhouettes",
            "frame-seq-default",
        ] {
            let r = row(name);
            // The combine follows the object motion, and where an animated object's LODs moved
            // differently it searches the older LOD where the camera alone puts the pixel.
            assert_eq!(r.see_through, 0.0, "{name} in {}", scene.name);
            // The combine's rectangles hold every pixel of an object in transition (they take
            // the swaying tree's whole reach), so see-through is measured everywhere it can be.
            assert_eq!(r.outside_rects, 0, "{name} in {}", scene.name);
            // Reprojecting last frame's buffer misplaces a thin band of silhouette at most:
            // measured 0.11-1.0 % here; with the first estimate alone (no `reproject_refine`)
            // 0.71-2.36 %, 1.96 % on `simple`.
            assert!(
                r.silhouette_error < 0.015,
                "{name} in {}: silhouette error {}",
                scene.name,
                r.silhouette_error
            );
            // Without a t-instance there is no combine: exactly a hard switch's fragments.
            assert_eq!(
                r.idle_fragments_vs_hard.is_some(),
                counts,
                "fragment counts"
            );
            if let Some(idle) = r.idle_fragments_vs_hard {
                assert_eq!(
                    idle, 1.0,
                    "{name} in {}: frames without a t-instance",
                    scene.name
                );
            }
            // One LOD per object per frame (the paper's point), never both; the default route
            // draws the t-instances' older levels once more, depth only.
            let (lo, mut hi) = one_lod_per_frame(scene, frames);
            if name == "frame-seq-default" {
                hi += older_level_depth_pass(scene, frames);
            }
            assert!(
                (lo..=hi).contains(&r.triangles),
                "{name}: {} not in {lo}..={hi}",
                r.triangles
            );
            // Frame-sequential LOD pops less than unpopping (measured 0.64-0.88x static), and the
            // complementary schedule as little as the blue-noise dither (0.91-1.02x).
            let unpopping = row("unpopping");
            assert!(
                r.pop_static < 0.95 * unpopping.pop_static,
                "{name} in {}: pop {} against unpopping's {}",
                scene.name,
                r.pop_static,
                unpopping.pop_static
            );
            if name != "frame-seq-object-space" {
                // With the screen anchor also under a moving camera (0.82-0.90x); in `chain`,
                // whose small far objects change mostly in colour (their levels differ by a
                // pixel at most), the screen-anchored schedules measured 0.96-1.02x: 5 % above;
                // with the levels' silhouettes 1.04-1.06x there (a far object's silhouette is a
                // few pixels, each one a large share of its change): 4 % above.
                let most = match (scene.name.as_str(), name.ends_with("silhouettes")) {
                    ("chain", false) => 1.05,
                    ("chain", true) => 1.10,
                    _ => 1.0,
                };
                assert!(
                    r.pop_moving < most * unpopping.pop_moving,
                    "{name} in {}: moving pop {} against unpopping's {}",
                    scene.name,
                    r.pop_moving,
                    unpopping.pop_moving
                );
            }
            if name == "frame-seq-complementary" {
                let dither = row("dither-blue-noise").pop_static;
                assert!(
                    r.pop_static <= 1.1 * dither,
                    "{name} in {}: pop {} against the dither's {dither}",
                    scene.name,
                    r.pop_static
                );
            }
        }
        // See-through and ghosts, counted on every frame of the transition with both cameras:
        // the combine that knows the older levels' coverage leaves a few pixel-frames (here,
        // 96x64 and 8 frames, 0-2 per scene and schedule; the estimate 18-85), each fewer than
        // the estimate with the same schedule. Limit: 3 above the measured. The default route,
        // the older-level depth pass, knows what the rasterizer covers and how deep: none.
        let default = row("frame-seq-default");
        assert_eq!(
            (default.see_through_pixel_frames, default.ghost_pixel_frames),
            (0, 0),
            "frame-seq-default in {}: see-through and ghost pixel-frames",
            scene.name
        );
        // An octahedral impostor has no outline for the silhouettes' route: as the older level
        // it is left to the estimate (`impostors`: 38 pixel-frames against the estimate's 94),
        // so there fewer than the estimate and at most 45 (20 % above the measured).
        let octahedral = scene.objects.iter().any(|o| {
            o.fine
                .octahedral_of()
                .or(o.coarse.octahedral_of())
                .is_some()
        });
        for (estimated, known) in [
            ("frame-seq-complementary", "frame-seq-silhouettes"),
            ("frame-seq-complementary", "frame-seq-default"),
        ] {
            let wrong = |r: &TransitionMetrics| r.see_through_pixel_frames + r.ghost_pixel_frames;
            let (estimated, count) = (wrong(row(estimated)), wrong(row(known)));
            let partly_estimated = octahedral && known == "frame-seq-silhouettes";
            let most = if partly_estimated { 45 } else { 5 };
            assert!(
                count <= most && count < estimated,
                "in {}: see-through and ghosts {count} pixel-frames with {known}, {estimated} estimated",
                scene.name
            );
        }
    }
    for u in &report.upsampling {
        assert!(
            u.psnr[1] > u.psnr[0],
            "r = {}: bilateral must beat bilinear",
            u.r
        );
        assert!(
            u.psnr[2] > u.psnr[1],
            "r = {}: fine-grained must beat bilateral",
            u.r
        );
        assert!(u.ssim.iter().all(|s| *s > 0.0 && *s <= 1.0), "{:?}", u.ssim);
        assert!(u.ssim[1] >= u.ssim[0], "r = {}: {:?}", u.r, u.ssim);
        // The packed L (half-float color, f32 depth, half foreshortened normal) loses no quality
        // against color + geometry: at most 0.1 dB and 0.001 SSIM below, bilateral and
        // fine-grained alike (its f32 depth, finer than the rgba16float geometry's, may gain).
        for (packed, unpacked) in [(3, 1), (4, 2)] {
            let (dp, ds) = (
                u.psnr[packed] - u.psnr[unpacked],
                u.ssim[packed] - u.ssim[unpacked],
            );
            say(&format!(
                "demo figure packed L r = {} {}: {dp:+.3} dB, {ds:+.5} SSIM",
                u.r, METHODS[unpacked]
            ));
            assert!(
                dp >= -0.1 && ds >= -0.001,
                "r = {}: packed L {dp} dB / {ds} SSIM from the unpacked",
                u.r
            );
        }
    }
    let settle = |name: &str| {
        report
            .controllers
            .iter()
            .find(|c| c.name.starts_with(name))
            .and_then(|c| c.settling_frames)
            .unwrap_or(f32::INFINITY)
    };
    assert!(settle("lodkit") < settle("paper"));

    // The generated chain: a row per level, the picture the page shows.
    let chain = report.chain.as_ref().expect("the chain scene's report");
    assert_eq!(
        chain.levels.len(),
        lodkit_cli::demo::fixtures::lod_chain::levels()
    );
    assert!(out.join(&chain.picture).is_file());

    // Framebuffer LOD at --fb-size: every pass of every configuration timed, the sweep's shading
    // work really costs (the full-resolution frame at the largest work is slower than without),
    // and each controller ran the whole closed loop.
    let cost = &report.frame_cost;
    assert_eq!(cost.breakdown.len(), 1 + 4 * 4);
    assert!(
        cost.breakdown[1..]
            .iter()
            .all(|p| p.ms.iter().all(|t| *t > 0.0))
    );
    let (first, last) = (&cost.sweep[0], cost.sweep.last().unwrap());
    assert!(
        last.full_ms > 2.0 * first.full_ms,
        "{:?} vs {:?}",
        last,
        first
    );
    // Each controller runs on the real frame: a frame time and an r for every frame. The
    // direction of its answer is not asserted: at this test's 128x72 the frame time is mostly
    // overhead and noise, the demo's tables at 1280x720 show it.
    let closed = &report.closed_loop;
    assert_eq!(closed.runs().count(), 3);
    assert!(closed.repeats.iter().all(|runs| runs.len() == 3));
    // Whether r moves depends on the frame times this machine measures: on a loaded machine a
    // controller may hold r from the start (a two-core CI run with two busy loops beside it kept
    // the online controller at r = 1.0 for the whole run). That is a figure, reported here and
    // in the demo's tables, not a verdict; the controllers' pass/fail tests drive them with
    // modelled frame times (`upsampling::measure_controllers`, lodkit_bevy's controller test).
    let step = lodkit_cli::demo::measures::closed_loop::STEP_FRAME;
    for run in closed.repeats.iter().flatten() {
        assert_eq!(
            run.ms.len(),
            lodkit_cli::demo::measures::closed_loop::FRAMES
        );
        let distinct = |rs: &[f32]| {
            let mut v = rs.to_vec();
            v.sort_by(f32::total_cmp);
            v.dedup();
            v
        };
        let (all, after) = (distinct(&run.r), distinct(&run.r[step..]));
        if all.len() == 1 {
            say(&format!(
                "demo test: {} kept r at {all:?} for the whole run",
                run.name
            ));
        } else if after.len() == 1 {
            say(&format!(
                "demo test: {} held r at {after:?} after the step",
                run.name
            ));
        }
    }

    // Every image the page refers to exists, and the generated docs name the adapter.
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    let sources: Vec<&str> = html
        .split("src=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    assert!(sources.len() >= 40, "{} images", sources.len());
    for src in &sources {
        assert!(out.join(src).is_file(), "index.html shows missing {src}");
    }
    for doc in ["quality.md", "benchmarks.md"] {
        let text = std::fs::read_to_string(out.join("docs").join(doc)).unwrap();
        assert!(
            text.contains(&report.adapter) && text.contains("Generated by"),
            "{doc}"
        );
        // The header's figures sit where its words say (96x64 images, 8-frame transitions).
        let said = "Images 96x64, transitions of 8 frames";
        assert!(text.contains(said), "{doc}'s header lacks {said:?}");
    }
    // Every picture a guide in docs/ shows is one the demo writes with --docs.
    let guides = crate::support::workspace_root().join("docs");
    for guide in std::fs::read_dir(&guides).unwrap().flatten() {
        let text = std::fs::read_to_string(guide.path()).unwrap_or_default();
        for picture in text.split("](img/").skip(1) {
            let name = &picture[..picture.find(')').unwrap()];
            let written = out.join("docs/img").join(name);
            let size = std::fs::metadata(&written).map_or(0, |m| m.len());
            assert!(
                size > 1000,
                "{:?} shows img/{name}, which --docs did not write",
                guide.path()
            );
        }
    }
    let Some(mut page) = browser_script("page.mjs") else {
        return;
    };
    let shot = out.join("screenshot.png");
    let result = page
        .arg(out.join("index.html"))
        .arg(&shot)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&result.stdout).into_owned()
        + &String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "index.html in Chromium:\n{text}");
    assert!(
        text.contains(&format!("images: {0}/{0} loaded", sources.len())),
        "{text}"
    );
    let png = std::fs::read(&shot).unwrap();
    assert!(
        png.starts_with(b"\x89PNG") && png.len() > 10_000,
        "screenshot"
    );
    say(&format!(
        "demo report opened in Chromium: {}",
        shot.display()
    ));
}
