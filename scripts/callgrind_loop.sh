#!/usr/bin/env bash
# Instruction counts of the render loop (callgrind, collecting inside render_passes only),
# which do not drift with the machine's load: the default scene under whitted and the
# Cornell box under path, 4 spp on one thread. For refactors of the hot path: compare a
# binary before and after.
#
#   scripts/callgrind_loop.sh [HERON_BINARY...]     (default: target/release/heron)
#
# Prints one line per (binary, scene): the instruction count ("Ir").
set -euo pipefail
cd "$(dirname "$0")/.."
bins=("$@")
[ ${#bins[@]} -gt 0 ] || bins=(target/release/heron)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for bin in "${bins[@]}"; do
  for scene in default cornell-box; do
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --collect-atstart=no \
      --toggle-collect='*render_passes*' \
      "$bin" render "scenes/$scene.toml" -o "$tmp/cg.exr" --spp 4 --threads 1 --quiet --no-png \
      >/dev/null 2>"$tmp/log"
    ir=$(grep -E '^(summary|totals):' "$tmp/cg.out" | head -n 1 | awk '{print $2}')
    printf '%s\t%s\t%s\n' "$bin" "$scene" "$ir"
  done
done
