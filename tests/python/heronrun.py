"""Running the heron CLI for the render checks in tests/python.

The render tests run:

    heron render SCENE.toml -o OUT.exr [--spp N] [--seed S] [--threads N] [EXTRA...]

(EXTRA: further flags such as `--xyz --spectral-bins 94`) from HERON_BIN (default
<repo>/target/release/heron). A missing binary makes each render test FAIL with a
message saying how to build or point to it; it is never skipped.
"""
from __future__ import annotations

import dataclasses
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = pathlib.Path(__file__).resolve().parent / "scenes"
DEFAULT_BIN = REPO / "target" / "release" / "heron"
RENDER_TIMEOUT_S = float(os.environ.get("HERON_TEST_TIMEOUT", "1200"))


def heron_bin_path() -> pathlib.Path:
    env = os.environ.get("HERON_BIN")
    return pathlib.Path(env).expanduser().resolve() if env else DEFAULT_BIN


def require_heron_bin() -> pathlib.Path:
    """The heron binary, or pytest.fail (inside the calling test) saying how to get one."""
    path = heron_bin_path()
    origin = "HERON_BIN" if os.environ.get("HERON_BIN") else "default <repo>/target/release/heron"
    if not path.is_file():
        pytest.fail(
            f"heron binary not found at {path} ({origin}). Build it with "
            f"`cargo build --release` in {REPO}, or set HERON_BIN to a built heron binary.",
            pytrace=False,
        )
    if not os.access(path, os.X_OK):
        pytest.fail(f"heron binary at {path} ({origin}) is not executable.", pytrace=False)
    return path


@dataclasses.dataclass(frozen=True)
class Render:
    scene: pathlib.Path
    args: tuple
    exr: pathlib.Path
    png: pathlib.Path
    outdir: pathlib.Path
    stdout: str
    stderr: str


class Renderer:
    """Runs `heron render`; results are cached per (scene, options) for the session."""

    def __init__(self, tmp_factory):
        self._tmp = tmp_factory
        self._cache: dict = {}

    def __call__(self, scene: str, *, spp: int | None = None, seed: int | None = None,
                 threads: int | None = None, extra: tuple[str, ...] = ()) -> Render:
        scene_path = SCENES / scene
        assert scene_path.is_file(), f"test scene {scene_path} is missing"
        args = []
        if spp is not None:
            args += ["--spp", str(spp)]
        if seed is not None:
            args += ["--seed", str(seed)]
        if threads is not None:
            args += ["--threads", str(threads)]
        args += [str(x) for x in extra]
        key = (scene, tuple(args))
        if key not in self._cache:
            self._cache[key] = self._run(scene_path, tuple(args))
        return self._cache[key]

    def _run(self, scene_path: pathlib.Path, args: tuple) -> Render:
        binary = require_heron_bin()
        outdir = self._tmp.mktemp(scene_path.stem)
        exr = outdir / "out.exr"
        cmd = [str(binary), "render", str(scene_path), "-o", str(exr), *args]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO,
                                  timeout=RENDER_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"`{' '.join(cmd)}` did not finish within {RENDER_TIMEOUT_S:.0f} s "
                        f"(HERON_TEST_TIMEOUT)", pytrace=False)
        if proc.returncode != 0:
            pytest.fail(
                f"`{' '.join(cmd)}` exited with status {proc.returncode}\n"
                f"--- stderr (last 3000 chars) ---\n{proc.stderr[-3000:]}\n"
                f"--- stdout (last 1000 chars) ---\n{proc.stdout[-1000:]}",
                pytrace=False,
            )
        if not exr.is_file():
            pytest.fail(f"`{' '.join(cmd)}` succeeded but wrote no {exr}", pytrace=False)
        return Render(scene_path, args, exr, exr.with_suffix(".png"), outdir,
                      proc.stdout, proc.stderr)
