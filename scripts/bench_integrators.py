#!/usr/bin/env python3
"""Run time against error for heron's integrators on scenes with caustics.

    .venv/bin/python scripts/bench_integrators.py [--scenes caustic-glass,caustic-dispersion,newton-prism]
        [--ref-spp 2048] [--spp 16,64,256] [--threads 2] [--target 0.05]

For each scene: a reference rendered by `bdpt` with 8 lanes at --ref-spp (another
seed), then `path`, `lighttrace` and `bdpt` at each spp with the scene's other settings,
interleaved. Time is heron's own render time ("in X s"); error is the relative RMSE of
linear sRGB against the reference, sqrt(Σ(x − ref)²)/sqrt(Σ ref²), as `heron converge`
defines it. RMSE·√t is constant for an unbiased estimator; the time to reach the target
error is (RMSE·√t / target)², from the median RMSE·√t over the spp values.

Light tracing cannot see lights at infinity or specular surfaces directly; on scenes
that show them (caustic-glass's sky and ball) its error therefore does not fall to
zero, and the script says so (its RMSE·√t grows with spp).
"""
from __future__ import annotations

import argparse
import pathlib
import re
import statistics
import subprocess
import tempfile

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[1]
XYZ_TO_SRGB = np.array([[3.2404542, -1.5371385, -0.4985314],
                        [-0.9692660, 1.8760108, 0.0415560],
                        [0.0556434, -0.2040259, 1.0572252]])


def read_xyz(path):
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "XYZ"], -1)


def render(scene, integrator, spp, seed, threads, lanes, tmp):
    out = tmp / "b.exr"
    p = subprocess.run([str(REPO / "target" / "release" / "heron"), "render", str(scene), "-o",
                        str(out), "--integrator", integrator, "--spp", str(spp), "--seed",
                        str(seed), "--threads", str(threads), "--lanes", str(lanes), "--xyz",
                        "--no-png", "--quiet"], check=True, capture_output=True, text=True)
    return read_xyz(out), float(re.search(r" in ([0-9.]+) s:", p.stderr).group(1))


def rel_rmse(a, r):
    a, r = a @ XYZ_TO_SRGB.T, r @ XYZ_TO_SRGB.T
    return float(np.sqrt(((a - r) ** 2).sum() / (r ** 2).sum()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="caustic-glass,caustic-dispersion,newton-prism")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--target", type=float, default=0.05)
    a = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-bench-"))
    spps = [int(s) for s in a.spp.split(",")]
    print("scene,integrator,spp,time_s,rel_rmse,rmse_sqrt_time")
    summary = []
    for name in a.scenes.split(","):
        scene = REPO / "scenes" / f"{name}.toml"
        ref, tref = render(scene, "bdpt", a.ref_spp, 100_000, a.threads, 8, tmp)
        print(f"# {name}: bdpt reference, {a.ref_spp} spp, 8 lanes, {tref:.0f} s", flush=True)
        eff = {}
        errs = {}
        for spp in spps:
            for integ in ("path", "lighttrace", "bdpt"):
                img, t = render(scene, integ, spp, 1, a.threads, 4, tmp)
                e = rel_rmse(img, ref)
                eff.setdefault(integ, []).append(e * t ** 0.5)
                errs.setdefault(integ, []).append(e)
                print(f"{name},{integ},{spp},{t:.3f},{e:.5f},{e * t ** 0.5:.5f}", flush=True)
        for integ, v in eff.items():
            e = errs[integ]
            if e[-1] > 0.8 * e[0]:
                # The error does not fall as 1/√t: the integrator cannot see part of the
                # image (or finds it too rarely to show at these sample counts).
                summary.append(f"{name}: {integ}'s error does not fall ({e[0]:.3f} → {e[-1]:.3f})")
                continue
            t5 = (statistics.median(v) / a.target) ** 2
            summary.append(f"{name}: {integ} reaches {a.target:.0%} relative RMSE in about {t5:.1f} s")
    print()
    print("\n".join(summary))


if __name__ == "__main__":
    main()
