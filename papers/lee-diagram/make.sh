#!/usr/bin/env bash
# Regenerates papers/lee-diagram: data/*.csv and figures/*.png.
#
#   papers/lee-diagram/make.sh [OUTDIR]      (default: this folder)
#
# Needs a release build of heron (target/release/heron, or HERON_BIN) and the project's
# .venv (scripts/setup.sh; or HERON_PYTHON). Same heron and .venv => same bytes.
set -euo pipefail
export PYTHONDONTWRITEBYTECODE=1
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
out="${1:-$here}"
heron="${HERON_BIN:-$repo/target/release/heron}"
py="${HERON_PYTHON:-$repo/.venv/bin/python}"
[ -x "$heron" ] || { echo "error: no heron binary at $heron (cargo build --release, or set HERON_BIN)" >&2; exit 1; }
[ -x "$py" ] || { echo "error: no Python at $py (scripts/setup.sh, or set HERON_PYTHON)" >&2; exit 1; }

mkdir -p "$out/data" "$out/figures"

# The Lee diagram of the primary bow straight from heron (Lorenz–Mie for every radius,
# D65 sun averaged over its 0.2666° disk, CIE 1931 2°, λ every 10 nm over 380–780 nm):
# 24 radii log-spaced from 10 µm to 1 mm, θ from the antisolar point 36°–44° every 0.05°.
"$heron" sky lee --radius-from 0.01 --radius-to 1 --radii 24 \
    --from 36 --to 44 --step 0.05 --lambda-step 10 -o "$out/data/lee_primary.csv"

"$py" "$here/make_figures.py" --out "$out"
