#!/usr/bin/env bash
# One command for a real GPU: the figures that need one, on GPU timestamps where the device has
# them (`lodkit gpu-report`: pass ratios at 1920x1080 and 3840x2160, the framebuffer-LOD frame
# cost sweep, GPU selection from 10^4 to 10^7 instances), then the GPU test binaries on Vulkan
# and on GL, each binary's result and wall time added to the Markdown. About 2-3 minutes on a
# GPU; writes gpu-report.json, gpu-report.md and one log per test run into --out.
#
#   bash scripts/gpu-report.sh [--quick] [--out DIR] [--lodkit BIN] [--tests "BIN..."] [--no-tests]
#
#   --quick      small sizes and counts (a check of the command on a software GPU)
#   --lodkit     a `lodkit` binary built elsewhere (default: cargo build --release -p lodkit-cli)
#   --tests      GPU test binaries built elsewhere (default: cargo test --release --no-run
#                --test integration --test gl_threads); carry them to a machine without cargo
#   --no-tests   the figures only
#   --backends   the backends the tests run on (default "vulkan gl")
#
# Exit status: that of `lodkit gpu-report`, or 1 when a test binary failed.
set -euo pipefail
cd "$(dirname "$0")/.."

quick=""
out="lodkit-gpu-report"
lodkit=""
tests=""
run_tests=1
backends="vulkan gl"
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick="--quick" ;;
    --out) out="$2"; shift ;;
    --lodkit) lodkit="$2"; shift ;;
    --tests) tests="$2"; shift ;;
    --no-tests) run_tests=0 ;;
    --backends) backends="$2"; shift ;;
    *) echo "usage: $0 [--quick] [--out DIR] [--lodkit BIN] [--tests \"BIN...\"] [--no-tests] [--backends \"vulkan gl\"]" >&2; exit 2 ;;
  esac
  shift
done

export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/lodkit-xdg-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 0700 "$XDG_RUNTIME_DIR"
mkdir -p "$out"

if [ -z "$lodkit" ]; then
  cargo build --release -q -p lodkit-cli
  lodkit="$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release/lodkit"
fi
if [ "$run_tests" -eq 1 ] && [ -z "$tests" ]; then
  tests=$(cargo test --release --no-run --message-format=json --test integration --test gl_threads 2>/dev/null |
    python3 -c 'import json,sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable"):
        print(m["executable"])')
fi

status=0
"$lodkit" gpu-report --out "$out" $quick || status=$?
[ "$status" -eq 0 ] || { echo "error: lodkit gpu-report failed ($status)" >&2; exit "$status"; }

if [ "$run_tests" -eq 1 ]; then
  {
    echo
    echo "## GPU test binaries"
    echo
    echo "| backend | binary | result | wall time |"
    echo "| --- | --- | --- | --- |"
  } >> "$out/gpu-report.md"
  for backend in $backends; do
    for bin in $tests; do
      name=$(basename "$bin" | sed 's/-[0-9a-f]*$//')
      log="$out/tests-$backend-$name.log"
      threads=""
      [ "$backend" = gl ] && threads="--test-threads 1"
      start=$(date +%s)
      rc=0
      LODKIT_BACKEND="$backend" LODKIT_REQUIRE_GPU=1 "$bin" $threads >"$log" 2>&1 || rc=$?
      seconds=$(( $(date +%s) - start ))
      result=$(grep -E '^test result:' "$log" | tail -1 | sed 's/^test result: //; s/; finished in.*//')
      [ -n "$result" ] || result="did not finish (exit $rc): see $(basename "$log")"
      adapter=$(grep -m1 -E '^lodkit GPU tests run on: ' "$log" | sed 's/^lodkit GPU tests run on: //' || true)
      echo "| $backend${adapter:+ ($adapter)} | $name | $result | ${seconds} s |" >> "$out/gpu-report.md"
      echo "$backend $name: $result (${seconds} s)"
      [ "$rc" -eq 0 ] || status=1
    done
  done
fi
echo "wrote $out/gpu-report.md and $out/gpu-report.json"
exit "$status"
