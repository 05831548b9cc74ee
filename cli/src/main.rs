//! `lodkit`: list the shader library, check shaders that import it, export them to other
//! languages, and run the demo that measures every technique.
//!
//! Exit codes: 0 success, 1 a shader is invalid or the demo failed (no GPU adapter included),
//! 2 usage, scene-file or I/O error. A reader that stops early (`lodkit ... | head -1`) changes
//! none of them: everything printed on stdout goes through `output::Output`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod check;
mod compose;
mod library;
mod lod;
mod output;
mod stats;

use compose::{Outcome, compose_file, print_error};
use output::Output;

use clap::{Parser, Subcommand, ValueEnum};
use lodkit::shaders::{self, ExportOptions, ExportTarget, Exported, ShaderDefValue, ShaderError};

#[derive(Parser)]
#[command(
    name = "lodkit",
    version,
    long_version = concat!(
        env!("CARGO_PKG_VERSION"),
        "\nbuilt with ",
        env!("LODKIT_TOOL_VERSIONS")
    ),
    about = "Smooth discrete-LOD and framebuffer-LOD shader modules"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, Default, ValueEnum)]
enum Format {
    /// Diagnostics for people: file:line:col, the source line, a caret.
    #[default]
    Human,
    /// One JSON document on stdout, for CI tools.
    Json,
}

#[derive(Clone, Copy, ValueEnum)]
enum Stage {
    Vertex,
    Fragment,
    Compute,
}

#[derive(Clone, Copy, ValueEnum)]
enum Target {
    Spv,
    Msl,
    Hlsl,
    Glsl,
    GlslEs,
    Wgsl,
    /// The naga_oil WGSL file itself in WESL form, not composed: `#import`s become `import`s,
    /// `#ifdef` blocks `@if` attributes (lodkit's converter, as its WESL package is made).
    Wesl,
}

#[derive(clap::Args)]
struct ComposeArgs {
    /// Folder of your own modules (`#define_import_path`) and GLSL headers; repeatable.
    #[arg(short = 'I', value_name = "DIR")]
    include: Vec<PathBuf>,
    /// Shader def: NAME (true), NAME=true|false, NAME=-3 (int), NAME=3u (uint); repeatable.
    #[arg(short = 'D', value_name = "NAME[=VALUE]", value_parser = parse_def)]
    define: Vec<(String, ShaderDefValue)>,
    /// Stage of a GLSL file (default: from the extension .vert, .frag, .comp).
    #[arg(long)]
    stage: Option<Stage>,
    /// Validator capabilities beyond WebGPU's, for shaders of a native engine: `all`, or names
    /// such as `immediates,float64,shader-int64` (aliases: push-constants, f64, int64, f16).
    #[arg(long, value_name = "LIST", value_parser = shaders::parse_capabilities)]
    capabilities: Option<naga::valid::Capabilities>,
    /// Leave out every file under the -I folders whose path contains PATTERN (e.g. the stand-in
    /// of a module an engine swaps by build feature); repeatable.
    #[arg(long, value_name = "PATTERN")]
    exclude: Vec<String>,
}

