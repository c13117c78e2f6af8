#!/usr/bin/env bash
# Does a change keep every image's expectation? For a change that may alter an image's
# bytes but not what it estimates (a sampling change, a faster kernel): renders every
# scene in scenes/ under every integrator with the binary built from BASE (seed 1) and
# with the working tree's (seed 2), each with --variance (sppm: without, it has none),
# and holds each pair to `heron compare`'s region z-test, the whole family at α = 0.01
# (Šidák over the pairs, then over each pair's tests). Prints one line per pair and
# exits 1 if any differs. A refusal must be the same message on both sides.
#
#   scripts/same_expectation.sh [BASE]        (default HEAD)
#
# Environment: SCENES="default metals" (names without .toml; default: every scene),
# INTEGRATORS="path bdpt" (default: whitted path lighttrace bdpt sppm), SPP (samples
# per pixel, default 64; sppm runs SPP iterations), REGION (default 32: a region of a
# full-size image covers what a region of 8 pixels covers at a quarter of the size).
# sppm's pairs use the spread of the differences within a region, which its pixels'
# shared photons make an underestimate, so they get `--tolerance 0.02` (both sides have
# the same radius bias). Binaries are built and kept as scripts/same_images.sh keeps them
# (target/same-images/heron-COMMIT, heron-worktree).
set -euo pipefail
cd "$(dirname "$0")/.."
base=$(git rev-parse "${1:-HEAD}")
spp=${SPP:-64}
region=${REGION:-32}
integrators=${INTEGRATORS:-whitted path lighttrace bdpt sppm}
root=$PWD/target/same-images
out=$root/expectation
mkdir -p "$out"

build() { # $1: source dir, $2: target dir
  (cd "$1" && HERON_BUILD_COMMIT=same-images CARGO_TARGET_DIR="$2" \
    cargo build --release --locked --quiet --bin heron)
}
if [ ! -x "$root/heron-$base" ]; then
  wt="$root/worktree"
  git worktree remove --force "$wt" 2>/dev/null || rm -rf "$wt"
  git worktree prune
  git worktree add --detach "$wt" "$base" >/dev/null
  build "$wt" "$root/target"
  cp "$root/target/release/heron" "$root/heron-$base"
  git worktree remove --force "$wt"
fi
build "$PWD" "$root/target-worktree"
cp "$root/target-worktree/release/heron" "$root/heron-worktree"

if [ -n "${SCENES:-}" ]; then
  scenes=$(for s in $SCENES; do echo "scenes/$s.toml"; done)
else
  scenes=$(ls scenes/*.toml)
fi

pairs=()
for scene in $scenes; do
  name=$(basename "$scene" .toml)
  for integ in $integrators; do
    var=--variance
    [ "$integ" = sppm ] && var=
    for side in base new; do
      bin=$root/heron-$base seed=1
      [ "$side" = new ] && bin=$root/heron-worktree seed=2
      # shellcheck disable=SC2086
      "$bin" render "$scene" --integrator "$integ" --spp "$spp" --seed "$seed" $var \
        -o "$out/$name.$integ.$side.exr" --no-png --quiet --threads 2 \
        >"$out/$name.$integ.$side.log" 2>&1 || echo "exit $?" >>"$out/$name.$integ.$side.log"
    done
    pairs+=("$name.$integ")
  done
done

n=${#pairs[@]}
alpha=$(python3 -c "print(1 - (1 - 0.01) ** (1 / $n))")
echo "$n pairs, each at family-wise level $alpha"
differ=0
for p in "${pairs[@]}"; do
  a=$out/$p.base.exr b=$out/$p.new.exr
  if [ -e "$a" ] && [ -e "$b" ]; then
    tol=0
    [ "${p##*.}" = sppm ] && tol=0.02
    if r=$("$root/heron-worktree" compare "$b" "$a" --region "$region" --alpha "$alpha" \
      --tolerance "$tol" --max-listed 3); then
      echo "same      $p ($(grep -o 'largest |z| [0-9.]*' <<<"$r"))"
    else
      echo "DIFFERENT $p"
      grep -E '^mean difference|^  ' <<<"$r" | head -n 5
      differ=1
    fi
  elif [ ! -e "$a" ] && [ ! -e "$b" ] &&
    cmp -s <(grep -i error "$out/$p.base.log") <(grep -i error "$out/$p.new.log"); then
    echo "same      $p (refused on both sides: $(grep -i -m1 error "$out/$p.new.log" | cut -c1-90))"
  else
    echo "DIFFERENT $p (one side failed)"
    tail -n 2 "$out/$p.base.log" "$out/$p.new.log"
    differ=1
  fi
done
exit $differ
