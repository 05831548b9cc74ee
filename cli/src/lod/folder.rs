//! `lodkit lod DIR -o OUT`: every glTF and GLB file below DIR, in parallel, into the same
//! relative path below OUT; a bar on a terminal (a line per file elsewhere), a summary table,
//! a JSON report with `--report`, and an exit status that says whether any file failed. A file
//! that fails is named with its error and the others go on.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use lodkit_cli::progress::Progress;

use super::{LodArgs, MeshReport, convert, is_gltf_name};
use crate::output::{self, Output};

/// One file's outcome.
#[derive(serde::Serialize)]
struct FileReport {
    input: String,
    output: String,
    /// None: written; else why not.
    error: Option<String>,
    /// 0 written, 1 the file or a mesh is unusable, 2 an I/O error.
    exit_code: u8,
    seconds: f64,
    /// Triangles of the meshes as they were (level 0) and of their last levels.
    triangles: usize,
    last_level_triangles: usize,
    warnings: Vec<String>,
    meshes: Vec<MeshReport>,
}

#[derive(serde::Serialize)]
struct FolderReport {
    input: String,
    output: String,
    pixel_error: f32,
    threads: usize,
    seconds: f64,
    failed: usize,
    files: Vec<FileReport>,
}

/// The glTF and GLB files below `dir` (sorted; `skip` and what lies below it left out).
fn gltf_files(dir: &Path, skip: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut folders = vec![dir.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder)? {
            let path = entry?.path();
            let same = |a: &Path| matches!((a.canonicalize(), skip.canonicalize()), (Ok(a), Ok(b)) if a == b);
            if path.is_dir() {
                if !same(&path) {
                    folders.push(path);
                }
            } else if is_gltf_name(&path) {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// Runs `lodkit lod` over a folder (see the module's docs). Exit 0 when every file was written,
/// 1 when any failed, 2 when the folders cannot be read or made.
pub fn run(args: &LodArgs) -> ExitCode {
    let fail = |message: String| {
        output::eprintln(&format!("error: {message}"));
        ExitCode::from(2)
    };
    let (dir, out) = (&args.input, &args.output);
    if out.is_file() || is_gltf_name(out) {
        return fail(format!(
            "-o {}: with a folder as input the output is a folder",
            out.display()
        ));
    }
    let files = match gltf_files(dir, out) {
        Ok(f) => f,
        Err(e) => return fail(format!("cannot read `{}`: {e}", dir.display())),
    };
    if files.is_empty() {
        return fail(format!("no .gltf or .glb file below `{}`", dir.display()));
    }
    if let Err(e) = std::fs::create_dir_all(out) {
        return fail(format!("cannot create `{}`: {e}", out.display()));
    }
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(files.len());
    let progress = Progress::new(true, files.len());
    progress.set_message("lodkit lod");
    let start = Instant::now();
    let next = AtomicUsize::new(0);
    let (send, receive) = mpsc::channel();
    let mut reports: Vec<Option<FileReport>> = (0..files.len()).map(|_| None).collect();
    std::thread::scope(|scope| {
        for _ in 0..threads {
            let send = send.clone();
            let (files, next) = (&files, &next);
            scope.spawn(move || {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(input) = files.get(k) else { break };
                    let _ = send.send((k, one(args, input)));
                }
            });
        }
        drop(send);
        for (k, report) in receive {
            for w in &report.warnings {
                progress.println(&format!("warning: {}: {w}", report.input));
            }
            if let Some(e) = &report.error {
                progress.println(&format!("error: {}: {e}", report.input));
            }
            if report.error.is_some() {
                progress.inc(1);
            } else {
                progress.done(report.input.clone());
            }
            reports[k] = Some(report);
        }
    });
    progress.finish();
    let files: Vec<FileReport> = reports.into_iter().flatten().collect();
    let failed = files.iter().filter(|f| f.error.is_some()).count();
    let mut stdout = Output::default();
    stdout.println(&summary(&files));
    stdout.println(&format!(
        "{} of {} files written into {} ({} failed), {:.1} s on {threads} thread{}",
        files.len() - failed,
        files.len(),
        out.display(),
        failed,
        start.elapsed().as_secs_f64(),
        if threads == 1 { "" } else { "s" }
    ));
    if let Some(path) = &args.report {
        let report = FolderReport {
            input: dir.display().to_string(),
            output: out.display().to_string(),
            pixel_error: args.pixel_error,
            threads,
            seconds: start.elapsed().as_secs_f64(),
            failed,
            files,
        };
        let text = serde_json::to_string_pretty(&report).expect("a report is JSON");
        if let Err(e) = std::fs::write(path, text) {
            output::eprintln(&format!("error: cannot write `{}`: {e}", path.display()));
            return stdout.finish(ExitCode::from(2));
        }
    }
    stdout.finish(ExitCode::from(u8::from(failed > 0)))
}

/// Converts one file of the folder into the same relative path below the output folder.
fn one(args: &LodArgs, input: &Path) -> FileReport {
    let start = Instant::now();
    let relative = input.strip_prefix(&args.input).unwrap_or(input);
    let output = args.output.join(relative);
    let file_args = LodArgs {
        input: input.to_path_buf(),
        output: output.clone(),
        report: None,
        grouping: args.grouping.clone(),
        ..*args
    };
    let mut warnings = Vec::new();
    let made = output
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .map_err(|e| (2, format!("cannot create `{}`: {e}", output.display())))
        .and_then(|()| convert(&file_args, &mut |w| warnings.push(w)));
    let (meshes, error, exit_code) = match made {
        Ok(meshes) => (meshes, None, 0),
        Err((code, e)) => (Vec::new(), Some(e), code),
    };
    let count = |first: bool| -> usize {
        meshes
            .iter()
            .filter_map(|m| {
                if first {
                    m.levels.first()
                } else {
                    m.levels.last()
                }
            })
            .map(|l| l.triangles)
            .sum()
    };
    FileReport {
        input: input.display().to_string(),
        output: output.display().to_string(),
        error,
        exit_code,
        seconds: start.elapsed().as_secs_f64(),
        triangles: count(true),
        last_level_triangles: count(false),
        warnings,
        meshes,
    }
}

/// The summary table: a row per file.
fn summary(files: &[FileReport]) -> String {
    let mut text = format!(
        "{:<48} {:>7} {:>6} {:>10} {:>10} {:>8}\n",
        "file", "status", "meshes", "triangles", "last level", "seconds"
    );
    for f in files {
        let name = Path::new(&f.input)
            .file_name()
            .map_or(f.input.clone(), |n| n.to_string_lossy().into_owned());
        let status = if f.error.is_some() { "failed" } else { "ok" };
        text.push_str(&format!(
            "{name:<48} {status:>7} {:>6} {:>10} {:>10} {:>8.2}\n",
            f.meshes.len(),
            f.triangles,
            f.last_level_triangles,
            f.seconds
        ));
    }
    text.pop();
    text
}
