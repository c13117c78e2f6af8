#!/usr/bin/env bash
# Does a change leave every image as it was? Renders every scene in scenes/ under every
# integrator with the binary built from BASE (a commit; default HEAD~1) and with the
# working tree's, and compares the EXR bytes (and, for a render that fails, the message).
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

render_all() { # $1: heron binary, $2: output dir, $3...: extra flags
  mkdir -p "$2"
  for scene in scenes/*.toml; do
    name=$(basename "$scene" .toml)
    for integ in whitted path lighttrace bdpt; do
      out="$2/$name.$integ"
      [ -e "$out.done" ] && continue
      # shellcheck disable=SC2086
      if "$1" render "$scene" -o "$out.exr" --spp "$spp" --integrator "$integ" \
        --no-png --quiet --threads 2 ${3:-} >"$out.log" 2>&1; then
        :
      else
        echo "exit $?" >>"$out.log"
      fi
      # Timing lines differ between runs; keep only what the render said of its input.
      grep -v -i -E 'seconds|[0-9.]+ ?s\b|/s\b|time' "$out.log" >"$out.msg" || true
      touch "$out.done"
    done
  done
}

base_dir="$root/renders-$base-spp$spp"
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
