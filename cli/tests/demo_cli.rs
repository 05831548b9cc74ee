//! The demo harness's command line, its scene files, its metrics' definitions and its fragment
//! counter, against hand-derived expectations.

use std::process::Command;

use lodkit::gpu::counters::{CounterKind, FragmentCounter};
use lodkit::metrics::{pop, transition_change};
use lodkit_cli::demo::fixtures::render::Technique;
use lodkit_cli::demo::fixtures::scene::{DemoScene, SceneError};
use lodkit_cli::demo::utc_date;

use crate::support::{say, scratch};

fn lodkit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lodkit"))
}

#[test]
fn change_and_pop_follow_their_definitions() {
    let black = [0u8, 0, 0, 255];
    let color = [30u8, 60, 90, 255];
    // Only the image changed: mean of 30, 60, 90 over 255.
    let c = transition_change(&black, &color, &black, &black);
    assert!((c - 60.0 / 255.0).abs() < 1e-12, "{c}");
    // Image and reference changed alike (camera motion): nothing is left.
    assert_eq!(transition_change(&black, &color, &black, &color), 0.0);
    // Alpha is ignored.
    assert_eq!(
        transition_change(&[0, 0, 0, 0], &[0, 0, 0, 255], &black, &black),
        0.0
    );
    assert_eq!(pop(&[0.0, 0.5, 0.0]), 1.0);
    assert!((pop(&[0.1, 0.3, 0.1]) - 0.6).abs() < 1e-6);
    assert_eq!(pop(&[0.0, 0.0]), 0.0);
}

#[test]
fn utc_dates_match_the_calendar() {
    assert_eq!(utc_date(0), "1970-01-01");
    assert_eq!(utc_date(951_782_400), "2000-02-29");
    assert_eq!(utc_date(1_704_067_199), "2023-12-31");
    assert_eq!(utc_date(1_709_251_200), "2024-03-01");
}

