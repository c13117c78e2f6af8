#!/usr/bin/env bash
# Do the integrators agree? The cross-integrator test (tests/agree.rs) at its full size:
# every bundled scene under every integrator that accepts it, 96 pixels on the longer
# side and four times the test command's samples (2048 spp for path and light tracing,
# 1024 for BDPT, 512 SPPM iterations), each comparable pair held to heron compare's
# region z-test, and the media scenes' estimators and packet engines against each other.
# Prints one line per pair (regions, largest |z|, the whole image's difference and the
# smallest difference its test resolves), each render's time to relMSE 1e-3, and what is
# not compared and why; exits 1 if any pair differs. About 20 minutes on two cores;
# BENCHMARKS.md, "Integrators agree", records a run.
#
#   scripts/agree.sh [LOG]      (LOG default target/agree-full.log)
set -euo pipefail
cd "$(dirname "$0")/.."
log=${1:-target/agree-full.log}
mkdir -p "$(dirname "$log")"
HERON_AGREE=full cargo test --release --locked --test agree -- --nocapture --test-threads 1 2>&1 |
  tee "$log" | grep -E "regions  max|^not compared|cost: |comparisons|pairs resolve|test result|panicked"
