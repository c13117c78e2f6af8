#!/usr/bin/env bash
# How far heron's renders are from raw Embree (BENCHMARKS.md "The traversal limit"):
# `heron bench limit` on the course's default scene with a black background under
# `whitted` (as scripts/bench_mitsuba.py compares it) and on the Cornell box under
# `path`: each records its render's Embree calls on one thread, then times the render
# (one thread) against the raw C program's replay of those calls and heron's own
# wrapper's replay, interleaved, ROUNDS timed rounds after a warm-up.
#
#   scripts/bench_limit.sh [HERON_BINARY] [SPP] [ROUNDS]     (defaults: target/release/heron, 16, 5)
#
# Prints each scene's report: the calls by kind, then `measure,median_s,min_s,max_s,over_raw`
# rows; heron_render's over_raw is the render's time as a multiple of raw Embree's.
# A log takes about 36 bytes per ray (~300 MB per scene at 16 spp), in a temporary file.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/heron}
spp=${2:-16}
rounds=${3:-5}
# Beside the original, so that relative paths in the scene still resolve.
black=scenes/.default-black-$$.toml
trap 'rm -f "$black"' EXIT
sed -E 's/^background[[:space:]]*=.*$/background = 0.0/' scenes/default.toml >"$black"
grep -q '^background = 0.0$' "$black"
"$bin" bench limit "$black" --integrator whitted --spp "$spp" --rounds "$rounds"
echo
"$bin" bench limit scenes/cornell-box.toml --integrator path --spp "$spp" --rounds "$rounds"
