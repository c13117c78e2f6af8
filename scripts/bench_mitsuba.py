#!/usr/bin/env python3
"""Equal-error render time: heron's path tracer against Mitsuba 3 on the same scene.

    .venv/bin/python scripts/bench_mitsuba.py [--scene scenes/cornell-box.toml]
        [--ref-spp 4096] [--spp 16,32,64,128,256] [--rounds 3] [--threads 2]
        [--heron-args "--lanes 8"]... [--mitsuba-integrator direct] [--black-background]
        [--mitsuba-sampler ldsampler]

The course's default scene (a point light, Lambertian shapes: heron's Whitted tracer
is direct lighting there) is compared with Mitsuba's `direct` integrator, one emitter
sample and no BSDF samples (which could never reach the point light), and a black
background, as issue 9 specifies:

    .venv/bin/python scripts/bench_mitsuba.py --scene scenes/default.toml \
        --mitsuba-integrator direct --black-background

Each renderer is measured against its own high-sample reference (heron's made by heron
with 8 lanes, Mitsuba's by its LLVM variant: both Mitsuba variants compute the same
estimator),
so neither is charged for the other's small systematic differences. Runs are
interleaved (for each round and spp: heron, Mitsuba scalar_spectral, Mitsuba
llvm_ad_spectral, and any extra heron settings), because this machine's timings drift by
±15% over minutes; the reported time is the median over the rounds.

Time is the render alone: heron's own "in X s" (after loading the scene and building
Embree's BVH), and the wall time of Mitsuba's mi.render (after mi.load_dict; the LLVM
variant's kernels are compiled by a warm-up render first). Error is the relative RMSE
of linear sRGB, sqrt(Σ(x − ref)²)/sqrt(Σ ref²), as `heron converge` defines it, with
both images converted from XYZ by the same IEC 61966-2-1 matrix. RMSE·√t is constant
for an unbiased estimator; the time heron needs to reach Mitsuba's error at 64 spp is
(RMSE·√t of heron / RMSE of Mitsuba at 64 spp)², from heron's median RMSE·√t.

Needs the pinned .venv (scripts/setup-python.sh) and a release build of heron.
"""
from __future__ import annotations

import argparse
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "python"))
from mitsuba_scene import heron_spectra, mitsuba_dict, xyz_normalisation  # noqa: E402

from exr_error import read_xyz, rel_rmse  # noqa: E402


class Heron:
    def __init__(self, binary, scene, threads, extra, tmp):
        self.binary, self.scene, self.threads, self.extra, self.tmp = binary, scene, threads, extra, tmp
        self.name = "heron" + (f" {' '.join(extra)}" if extra else "")

    def render(self, spp, seed):
        out = self.tmp / "h.exr"
        p = subprocess.run([str(self.binary), "render", str(self.scene), "-o", str(out),
                            "--spp", str(spp), "--seed", str(seed), "--threads", str(self.threads),
                            "--xyz", "--no-png", "--quiet", *self.extra],
                           check=True, capture_output=True, text=True)
        t = float(re.search(r" in ([0-9.]+) s:", p.stderr).group(1))
        return read_xyz(out), t


