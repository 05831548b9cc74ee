//! `lodkit lod`: a LOD chain for every mesh of a glTF / GLB file (`lodkit::lod_chain`), written
//! back as glTF with `MSFT_lod` (levels as nodes, screen coverages in `MSFT_screencoverage`), a
//! table per mesh and an optional JSON report.

mod compressed;
mod folder;
mod impostor;
mod objects;
mod read;
mod write;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use lodkit::lod_chain::{
    LodChain, LodChainDescriptor, MeshData, PixelErrorCamera, SmallMesh, hide_distance,
    switch_distances,
};

use crate::output::{self, Output};

/// What `lodkit lod` was asked to do.
pub struct LodArgs {
    pub input: PathBuf,
    pub output: PathBuf,
    pub pixel_error: f32,
    pub levels: usize,
    pub ratio: f32,
    pub fov_y_degrees: f32,
    pub viewport_height: f32,
    pub aspect: f32,
    pub lock_border: bool,
    pub keep_small: bool,
    pub report: Option<PathBuf>,
    /// Which meshes share their switch distances (an object switches as a whole).
    pub grouping: objects::Grouping,
    /// Bake each mesh's impostor as its last level (`--impostor`).
    pub impostor: Option<ImpostorOptions>,
}

pub use impostor::{ImpostorFlags, ImpostorOptions};
pub use objects::Grouping;

/// One row of the table and the report.
#[derive(serde::Serialize)]
struct LevelRow {
    level: usize,
    triangles: usize,
    /// Upper bound of the Hausdorff distance from LOD0, object units.
    error: f32,
    /// Whether that bound's work was capped on degenerate geometry (a looser upper bound).
    error_capped: bool,
    /// View-normalized distance from which the level is used.
    switch_distance: f32,
    /// `MSFT_screencoverage` entry: below this share of the screen the next level takes over.
    screen_coverage: f32,
    seconds: f64,
    /// The level is the mesh's impostor (`--impostor`): `error` is `impostor_error` of its atlas.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    impostor: bool,
}

#[derive(serde::Serialize)]
struct MeshReport {
    mesh: usize,
    name: String,
    /// The node whose meshes switch together with this one (its name), or the mesh itself.
    object: String,
    radius: f32,
    /// Half the diagonal of the box around the mesh (what its screen coverage measures).
    #[serde(skip)]
    box_radius: f32,
    /// View-normalized distance beyond which the mesh covers less than the pixel error.
    max_distance: f32,
    levels: Vec<LevelRow>,
    warnings: Vec<String>,
}

#[derive(serde::Serialize)]
struct Report {
    input: String,
    output: String,
    pixel_error: f32,
    fov_y_degrees: f32,
    viewport_height: f32,
    aspect: f32,
    meshes: Vec<MeshReport>,
}

/// Screen share (Babylon.js's `MSFT_screencoverage`: the bounding sphere's projected area over
/// the viewport's, `π R² |P11|² / (4 aspect D²)`) at view-normalized distance `d`.
fn coverage(radius: f32, d: f32, aspect: f32) -> f32 {
    let c = std::f32::consts::PI * radius * radius / (4.0 * aspect * d * d);
    if c.is_finite() { c.min(1.0) } else { 1.0 }
}

/// Runs `lodkit lod` on a file, or on every glTF file of a folder ([`folder::run`]). Exit 0 on
/// success, 1 when the file or a mesh in it is unusable (a folder: when any file failed), 2 for
/// I/O errors.
pub fn run(args: &LodArgs) -> ExitCode {
    if args.input.is_dir() {
        return folder::run(args);
    }
    let file = args.input.display().to_string();
    let mut warn = |w: String| output::eprintln(&format!("warning: {file}: {w}"));
    let reports = match convert(args, &mut warn) {
        Ok(r) => r,
        Err((code, message)) => {
            output::eprintln(&format!("error: {file}: {message}"));
            return ExitCode::from(code);
        }
    };
    let mut stdout = Output::default();
    for r in &reports {
        stdout.println(&table(r));
    }
    stdout.println(&format!("wrote {}", args.output.display()));
    if let Some(path) = &args.report {
        let report = Report {
            input: file.clone(),
            output: args.output.display().to_string(),
            pixel_error: args.pixel_error,
            fov_y_degrees: args.fov_y_degrees,
            viewport_height: args.viewport_height,
            aspect: args.aspect,
            meshes: reports,
        };
        let text = serde_json::to_string_pretty(&report).expect("a report is JSON");
        if let Err(e) = std::fs::write(path, text) {
            output::eprintln(&format!("error: cannot write `{}`: {e}", path.display()));
            return ExitCode::from(2);
        }
    }
    stdout.finish(ExitCode::SUCCESS)
}

