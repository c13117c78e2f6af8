#!/usr/bin/env bash
# Regenerates papers/aristotelian-rainbow: data/*.csv and figures/*.png.
#
#   papers/aristotelian-rainbow/make.sh [OUTDIR]      (default: this folder)
#
# Needs a release build of heron (target/release/heron, or HERON_BIN) and the project's
# .venv (scripts/setup.sh; or HERON_PYTHON). Same heron and .venv => same bytes.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
out="${1:-$here}"
heron="${HERON_BIN:-$repo/target/release/heron}"
py="${HERON_PYTHON:-$repo/.venv/bin/python}"
[ -x "$heron" ] || { echo "error: no heron binary at $heron (cargo build --release, or set HERON_BIN)" >&2; exit 1; }
[ -x "$py" ] || { echo "error: no Python at $py (scripts/setup.sh, or set HERON_PYTHON)" >&2; exit 1; }
export PYTHONDONTWRITEBYTECODE=1

mkdir -p "$out/data" "$out/figures"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# The seed's bow (heron sky profile --model aristotle, background 0): radiance against
# the angle θ from the antisolar point at a few wavelengths, for a point-like sun
# (0.001°) and for the real solar disk (0.2666°). The bow spans 42° ± the sun's radius.
lams="400,450,500,550,600,650,700"
"$heron" sky profile --model aristotle --sun-radius 0.001 --lambda "$lams" \
    --from 41.9985 --to 42.0015 --step 0.00001 > "$out/data/profiles_point_sun.csv"
"$heron" sky profile --model aristotle --sun-radius 0.2666 --lambda "$lams" \
    --from 41.6 --to 42.4 --step 0.002 > "$out/data/profiles_solar_disk.csv"

# The same on the texture's 5 nm grid (360–830 nm) for the colour strips; only their
# colours (data/colour_strip_*.csv) are kept.
grid="$(seq -s, 360 5 830)"
"$heron" sky profile --model aristotle --sun-radius 0.001 --lambda "$grid" \
    --from 41.9985 --to 42.0015 --step 0.00001 > "$work/spectral_point_sun.csv"
"$heron" sky profile --model aristotle --sun-radius 0.2666 --lambda "$grid" \
    --from 41.6 --to 42.4 --step 0.002 > "$work/spectral_solar_disk.csv"

"$py" "$here/make_figures.py" --heron "$heron" --texture "$repo/spectra/aristotle_bow.csv" --out "$out" --work "$work"
