"""Building and unpacking the relocatable CLI tarball (scripts/build-dist.sh) for the
tests that use it: test_dist.py (the tarball itself) and test_slurm.py (the cluster
recipe runs the unpacked tarball's binary)."""
from __future__ import annotations

import pathlib
import subprocess
import tarfile
import tomllib

from heronrun import REPO

VERSION = tomllib.loads((REPO / "Cargo.toml").read_text())["package"]["version"]
TOP = f"heron-{VERSION}-linux-x86_64"


def build_tarball(outdir: pathlib.Path) -> pathlib.Path:
    """Runs scripts/build-dist.sh OUTDIR; returns the tarball, the only file it leaves."""
    proc = subprocess.run(["bash", str(REPO / "scripts" / "build-dist.sh"), str(outdir)],
                          capture_output=True, text=True, cwd=REPO, timeout=1800)
    assert proc.returncode == 0, f"build-dist.sh failed:\n{proc.stderr[-5000:]}\n{proc.stdout}"
    tarball = outdir / f"{TOP}.tar.gz"
    assert proc.stdout.strip().splitlines()[-1] == str(tarball), proc.stdout
    assert sorted(p.name for p in outdir.iterdir()) == [tarball.name], \
        "build-dist.sh left a temporary file beside the tarball"
    return tarball


def unpack(tarball: pathlib.Path, dest: pathlib.Path, moved_to: pathlib.Path) -> pathlib.Path:
    """Unpacks into dest, checks every member is under the one top folder, then moves that
    folder to moved_to (another name and place: nothing may depend on where it was built
    or unpacked). Returns moved_to."""
    with tarfile.open(tarball) as t:
        names = t.getnames()
        t.extractall(dest, filter="data")
    assert all(n == TOP or n.startswith(TOP + "/") for n in names), names
    (dest / TOP).rename(moved_to)
    return moved_to
