#!/usr/bin/env bash
# Does a change leave every image as it was? Renders every scene in scenes/ under every
# integrator (whitted, path, lighttrace, bdpt, sppm) and in the variants that run other
# code (--variance, spectral bins, polarised transport, shards merged by heron merge)
# with the binary built from BASE (a commit; default HEAD~1) and with the working
# tree's, and compares the EXR bytes (and, for a render that fails, the message).
# QUICK=1 renders the integrators only.
#
#   scripts/same_images.sh [BASE] [SPP]     (SPP default 4; 2 spp with --lanes 8 reaches
#                                            every kernel branch the scene uses)
#
# NEW_ARGS (environment) adds flags to the working tree's renders only, e.g.
# NEW_ARGS="--packets camera" to compare a new default's alternative with the old default.
#
# BASE is built in a git worktree under target/same-images/ (its own target directory,
# kept between runs), and its binary and renders are kept by commit, so a second run against the
# same BASE only renders the working tree's side. Prints one line per (scene, integrator)
# and exits 1 if any differs. Meant for refactors: "a refactor changes no image".
#
# Every EXR records the commit heron was built from (heron.commit), so both sides are
# built with HERON_BUILD_COMMIT=same-images (build.rs), the working tree's in
# target/same-images/target-worktree, not in target/release. (A BASE older than that attribute
# differs in its header.)
set -euo pipefail
cd "$(dirname "$0")/.."
base=$(git rev-parse "${1:-HEAD~1}")
spp=${2:-4}
root=$PWD/target/same-images
mkdir -p "$root"

build() { # $1: source dir, $2: target dir
  (cd "$1" && HERON_BUILD_COMMIT=same-images CARGO_TARGET_DIR="$2" \
    cargo build --release --locked --quiet --bin heron)
}

render_one() { # $1: heron binary, $2: output path without .exr, $3...: scene and flags
  local bin=$1 out=$2
  shift 2
  if "$bin" render "$@" -o "$out.exr" --spp "$spp" --no-png --quiet --threads 2 >"$out.log" 2>&1; then
    :
  else
    echo "exit $?" >>"$out.log"
  fi
}

# A sharded render: shards 0/2 and 1/2 as film files, then heron merge (the film files
# themselves may change format; the merged image must not).
render_sharded() { # $1: heron binary, $2: output path without .exr, $3...: scene and flags
  local bin=$1 out=$2
  shift 2
  {
    for k in 0 1; do
      "$bin" render "$@" --shard "$k/2" -o "$out.part$k.heronfilm" --spp "$spp" --no-png \
        --quiet --threads 2 || echo "exit $?"
    done
    "$bin" merge "$out.part0.heronfilm" "$out.part1.heronfilm" -o "$out.exr" --no-png ||
      echo "exit $?"
    rm -f "$out".part*.heronfilm
  } >"$out.log" 2>&1
}

# Every integrator, then the variants that run other code: the film's squares
# (--variance), spectral bins, polarised transport and sharded renders.
VARIANTS=(
  "var-bins path: --integrator path --variance --spectral-bins 4"
  "var-bins bdpt: --integrator bdpt --variance --spectral-bins 4"
  "var-bins lighttrace: --integrator lighttrace --variance --spectral-bins 4"
  "pol-bins path: --integrator path --polarization --spectral-bins 4"
  "pol-bins whitted: --integrator whitted --polarization --spectral-bins 4"
  "pol-bins lighttrace: --integrator lighttrace --polarization --spectral-bins 4"
  "pol-bins bdpt: --integrator bdpt --polarization --spectral-bins 4"
  "sppm-bins sppm: --integrator sppm --spectral-bins 4"
  "shard path: --integrator path --variance --spectral-bins 4 --shard"
  "shard bdpt: --integrator bdpt --variance --spectral-bins 4 --shard"
  "shard sppm: --integrator sppm --shard"
  "shard pol-lighttrace: --integrator lighttrace --polarization --spectral-bins 4 --shard"
)

render_all() { # $1: heron binary, $2: output dir, $3...: extra flags
  mkdir -p "$2"
  for scene in scenes/*.toml; do
    name=$(basename "$scene" .toml)
    jobs=()
    for integ in whitted path lighttrace bdpt sppm; do
      jobs+=("$integ: --integrator $integ")
    done
    if [ -z "${QUICK:-}" ]; then
      jobs+=("${VARIANTS[@]}")
    fi
    for job in "${jobs[@]}"; do
      label=${job%%:*}
      flags=${job#*: }
      out="$2/$name.${label// /.}"
      [ -e "$out.done" ] && continue
      # shellcheck disable=SC2086
      case "$flags" in
        *--shard) render_sharded "$1" "$out" "$scene" ${flags% --shard} ${3:-} ;;
        *) render_one "$1" "$out" "$scene" $flags ${3:-} ;;
      esac
      # Timing lines differ between runs, and paths between the two sides' folders; keep
      # only what the render said of its input.
      { grep -v -i -E 'seconds|[0-9.]+ ?s\b|/s\b|time' "$out.log" || true; } |
        sed "s#$2/##g" >"$out.msg"
      touch "$out.done"
    done
  done
}

base_dir="$root/renders-$base-spp$spp${QUICK:+-quick}"
if [ ! -e "$base_dir/complete" ]; then
  wt="$root/worktree"
  git worktree remove --force "$wt" 2>/dev/null || rm -rf "$wt"
  git worktree prune
  git worktree add --detach "$wt" "$base" >/dev/null
  # The binary is kept by commit too (target/same-images/heron-COMMIT).
  if [ ! -x "$root/heron-$base" ]; then
    build "$wt" "$root/target"
    cp "$root/target/release/heron" "$root/heron-$base"
  fi
  (cd "$wt" && render_all "$root/heron-$base" "$base_dir")
  git worktree remove --force "$wt"
  touch "$base_dir/complete"
fi

# Not the base's target dir: cargo keys a package's build by its path relative to the
# workspace, so the working tree's sources (older files than the base's fresh checkout)
# would look up to date there and the base's binary would be compared with itself.
build "$PWD" "$root/target-worktree"
cp "$root/target-worktree/release/heron" "$root/heron-worktree"
new_dir="$root/renders-worktree"
rm -rf "$new_dir"
render_all "$root/heron-worktree" "$new_dir" "${NEW_ARGS:-}"

differ=0
for f in "$base_dir"/*.msg; do
  key=$(basename "$f" .msg)
  a="$base_dir/$key.exr"
  b="$new_dir/$key.exr"
  if [ -e "$a" ] || [ -e "$b" ]; then
    if [ -e "$a" ] && [ -e "$b" ] && cmp -s "$a" "$b"; then
      echo "same   $key"
    else
      echo "DIFFER $key (EXR bytes)"
      differ=1
    fi
  elif cmp -s "$f" "$new_dir/$key.msg"; then
    echo "same   $key (no image: $(tail -n 2 "$f" | head -n 1 | cut -c1-100))"
  else
    echo "DIFFER $key (messages)"
    diff "$f" "$new_dir/$key.msg" | head -n 6 || true
    differ=1
  fi
done
exit $differ
