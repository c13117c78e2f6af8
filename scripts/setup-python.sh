#!/usr/bin/env bash
# Creates the project's Python environment <repo>/.venv (git-ignored) with exactly the
# pinned packages of tests/python/requirements.txt: colour-science and friends for the
# colour checks in tests/python and for scripts/gen_spectra.py, and Mitsuba 3 (with
# Dr.Jit), the reference renderer for the path tracer comparison tests and benchmarks.
#
# Idempotent: .venv/.requirements.sha256 records the sha256 of the requirements file the
# environment was built from; when it matches, nothing is done. When it differs (or the
# environment is broken) .venv is removed and built again, so no package of an older
# requirements file is left behind.
#
# Downloads nothing except through pip (from PyPI, or pip's configured find-links).
# Needs python3 >= 3.11 with the venv module (Debian: apt-get install python3-venv).
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

if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$want" ] \
    && "$VENV/bin/python" -c 'import sys' >/dev/null 2>&1; then
    log "$VENV is up to date with tests/python/requirements.txt (sha256 ${want:0:12}…); nothing to do"
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

echo "$want" >"$STAMP"
log "done: $("$VENV/bin/python" -c 'import colour; print("colour-science", colour.__version__)'); run the checks with: .venv/bin/python -m pytest tests/python"
