#!/usr/bin/env python3
"""Run time against error for heron's integrators on scenes with caustics.

    .venv/bin/python scripts/bench_integrators.py [--scenes caustic-glass,caustic-dispersion,newton-prism]
        [--integrators path,lighttrace,bdpt] [--ref-integrator bdpt] [--ref-spp 2048]
        [--spp 16,64,256] [--threads 2] [--target 0.05]
        [--roi caustic-dispersion=X0,Y0,X1,Y1 ...] [--heron target/release/heron]
        [--keep DIR] [--reference-from DIR]

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

--roi-ref-integrator renders a second reference, the same way, for the region's errors
only: on a caustic seen directly, light tracing converges where BDPT's reference keeps
fireflies; the script prints how far the two references differ over the region.

`roi_worst_share` is the part of the region's relMSE that its worst 1% of pixels hold
(by their mean relative squared error over the channels): near 1, a few fireflies
decide it. --keep DIR writes the reference's halves (SCENE-ref-half0.exr,
SCENE-ref-half1.exr) and every run (SCENE-INTEGRATOR-SPPspp.exr) there;
--reference-from DIR reads the halves from such a folder instead of rendering them.

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
import shutil
import statistics
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from exr_error import (REL_MSE_EPSILON, XYZ_TO_SRGB, crop, parse_roi, read_xyz,  # noqa: E402
                       reference_own_error, rel_mse, rel_rmse)

REPO = pathlib.Path(__file__).resolve().parents[1]


def render(heron, scene, integrator, spp, seed, threads, lanes, tmp, extra=(), keep=None):
    out = tmp / "b.exr"
    p = subprocess.run([str(heron), "render", str(scene), "-o", str(out), "--integrator",
                        integrator, "--spp", str(spp), "--seed", str(seed), "--threads",
                        str(threads), "--lanes", str(lanes), "--xyz", "--no-png", "--quiet",
                        *extra], check=True, capture_output=True, text=True)
    if keep:
        shutil.copyfile(out, keep)
    return read_xyz(out), float(re.search(r" in ([0-9.]+) s:", p.stderr).group(1))


def worst_share(img, ref, roi, fraction=0.01):
    """The part of the relMSE over `roi` held by its worst `fraction` of pixels."""
    a, r = crop(img, roi) @ XYZ_TO_SRGB.T, crop(ref, roi) @ XYZ_TO_SRGB.T
    e = np.sort(((a - r) ** 2 / (r ** 2 + REL_MSE_EPSILON)).mean(-1).ravel())[::-1]
    k = max(1, int(round(fraction * e.size)))
    return float(e[:k].sum() / e.sum()) if e.sum() > 0 else 0.0


def measures(img, ref, roi, roi_ref):
    """(rel_rmse, rel_mse, roi_rel_rmse, roi_rel_mse, roi_worst_share), the last three
    against `roi_ref` and None without a roi."""
    m = [rel_rmse(img, ref), rel_mse(img, ref)]
    m += ([rel_rmse(img, roi_ref, roi), rel_mse(img, roi_ref, roi),
           worst_share(img, roi_ref, roi)] if roi else [None, None, None])
    return m


def fmt(v):
    return "" if v is None else f"{v:.5g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="caustic-glass,caustic-dispersion,newton-prism")
    ap.add_argument("--integrators", default="path,lighttrace,bdpt")
    ap.add_argument("--ref-integrator", default="bdpt")
    ap.add_argument("--roi-ref-integrator", metavar="INTEGRATOR",
                    help="render a second reference with this integrator for the region's "
                         "errors (one that converges there, e.g. lighttrace on a caustic "
                         "seen directly); default: the reference")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--target", type=float, default=0.05)
    ap.add_argument("--roi", action="append", default=[], metavar="SCENE=X0,Y0,X1,Y1",
                    help="a scene's region of interest (repeat for several scenes)")
    ap.add_argument("--heron", default=str(REPO / "target" / "release" / "heron"))
    ap.add_argument("--keep", type=pathlib.Path, metavar="DIR",
                    help="write the reference's halves and every run's EXR into DIR")
    ap.add_argument("--reference-from", type=pathlib.Path, metavar="DIR",
                    help="read the reference's halves from DIR (made with --keep)")
    a = ap.parse_args()
    for flag, d in (("--keep", a.keep), ("--reference-from", a.reference_from)):
        if d is not None and not d.is_dir():
            ap.error(f"{flag} {d}: expected an existing folder")
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
    print("scene,integrator,spp,time_s,rel_rmse,rmse_sqrt_time,rel_mse,roi_rel_rmse,roi_rel_mse,"
          "roi_worst_share")
    summary = []
    for name in a.scenes.split(","):
        scene = REPO / "scenes" / f"{name}.toml"
        roi = rois.get(name)
        half = a.ref_spp // 2

        def reference(integrator, tag):
            """The two halves and their render time (0 when read from a folder)."""
            halves, tref = [], 0.0
            for k, seed in enumerate((100_000, 100_001)):
                name_k = f"{name}-{tag}-half{k}.exr"
                if a.reference_from:
                    halves.append(read_xyz(a.reference_from / name_k))
                    continue
                h, t = render(a.heron, scene, integrator, half, seed, a.threads, 8, tmp,
                              ("--sampler", "independent"), a.keep and a.keep / name_k)
                halves.append(h)
                tref += t
            made = (f"read from {a.reference_from}" if a.reference_from else
                    f"{integrator}, 2 x {half} spp, 8 lanes, {tref:.0f} s")
            return halves, made

        halves, made = reference(a.ref_integrator, "ref")
        ref = 0.5 * (halves[0] + halves[1])
        if roi:
            crop(ref, roi)  # a rectangle outside the image fails here, before the runs
        own = reference_own_error(*halves)
        print(f"# {name}: reference {made}; "
              f"its own error rel_rmse {own[0]:.4g}, rel_mse {own[1]:.4g}", flush=True)
        roi_ref, own_roi = ref, (None, None)
        if roi:
            rect = ",".join(map(str, roi))
            if a.roi_ref_integrator not in (None, a.ref_integrator):
                roi_halves, made = reference(a.roi_ref_integrator, "roiref")
                roi_ref = 0.5 * (roi_halves[0] + roi_halves[1])
                own_roi = reference_own_error(*roi_halves, roi)
                # Both references are unbiased over the region or they disagree there.
                y = crop(ref, roi)[..., 1].mean() / crop(roi_ref, roi)[..., 1].mean()
                print(f"# {name}: the region's reference {made}; against it the whole "
                      f"reference has over roi {rect} rel_rmse {rel_rmse(ref, roi_ref, roi):.4g}, "
                      f"rel_mse {rel_mse(ref, roi_ref, roi):.4g}, mean Y ratio {y:.4f}",
                      flush=True)
            else:
                own_roi = reference_own_error(*halves, roi)
            print(f"# {name}: the region's reference's own error over roi {rect}: rel_rmse "
                  f"{own_roi[0]:.4g}, rel_mse {own_roi[1]:.4g}", flush=True)
        floor = [own[0], own[1], own_roi[0], own_roi[1]]
        eff, errs = {}, {}
        for spp in spps:
            for integ in a.integrators.split(","):
                img, t = render(a.heron, scene, integ, spp, 1, a.threads, 4, tmp,
                                keep=a.keep and a.keep / f"{name}-{integ}-{spp}spp.exr")
                m = measures(img, ref, roi, roi_ref)
                # Squared errors add: a squared error within twice the reference's own is
                # mostly the reference's.
                near = [f for f, v, f0, sq in zip(("rel_rmse", "rel_mse", "roi_rel_rmse",
                                                   "roi_rel_mse"), m, floor, (2, 1, 2, 1))
                        if v is not None and v ** sq < 2 * f0 ** sq]
                m, worst = m[:4], m[4]
                eff.setdefault(integ, []).append((m[0] * t ** 0.5, m[1] * t,
                                                  m[3] * t if roi else None))
                errs.setdefault(integ, []).append(m)
                note = f"  # within 2x the reference's own: {' '.join(near)}" if near else ""
                print(f"{name},{integ},{spp},{t:.3f},{m[0]:.5g},{m[0] * t ** 0.5:.5g},"
                      f"{fmt(m[1])},{fmt(m[2])},{fmt(m[3])},{fmt(worst)}{note}", flush=True)
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
