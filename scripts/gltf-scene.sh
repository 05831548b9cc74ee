#!/usr/bin/env bash
# Writes lodkit_bevy/examples/assets/lod_scene.glb, the glTF scene lodkit_bevy's `gltf_scene`
# example loads: the scene's source (four objects, five materials) from
# `lodkit_cli::demo::fixtures::gltf_scene`, then `lodkit lod` on it, as an asset pipeline runs it.
# `cargo test -p lodkit-cli lod::` fails while the committed file is not what this writes.
set -euo pipefail
cd "$(dirname "$0")/.."
source_dir=$(mktemp -d)
trap 'rm -rf "$source_dir"' EXIT
mkdir -p lodkit_bevy/examples/assets
# shellcheck disable=SC2207 # the example prints space-free arguments
args=($(cargo run -q -p lodkit-cli --example gltf_scene -- "$source_dir"))
cargo run -q -p lodkit-cli -- lod "${args[@]}"
