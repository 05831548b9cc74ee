#!/usr/bin/env bash
# Checks Bevy 0.19.1's shader tree (the .wgsl files of its render crates) with `lodkit check`
# and the permutation file cli/tests/bevy/permutations-0.19.toml: every top-level shader (a
# file without `#define_import_path`) under the def sets Bevy's pipelines give it, against the
# tree's modules (-I). Bevy's shaders are not part of lodkit: they are read from cargo's
# registry, fetched there by a scratch manifest (network on the first run; `--offline` when the
# registry has them), and copied into a temporary folder removed on exit.
#   bash scripts/check-bevy-tree.sh [--lodkit PATH] [--offline] [-- LODKIT_CHECK_ARGS...]
# Prints lodkit's report and its closing line (sets checked, distinct modules validated,
# failures, time); exits with lodkit check's code. docs/check.md says how to read it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
lodkit=lodkit
offline=()
while [ $# -gt 0 ]; do
  case $1 in
    --lodkit) lodkit=$2; shift 2 ;;
    --offline) offline=(--offline); shift ;;
    --) shift; break ;;
    *) echo "usage: check-bevy-tree.sh [--lodkit PATH] [--offline] [-- LODKIT_CHECK_ARGS...]" >&2; exit 2 ;;
  esac
done
# The check runs from a scratch folder: a relative path to lodkit is taken from here.
case $lodkit in
  */*) lodkit=$(cd "$(dirname "$lodkit")" && pwd)/$(basename "$lodkit") ;;
esac
crates=(bevy_pbr bevy_core_pipeline bevy_render bevy_sprite_render bevy_ui_render
  bevy_gizmos_render bevy_anti_alias bevy_post_process)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/fetch/src" "$work/tree"
echo 'fn main() {}' >"$work/fetch/src/main.rs"
{
  printf '[package]\nname = "bevy-shader-tree"\nversion = "0.0.0"\nedition = "2021"\npublish = false\n\n[dependencies]\n'
  for c in "${crates[@]}"; do printf '%s = "=0.19.1"\n' "$c"; done
} >"$work/fetch/Cargo.toml"
cargo fetch "${offline[@]}" --quiet --manifest-path "$work/fetch/Cargo.toml"
# Each crate's folder in the registry, from cargo's own metadata.
cargo metadata "${offline[@]}" --format-version 1 --manifest-path "$work/fetch/Cargo.toml" |
  python3 -c '
import json, os, sys
wanted = set(sys.argv[1:])
for p in json.load(sys.stdin)["packages"]:
    if p["name"] in wanted and p["version"] == "0.19.1":
        print(p["name"], os.path.dirname(p["manifest_path"]))
' "${crates[@]}" >"$work/crates.txt"
[ "$(wc -l <"$work/crates.txt")" -eq "${#crates[@]}" ] || {
  echo "error: cargo found $(wc -l <"$work/crates.txt") of the ${#crates[@]} crates at 0.19.1" >&2
  exit 2
}
while read -r name dir; do
  (cd "$dir/src" && find . -name '*.wgsl' -print0 | while IFS= read -r -d '' f; do
    mkdir -p "$work/tree/$name/$(dirname "$f")"
    cp "$f" "$work/tree/$name/$f"
  done)
done <"$work/crates.txt"
# Bevy fills in the storage format of its mip-generation shader by text before composing it
# (`##TEXTURE_FORMAT##`, once per format; rgba16float is the HDR view's).
sed -i 's/##TEXTURE_FORMAT##/rgba16float/g' "$work/tree/bevy_core_pipeline/mip_generation/downsample.wgsl"
cp "$root/cli/tests/bevy/permutations-0.19.toml" "$work/tree/permutations.toml"
cd "$work/tree"
# Top-level shaders: files without `#define_import_path`. Those of bevy_pbr/meshlet belong to
# Bevy's `meshlet` feature (off by default; it swaps in meshlet/visibility_buffer_resolve.wgsl
# for the dummy module and needs push constants): the default build is checked.
mapfile -t shaders < <(grep -rL --include='*.wgsl' '^[[:space:]]*#define_import_path' . |
  sed 's|^\./||' | grep -v '^bevy_pbr/meshlet/' | sort)
echo "Bevy 0.19.1: $(find . -name '*.wgsl' | wc -l) .wgsl files, ${#shaders[@]} top-level shaders" >&2
# Bevy's global defs: the pipeline cache's storage-buffer limit (wgpu's default limit, 8), the
# mesh view types' light counts (bevy_pbr's native constants), the material bind group
# (MATERIAL_BIND_GROUP_INDEX, 3) and the tonemapping LUT's binding indices in bevy_pbr's mesh
# view (18, 19; the 2D pipelines set their own, which bind fewer resources). A native engine's
# capabilities: Bevy asks for what the device has (push constants, dual-source blending, ...).
"$lodkit" check --permutations permutations.toml -I . --exclude meshlet/visibility_buffer_resolve.wgsl \
  --capabilities all \
  -D AVAILABLE_STORAGE_BUFFER_BINDINGS=8u -D MAX_DIRECTIONAL_LIGHTS=10u \
  -D MAX_CASCADES_PER_LIGHT=4u -D MAX_RECT_LIGHTS=8u \
  -D TONEMAPPING_LUT_TEXTURE_BINDING_INDEX=18u -D TONEMAPPING_LUT_SAMPLER_BINDING_INDEX=19u \
  -D MATERIAL_BIND_GROUP=3u \
  "$@" "${shaders[@]}"
