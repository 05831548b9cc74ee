#!/usr/bin/env bash
# `lodkit lod` against gltfpack on one large mesh, side by side in one run on this machine: the
# rock of `cli/examples/rock.rs` (1,310,720 triangles by default), `lodkit lod --levels 4` (three
# simplified levels, each with its bound) against one `gltfpack -si 0.5` pass (one
# simplification to half, gltfpack's defaults otherwise), each run ROUNDS times (3 by default),
# the wall time and peak resident memory of every run printed and the medians summed up.
#
#   bash scripts/lod-bench.sh OUT [--subdivisions N] [--rounds ROUNDS]
#
# Needs node and npm (it installs gltfpack 1.3.0 into OUT/tools), GNU time (/usr/bin/time) and
# builds lodkit-cli in release.
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "$1")
shift
subdivisions=8
rounds=3
while [ $# -gt 0 ]; do
  case "$1" in
    --subdivisions) subdivisions=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
mkdir -p "$out/tools"
npm install --silent --prefix "$out/tools" gltfpack@1.3.0 >/dev/null
cargo build --quiet --release -p lodkit-cli --bin lodkit --example rock
lodkit=$PWD/target/release/lodkit
gltfpack=$out/tools/node_modules/.bin/gltfpack
rock=$out/rock.glb
target/release/examples/rock "$rock" --subdivisions "$subdivisions"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs)"
echo "lodkit: $("$lodkit" --version | head -n 1); gltfpack: $("$gltfpack" -v 2>&1 | head -n 1)"

# One timed run: prints "seconds peak-MiB".
timed() {
  /usr/bin/time -f '%e %M' -o "$out/time.txt" "$@" >"$out/run.log" 2>&1 ||
    { cat "$out/run.log" >&2; exit 1; }
  awk '{ printf "%.2f %.0f\n", $1, $2 / 1024 }' "$out/time.txt"
}
median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

: >"$out/lodkit.txt"
: >"$out/gltfpack.txt"
for round in $(seq 1 "$rounds"); do
  # Alternated, so that neither runs only on a warm or a cold machine.
  l=$(timed "$lodkit" lod "$rock" -o "$out/rock_lod.glb" --levels 4)
  cp "$out/run.log" "$out/lodkit.log"
  g=$(timed "$gltfpack" -i "$rock" -o "$out/rock_half.glb" -si 0.5)
  echo "round $round: lodkit lod --levels 4: $l (s, MiB); gltfpack -si 0.5: $g"
  echo "$l" >>"$out/lodkit.txt"
  echo "$g" >>"$out/gltfpack.txt"
done
lt=$(cut -d' ' -f1 "$out/lodkit.txt" | median)
lm=$(cut -d' ' -f2 "$out/lodkit.txt" | median)
gt=$(cut -d' ' -f1 "$out/gltfpack.txt" | median)
gm=$(cut -d' ' -f2 "$out/gltfpack.txt" | median)
echo "median of $rounds: lodkit lod --levels 4 ${lt} s, ${lm} MiB peak; gltfpack -si 0.5 ${gt} s, ${gm} MiB peak; ratio $(awk -v a="$lt" -v b="$gt" 'BEGIN { printf "%.2f", a / b }')"
echo "lodkit's levels (last run):"
grep -E '^\s*(level|[0-9])' "$out/lodkit.log" || cat "$out/lodkit.log"
