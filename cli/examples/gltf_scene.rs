//! Writes the glTF scene lodkit_bevy's `gltf_scene` example loads, before `lodkit lod` gives it
//! levels (`lodkit_cli::demo::fixtures::gltf_scene`), into DIR, and prints the arguments of the
//! `lodkit lod` run that makes the committed file of it; with `--impostor`, of the run that makes
//! the committed file with impostors (`scripts/gltf-scene.sh` runs all three).
//!
//! ```text
//! cargo run -p lodkit-cli --example gltf_scene -- DIR [--impostor]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use lodkit_cli::demo::fixtures::gltf_scene::{
    ASSET, IMPOSTOR_ASSET, impostor_lod_args, lod_args, write,
};

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let (Some(dir), flag) = (args.next().map(PathBuf::from), args.next()) else {
        eprintln!("usage: gltf_scene DIR [--impostor]");
        return ExitCode::from(2);
    };
    let impostor = match flag.as_ref().and_then(|f| f.to_str()) {
        None => false,
        Some("--impostor") if args.next().is_none() => true,
        _ => {
            eprintln!("usage: gltf_scene DIR [--impostor]");
            return ExitCode::from(2);
        }
    };
    match write(&dir) {
        Ok(source) => {
            let mut args = vec![source.display().to_string()];
            args.extend(match impostor {
                false => lod_args(Path::new(ASSET)),
                true => impostor_lod_args(Path::new(IMPOSTOR_ASSET)),
            });
            println!("{}", args.join(" "));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}: {e}", dir.display());
            ExitCode::from(2)
        }
    }
}
