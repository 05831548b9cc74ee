#!/usr/bin/env bash
# Makes a Python >= 3.12 virtual environment with wesl-py (wesl-rs 0.6, Bevy 0.20's linker) for
# the WESL tests, outside the clone, when such a Python is on the machine (python3.12/3.13 on
# PATH, or pyenv's). Prints the environment's python on stdout; prints nothing when there is no
# Python >= 3.12 (the tests then say SKIPPED for wesl-py).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
py=""
for cand in python3.13 python3.12 "$HOME"/.pyenv/versions/3.1[2-9]*/bin/python3 python3; do
  if command -v "$cand" >/dev/null 2>&1 &&
     "$cand" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 12) else 1)' 2>/dev/null; then
    py=$(command -v "$cand"); break
  fi
done
[ -n "$py" ] || exit 0
venv="${LODKIT_CACHE:-$HOME/.cache/lodkit}/wesl-py"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import wesl' 2>/dev/null; then
  "$py" -m venv "$venv" >&2
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt" >&2
fi
echo "$venv/bin/python"
