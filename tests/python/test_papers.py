"""papers/: every figure set regenerates byte for byte.

Each set papers/NAME has a make.sh that takes an output folder (default: its own) and
writes OUT/data/*.csv and OUT/figures/*.png from heron (HERON_BIN, default
<repo>/target/release/heron) and this Python (HERON_PYTHON, set here to the running
interpreter, i.e. the project's .venv). The test runs it into a temporary folder and
checks that it writes exactly the committed files, with the same bytes. A mismatch means
heron's output, a pinned package or a script changed: rerun papers/NAME/make.sh and
commit the result if the change is intended.

The full sets run here (no reduced mode): descartes-rainbow takes about 25 s on two
cores (about 2 900 `heron trace` runs), aristotelian-rainbow about 5 s, lee-diagram about
55 s (24 radii × 41 wavelengths of Lorenz–Mie series, up to x = 16 500).
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import pytest

from heronrun import REPO, require_heron_bin

PAPERS = REPO / "papers"
SETS = ["aristotelian-rainbow", "descartes-rainbow", "ice-halos", "lee-diagram"]
OUTPUT_DIRS = ("data", "figures")
TIMEOUT_S = float(os.environ.get("HERON_PAPERS_TIMEOUT", "300"))


def committed_files(folder: pathlib.Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes()
            for d in OUTPUT_DIRS for p in sorted((folder / d).rglob("*")) if p.is_file()}


def test_every_set_is_listed():
    found = sorted(p.parent.name for p in PAPERS.glob("*/make.sh"))
    assert found == sorted(SETS), f"papers/*/make.sh: {found}; test_papers.SETS: {SETS}"
    index = (PAPERS / "README.md").read_text()
    for name in SETS:
        assert name in index, f"papers/README.md does not list {name}"


@pytest.mark.parametrize("name", SETS)
def test_set_regenerates_byte_identical(name, tmp_path):
    heron = require_heron_bin()
    folder = PAPERS / name
    want = committed_files(folder)
    assert want, f"{folder} has no committed data/ or figures/"
    env = dict(os.environ, HERON_BIN=str(heron), HERON_PYTHON=sys.executable)
    cmd = [str(folder / "make.sh"), str(tmp_path)]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=REPO,
                              timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"`{' '.join(cmd)}` took more than {TIMEOUT_S:.0f} s "
                    f"(HERON_PAPERS_TIMEOUT)", pytrace=False)
    assert proc.returncode == 0, (
        f"`{' '.join(cmd)}` exited with {proc.returncode}\n{proc.stderr[-3000:]}")
    got = committed_files(tmp_path)
    assert sorted(got) == sorted(want), (
        f"files written {sorted(got)} differ from the committed {sorted(want)}")
    differ = [f for f in want if got[f] != want[f]]
    assert not differ, (
        f"papers/{name}: regenerated files differ from the committed ones: {differ}. "
        f"Rerun papers/{name}/make.sh and commit if the change is intended.")
