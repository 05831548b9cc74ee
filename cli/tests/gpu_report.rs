//! `scripts/gpu-report.sh` and `lodkit gpu-report` in their `--quick` form on the software GPU:
//! the report names its adapter and clock, has every section with figures in it, and the
//! script tabulates each test binary's result per backend (here a stand-in binary, so the test
//! does not run the GPU suites inside itself).

use std::process::Command;

use crate::support::{say, workspace_root};

#[test]
fn gpu_report_quick_writes_every_section_on_the_clock_it_names() {
    let gpu = lodkit_test_gpu!();
    let out = tempfile::tempdir().unwrap();
    // A stand-in test binary: what a test binary prints, and a failure on GL.
    let fake = out.path().join("integration-0123abcd");
    std::fs::write(
        &fake,
        "#!/bin/sh\necho 'lodkit GPU tests run on: stand-in'\n\
         if [ \"$LODKIT_BACKEND\" = gl ]; then echo 'test result: FAILED. 1 passed; 1 failed'; exit 101; fi\n\
         echo 'test result: ok. 2 passed; 0 failed; 0 ignored'\n",
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let report_dir = out.path().join("report");
    let output = Command::new("bash")
        .current_dir(workspace_root())
        .args(["scripts/gpu-report.sh", "--quick", "--out"])
        .arg(&report_dir)
        .arg("--lodkit")
        .arg(env!("CARGO_BIN_EXE_lodkit"))
        .arg("--tests")
        .arg(&fake)
        .env("LODKIT_BACKEND", gpu_backend(gpu))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    // The stand-in failed on GL: the script says so in its exit status.
    assert_eq!(output.status.code(), Some(1), "{stdout}\n{stderr}");
    let md = std::fs::read_to_string(report_dir.join("gpu-report.md")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report_dir.join("gpu-report.json")).unwrap())
            .unwrap();
    say(&md);
    let clock = json["clock"].as_str().unwrap();
    let timestamps = gpu.device.features().contains(
        wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS,
    );
    assert_eq!(
        clock,
        if timestamps {
            "gpu_timestamps"
        } else {
            "wall_clock"
        },
        "the report reads timestamps where the device has them"
    );
    assert!(
        md.contains(&gpu.adapter_summary()),
        "the adapter heads the report"
    );
    for section in [
        "## Pass time ratios",
        "## Framebuffer LOD: where a frame's time goes",
        "## Framebuffer LOD: speed-up against shading cost",
        "## GPU LOD selection",
        "## GPU test binaries",
    ] {
        assert!(md.contains(section), "{section} in\n{md}");
    }
    let ratios = json["pass_ratios"].as_array().unwrap();
    assert_eq!(ratios.len(), 5 + 4, "upsample, packed, combine ratios");
    for r in ratios {
        let ratio = r["ratio"].as_f64().unwrap();
        assert!(ratio.is_finite() && ratio > 0.0, "{r}");
        assert_eq!(r["clock"], json["clock"], "{r}");
    }
    let rows = json["selection"]["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert!(
        rows.iter()
            .all(|r| r["gpu_per_second"].as_f64().unwrap() > 0.0)
    );
    assert!(
        md.contains("| vulkan (stand-in) | integration | ok. 2 passed; 0 failed; 0 ignored |"),
        "{md}"
    );
    assert!(
        md.contains("| gl (stand-in) | integration | FAILED. 1 passed; 1 failed |"),
        "{md}"
    );
}

fn gpu_backend(gpu: &lodkit::gpu::GpuContext) -> &'static str {
    match gpu.adapter.get_info().backend {
        wgpu::Backend::Gl => "gl",
        _ => "vulkan",
    }
}
