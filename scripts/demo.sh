#!/usr/bin/env bash
# The README's main command: builds the `lodkit` command, makes sure a GPU adapter is there
# (a real GPU is used when present; otherwise the software GPU is installed with apt), then
# runs `lodkit demo` with the arguments given (e.g. --out DIR --size 640x360).
set -euo pipefail
cd "$(dirname "$0")/.."

# A private runtime dir keeps the Vulkan loader quiet on machines without a session.
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/lodkit-xdg-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 0700 "$XDG_RUNTIME_DIR"

lodkit() { cargo run --quiet --release -p lodkit-cli -- "$@"; }

cargo build --release -p lodkit-cli
if ! lodkit adapter; then
  echo "no GPU adapter: installing the software GPU (lavapipe)"
  bash scripts/install-deps.sh
  lodkit adapter
fi
lodkit demo "$@"
