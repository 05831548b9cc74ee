#!/usr/bin/env bash
# Runs `lodkit lod` over every glTF / GLB file under MODELS (and, with gltfpack, over each file
# through `gltfpack` and `gltfpack -c`), validates every input and output with the Khronos glTF
# validator, and lists each file's errors with those its output adds (none expected).
#
#   bash scripts/lod-validate.sh MODELS OUT
#
# Needs node and npm (it installs gltf-validator 2.0.0-dev.3.10 and gltfpack 1.3.0 into
# OUT/tools) and a release build of lodkit-cli.
set -euo pipefail
cd "$(dirname "$0")/.."
models=$(realpath "$1")
out=$(realpath -m "$2")
mkdir -p "$out/tools" "$out/lod"
npm install --silent --prefix "$out/tools" gltf-validator@2.0.0-dev.3.10 gltfpack@1.3.0 >/dev/null
cargo build --quiet --release -p lodkit-cli
lodkit=$PWD/target/release/lodkit
gltfpack=$out/tools/node_modules/.bin/gltfpack
inputs=()
while IFS= read -r file; do
  name=$(basename "${file%.*}")
  inputs+=("$file")
  "$lodkit" lod "$file" -o "$out/lod/${name}_lod.glb" >"$out/lod/$name.log" 2>&1 ||
    echo "lodkit lod failed: $file: $(tail -n 1 "$out/lod/$name.log")"
  for variant in p c; do
    flag=(); [ "$variant" = c ] && flag=(-c)
    packed=$out/lod/${name}_$variant.glb
    "$gltfpack" "${flag[@]}" -i "$file" -o "$packed" >/dev/null 2>&1 || continue
    inputs+=("$packed")
    "$lodkit" lod "$packed" -o "$out/lod/${name}_${variant}_lod.glb" >"$out/lod/${name}_$variant.log" 2>&1 ||
      echo "lodkit lod failed: $packed: $(tail -n 1 "$out/lod/${name}_$variant.log")"
  done
done < <(find "$models" -name '*.glb' -o -name '*.gltf' | sort)
NODE_PATH=$out/tools/node_modules node scripts/gltf-validate.js "${inputs[@]}" "$out"/lod/*_lod.glb >"$out/validation.json"
python3 - "$out/validation.json" <<'PY'
import json, os, sys
report = json.load(open(sys.argv[1]))
outputs = {k[:-len("_lod.glb")]: v for k, v in report.items() if k.endswith("_lod.glb")}
added = 0
for path, found in sorted(report.items()):
    if path.endswith("_lod.glb"):
        continue
    stem = os.path.join(os.path.dirname(sys.argv[1]), "lod", os.path.basename(path).rsplit(".", 1)[0])
    out = outputs.get(stem)
    codes, out_codes = found.get("codes", {}), (out or {}).get("codes", {})
    new = {c: n for c, n in out_codes.items() if n > codes.get(c, 0)}
    added += sum(new.values())
    print(f"{os.path.basename(path):40} input {found.get('errors', found.get('failed'))} errors"
          f" {codes or ''}; output {'-' if out is None else out.get('errors', out.get('failed'))};"
          f" added {new or 'none'}")
print(f"errors the outputs add: {added}")
PY