#[test]
fn scene_files_name_the_line_and_the_field() {
    let good = DemoScene::simple();
    let text = ron::ser::to_string_pretty(&good, Default::default()).unwrap();
    assert_eq!(DemoScene::from_ron(&text, "s.ron").unwrap(), good);

    let broken = text.replacen("objects:", "objects", 1);
    match DemoScene::from_ron(&broken, "s.ron") {
        Err(SceneError::Parse { path, line, .. }) => {
            assert_eq!(path, "s.ron");
            let expected = text.lines().position(|l| l.contains("objects:")).unwrap() + 1;
            assert_eq!(line, expected, "{broken}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    let mut bad = good.clone();
    bad.objects[3].fine = lodkit_cli::demo::fixtures::scene::Shape::Sphere {
        rings: 1,
        segments: 8,
    };
    let text = ron::ser::to_string_pretty(&bad, Default::default()).unwrap();
    let e = DemoScene::from_ron(&text, "s.ron").unwrap_err().to_string();
    assert!(
        e.contains("objects[3].fine") && e.contains("rings = 1"),
        "{e}"
    );
    let mut bad = good.clone();
    bad.objects[0].scale = [1.0, 0.0, 1.0];
    let e = bad.check().unwrap_err();
    assert!(e.contains("objects[0].scale"), "{e}");
    let mut bad = good.clone();
    bad.camera.eye = [0.0, 5.0, -2.5];
    bad.camera.target = [0.0, 0.0, -2.5];
    assert!(bad.check().unwrap_err().contains("camera.eye"));
    let mut bad = good.clone();
    bad.camera.moving_eye = [2.0 * bad.camera.target[0] - bad.camera.eye[0], 3.0, -12.5];
    bad.camera.eye = [bad.camera.eye[0], 3.0, 7.5];
    bad.camera.target = [bad.camera.target[0], 3.0, -2.5];
    assert!(
        bad.check().unwrap_err().contains("passes through"),
        "{:?}",
        bad.check()
    );
    let mut bad = good.clone();
    bad.objects[0].fine = lodkit_cli::demo::fixtures::scene::Shape::Sphere {
        rings: 256,
        segments: 512,
    };
    // 16 spheres of 262 144 triangles each: over the 4 million budget.
    let big = bad.objects[0].fine;
    bad.objects.iter_mut().for_each(|o| o.fine = big);
    assert!(bad.check().unwrap_err().contains("triangles"));
    let mut bad = good;
    bad.objects.iter_mut().for_each(|o| o.transition = false);
    assert!(bad.check().unwrap_err().contains("transition"));
    let e = DemoScene::from_file(std::path::Path::new("no/such/scene.ron")).unwrap_err();
    assert!(e.to_string().contains("no/such/scene.ron"), "{e}");
}

#[test]
fn demo_command_rejects_bad_options_with_usage_errors() {
    let out = lodkit().args(["demo", "--size", "10x10"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--size 10x10"));
    let out = lodkit().args(["demo", "--size", "wide"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("WxH"));
    let out = lodkit().args(["demo", "--pairs", "0"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--pairs 0"));
    let out = lodkit()
        .args(["demo", "--size", "4096x4096", "--frames", "600"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("MiB"));
    let out = lodkit()
        .args(["demo", "--scene", "no/such/scene.ron"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/scene.ron"));
}

/// A run whose stderr is not a terminal (a CI log, a pipe) prints a line per scene and part,
/// with the seconds since the start, where a terminal gets the progress bar.
#[test]
fn demo_prints_a_line_per_part_when_its_output_is_not_a_terminal() {
    let _gpu = lodkit_test_gpu!();
    let out = scratch("demo-lines");
    std::fs::create_dir_all(&*out).unwrap();
    let scene = out.join("simple.ron");
    let text = ron::ser::to_string_pretty(&DemoScene::simple(), Default::default()).unwrap();
    std::fs::write(&scene, text).unwrap();
    let run = lodkit()
        .arg("demo")
        .arg("--out")
        .arg(&*out)
        .arg("--scene")
        .arg(&scene)
        .args([
            "--size",
            "64x64",
            "--frames",
            "4",
            "--pairs",
            "1",
            "--fb-size",
            "64x64",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| l.starts_with('[')).collect();
    for technique in Technique::ALL {
        let part = format!("scene simple: {}: done", technique.name());
        assert!(
            lines.iter().any(|l| l.ends_with(&part)),
            "no line `{part}` in\n{stderr}"
        );
    }
    for part in [
        "framebuffer LOD: timing: done",
        "pass time ratios",
        "plots and report",
    ] {
        assert!(
            lines.iter().any(|l| l.contains(part)),
            "no `{part}` in\n{stderr}"
        );
    }
    assert!(
        lines.last().is_some_and(|l| l.ends_with("] done")),
        "{stderr}"
    );
}

#[test]
fn demo_without_an_adapter_says_what_to_install() {
    // This build has no Metal backend on Linux, so asking for it finds no adapter at all.
    if cfg!(target_os = "macos") {
        return;
    }
    let dir = scratch("no-adapter");
    let out = lodkit()
        .env("LODKIT_BACKEND", "metal")
        .args(["demo", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("mesa-vulkan-drivers"), "{stderr}");
}

const FLAT: &str = "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> { return vec4<f32>(v.uv, 0.0, 1.0); }
";

const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Counts one fullscreen triangle over a `w` x `h` target.
fn count_fullscreen(gpu: &lodkit::gpu::GpuContext, w: u32, h: u32) -> (CounterKind, u64) {
    let pipeline =
        lodkit_cli::demo::measures::upsample_timing::plain_pass(gpu, FLAT, "flat.wgsl").unwrap();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    let target = lodkit::gpu::resources::texture_2d(gpu, (w, h), FORMAT, usage, "t").unwrap();
    let view = target.create_view(&Default::default());
    let counter = FragmentCounter::new(gpu).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: counter.occlusion_query_set(),
            multiview_mask: None,
        });
        counter.begin(&mut pass);
        pass.set_pipeline(&pipeline);
        pass.draw(0..3, 0..1);
        counter.end(&mut pass);
    }
    (counter.kind(), counter.read(gpu, encoder).unwrap())
}

#[test]
fn fragment_counter_counts_every_pixel_of_a_fullscreen_triangle() {
    let shared = lodkit_test_gpu!();
    // The shared device has no optional features (occlusion query); the demo's asks for
    // pipeline statistics where the adapter has them.
    let demo_gpu = lodkit_cli::demo::open_gpu().unwrap();
    let (w, h) = (64, 48);
    for gpu in [shared, &demo_gpu] {
        let (kind, count) = count_fullscreen(gpu, w, h);
        say(&format!("{kind:?}: {count} for {w}x{h}"));
        let pixels = u64::from(w * h);
        if kind == CounterKind::FragmentInvocations {
            // Drivers may count helper invocations too (lavapipe: 12.5 % more here).
            assert!((pixels..2 * pixels).contains(&count), "{kind:?}: {count}");
        } else if kind.is_count() {
            assert_eq!(count, pixels, "{kind:?}");
        } else {
            assert!(count >= 1, "{kind:?}: {count}");
        }
    }
}
