#!/usr/bin/env python3
"""Run time against error for heron's integrators on scenes with caustics.

    .venv/bin/python scripts/bench_integrators.py [--scenes caustic-glass,caustic-dispersion,newton-prism]
        [--integrators path,lighttrace,bdpt] [--ref-integrator bdpt] [--ref-spp 2048]
        [--spp 16,64,256] [--threads 2] [--target 0.05]
        [--roi caustic-dispersion=X0,Y0,X1,Y1 ...] [--heron target/release/heron]

For each scene: a reference rendered by --ref-integrator with 8 lanes and independent
numbers as two halves of --ref-spp/2 samples each (seeds 100000 and 100001, averaged),
then each integrator at each spp with the scene's other settings and 4 lanes,
interleaved. Time is heron's own render time ("in X s"). The errors of linear sRGB
against the reference are those of `heron converge` (scripts/exr_error.py, the same
definitions as src/compare.rs): the relative RMSE sqrt(Σ(x − ref)²)/sqrt(Σ ref²), the
relMSE mean((x − ref)² / (ref² + 0.01)), and both over the scene's region of interest
when --roi gives one (x0 ≤ x < x1, y0 ≤ y < y1 from the top-left).

The reference's own error comes from its halves: (h₁ − h₂)/2 has the whole reference's
error's variance, so it is measured like a run's error and printed first; it is part of
every row's measured squared error (E‖x − ref‖² = E‖x − truth‖² + E‖ref − truth‖²), and
a row whose error is within twice it is marked.

RMSE·√t and relMSE·t are constant for an unbiased estimator; the time to reach the
target is (RMSE·√t / target)² and relMSE·t / target, from the medians over the spp
values. Light tracing cannot see lights at infinity or specular surfaces directly; on
scenes that show them (caustic-glass's sky and ball) its error therefore does not fall
to zero, and the script says so.
"""
from __future__ import annotations

import argparse
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from exr_error import crop, parse_roi, read_xyz, reference_own_error, rel_mse, rel_rmse  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[1]


def render(heron, scene, integrator, spp, seed, threads, lanes, tmp, extra=()):
    out = tmp / "b.exr"
    p = subprocess.run([str(heron), "render", str(scene), "-o", str(out), "--integrator",
                        integrator, "--spp", str(spp), "--seed", str(seed), "--threads",
                        str(threads), "--lanes", str(lanes), "--xyz", "--no-png", "--quiet",
                        *extra], check=True, capture_output=True, text=True)
    return read_xyz(out), float(re.search(r" in ([0-9.]+) s:", p.stderr).group(1))


def measures(img, ref, roi):
    """(rel_rmse, rel_mse, roi_rel_rmse, roi_rel_mse); the last two None without a roi."""
    m = [rel_rmse(img, ref), rel_mse(img, ref)]
    m += [rel_rmse(img, ref, roi), rel_mse(img, ref, roi)] if roi else [None, None]
    return m


def fmt(v):
    return "" if v is None else f"{v:.5g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="caustic-glass,caustic-dispersion,newton-prism")
    ap.add_argument("--integrators", default="path,lighttrace,bdpt")
    ap.add_argument("--ref-integrator", default="bdpt")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--target", type=float, default=0.05)
    ap.add_argument("--roi", action="append", default=[], metavar="SCENE=X0,Y0,X1,Y1",
                    help="a scene's region of interest (repeat for several scenes)")
    ap.add_argument("--heron", default=str(REPO / "target" / "release" / "heron"))
    a = ap.parse_args()
    rois = {}
    for r in a.roi:
        name, _, rect = r.partition("=")
        try:
            rois[name] = parse_roi(rect)
        except ValueError as e:
            ap.error(f"--roi {r}: {e}")
    if a.ref_spp < 2:
        ap.error(f"--ref-spp {a.ref_spp}: expected at least 2 (two halves)")
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-bench-"))
    spps = [int(s) for s in a.spp.split(",")]
    print("scene,integrator,spp,time_s,rel_rmse,rmse_sqrt_time,rel_mse,roi_rel_rmse,roi_rel_mse")
    summary = []
    for name in a.scenes.split(","):
        scene = REPO / "scenes" / f"{name}.toml"
        roi = rois.get(name)
        half = a.ref_spp // 2
        halves, tref = [], 0.0
        for seed in (100_000, 100_001):
            h, t = render(a.heron, scene, a.ref_integrator, half, seed, a.threads, 8, tmp,
                          ("--sampler", "independent"))
            halves.append(h)
            tref += t
        ref = 0.5 * (halves[0] + halves[1])
        if roi:
            crop(ref, roi)  # a rectangle outside the image fails here, before the runs
        own = reference_own_error(*halves)
        own_roi = reference_own_error(*halves, roi) if roi else (None, None)
        print(f"# {name}: {a.ref_integrator} reference, 2 x {half} spp, 8 lanes, {tref:.0f} s; "
              f"its own error rel_rmse {own[0]:.4g}, rel_mse {own[1]:.4g}"
              + (f"; over roi {','.join(map(str, roi))}: rel_rmse {own_roi[0]:.4g}, "
                 f"rel_mse {own_roi[1]:.4g}" if roi else ""), flush=True)
        floor = [own[0], own[1], own_roi[0], own_roi[1]]
        eff, errs = {}, {}
        for spp in spps:
            for integ in a.integrators.split(","):
                img, t = render(a.heron, scene, integ, spp, 1, a.threads, 4, tmp)
                m = measures(img, ref, roi)
                # Squared errors add: a squared error within twice the reference's own is
                # mostly the reference's.
                near = [f for f, v, f0, sq in zip(("rel_rmse", "rel_mse", "roi_rel_rmse",
                                                   "roi_rel_mse"), m, floor, (2, 1, 2, 1))
                        if v is not None and v ** sq < 2 * f0 ** sq]
                eff.setdefault(integ, []).append((m[0] * t ** 0.5, m[1] * t,
                                                  m[3] * t if roi else None))
                errs.setdefault(integ, []).append(m)
                note = f"  # within 2x the reference's own: {' '.join(near)}" if near else ""
                print(f"{name},{integ},{spp},{t:.3f},{m[0]:.5g},{m[0] * t ** 0.5:.5g},"
                      f"{fmt(m[1])},{fmt(m[2])},{fmt(m[3])}{note}", flush=True)
        for integ, v in eff.items():
            e = errs[integ]
            if e[-1][0] > 0.8 * e[0][0]:
                # The error does not fall as 1/√t: the integrator cannot see part of the
                # image (or finds it too rarely to show at these sample counts).
                summary.append(f"{name}: {integ}'s relative RMSE does not fall "
                               f"({e[0][0]:.3f} → {e[-1][0]:.3f})")
            else:
                t5 = (statistics.median(x[0] for x in v) / a.target) ** 2
                summary.append(f"{name}: {integ} reaches {a.target:.0%} relative RMSE in about "
                               f"{t5:.1f} s")
            for k, what in ((1, "relMSE"), (2, "relMSE over the roi")):
                if v[0][k] is None:
                    continue
                col = 1 if k == 1 else 3
                if e[-1][col] > 0.5 * e[0][col]:
                    summary.append(f"{name}: {integ}'s {what} does not fall as 1/t "
                                   f"({e[0][col]:.4g} → {e[-1][col]:.4g})")
                    continue
                t5 = statistics.median(x[k] for x in v) / a.target
                summary.append(f"{name}: {integ} reaches {a.target:.0%} {what} in about "
                               f"{t5:.1f} s")
    print()
    print("\n".join(summary))


if __name__ == "__main__":
    main()
