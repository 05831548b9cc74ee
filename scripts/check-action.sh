#!/usr/bin/env bash
# The step of lodkit's GitHub Action (action.yml at the repository root) that runs
# `lodkit check`. The action's inputs arrive as environment variables; lists are separated by
# spaces or newlines:
#   LODKIT_PATHS         shader files or globs (`**` matches folders at any depth); required
#   LODKIT_INCLUDE       folders of your own modules and GLSL headers (-I)
#   LODKIT_DEFS          shader defs, NAME or NAME=VALUE (-D)
#   LODKIT_BUDGET        a shader-cost budget, .ron or .toml (--budget)
#   LODKIT_CAPABILITIES  validator capabilities beyond WebGPU's (--capabilities)
#   LODKIT_PERMUTE       true: check the combinations of the defs each shader tests (--permute)
#   LODKIT_PERMUTATIONS  a permutation file, .toml or .ron (--permutations)
#   LODKIT_MAX_SETS      the most sets checked as every combination (--max-sets)
#   LODKIT_FORMAT        github (default), sarif, json or human (--format)
#   LODKIT_OUTPUT        a file to write the report into instead of the log
#   LODKIT_ARGS          further arguments for `lodkit check`
# It exits as `lodkit check` does: 0 all valid, 1 a shader invalid or over budget, 2 a file
# unreadable or a usage error (also: a glob that matches no file, no paths at all).
set -euo pipefail
shopt -s globstar nullglob

# Splits $2 on spaces and newlines into the array named $1 (no glob expansion).
words() {
  local -n into=$1
  into=()
  read -r -d '' -a into <<<"${2:-}" || true
}

words paths "${LODKIT_PATHS:-}"
words include "${LODKIT_INCLUDE:-}"
words defs "${LODKIT_DEFS:-}"
words extra "${LODKIT_ARGS:-}"

if [ "${#paths[@]}" -eq 0 ]; then
  echo "error: the action's \`paths\` input names no shader" >&2
  exit 2
fi

args=(check --format "${LODKIT_FORMAT:-github}")
for dir in "${include[@]}"; do args+=(-I "$dir"); done
for def in "${defs[@]}"; do args+=(-D "$def"); done
[ -n "${LODKIT_BUDGET:-}" ] && args+=(--budget "$LODKIT_BUDGET")
[ -n "${LODKIT_CAPABILITIES:-}" ] && args+=(--capabilities "$LODKIT_CAPABILITIES")
[ "${LODKIT_PERMUTE:-false}" = true ] && args+=(--permute)
[ -n "${LODKIT_PERMUTATIONS:-}" ] && args+=(--permutations "$LODKIT_PERMUTATIONS")
[ -n "${LODKIT_MAX_SETS:-}" ] && args+=(--max-sets "$LODKIT_MAX_SETS")
args+=("${extra[@]}")

files=()
for pattern in "${paths[@]}"; do
  case $pattern in
    *[*?[]*)
      # shellcheck disable=SC2206 # the glob is meant to expand here
      matched=($pattern)
      if [ "${#matched[@]}" -eq 0 ]; then
        echo "error: no file matches \`$pattern\` (from the action's \`paths\` input)" >&2
        exit 2
      fi
      files+=("${matched[@]}")
      ;;
    *) files+=("$pattern") ;; # a missing file is lodkit's to report (exit 2)
  esac
done

echo "lodkit ${args[*]} (${#files[@]} files)" >&2
status=0
if [ -n "${LODKIT_OUTPUT:-}" ]; then
  lodkit "${args[@]}" "${files[@]}" >"$LODKIT_OUTPUT" || status=$?
  echo "report written to $LODKIT_OUTPUT" >&2
else
  lodkit "${args[@]}" "${files[@]}" || status=$?
fi
exit "$status"
