#!/usr/bin/env bash
# Cost of sharding: one heron render against the same render as N shards run one after
# another (each shard loads the scene, builds the BVH and writes its film file) plus
# heron merge, interleaved round by round so the machine's drift hits both alike.
# Checks that the merged EXR equals the single render's bytes every round.
#
#   scripts/bench_shards.sh [SCENE] [SPP] [N] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:-scenes/cornell-box.toml}"; spp="${2:-64}"; n="${3:-4}"; rounds="${4:-3}"
heron="${HERON_BIN:-target/release/heron}"
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
for r in $(seq 1 "$rounds"); do
  t0=$(now)
  "$heron" render "$scene" -o "$work/single.exr" --spp "$spp" --quiet --no-png 2>/dev/null
  t1=$(now)
  for k in $(seq 0 $((n - 1))); do
    "$heron" render "$scene" -o "$work/part-$k.heronfilm" --spp "$spp" --shard "$k/$n" --quiet 2>/dev/null
  done
  t2=$(now)
  "$heron" merge "$work"/part-*.heronfilm -o "$work/merged.exr" --no-png 2>/dev/null
  t3=$(now)
  cmp -s "$work/single.exr" "$work/merged.exr" || { echo "round $r: merged EXR differs" >&2; exit 1; }
  python3 -c "import sys; a,b,c,d=map(float,sys.argv[1:]); print(f'round $r: single {b-a:.2f} s, {$n} shards {c-b:.2f} s + merge {d-c:.2f} s = {(d-b)/(b-a):.3f}x')" "$t0" "$t1" "$t2" "$t3"
done
