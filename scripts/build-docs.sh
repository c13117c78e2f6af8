#!/usr/bin/env bash
# Builds the guide (docs/, mkdocs.yml) as a website into OUTDIR, with the Python API
# reference:
#
#   scripts/build-docs.sh OUTDIR      then open OUTDIR/index.html
#
# OUTDIR is emptied first (mkdocs cleans its site folder): give a new or disposable one.
#
# pdoc writes the reference of the module `heron` installed in the Python that runs it
# (PYTHON, default .venv/bin/python, where scripts/setup-python.sh installs it), from its
# docstrings and the stub heron/__init__.pyi the package carries beside the module, into
# api/ of a copy of docs/. The copy replaces docs/api/heron.html, a placeholder that is
# there so that the pages' links to api/heron.html resolve under a plain `mkdocs serve`
# too. Then `mkdocs build --strict` builds the copy: any warning (a broken link or anchor,
# a page missing from the nav) fails the build. tests/python/test_docs.py runs this.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
if [ $# -ne 1 ]; then
  echo "usage: scripts/build-docs.sh OUTDIR" >&2
  exit 2
fi
OUT="$(realpath -m "$1")"
PYTHON="${PYTHON:-$ROOT/.venv/bin/python}"

stage="$(mktemp -d)"
trap 'rm -rf "$stage"' EXIT
cp -r "$ROOT/docs" "$ROOT/mkdocs.yml" "$stage/"
rm -rf "$stage/docs/api"
"$PYTHON" -m pdoc --docformat restructuredtext --output-directory "$stage/docs/api" heron
"$PYTHON" -m mkdocs build --strict --config-file "$stage/mkdocs.yml" --site-dir "$OUT"
