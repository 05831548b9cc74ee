#!/usr/bin/env bash
# Writes lodkit_bevy/examples/assets/lod_scene.glb, the glTF scene lodkit_bevy's `gltf_scene`
# example loads: the scene's source (four objects, five materials) from
# `lodkit_cli::demo::fixtures::gltf_scene`, then `lodkit lod` on it, as an asset pipeline runs it;
# and impostor_scene.glb, the same with `--impostor` (the impostors baked on this machine's GPU).
# `cargo test -p lodkit-cli lod::` fails while the committed files are not what this writes
# (the impostor atlases' pixels aside: another GPU bakes other roundings).
set -euo pipefail
cd "$(dirname "$0")/.."
source_dir=$(mktemp -d)
trap 'rm -rf "$source_dir"' EXIT
mkdir -p lodkit_bevy/examples/assets
# shellcheck disable=SC2207 # the example prints space-free arguments
args=($(cargo run -q -p lodkit-cli --example gltf_scene -- "$source_dir"))
cargo run -q -p lodkit-cli -- lod "${args[@]}"
# shellcheck disable=SC2207
args=($(cargo run -q -p lodkit-cli --example gltf_scene -- "$source_dir" --impostor))
cargo run -q -p lodkit-cli -- lod "${args[@]}"
