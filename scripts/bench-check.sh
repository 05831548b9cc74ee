#!/usr/bin/env bash
# Whole-process time of `lodkit check FILE` against naga-cli's `naga FILE` on the same shader:
# median wall and CPU (user + system) time of RUNS runs each, interleaved. A lodkit pass that
# imports lodkit's modules is composed first (`lodkit export --to wgsl`) so that naga reads the
# same shader. With --wesl each naga_oil WGSL file is first converted to WESL
# (`lodkit export --to wesl`, as a Bevy 0.20 project would hold it) and the WESL file is checked.
# docs/check.md keeps the figures.
#   bash scripts/bench-check.sh [--runs N] [--lodkit PATH] [--wesl] FILE...
# Needs python3 and naga-cli 30 (`cargo install naga-cli --version 30.0.1`).
set -euo pipefail
runs=15
lodkit=lodkit
wesl=0
while [ $# -gt 0 ]; do
  case $1 in
    --runs) runs=$2; shift 2 ;;
    --lodkit) lodkit=$2; shift 2 ;;
    --wesl) wesl=1; shift ;;
    *) break ;;
  esac
done
[ $# -gt 0 ] || { echo "usage: bench-check.sh [--runs N] [--lodkit PATH] [--wesl] FILE..." >&2; exit 2; }
command -v naga >/dev/null || { echo "error: naga-cli is not on PATH" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for file in "$@"; do
  if [ "$wesl" = 1 ]; then
    converted="$work/$(basename "${file%.*}").wesl"
    "$lodkit" export --to wesl "$file" -o "$converted" 2>/dev/null
    file=$converted
  fi
  # naga reads the composed shader as WGSL whatever the source's dialect (.wesl, GLSL).
  composed="$work/$(basename "${file%.*}").wgsl"
  "$lodkit" export --to wgsl "$file" -o "$composed" 2>/dev/null
  python3 - "$runs" "$lodkit" "$file" "$composed" <<'PY'
import os, resource, statistics, subprocess, sys, time
runs, lodkit, file, composed = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
def once(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu
tools = {"lodkit check": [lodkit, "check", file], "naga": ["naga", composed]}
got = {k: [] for k in tools}
for _ in range(runs):
    for name, cmd in tools.items():
        got[name].append(once(cmd))
med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v)) for k, v in got.items()}
l, n = med["lodkit check"], med["naga"]
print(f"{file}: median of {runs} runs: lodkit check {l[0]*1e3:.1f} ms wall, {l[1]*1e3:.1f} ms CPU; "
      f"naga {n[0]*1e3:.1f} ms wall, {n[1]*1e3:.1f} ms CPU; ratio {l[0]/n[0]:.2f}x wall, {l[1]/max(n[1],1e-9):.2f}x CPU")
PY
done