/// Writes the chains of `args.input` into `args.output` and returns the meshes' reports, or
/// the exit code and the error (1: the file or a mesh is unusable, 2: I/O); each warning goes
/// to `warn`.
fn convert(args: &LodArgs, warn: &mut dyn FnMut(String)) -> Result<Vec<MeshReport>, (u8, String)> {
    let fail = |code: u8, message: String| Err((code, message));
    let camera = PixelErrorCamera {
        fov_y: args.fov_y_degrees.to_radians(),
        viewport_height: args.viewport_height,
        pixel_error: args.pixel_error,
        hysteresis: 0.0,
    };
    if let Err(e) = camera.validate() {
        return fail(2, e.to_string());
    }
    if !is_gltf_name(&args.output) {
        return fail(
            2,
            format!(
                "-o {}: the output must end in .gltf or .glb",
                args.output.display()
            ),
        );
    }
    if !(args.aspect.is_finite() && args.aspect > 0.0) {
        return fail(2, format!("--aspect {} must be > 0", args.aspect));
    }
    if let Some(o) = &args.impostor {
        let layout = lodkit::impostor::ImpostorLayout {
            frames: o.frames,
            frame_size: o.frame_size,
            shape: o.shape,
            center: [0.0; 3],
            radius: 1.0,
        };
        if let Err(e) = layout.validate() {
            return fail(2, format!("--impostor-frames / --impostor-frame-size: {e}"));
        }
    }
    let descriptor = LodChainDescriptor {
        levels: args.levels,
        ratio: args.ratio,
        camera,
        lock_border: args.lock_border,
        small_mesh: if args.keep_small {
            SmallMesh::SingleLevel
        } else {
            SmallMesh::Error
        },
        ..Default::default()
    };
    let read::Opened {
        document,
        buffers,
        required_here,
    } = match read::open(&args.input) {
        Ok(x) => x,
        Err(e) => return fail(if e.starts_with("cannot read") { 2 } else { 1 }, e),
    };
    let mut out = write::Output::new(document.clone(), &buffers);
    out.require(&required_here);
    // Images beside the input go into the output's buffer: it is whole wherever it is written.
    let base = args.input.parent().unwrap_or(Path::new("."));
    let embedded = out.embed_images(base);
    for w in embedded.warnings {
        warn(w);
    }
    for w in copy_beside(base, &args.output, &embedded.copies) {
        warn(w);
    }
    // Every mesh's chain first: an object's meshes share their distances.
    let mut planned = Vec::new();
    let mut gpu = None;
    for mesh in document.meshes() {
        let name = mesh.name().unwrap_or("").to_owned();
        let label = format!("mesh {} '{name}'", mesh.index());
        let input = match read::mesh(&mesh, &buffers) {
            Ok(i) => i,
            Err(e) => return fail(1, format!("{label}: {e}")),
        };
        let mut warnings = input.warnings.clone();
        let mut chains = Vec::new();
        for p in &input.primitives {
            if !p.carried.is_empty() {
                let names: Vec<&str> = p.carried.iter().map(|(s, _)| s.as_str()).collect();
                warnings.push(format!(
                    "primitive {}: {} carried into the levels unweighed (the simplifier weighs only position, NORMAL and TEXCOORD_0)",
                    p.index,
                    names.join(", ")
                ));
            }
            let data = MeshData {
                positions: &p.positions,
                indices: &p.indices,
                normals: p.normals.as_deref(),
                uvs: p.uvs.as_deref(),
            };
            match LodChain::build(&data, &descriptor) {
                Ok(chain) => chains.push(chain),
                Err(e) => return fail(1, format!("{label} primitive {}: {e}", p.index)),
            }
        }
        let mut report = match plan(&chains, args, &camera) {
            Ok(rows) => rows,
            Err(e) => return fail(1, format!("{label}: {e}")),
        };
        let atlas = match &args.impostor {
            Some(options) => {
                let gpu = match &gpu {
                    Some(g) => g,
                    None => match lodkit::gpu::GpuContext::new_headless(&Default::default()) {
                        Ok(g) => gpu.insert(g),
                        Err(e) => return fail(2, format!("--impostor needs a GPU: {e}")),
                    },
                };
                let mut note = |w: String| warnings.push(w);
                let start = std::time::Instant::now();
                let atlas = impostor::bake(gpu, &mesh, &input, &buffers, base, options, &mut note)
                    .and_then(|atlas| {
                        let seconds = start.elapsed().as_secs_f64();
                        add_impostor_row(&mut report, &atlas, &camera, seconds).map(|()| atlas)
                    });
                match atlas {
                    Ok(atlas) => Some(atlas),
                    Err(e) => {
                        warnings.push(e);
                        None
                    }
                }
            }
            None => None,
        };
        for w in &warnings {
            warn(format!("{label}: {w}"));
        }
        let report = MeshReport {
            mesh: mesh.index(),
            name,
            warnings,
            ..report
        };
        planned.push((input, chains, report, atlas));
    }
    let objects = match objects::objects(&document, &args.grouping) {
        Ok(o) => o,
        Err(e) => return fail(2, e),
    };
    let own: Vec<Vec<f32>> = planned
        .iter()
        .map(|(_, _, r, _)| {
            let switches = r.levels.iter().map(|l| l.switch_distance);
            switches.chain(std::iter::once(r.max_distance)).collect()
        })
        .collect();
    let shared = objects::shared(&objects, &own);
    let mut reports = Vec::new();
    for ((input, chains, mut report, atlas), (object, distances)) in
        planned.into_iter().zip(objects.iter().zip(&shared))
    {
        report.object = object.name.clone();
        report.max_distance = *distances.last().unwrap_or(&report.max_distance);
        let count = report.levels.len();
        for (i, row) in report.levels.iter_mut().enumerate() {
            row.switch_distance = distances[i];
            let next = distances.get(i + 1).copied().unwrap_or(report.max_distance);
            row.screen_coverage = coverage(report.box_radius, next, args.aspect);
        }
        let impostor = match &atlas {
            Some(atlas) => {
                let base = document
                    .meshes()
                    .nth(report.mesh)
                    .and_then(|m| m.name().map(str::to_owned))
                    .unwrap_or_else(|| format!("mesh{}", report.mesh));
                let (color, normal_depth) = match impostor::pngs(atlas) {
                    Ok(p) => p,
                    Err(e) => return fail(2, e),
                };
                Some(out.add_impostor(&base, &color, &normal_depth, &atlas.layout))
            }
            None => None,
        };
        let mesh_levels = count - usize::from(impostor.is_some());
        let levels: Vec<Vec<write::LevelPrimitive>> = (0..mesh_levels)
            .map(|i| {
                input
                    .primitives
                    .iter()
                    .zip(&chains)
                    .map(|(p, chain)| {
                        let l = &chain.levels()[i.min(chain.levels().len() - 1)];
                        write::LevelPrimitive {
                            primitive: p.index,
                            positions: l.positions(),
                            normals: l.normals(),
                            uvs: l.uvs(),
                            indices: l.indices(),
                            file_vertices: l
                                .source_vertices()
                                .iter()
                                .map(|&v| p.file_vertex[v as usize])
                                .collect(),
                            carried: &p.carried,
                        }
                    })
                    .collect()
            })
            .collect();
        if count > 1 {
            let coverages: Vec<f32> = report.levels.iter().map(|r| r.screen_coverage).collect();
            out.add_levels(report.mesh, &levels, impostor.as_ref(), &coverages);
        }
        reports.push(report);
    }
    if let Err(e) = out.write(&args.output) {
        return fail(2, e);
    }
    Ok(reports)
}

