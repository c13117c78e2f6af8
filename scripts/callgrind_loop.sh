#!/usr/bin/env bash
# Instruction counts of the render loop, which do not drift with the machine's load: the
# default scene under whitted and the Cornell box under path, on one thread. For refactors
# of the hot path: compare a binary before and after. Callgrind toggles collection per
# thread: on the calling thread in the pass loop (render_passes: the tiles added to the
# film), on the worker in each tile (render_tile, never inlined; before the one tile
# engine, the pass loop's closure render_passes::{{closure}}, into which the tile loops
# were inlined). The patterns never nest in one binary, so an older binary counts what it
# counted before.
#
#   scripts/callgrind_loop.sh [HERON_BINARY...]     (default: target/release/heron)
#   SPP=64 SIZE=128 scripts/callgrind_loop.sh ...   (per-sample cost at a real sample count)
#   FLAGS="--packets paths" scripts/callgrind_loop.sh  (extra render flags)
#   SCENES="fogbow rain-curtain" scripts/callgrind_loop.sh  (other scenes of scenes/)
#
# SPP (default 4) is the samples per pixel; SIZE, if set, renders a SIZE×SIZE copy of each
# scene (the Sobol' sampler's per-pixel work is shared by a pixel's samples, so 4 spp
# overstates it; 64 spp at 128² costs the same instructions as 4 spp at 512²).
# Prints one line per (binary, scene): the instruction count ("Ir"), the instructions per
# sample and the sha256 of the EXR (equal bytes for an optimisation that keeps the image).
# The EXR records the commit heron was built from (heron.commit): to compare the sha256 of
# two commits' binaries, build both with the same HERON_BUILD_COMMIT (see build.rs).
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck disable=SC2086  # FLAGS is split into flags on purpose
bins=("$@")
[ ${#bins[@]} -gt 0 ] || bins=(target/release/heron)
spp=${SPP:-4}
tmp=$(mktemp -d)
# The scenes' copies sit beside them, so that the files they name (meshes) resolve.
trap 'rm -rf "$tmp" scenes/.callgrind-*.toml' EXIT
scenes=(${SCENES:-default cornell-box})
for scene in "${scenes[@]}"; do
  if [ -n "${SIZE:-}" ]; then
    sed -E "s/^resolution = \[[0-9]+, *[0-9]+\]/resolution = [$SIZE, $SIZE]/" \
      "scenes/$scene.toml" >"scenes/.callgrind-$scene.toml"
  else
    cp "scenes/$scene.toml" "scenes/.callgrind-$scene.toml"
  fi
done
for bin in "${bins[@]}"; do
  for scene in "${scenes[@]}"; do
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --collect-atstart=no \
      --toggle-collect='*render_passes*' --toggle-collect='*::render_tile' \
      "$bin" render "scenes/.callgrind-$scene.toml" -o "$tmp/cg.exr" --spp "$spp" --threads 1 --quiet \
      --no-png ${FLAGS:-} >"$tmp/out" 2>"$tmp/log"
    ir=$(grep -E '^(summary|totals):' "$tmp/cg.out" | head -n 1 | awk '{print $2}')
    px=$(cat "$tmp/out" "$tmp/log" | grep -oE ': [0-9]+x[0-9]+ at' | head -n 1 | grep -oE '[0-9]+x[0-9]+' || true)
    per=""
    if [ -n "$px" ]; then
      per=$(( ir / (${px%x*} * ${px#*x} * spp) ))
    fi
    sha=$(sha256sum "$tmp/cg.exr" | cut -c1-16)
    printf '%s\t%s\t%s\t%s\t%s\n' "$bin" "$scene" "$ir" "$per" "$sha"
  done
done
