#!/usr/bin/env bash
# Runs every heron test: Rust (unit, integration, physics; in release mode because the
# statistical tests are heavy) and Python (colour-science and OpenEXR checks of heron's
# output). Installs what is missing first.
set -euo pipefail
cd "$(dirname "$0")/.."

# Each phase's start time, UTC, so that a CI log shows where its minutes go.
phase() { echo "test.sh: $(date -u +%H:%M:%S) $*"; }

# A fresh clone's index holds "racily clean" entries (files written in the second the
# index was), which the first `git status` that may write rewrites. heron's build script
# watches the index (for the commit and dirty state it records), so that rewrite, made by
# whichever test ran git first, rebuilt heron in every later build (the tarball's and the
# wheels': about four minutes of CI). Settle it once, before anything is built (the
# set-up builds the Python module).
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git update-index -q --really-refresh >/dev/null 2>&1 || true
fi

phase "set-up"
scripts/setup.sh --deps

# No separate `cargo build --release` first: `cargo test --release` builds the binary the
# integration and Python tests run. Cargo.toml asks for the dependency features that the
# dev-dependencies turn on, so the two builds are one and the tarball's `cargo build
# --release` (tests/python/test_dist.py) finds it up to date.
phase "cargo test"
cargo test --release --locked

# The Embree tests (the renderer's, the stability suite's, the raw-Embree benchmark's and
# the ray logs' too) again on Embree 4.4, the library of the pinned
# embreex wheel in .venv, linked by build.rs without headers (HERON_EMBREE4_LIB), in a
# target directory of its own so the Embree 3 build stays as it is.
# Without debug information (CARGO_PROFILE_RELEASE_DEBUG=0; the code is the same):
# this build exists only to run these tests, and the line tables cost it time.
phase "Embree 4 build and tests"
embree4_lib="$(echo "$PWD"/.venv/lib/python3*/site-packages/embreex.libs)"
HERON_EMBREE4_LIB="$embree4_lib" CARGO_TARGET_DIR="$PWD/target/embree4" CARGO_PROFILE_RELEASE_DEBUG=0 \
    cargo test --release --locked --test embree --test render --test stability --test bench_traversal \
    --test bench_limit --test packets

# pytest exits 5 when it collects nothing; any non-zero exit fails this script.
phase "pytest"
HERON_BIN="$PWD/target/release/heron" .venv/bin/python -m pytest tests/python -q --durations=15
phase "done"
