#!/usr/bin/env bash
# Instructions per ray of `heron bench traversal --raw`, heron's pass against the raw C
# program's on the identical rays, counted by callgrind (which, unlike a clock, does not
# drift with the machine's load): for each width, one callgrind run of both processes,
# collecting only inside heron's `HeronTracer::trace` and the C program's `trace1`,
# `trace4`, `trace8`, `trace16` and `trace_stream`, one dump per pass.
#
#   scripts/callgrind_traversal.sh [HERON_BINARY] [MESH_N] [W,H]
#
# defaults: target/release/heron, the ~1M-triangle mesh (n = 708), 256,256 camera rays.
# Prints one line per (ray set, width), in instructions per ray: Embree's own (inside
# rtcIntersect*, the same on both sides), heron's and the raw program's outside Embree
# (building the rays, the query call, reading the hits, the loop), their difference
# (what heron's wrapper adds), and the whole pass's raw ÷ heron.
# Valgrind emulates no AVX-512, so Embree runs its AVX2 kernels here, on both sides alike.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/heron}
n=${2:-708}
size=${3:-256,256}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" bench mesh -o "$tmp/mesh.obj" --n "$n"
printf 'rays\twidth\tcount\tembree\theron_outside\traw_outside\theron_minus_raw\traw_over_heron\n'
for w in 1 4 8 16 stream; do
  rm -f "$tmp"/cg.*
  fn=trace$w
  [ "$w" = stream ] && fn=trace_stream
  valgrind --tool=callgrind --trace-children=yes \
    --trace-children-skip='*/gcc,*/cc1,*/as,*/ld,*/collect2,*/lto-wrapper' \
    --callgrind-out-file="$tmp/cg.%p" --collect-atstart=no \
    --toggle-collect='heron::bench::HeronTracer::trace' --toggle-collect="$fn" \
    --dump-after='heron::bench::HeronTracer::trace' --dump-after="$fn" \
    "$bin" bench traversal --mesh "$tmp/mesh.obj" --eye 0,0.3,3 --look-at 0,0,0 --fov 45 \
    --size "$size" --rounds 1 --widths "$w" --raw >"$tmp/out.csv" 2>"$tmp/log" || {
    cat "$tmp/log" >&2
    exit 1
  }
  # Each process wrote cg.PID.1 … one per pass: set 0 warm-up, set 0 timed, set 1
  # warm-up, set 1 timed (fewer where the query does not exist). The timed passes count.
  heron_pid=$(grep -l 'bench traversal' "$tmp"/cg.*.1 | head -n 1 | sed 's/.*cg\.\([0-9]*\)\.1/\1/')
  raw_pid=$(grep -l 'embree_raw' "$tmp"/cg.*.1 | head -n 1 | sed 's/.*cg\.\([0-9]*\)\.1/\1/')
  ir() { [ -f "$1" ] && grep -E '^(summary|totals):' "$1" | head -n 1 | awk '{print $2}' || echo -; }
  # Inclusive count of Embree's query entry points (rtcIntersect1/4/8/16/1M).
  in_embree() {
    callgrind_annotate --inclusive=yes "$1" 2>/dev/null |
      awk '/\?\?\?:rtc(Intersect|Occluded)[0-9M]* \[/ {gsub(",", "", $1); s += $1} END {print s + 0}'
  }
  for set in 0 1; do
    name=$([ $set = 0 ] && echo coherent || echo incoherent)
    count=$(awk -F, -v s="$name" '$1 == s {print $3}' "$tmp/out.csv")
    traced=$(awk -F, -v s="$name" '$1 == s {print $5}' "$tmp/out.csv")
    h=$(ir "$tmp/cg.$heron_pid.$((2 * set + 2))")
    r=$(ir "$tmp/cg.$raw_pid.$((2 * set + 2))")
    # "-": no such query in this Embree (the stream API on Embree 4).
    if [ "$traced" = - ] || [ "$h" = - ] || [ "$r" = - ]; then
      printf '%s\t%s\t%s\t-\t-\t-\t-\t-\n' "$name" "$w" "$count"
    else
      eh=$(in_embree "$tmp/cg.$heron_pid.$((2 * set + 2))")
      er=$(in_embree "$tmp/cg.$raw_pid.$((2 * set + 2))")
      awk -v s="$name" -v w="$w" -v c="$count" -v h="$h" -v r="$r" -v eh="$eh" -v er="$er" \
        'BEGIN {printf "%s\t%s\t%s\t%.1f\t%.1f\t%.1f\t%.1f\t%.4f\n", s, w, c, er/c, (h-eh)/c, (r-er)/c, (h-eh-r+er)/c, r/h}'
    fi
  done
done
