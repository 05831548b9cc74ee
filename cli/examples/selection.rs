//! LOD selection over a camera path: loads LOD groups from RON, drives a camera away from three
//! objects and back (with a pause inside a hysteresis band), prints a timeline of the chosen LOD
//! and transition per object, and plots it.
//!
//! `cargo run --example selection -- [--config FILE] [--out DIR] [--mode hard|distance|time]`
//! Writes DIR/selection.png (default DIR: lodkit-out/selection).

use std::path::PathBuf;

use glam::Vec3;
use lodkit::select::config::LodConfig;
use lodkit::select::*;
use lodkit_cli::demo::report::plots::{Chart, Series, line_chart};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let config_path = arg("--config").unwrap_or_else(|| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/examples/data/lod_groups.ron").to_owned()
    });
    let out = PathBuf::from(arg("--out").unwrap_or_else(|| "lodkit-out/selection".to_owned()));
    let text = std::fs::read_to_string(&config_path)?;
    let config = LodConfig::from_ron(&text).map_err(|e| format!("{config_path}:{e}"))?;
    let mut settings = config.settings()?;
    match arg("--mode").as_deref() {
        Some("hard") => settings.transition = TransitionMode::Hard,
        Some("distance") => settings.transition = TransitionMode::Distance,
        Some("time") | None => {}
        Some(other) => return Err(format!("unknown mode `{other}`").into()),
    }
    let named = config.groups()?;
    let group_of = |name: &str| {
        named
            .iter()
            .position(|(n, _)| n == name)
            .ok_or(format!("no group `{name}` in {config_path}"))
    };
    let groups: Vec<LodGroup> = named.iter().map(|(_, g)| g.clone()).collect();
    // Three objects along -z. The camera walks out 120 m, comes back to where tree A is 81 m away
    // (inside the band around its 80 m level), stands still there for a second, and walks home.
    let objects = [
        ("tree A", "tree", Vec3::new(0.0, 0.0, -10.0)),
        ("tree B", "tree", Vec3::new(4.0, 0.0, -40.0)),
        ("rock", "rock", Vec3::new(-3.0, 0.0, -5.0)),
    ];
    let positions: Vec<Vec3> = objects.iter().map(|o| o.2).collect();
    let ids: Vec<u32> = objects
        .iter()
        .map(|o| group_of(o.1).map(|g| g as u32))
        .collect::<Result<_, _>>()?;
    let scales = vec![1.0; objects.len()];
    let batch = InstanceBatch {
        positions: &positions,
        max_scales: &scales,
        groups: &ids,
    };
    let proj = glam::camera::rh::proj::directx::perspective(
        std::f32::consts::FRAC_PI_2,
        16.0 / 9.0,
        0.1,
        1000.0,
    );
    let dt = 1.0 / 30.0;
    let path: Vec<f32> = (0..=120)
        .chain((61..120).rev())
        .chain(std::iter::repeat_n(61, 30))
        .chain((0..61).rev())
        .map(|z| z as f32)
        .collect();
    let mut states = vec![LodState::NEW; objects.len()];
    let mut out_sel = vec![LodSelection::default(); objects.len()];
    let mut series: Vec<Vec<(f32, f32)>> = vec![Vec::new(); objects.len()];
    println!(
        "frame  camera-z  {}",
        objects
            .iter()
            .map(|o| format!("{:<28}", o.0))
            .collect::<String>()
    );
    for (frame, z) in path.iter().enumerate() {
        let camera = LodCamera::new(Vec3::new(0.0, 1.5, 10.0 + z), proj);
        select_batch(
            &camera,
            &settings,
            &groups,
            &batch,
            dt,
            &mut states,
            &mut out_sel,
        )?;
        let mut row = format!("{frame:>5}  {:>8.1}  ", 10.0 + z);
        for (i, s) in out_sel.iter().enumerate() {
            // Effective level: current + transition toward next (fractional during a blend).
            let effective = match s.next {
                Some(n) => s.current as f32 + (n as f32 - s.current as f32) * s.transition,
                None => s.current as f32,
            };
            series[i].push((frame as f32, if s.visible { effective } else { f32::NAN }));
            let mesh = &groups[ids[i] as usize].levels()[s.current as usize].mesh;
            let cell = match (s.visible, s.next) {
                (false, _) => "hidden".to_owned(),
                (true, Some(n)) => {
                    let next_mesh = &groups[ids[i] as usize].levels()[n as usize].mesh;
                    format!("{mesh}->{next_mesh} {:.2}", s.transition)
                }
                (true, None) if s.fade < 1.0 => format!("{mesh} fade {:.2}", s.fade),
                (true, None) => mesh.clone(),
            };
            row.push_str(&format!("{cell:<28}"));
        }
        if frame % 10 == 0 || out_sel.iter().any(|s| s.next.is_some()) {
            println!("{row}");
        }
    }
    let file = out.join("selection.png");
    let chart = Chart {
        title: format!(
            "LOD per object along the camera path ({:?}), fractional while blending",
            settings.transition
        ),
        x_label: "frame".to_owned(),
        y_label: "level".to_owned(),
        series: series
            .iter()
            .enumerate()
            .map(|(i, points)| Series {
                name: objects[i].0.to_owned(),
                points: points.iter().copied().filter(|p| p.1.is_finite()).collect(),
            })
            .collect(),
        markers: false,
        reference: None,
        y_from_zero: false,
    };
    line_chart(&file, &chart)?;
    println!("wrote {}", file.display());
    Ok(())
}
