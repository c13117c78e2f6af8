#!/usr/bin/env bash
# Regenerates papers/descartes-rainbow: data/*.csv and figures/*.png.
#
#   papers/descartes-rainbow/make.sh [OUTDIR]      (default: this folder)
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
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Profiles straight from heron (CSV: theta_deg,<λ>nm,…; unit dσ/dΩ/(πa²) per sr).
# Point-like sun (0.001°), one order at a time, fine steps: the peak of each column is
# the bow's angle at that wavelength (kept out of the repository: 1.4 MB).
lams_table="$(seq -s, 380 10 780)"
"$heron" sky profile --model descartes --k 1 --sun-radius 0.001 --lambda "$lams_table" \
    --from 40.0 --to 42.8 --step 0.001 > "$work/peak_k1.csv"
"$heron" sky profile --model descartes --k 2 --sun-radius 0.001 --lambda "$lams_table" \
    --from 49.8 --to 54.6 --step 0.001 > "$work/peak_k2.csv"

# Alexander's dark band: both orders, the real solar disk (0.2666°), 30°–60°.
lams_band="$(seq -s, 380 5 780)"
"$heron" sky profile --model descartes --k both --lambda "$lams_band" \
    --from 30 --to 60 --step 0.1 > "$out/data/dark_band_unpolarised.csv"
for pol in s p; do
    "$heron" sky profile --model descartes --k both --polarisation "$pol" --lambda 550 \
        --from 30 --to 60 --step 0.1 > "$out/data/dark_band_550nm_$pol.csv"
done
# With the external reflection (k = 0) as well: the band is no longer black.
"$heron" sky profile --model descartes --k all --lambda 450,550,650 \
    --from 30 --to 60 --step 0.1 > "$out/data/dark_band_k012.csv"

# Geometric (descartes) vs Airy vs Mie near the primary bow, real solar disk.
for a in 0.1 1; do
    "$heron" sky profile --model descartes --k 1 --lambda 450,550,650 \
        --from 38 --to 43.5 --step 0.01 > "$out/data/drop_a${a}mm_descartes.csv"
    "$heron" sky profile --model airy --k 1 --droplet-radius "$a" --lambda 450,550,650 \
        --from 38 --to 43.5 --step 0.01 > "$out/data/drop_a${a}mm_airy.csv"
    "$heron" sky profile --model mie --droplet-radius "$a" --lambda 450,550,650 \
        --from 38 --to 43.5 --step 0.01 > "$out/data/drop_a${a}mm_mie.csv"
done

# heron trace (the renderer's own refraction code) for n(λ), D(b) and the minimum
# deviation; then every table and figure.
"$py" "$here/make_figures.py" --heron "$heron" --out "$out" --work "$work"
