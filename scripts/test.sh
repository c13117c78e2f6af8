#!/usr/bin/env bash
# Runs every heron test: Rust (unit, integration, physics; in release mode because the
# statistical tests are heavy) and Python (colour-science and OpenEXR checks of heron's
# output). Installs what is missing first.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh --deps

cargo build --release --locked
cargo test --release --locked

# pytest exits 5 when it collects nothing; any non-zero exit fails this script.
HERON_BIN="$PWD/target/release/heron" .venv/bin/python -m pytest tests/python -q
