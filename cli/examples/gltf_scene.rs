//! Writes the glTF scene lodkit_bevy's `gltf_scene` example loads, before `lodkit lod` gives it
//! levels (`lodkit_cli::demo::fixtures::gltf_scene`), into DIR, and prints the arguments of the
//! `lodkit lod` run that makes the committed file of it (`scripts/gltf-scene.sh` runs both).
//!
//! ```text
//! cargo run -p lodkit-cli --example gltf_scene -- DIR
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use lodkit_cli::demo::fixtures::gltf_scene::{ASSET, lod_args, write};

fn main() -> ExitCode {
    let Some(dir) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: gltf_scene DIR");
        return ExitCode::from(2);
    };
    match write(&dir) {
        Ok(source) => {
            let mut args = vec![source.display().to_string()];
            args.extend(lod_args(std::path::Path::new(ASSET)));
            println!("{}", args.join(" "));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}: {e}", dir.display());
            ExitCode::from(2)
        }
    }
}
