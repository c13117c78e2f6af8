#!/usr/bin/env bash
# Creates the project's Python environment <repo>/.venv (git-ignored) with exactly the
# pinned packages of tests/python/requirements.txt: colour-science and friends for the
# colour checks in tests/python and for scripts/gen_spectra.py, Mitsuba 3 (with
# Dr.Jit), the reference renderer for the path tracer comparison tests and benchmarks,
# and maturin; then builds heron's Python module `heron` (python/, PyO3) with that
# maturin and installs it into .venv.
#
# Idempotent: .venv/.requirements.sha256 records the sha256 of the requirements file the
# environment was built from; when it matches, the packages are left as they are. When
# it differs (or the environment is broken) .venv is removed and built again, so no
# package of an older requirements file is left behind. The module is built every time
# (in release, into target/python; a no-op cargo build when nothing changed) and
# installed when its wheel differs from the one installed (.venv/.heron-wheel.sha256):
# maturin writes wheels with fixed timestamps, so unchanged sources give the same bytes.
#
# Downloads nothing except through pip (from PyPI, or pip's configured find-links) and
# cargo (the module's crates, pinned by python/Cargo.lock, from crates.io).
# Needs python3 >= 3.11 with the venv module (Debian: apt-get install python3-venv), a
# Rust toolchain (cargo), and Embree as heron itself does (scripts/setup.sh).
#
# Environment: PYTHON (default python3) picks the interpreter that creates the venv.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/.venv"
REQ="$ROOT/tests/python/requirements.txt"
STAMP="$VENV/.requirements.sha256"
PYTHON="${PYTHON:-python3}"
export PIP_DISABLE_PIP_VERSION_CHECK=1

log() { echo "setup-python: $*"; }
die() {
    echo "setup-python: ERROR: $*" >&2
    exit 1
}

[ -f "$REQ" ] || die "missing $REQ"

if ! command -v "$PYTHON" >/dev/null 2>&1; then
    die "'$PYTHON' not found. On Debian/Ubuntu: apt-get install python3 python3-venv"
fi
if ! "$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)'; then
    die "$("$PYTHON" --version 2>&1) is too old: colour-science 0.4.7 needs Python >= 3.11"
fi

want="$("$PYTHON" -c 'import hashlib, sys; print(hashlib.sha256(open(sys.argv[1], "rb").read()).hexdigest())' "$REQ")"

# heron's own module, built and installed after the packages (see the top).
install_module() {
    local wheels="$ROOT/target/python/wheels" wheel have sha
    local wheel_stamp="$VENV/.heron-wheel.sha256"
    if ! command -v cargo >/dev/null 2>&1; then
        die "cargo not found: the Python module heron (python/) is built from Rust; install a Rust toolchain (1.80 or newer)"
    fi
    log "building the Python module heron (python/, maturin build --release, into target/python)"
    rm -rf "$wheels"
    # A target directory of its own: the module's crate has other dependencies (PyO3)
    # and its own release profile, and must not disturb the root crate's target/release.
    if ! CARGO_TARGET_DIR="$ROOT/target/python" "$VENV/bin/maturin" build --release --locked \
        --manifest-path "$ROOT/python/Cargo.toml" --interpreter "$VENV/bin/python" \
        --out "$wheels"; then
        die "maturin could not build the Python module (see cargo's message above)"
    fi
    wheel="$(ls "$wheels"/heron-*.whl)"
    sha="$("$VENV/bin/python" -c 'import hashlib, sys; print(hashlib.sha256(open(sys.argv[1], "rb").read()).hexdigest())' "$wheel")"
    have="$(cat "$wheel_stamp" 2>/dev/null || true)"
    if [ "$have" = "$sha" ] && "$VENV/bin/python" -c 'import heron' >/dev/null 2>&1; then
        log "the installed module heron is this build's (wheel sha256 ${sha:0:12}…)"
        return
    fi
    rm -f "$wheel_stamp"
    if ! "$VENV/bin/python" -m pip install --no-deps --force-reinstall --no-index "$wheel"; then
        die "pip could not install $wheel"
    fi
    if ! "$VENV/bin/python" -c 'import heron; heron.ior("water", [589.0])'; then
        die "the module heron does not import after installing $wheel (see the traceback above)"
    fi
    echo "$sha" >"$wheel_stamp"
    log "installed the module heron ($(basename "$wheel")); try: .venv/bin/python -c 'import heron; help(heron)'"
}

if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$want" ] \
    && "$VENV/bin/python" -c 'import sys' >/dev/null 2>&1; then
    log "$VENV is up to date with tests/python/requirements.txt (sha256 ${want:0:12}…)"
    install_module
    exit 0
fi

# Debian splits venv/ensurepip into python3-venv; without it `python3 -m venv` leaves a
# venv without pip. Detect that before creating anything.
if ! "$PYTHON" -c 'import venv, ensurepip' >/dev/null 2>&1; then
    die "$("$PYTHON" --version 2>&1) at $(command -v "$PYTHON") has no working venv/ensurepip module. On Debian/Ubuntu: apt-get install python3-venv"
fi

if [ -e "$VENV" ]; then
    if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$want" ]; then
        log "$VENV/bin/python does not run (was the system Python replaced?); rebuilding it"
    elif [ -f "$STAMP" ]; then
        log "tests/python/requirements.txt changed since $VENV was built; rebuilding it"
    else
        log "$VENV is incomplete or was not built by this script; rebuilding it"
    fi
    rm -rf "$VENV"
fi

log "creating $VENV with $("$PYTHON" --version 2>&1) ($(command -v "$PYTHON"))"
if ! "$PYTHON" -m venv "$VENV"; then
    rm -rf "$VENV"
    die "'$PYTHON -m venv $VENV' failed. On Debian/Ubuntu: apt-get install python3-venv"
fi
if ! "$VENV/bin/python" -m pip --version >/dev/null 2>&1; then
    rm -rf "$VENV"
    die "the new venv has no pip. On Debian/Ubuntu: apt-get install python3-venv"
fi

log "installing the pinned packages of tests/python/requirements.txt (pip, wheels only)"
if ! "$VENV/bin/python" -m pip install --no-deps --only-binary=:all: -r "$REQ"; then
    die "pip install -r $REQ failed (see pip's message above); $VENV is left unstamped and will be rebuilt on the next run"
fi

log "checking that the pinned set is complete and consistent (pip check)"
if ! "$VENV/bin/python" -m pip check; then
    die "pip check failed: tests/python/requirements.txt is missing a dependency or pins incompatible versions"
fi

# Mitsuba's variant is chosen only inside this check (scalar_spectral needs no libLLVM;
# the llvm_* variants load Debian's libllvm19 at run time, see scripts/setup.sh).
if ! "$VENV/bin/python" -c 'import colour, numpy, scipy, OpenEXR, OpenImageIO, PIL, pytest, miepython, drjit
import mitsuba as mi; mi.set_variant("scalar_spectral")' ; then
    die "the installed packages do not import (see the traceback above)"
fi
if ! "$VENV/bin/maturin" --version >/dev/null; then
    die "maturin does not run (see the message above)"
fi

echo "$want" >"$STAMP"
install_module
log "done: $("$VENV/bin/python" -c 'import colour; print("colour-science", colour.__version__)'); run the checks with: .venv/bin/python -m pytest tests/python"