/// The mesh's levels: level i is level i of every primitive's chain (its last where it has
/// fewer), its error the largest of theirs, its distances for the sphere around all of them.
fn plan(
    chains: &[LodChain],
    args: &LodArgs,
    camera: &PixelErrorCamera,
) -> Result<MeshReport, String> {
    let count = chains.iter().map(|c| c.levels().len()).max().unwrap_or(1);
    // The sphere around every primitive's sphere, centred on their common box's centre (which
    // is Babylon.js's bounding-sphere centre; its radius, half the box diagonal, is what its
    // screen coverage uses).
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for c in chains {
        for p in c.levels()[0].positions() {
            for ((l, h), x) in lo.iter_mut().zip(&mut hi).zip(p) {
                *l = l.min(*x);
                *h = h.max(*x);
            }
        }
    }
    let centre: [f32; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let dist = |a: [f32; 3], b: [f32; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let radius = chains
        .iter()
        .map(|c| {
            let s = c.bounding_sphere();
            dist(s.center, centre) + s.radius
        })
        .fold(0.0f32, f32::max)
        .next_up();
    let box_radius = 0.5 * dist(lo, hi);
    fn at(c: &LodChain, i: usize) -> &lodkit::lod_chain::LodChainLevel {
        &c.levels()[i.min(c.levels().len() - 1)]
    }
    let errors: Vec<f32> = (0..count)
        .map(|i| chains.iter().map(|c| at(c, i).error()).fold(0.0, f32::max))
        .collect();
    let distances = switch_distances(&errors, radius, camera).map_err(|e| e.to_string())?;
    let max_distance = hide_distance(radius, camera).map_err(|e| e.to_string())?;
    let levels = (0..count)
        .map(|i| {
            let next = distances.get(i + 1).copied().unwrap_or(max_distance);
            LevelRow {
                level: i,
                triangles: chains.iter().map(|c| at(c, i).triangles()).sum(),
                error: errors[i],
                error_capped: chains.iter().any(|c| at(c, i).error_capped()),
                switch_distance: distances[i],
                screen_coverage: coverage(box_radius, next, args.aspect),
                seconds: chains
                    .iter()
                    .filter(|c| i < c.levels().len())
                    .map(|c| c.levels()[i].time().as_secs_f64())
                    .sum(),
                impostor: false,
            }
        })
        .collect();
    Ok(MeshReport {
        mesh: 0,
        name: String::new(),
        object: String::new(),
        radius,
        box_radius,
        max_distance,
        levels,
        warnings: Vec::new(),
    })
}

/// Appends the impostor of `atlas` to `report`'s levels where `lodkit::impostor::
/// impostor_placement` puts it: its error (`impostor_error`), from the distance where its
/// picture stays within the pixel error, the mesh levels that would switch in beyond that left
/// out (with a warning); an error when it would never be shown.
fn add_impostor_row(
    report: &mut MeshReport,
    atlas: &lodkit::impostor::ImpostorAtlas,
    camera: &PixelErrorCamera,
    seconds: f64,
) -> Result<(), String> {
    let own = lodkit::impostor::impostor_switch_distance(&atlas.layout, camera)
        .map_err(|e| format!("impostor: {e}"))?;
    let distances: Vec<f32> = report.levels.iter().map(|l| l.switch_distance).collect();
    let placement = lodkit::impostor::impostor_placement(&distances, report.max_distance, own)
        .map_err(|e| {
            format!("impostor left out: {e}; more frames (--impostor-frames) bring it nearer")
        })?;
    if placement.mesh_levels < report.levels.len() {
        report.warnings.push(format!(
            "levels {}..={} left out: the impostor is within the pixel error from {own:.3} (view-normalized), nearer than they switch in",
            placement.mesh_levels,
            report.levels.len() - 1
        ));
        report.levels.truncate(placement.mesh_levels);
    }
    report.levels.push(LevelRow {
        level: report.levels.len(),
        triangles: 2,
        error: lodkit::impostor::impostor_error(&atlas.layout),
        error_capped: false,
        switch_distance: placement.distance,
        screen_coverage: 0.0,
        seconds,
        impostor: true,
    });
    Ok(())
}

fn table(r: &MeshReport) -> String {
    let mut s = format!(
        "mesh {} '{}' (switching with {}): radius {:.4}, hidden beyond {:.3} (view-normalized)\n",
        r.mesh, r.name, r.object, r.radius, r.max_distance
    );
    s.push_str("  level  triangles       error  switch distance  coverage     time\n");
    for l in &r.levels {
        s.push_str(&format!(
            "  {:>5}  {:>9}  {:>10.6}{} {:>15.4}  {:>8.5}  {:>5.0} ms\n",
            l.level,
            l.triangles,
            l.error,
            if l.error_capped { "*" } else { " " },
            l.switch_distance,
            l.screen_coverage,
            l.seconds * 1e3
        ));
        if l.impostor {
            s.truncate(s.trim_end().len());
            s.push_str("  impostor\n");
        }
    }
    if r.levels.iter().any(|l| l.error_capped) {
        s.push_str(
            "  * capped on degenerate geometry (long slivers): an upper bound, a looser one\n",
        );
    }
    s.trim_end().to_owned()
}

/// Whether `path` looks like a glTF file name (for the usage check of `-o`).
fn is_gltf_name(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// Copies the images at `paths` (relative to the input's folder `base`) to the same relative
/// paths beside `output`, unless that is the input's own folder; a warning for each that could
/// not be copied (the output then names a file that is not beside it).
fn copy_beside(base: &Path, output: &Path, paths: &[String]) -> Vec<String> {
    let target = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let base = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    let same = matches!(
        (base.canonicalize(), target.canonicalize()),
        (Ok(a), Ok(b)) if a == b
    );
    if same {
        return Vec::new();
    }
    let mut warnings = Vec::new();
    for path in paths {
        let (from, to) = (base.join(path), target.join(path));
        let copied = to
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .and_then(|()| std::fs::copy(&from, &to));
        if let Err(e) = copied {
            warnings.push(format!(
                "image '{path}': cannot copy it beside the output ({e}), left as a URI"
            ));
        }
    }
    warnings
}