class Mitsuba:
    def __init__(self, variant, scene_path, spectra, threads, integrator=None, mesh_dir=None,
                 sampler="independent"):
        import colour
        import drjit as dr
        import mitsuba as mi

        self.mi, self.dr, self.variant = mi, dr, variant
        self.name = f"mitsuba {variant}" + ("" if sampler == "independent" else f" {sampler}")
        mi.set_variant(variant)
        dr.set_thread_count(threads)
        self.scene = mi.load_dict(mitsuba_dict(mi, scene_path, spectra, integrator=integrator,
                                               mesh_dir=mesh_dir, sampler=sampler))
        self.k = xyz_normalisation(mi, colour)
        if variant.startswith("llvm"):
            self.render(4, 0)  # compile the kernels

    def render(self, spp, seed):
        self.mi.set_variant(self.variant)
        t0 = time.perf_counter()
        img = np.array(self.mi.render(self.scene, spp=spp, seed=seed), dtype=np.float64)
        return img * self.k, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="scenes/cornell-box.toml")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--spp", default="16,32,64,128,256")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--heron-args", action="append", default=[],
                    help="extra heron settings measured as further rows, e.g. '--lanes 8'")
    ap.add_argument("--mitsuba-integrator", choices=["path", "direct"], default="path")
    ap.add_argument("--mitsuba-sampler", default="ldsampler",
                    help="Mitsuba's sampler for its two runs: ldsampler (the default here: "
                         "low-discrepancy points, the like-for-like peer of heron's Sobol' "
                         "sampler), independent (Mitsuba's own default), stratified, "
                         "multijitter or orthogonal")
    ap.add_argument("--black-background", action="store_true",
                    help="render a copy of the scene with its background set to 0")
    a = ap.parse_args()
    scene = (REPO / a.scene).resolve()
    binary = REPO / "target" / "release" / "heron"
    spps = [int(s) for s in a.spp.split(",")]
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-bench-"))
    if a.black_background:
        text = re.sub(r"(?m)^background\s*=.*$", "background = 0.0", scene.read_text())
        # Beside the original, so that relative mesh paths still resolve.
        black = scene.with_name(f".{scene.stem}-black-{__import__('os').getpid()}.toml")
        black.write_text(text)
        import atexit

        atexit.register(black.unlink)
        scene = black
    integrator = None
    if a.mitsuba_integrator == "direct":
        integrator = {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0}
    spectra = heron_spectra(binary, scene)
    runners = [Heron(binary, scene, a.threads, [], tmp)]
    runners += [Heron(binary, scene, a.threads, x.split(), tmp) for x in a.heron_args]
    scalar = Mitsuba("scalar_spectral", scene, spectra, a.threads, integrator, tmp,
                     a.mitsuba_sampler)
    llvm = Mitsuba("llvm_ad_spectral", scene, spectra, a.threads, integrator, tmp,
                   a.mitsuba_sampler)
    runners += [scalar, llvm]

    print(f"# {a.scene}{' (black background)' if a.black_background else ''}, Mitsuba "
          f"{a.mitsuba_integrator}, {a.threads} threads, references at {a.ref_spp} spp, "
          f"{a.rounds} rounds", flush=True)
    t0 = time.perf_counter()
    refs = {}
    # One heron reference for every heron setting (all estimate the same image), with 8
    # lanes, its most efficient setting.
    href = Heron(binary, scene, a.threads, ["--lanes", "8"], tmp).render(a.ref_spp, 100_000)[0]
    for r in runners:
        if isinstance(r, Heron):
            refs[r.name] = href
    mref = llvm.render(a.ref_spp, 100_000)[0]
    refs[scalar.name] = refs[llvm.name] = mref
    print(f"# references took {time.perf_counter() - t0:.0f} s", flush=True)

    rows = {}
    for rnd in range(a.rounds):
        for spp in spps:
            for r in runners:
                img, t = r.render(spp, 1 + rnd)
                rows.setdefault((r.name, spp), []).append((t, rel_rmse(img, refs[r.name])))
    print("renderer,spp,time_s,rel_rmse,rmse_sqrt_time")
    eff = {}
    for (name, spp), v in rows.items():
        t = statistics.median(x[0] for x in v)
        e = statistics.median(x[1] for x in v)
        eff.setdefault(name, []).append(e * t ** 0.5)
        print(f"{name},{spp},{t:.3f},{e:.5f},{e * t ** 0.5:.5f}")
    print()
    for m in (scalar, llvm):
        e64 = statistics.median(x[1] for x in rows[(m.name, 64)])
        t64 = statistics.median(x[0] for x in rows[(m.name, 64)])
        for r in runners:
            if not isinstance(r, Heron):
                continue
            th = (statistics.median(eff[r.name]) / e64) ** 2
            print(f"{r.name} reaches {m.name}'s 64-spp error ({e64:.4f}) in {th:.3f} s; "
                  f"{m.name} takes {t64:.3f} s: ratio {th / t64:.3f}")


if __name__ == "__main__":
    main()
