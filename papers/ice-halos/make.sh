#!/usr/bin/env bash
# Regenerates papers/ice-halos: data/*.csv and figures/*.png.
#
#   papers/ice-halos/make.sh [OUTDIR]      (default: this folder)
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

# The 22° and 46° halos of randomly oriented crystals (c/a = 1), sun 20° up, along seven
# great circles through the sun (ψ = 0°, 30°, …, 180°; random crystals make every ψ
# alike, so make_figures.py averages them: seven columns of table cells).
"$heron" halo profile --sun-elevation 20 --crystals random --lambda 450,550,650 \
    --psi 0,30,60,90,120,150,180 \
    --from 15 --to 55 --step 0.05 --rays 524288 > "$out/data/random_profile.csv"

# Sun dogs of plates (c/a = 0.3 for a low sun, 1 above 30°, where thin plates let the ray
# fall out of the bottom face; tilt σ = 0.2°) for suns 0°–60°: make_figures.py asks for
# the great circle through each elevation's predicted sun dog and finds the peak.
"$py" "$here/make_figures.py" --heron "$heron" --out "$out" --repo "$repo"
