#!/usr/bin/env bash
# Runs every heron test: Rust (unit, integration, physics; in release mode because the
# statistical tests are heavy) and Python (colour-science and OpenEXR checks of heron's
# output). Installs what is missing first.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh --deps

cargo build --release --locked
cargo test --release --locked

# The Embree tests (the renderer's, the stability suite's, the raw-Embree benchmark's and
# the ray logs' too) again on Embree 4.4, the library of the pinned
# embreex wheel in .venv, linked by build.rs without headers (HERON_EMBREE4_LIB), in a
# target directory of its own so the Embree 3 build stays as it is.
embree4_lib="$(echo "$PWD"/.venv/lib/python3*/site-packages/embreex.libs)"
HERON_EMBREE4_LIB="$embree4_lib" CARGO_TARGET_DIR="$PWD/target/embree4" \
    cargo test --release --locked --test embree --test render --test stability --test bench_traversal \
    --test bench_limit --test packets

# pytest exits 5 when it collects nothing; any non-zero exit fails this script.
HERON_BIN="$PWD/target/release/heron" .venv/bin/python -m pytest tests/python -q --durations=15