#[derive(Subcommand)]
enum Command {
    /// List the library's modules, their functions and the shader defs they read.
    Modules {
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
    /// Compose each shader against the lodkit modules (and yours) and validate it.
    Check {
        #[command(flatten)]
        compose: ComposeArgs,
        #[arg(long, value_enum, default_value_t)]
        format: check::CheckFormat,
        /// Print what each entry point fetches (texture loads, samples, gathers, storage reads,
        /// per resource) and its ALU ops, counted from the IR for one invocation.
        #[arg(long)]
        stats: bool,
        /// RON or TOML entry points and maxima (`{ "fs_main": { "fetches": 9 } }`): exit 1 when
        /// one goes over. Keys: ENTRY or FILE:ENTRY, then optional `-D NAME[=VALUE]` defs the run
        /// must set (most defs wins). A loop of unknown trip count fails the budget unless the
        /// entry or the file's top sets `allow_unbounded_loops: true`.
        #[arg(long, value_name = "FILE")]
        budget: Option<PathBuf>,
        /// Check each shader under the combinations of the shader defs it and the modules it
        /// imports test (`#ifdef`, `#if`, `#{NAME}`, `@if`, `constants::NAME`): all of them when
        /// there are at most --max-sets, else the default, each def alone and every pair.
        /// `-D` defs are set in every set. Each failure names its set and the shortest set that
        /// still fails.
        #[arg(long)]
        permute: bool,
        /// A TOML or RON file that declares the def sets of the shaders its globs match
        /// (`one_of`, `optional`, `values`, `requires`, `excludes`); others are checked as with
        /// --permute.
        #[arg(long, value_name = "FILE")]
        permutations: Option<PathBuf>,
        /// The most sets that are checked as every combination; past it, pairwise.
        #[arg(long, value_name = "N", default_value_t = 256)]
        max_sets: usize,
        /// Shaders to check (.wgsl: naga_oil; .wesl: WESL linked by wesl-rs; .glsl/.vert/.frag/.comp).
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Write lodkit's WESL package (wesl.toml and <topic>.wesl, generated from the naga_oil
    /// modules) into a folder for wesl-rs projects, or with `--npm` the npm package `lodkit`
    /// (plus package.json and the ES module of the bundle wesl-js links, with its types).
    #[command(group = clap::ArgGroup::new("dest").required(true))]
    Wesl {
        /// Folder to write the WESL package into (created; the package's files in it are
        /// overwritten).
        #[arg(long, value_name = "DIR", group = "dest")]
        out: Option<PathBuf>,
        /// Folder to write the npm package into (created; ready for `npm pack` or `npm publish`).
        #[arg(long, value_name = "DIR", group = "dest")]
        npm: Option<PathBuf>,
    },
    /// Show the GPU adapter the demo would run on (Vulkan, then GL; `LODKIT_BACKEND=vulkan|gl`
    /// picks one) and what lodkit's passes may use on it. Exits 1 when there is none.
    Adapter,
    /// Render the built-in scenes with every technique, measure them, write images, plots and
    /// an HTML report.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "lodkit-demo")]
        out: PathBuf,
        /// Image size.
        #[arg(long, value_name = "WxH", default_value = "320x180", value_parser = parse_size)]
        size: (u32, u32),
        /// Frames a transition lasts.
        #[arg(long, default_value_t = 24)]
        frames: usize,
        /// A RON scene to measure instead of the built-in ones.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Interleaved pairs per pass-time ratio (a quarter of it: the frame-cost breakdown's timing
        /// rounds; an eighth: whole-frame timing rounds).
        #[arg(long, default_value_t = 40)]
        pairs: usize,
        /// Also write benchmarks.md, quality.md and the guides' pictures into this folder
        /// (e.g. `docs`).
        #[arg(long, value_name = "DIR")]
        docs: Option<PathBuf>,
        /// Size of the framebuffer-LOD frame-cost and closed-loop measurements.
        #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
        fb_size: (u32, u32),
    },
    /// Take the figures that need a real GPU, on GPU timestamps where it has them: pass ratios
    /// at 1920x1080 and 3840x2160, the framebuffer-LOD frame-cost sweep, GPU selection from
    /// 10^4 to 10^7 instances; writes gpu-report.json and gpu-report.md
    /// (`scripts/gpu-report.sh` also runs the GPU test binaries).
    GpuReport {
        /// Output folder.
        #[arg(long, default_value = "lodkit-gpu-report")]
        out: PathBuf,
        /// Small sizes and counts: a check of the command on a software GPU.
        #[arg(long)]
        quick: bool,
        /// Interleaved pairs per pass ratio.
        #[arg(long, default_value_t = 9)]
        pairs: usize,
    },
    /// Generate a LOD chain for every mesh of a glTF/GLB file (meshoptimizer, each level's error
    /// bounded) and write it back with `MSFT_lod`: levels as nodes, switch points as
    /// `MSFT_screencoverage` for the reference camera. Prints a table per mesh.
    Lod {
        /// The glTF (.gltf) or GLB (.glb) file; or a folder: every such file below it, in
        /// parallel, each written to the same relative path below the output folder (exit 1
        /// when any file failed, the others written all the same).
        input: PathBuf,
        /// Output file: .glb, or .gltf with its buffer in <stem>.bin beside it; a folder when
        /// the input is one.
        #[arg(short, long)]
        output: PathBuf,
        /// Largest screen-space deviation from the original, in pixels of the reference camera.
        #[arg(long, default_value_t = 1.0)]
        pixel_error: f32,
        /// Levels per mesh, LOD0 (the mesh itself) included.
        #[arg(long, default_value_t = 4)]
        levels: usize,
        /// Triangle share of each level relative to the one before.
        #[arg(long, default_value_t = 0.5)]
        ratio: f32,
        /// The reference camera's vertical field of view, degrees.
        #[arg(long, default_value_t = 60.0)]
        fov: f32,
        /// The reference viewport's height, pixels.
        #[arg(long, default_value_t = 1080.0)]
        viewport_height: f32,
        /// The reference viewport's width over height (screen coverages are shares of it).
        #[arg(long, default_value_t = 16.0 / 9.0)]
        aspect: f32,
        /// Keep vertices on open borders in place (chunks of terrain stay stitched).
        #[arg(long)]
        lock_border: bool,
        /// Fail on a mesh too small to simplify instead of keeping it as a single level.
        #[arg(long)]
        strict: bool,
        /// Also write the table as JSON (for a folder: every file's, with its status).
        #[arg(long, value_name = "FILE")]
        report: Option<PathBuf>,
        /// Give each mesh switch distances of its own (by default the meshes under one
        /// top-level node share theirs: an object switches as a whole).
        #[arg(long, conflicts_with_all = ["object", "one_object"])]
        per_mesh: bool,
        /// The whole file is one object: every mesh shares the distances (a file whose parts
        /// are top-level nodes, such as Khronos's FlightHelmet).
        #[arg(long, conflicts_with = "object")]
        one_object: bool,
        /// A node whose meshes switch together (repeatable): the meshes below it share their
        /// distances, wherever it is in the tree (a file whose one root node holds several
        /// objects names them).
        #[arg(long, value_name = "NODE")]
        object: Vec<String>,
        #[command(flatten)]
        impostor: lod::ImpostorFlags,
    },
    /// Compose a shader and write it through one of naga's back ends (`--to wesl`: convert a
    /// naga_oil WGSL file to WESL instead).
    Export {
        #[command(flatten)]
        compose: ComposeArgs,
        /// Output language.
        #[arg(long, value_enum)]
        to: Target,
        /// Entry point for GLSL output (needed when the shader has several).
        #[arg(long)]
        entry: Option<String>,
        /// Output file (`-` for stdout).
        #[arg(short, long)]
        output: PathBuf,
        /// The shader to export.
        file: PathBuf,
    },
}

fn parse_def(s: &str) -> Result<(String, ShaderDefValue), String> {
    let (name, value) = match s.split_once('=') {
        None => (s, ShaderDefValue::Bool(true)),
        Some((name, "true")) => (name, ShaderDefValue::Bool(true)),
        Some((name, "false")) => (name, ShaderDefValue::Bool(false)),
        Some((name, v)) => match v.strip_suffix('u') {
            Some(u) => (
                name,
                ShaderDefValue::UInt(u.parse().map_err(|_| format!("`{v}` is not a u32"))?),
            ),
            None => (
                name,
                ShaderDefValue::Int(
                    v.parse()
                        .map_err(|_| format!("`{v}` is not an i32, true or false"))?,
                ),
            ),
        },
    };
    let valid = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid {
        return Err(format!("`{name}` is not a shader def name"));
    }
    Ok((name.to_owned(), value))
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WxH (e.g. 320x180)"))?;
    let side = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{v}` in `{s}` is not a whole number of pixels"))
    };
    Ok((side(w)?, side(h)?))
}

fn demo(options: lodkit_cli::demo::DemoOptions) -> ExitCode {
    use lodkit_cli::demo::DemoError;
    let mut out = Output::default();
    out.println(&format!(
        "lodkit demo: writing into {}",
        options.out.display()
    ));
    let code = match lodkit_cli::demo::run(&options) {
        Ok(report) => {
            out.println(&lodkit_cli::demo::report::terminal::summary(&report));
            out.println(&format!(
                "open {}",
                options.out.join("index.html").display()
            ));
            if !report.plot_text {
                out.println("note: no TrueType font found, plots have no text (set LODKIT_FONT)");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            output::eprintln(&format!("error: {e}"));
            match e {
                DemoError::Options(_)
                | DemoError::Scene(_)
                | DemoError::Io { .. }
                | DemoError::Plot(_) => ExitCode::from(2),
                _ => ExitCode::from(1),
            }
        }
    };
    out.finish(code)
}

fn gpu_report(
    out_dir: &Path,
    options: &lodkit_cli::demo::measures::gpu_report::GpuReportOptions,
) -> ExitCode {
    use lodkit_cli::demo::measures::gpu_report::measure;
    use lodkit_cli::demo::report::gpu_report::{markdown, write};
    let mut out = Output::default();
    let run = lodkit_cli::demo::open_gpu().and_then(|gpu| {
        out.println(&format!("lodkit gpu-report on {}", gpu.adapter_summary()));
        let report = measure(&gpu, options)?;
        write(&report, out_dir)?;
        Ok(report)
    });
    let code = match run {
        Ok(report) => {
            out.println(&markdown(&report));
            out.println(&format!(
                "wrote {}",
                out_dir.join("gpu-report.md").display()
            ));
            ExitCode::SUCCESS
        }
        Err(e) => {
            output::eprintln(&format!("error: {e}"));
            ExitCode::from(1)
        }
    };
    out.finish(code)
}

fn adapter() -> ExitCode {
    match lodkit_cli::demo::open_gpu() {
        Ok(gpu) => {
            let mut out = Output::default();
            out.println(&gpu.adapter_summary());
            out.println(&format!("capabilities: {}", gpu.capabilities()));
            out.finish(ExitCode::SUCCESS)
        }
        Err(e) => {
            output::eprintln(&format!("error: {e}"));
            ExitCode::from(1)
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Adapter => adapter(),
        Command::GpuReport { out, quick, pairs } => gpu_report(
            &out,
            &lodkit_cli::demo::measures::gpu_report::GpuReportOptions { quick, pairs },
        ),
        // clap requires exactly one of the two.
        Command::Wesl { out, npm } => match npm {
            Some(dir) => library::write_wesl(&dir, true),
            None => library::write_wesl(&out.unwrap_or_default(), false),
        },
        Command::Demo {
            out,
            size,
            frames,
            scene,
            pairs,
            docs,
            fb_size,
        } => demo(lodkit_cli::demo::DemoOptions {
            out,
            size,
            frames,
            scene,
            timing_pairs: pairs,
            docs,
            fb_size,
            progress: true,
        }),
        Command::Modules { format } => library::modules(matches!(format, Format::Json)),
        Command::Check {
            compose,
            format,
            stats,
            budget,
            permute,
            permutations,
            max_sets,
            files,
        } => check::run(&check::CheckRun {
            compose: &compose,
            format,
            stats,
            budget: budget.as_deref(),
            permute,
            permutations: permutations.as_deref(),
            max_sets,
            files: &files,
        }),
        Command::Lod {
            input,
            output,
            pixel_error,
            levels,
            ratio,
            fov,
            viewport_height,
            aspect,
            lock_border,
            strict,
            report,
            per_mesh,
            one_object,
            object,
            impostor,
        } => lod::run(&lod::LodArgs {
            input,
            output,
            pixel_error,
            levels,
            ratio,
            fov_y_degrees: fov,
            viewport_height,
            aspect,
            lock_border,
            keep_small: !strict,
            report,
            grouping: match (per_mesh, one_object) {
                (true, _) => lod::Grouping::PerMesh,
                (false, true) => lod::Grouping::Whole,
                (false, false) => lod::Grouping::Nodes(object),
            },
            impostor: impostor.options(),
        }),
        Command::Export {
            compose,
            to,
            entry,
            output,
            file,
        } => export(&compose, to, entry, &output, &file),
    }
}

/// Writes `bytes` to `output` (`-` for stdout), saying what it wrote as `what`.
fn write_output(output: &Path, bytes: &[u8], what: &str) -> ExitCode {
    if output == Path::new("-") {
        let mut out = Output::default();
        out.write(bytes);
        return out.finish(ExitCode::SUCCESS);
    }
    match std::fs::write(output, bytes) {
        Ok(()) => {
            output::eprintln(&format!("wrote {} ({what})", output.display()));
            ExitCode::SUCCESS
        }
        Err(e) => {
            output::eprintln(&format!("error: cannot write `{}`: {e}", output.display()));
            ExitCode::from(2)
        }
    }
}

/// `export --to wesl`: the file converted, not composed. A construct with no WESL form is an
/// error naming its line (exit 1); an unreadable file exits 2.
fn export_wesl(file: &Path, output: &Path) -> ExitCode {
    let source = match std::fs::read_to_string(file) {
        Ok(s) => s,
        Err(e) => {
            output::eprintln(&format!("error: cannot read `{}`: {e}", file.display()));
            return ExitCode::from(2);
        }
    };
    // No package of its own: imports of lodkit's modules stay `lodkit::...`.
    match shaders::naga_oil_to_wesl(&source, "", "") {
        Ok(wesl) => write_output(
            output,
            wesl.as_bytes(),
            &format!("{} bytes of WESL", wesl.len()),
        ),
        Err(e) => {
            output::eprintln(&format!(
                "error: {}:{}: no WESL form: {}",
                file.display(),
                e.line,
                e.message
            ));
            ExitCode::from(1)
        }
    }
}

fn export(
    args: &ComposeArgs,
    to: Target,
    entry: Option<String>,
    output: &Path,
    file: &Path,
) -> ExitCode {
    let target = match to {
        Target::Spv => ExportTarget::SpirV,
        Target::Msl => ExportTarget::Msl,
        Target::Hlsl => ExportTarget::Hlsl,
        Target::Glsl => ExportTarget::Glsl,
        Target::GlslEs => ExportTarget::GlslEs,
        Target::Wgsl => ExportTarget::Wgsl,
        Target::Wesl => return export_wesl(file, output),
    };
    let mut library = match compose::library(args) {
        Ok(l) => l,
        Err(e) => {
            print_error(&e);
            return ExitCode::from(if matches!(e, ShaderError::Io { .. }) {
                2
            } else {
                1
            });
        }
    };
    let composed = match compose_file(&mut library, args, file) {
        Outcome::Valid(c) => *c,
        Outcome::Invalid(e) => {
            print_error(&e);
            return ExitCode::from(1);
        }
        Outcome::Unreadable(e) => {
            print_error(&e);
            return ExitCode::from(2);
        }
    };
    let exported = match shaders::export(&composed, target, &ExportOptions { entry_point: entry }) {
        Ok(x) => x,
        Err(e) => {
            print_error(&e);
            // Choosing an entry point that is missing or ambiguous is a usage error.
            let usage = matches!(e, ShaderError::EntryPoint(_));
            return ExitCode::from(if usage { 2 } else { 1 });
        }
    };
    let what = match &exported {
        Exported::SpirV(w) => format!("{} SPIR-V words", w.len()),
        Exported::Text(t) => format!("{} bytes of {target}", t.len()),
    };
    write_output(output, &exported.to_bytes(), &what)
}
