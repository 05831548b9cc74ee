//! Host-side figures for the generated benchmarks page: composing shaders against the library and
//! batch LOD selection, as medians of repeated runs. The criterion benches
//! (`cargo bench -p lodkit-cli --bench compose`, `--bench select`) measure the same workloads more thoroughly.

use std::hint::black_box;
use std::time::Instant;

use glam::{Mat4, Vec3};
use serde::Serialize;

use crate::demo::error::DemoError;
use crate::demo::measures::upsample_timing::median;
use lodkit::select::{
    InstanceBatch, LodCamera, LodGroup, LodSelection, LodSettings, LodState, TransitionMode,
    select_batch,
};
use lodkit::shaders::{
    self, ComposeDescriptor, Composed, ExportOptions, ExportTarget, ShaderLibrary,
};

/// A small user shader importing two lodkit modules.
pub const USER_SHADER: &str = "#import lodkit::normal_distance::foreshortened_normal_distance
#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}

@vertex
fn vs(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }

@fragment
fn fs(v: FullscreenVertex) -> @location(0) vec4<f32> {
    return vec4<f32>(foreshortened_normal_distance(vec3(v.uv, 1.0), vec3(0.0, 0.0, 1.0)));
}
";

/// Composes [`USER_SHADER`] against `library`.
pub fn compose_user_shader(library: &mut ShaderLibrary) -> Result<Composed, DemoError> {
    Ok(library.compose(&ComposeDescriptor {
        source: USER_SHADER,
        file_path: "user.wgsl",
        ..Default::default()
    })?)
}

/// A deterministic selection workload: `n` instances scattered over a 1 km square, two LOD
/// groups (one with a max distance), a 16:9 camera 2 m above the ground.
#[derive(Clone, Debug)]
pub struct SelectionWorkload {
    /// The camera.
    pub camera: LodCamera,
    /// The LOD groups.
    pub groups: Vec<LodGroup>,
    /// Instance positions.
    pub positions: Vec<Vec3>,
    /// Instance max scales.
    pub max_scales: Vec<f32>,
    /// Group index of each instance.
    pub group_ids: Vec<u32>,
}

impl SelectionWorkload {
    /// Builds the workload for `n` instances.
    pub fn new(n: usize) -> Self {
        let proj: Mat4 = glam::camera::rh::proj::directx::perspective(1.0, 16.0 / 9.0, 0.1, 2000.0);
        let camera = LodCamera::new(Vec3::new(0.0, 2.0, 0.0), proj);
        let groups = [
            LodGroup::from_distances(&[0.0, 20.0, 60.0, 150.0])
                .and_then(|g| g.with_max_distance(600.0)),
            LodGroup::from_distances(&[0.0, 40.0, 120.0]),
        ]
        .into_iter()
        .flatten()
        .collect();
        let noise = lodkit::noise::white_noise(3 * n, 11);
        Self {
            camera,
            groups,
            positions: noise
                .chunks(3)
                .map(|v| Vec3::new(v[0] * 1000.0 - 500.0, 0.0, v[1] * 1000.0 - 500.0))
                .collect(),
            max_scales: noise.chunks(3).map(|v| 0.5 + v[2]).collect(),
            group_ids: (0..n as u32).map(|i| i % 2).collect(),
        }
    }

    /// The instances as a batch.
    pub fn batch(&self) -> InstanceBatch<'_> {
        InstanceBatch {
            positions: &self.positions,
            max_scales: &self.max_scales,
            groups: &self.group_ids,
        }
    }

    /// The three transition modes the figures cover, with their names.
    pub fn modes() -> [(&'static str, LodSettings); 3] {
        [
            ("hard", TransitionMode::Hard),
            ("distance", TransitionMode::Distance),
            ("time", TransitionMode::Time { seconds: 0.5 }),
        ]
        .map(|(name, transition)| {
            (
                name,
                LodSettings {
                    hysteresis: 8.0,
                    transition,
                    ..Default::default()
                },
            )
        })
    }
}

/// One host-side figure.
#[derive(Clone, Debug, Serialize)]
pub struct CpuFigure {
    /// What was measured.
    pub what: String,
    /// Median over the runs.
    pub median: f64,
    /// Unit of `median`.
    pub unit: String,
    /// Runs.
    pub runs: usize,
}

fn time_ms(f: &mut dyn FnMut() -> Result<(), DemoError>) -> Result<f64, DemoError> {
    let t = Instant::now();
    f()?;
    Ok(t.elapsed().as_secs_f64() * 1e3)
}

/// Measures the host-side figures, `runs` times each.
pub fn cpu_figures(runs: usize) -> Result<Vec<CpuFigure>, DemoError> {
    let runs = runs.max(3);
    let figure = |what: &str, median: f64, unit: &str| CpuFigure {
        what: what.to_owned(),
        median,
        unit: unit.to_owned(),
        runs,
    };
    let mut out = Vec::new();
    let mut cold = Vec::new();
    for _ in 0..runs {
        cold.push(time_ms(&mut || {
            let mut library = ShaderLibrary::new()?;
            black_box(compose_user_shader(&mut library)?);
            Ok(())
        })?);
    }
    out.push(figure(
        "cold ShaderLibrary (naga_oil Composer + every module) + compose one shader",
        median(&cold),
        "ms",
    ));
    let mut library = ShaderLibrary::new()?;
    let mut warm = Vec::new();
    for _ in 0..runs {
        warm.push(time_ms(&mut || {
            black_box(compose_user_shader(&mut library)?);
            Ok(())
        })?);
    }
    out.push(figure(
        "compose one shader, warm library",
        median(&warm),
        "ms",
    ));
    let composed = compose_user_shader(&mut library)?;
    let mut export = Vec::new();
    for _ in 0..runs {
        export.push(time_ms(&mut || {
            let spv = shaders::export(&composed, ExportTarget::SpirV, &ExportOptions::default());
            black_box(spv.map_err(|e| DemoError::Internal(e.to_string()))?);
            Ok(())
        })?);
    }
    out.push(figure(
        "export that shader to SPIR-V",
        median(&export) * 1e3,
        "µs",
    ));
    let n = 100_000;
    let w = SelectionWorkload::new(n);
    for (name, settings) in SelectionWorkload::modes() {
        let mut states = vec![LodState::NEW; n];
        let mut sel = vec![LodSelection::default(); n];
        let mut times = Vec::new();
        for _ in 0..runs * 4 {
            times.push(time_ms(&mut || {
                select_batch(
                    &w.camera,
                    &settings,
                    &w.groups,
                    &w.batch(),
                    black_box(0.016),
                    &mut states,
                    &mut sel,
                )
                .map_err(|e| DemoError::Internal(e.to_string()))
            })?);
        }
        let rate = n as f64 / (median(&times) * 1e-3) / 1e6;
        out.push(CpuFigure {
            runs: times.len(),
            ..figure(
                &format!("select_batch, 100k instances, {name} transitions, one core"),
                rate,
                "M instances/s",
            )
        });
    }
    Ok(out)
}
