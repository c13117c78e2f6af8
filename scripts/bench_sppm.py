#!/usr/bin/env python3
"""Equal-time images and errors of `path`, `bdpt` and `sppm` on the scenes whose
caustics are seen through glass or water (issue 23), and photon mapping's error against
its time on the pool.

    .venv/bin/python scripts/bench_sppm.py [--scenes pool,lens-over-spectrum,caustic-dispersion]
        [--seconds 60] [--ref-seconds 600] [--sweep 30,60,120] [--threads 2]
        [--keep DIR] [--reference-from DIR] [--tune] [--heron target/release/heron]

For each scene a reference is rendered by `sppm` as two independent chains (seeds
100000 and 100001) of --ref-seconds each (`--time-limit`), averaged; their difference
estimates the reference's own error (its variance: a chain's remaining radius bias is
common to both halves and is not in it; scripts/exr_error.py `reference_own_error`).
Then every integrator renders for --seconds (`--time-limit`, so each stops at the first
pass boundary after it; `sppm` passes are iterations), in the order path, bdpt, sppm
and then again reversed, and the errors of linear sRGB against the reference are
printed: relative RMSE and relMSE (`heron converge`'s definitions) over the whole image
and over the scene's region of interest, where its caustic is seen through the glass.
The two passes' figures are printed separately, so the load's drift shows.

On the pool, `sppm` also renders for each of --sweep's times, and the time it needs to
reach a relMSE of 5% over the region is read off the sweep (log–log interpolation).

Times are heron's own render times ("in X s"); a render's first second or so (scene
load, the Embree build) is not in them. The images of the first pass are kept in
--keep DIR as SCENE-INTEGRATOR.exr, with the reference halves (SCENE-ref-half0.exr,
SCENE-ref-half1.exr), which --reference-from reads back instead of rendering.
"""
from __future__ import annotations

import argparse
import math
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from exr_error import read_xyz, reference_own_error, rel_mse, rel_rmse  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[1]

# Where each scene's caustic is seen through its glass (x0, y0, x1, y1 at the scene's own
# resolution): the pool's floor under the water, the spectrum inside the magnifier, and
# caustic-dispersion's floor under the caustic's core and halo (BENCHMARKS.md).
ROI = {
    "pool": (64, 160, 448, 480),
    "lens-over-spectrum": (160, 110, 350, 270),
    "caustic-dispersion": (196, 224, 256, 256),
}


def render(heron, scene, integrator, seconds, seed, threads, out, extra=()):
    p = subprocess.run(
        [str(heron), "render", str(scene), "-o", str(out), "--integrator", integrator,
         "--spp", "1000000", "--time-limit", str(seconds), "--seed", str(seed),
         "--threads", str(threads), "--lanes", "4", "--xyz", "--no-png", "--quiet",
         *extra],
        check=True, capture_output=True, text=True)
    m = re.search(r"at (\d+) spp.* in ([0-9.]+) s:", p.stderr)
    return int(m.group(1)), float(m.group(2))


def row(name, integrator, spp, t, img, ref, roi):
    e, m = rel_rmse(img, ref), rel_mse(img, ref)
    re_, rm = rel_rmse(img, ref, roi), rel_mse(img, ref, roi)
    print(f"{name},{integrator},{spp},{t:.1f},{e:.4f},{m:.4f},{re_:.4f},{rm:.4f}", flush=True)
    return rm


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="pool,lens-over-spectrum,caustic-dispersion")
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--ref-seconds", type=float, default=600)
    ap.add_argument("--sweep", default="30,60,120")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--keep", type=pathlib.Path)
    ap.add_argument("--reference-from", type=pathlib.Path)
    ap.add_argument("--heron", type=pathlib.Path, default=REPO / "target/release/heron")
    ap.add_argument("--tune", action="store_true",
                    help="on the pool, also sppm at --seconds for photons per iteration of "
                         "1/4, 1 and 4 per pixel and initial radii of automatic "
                         "(SppmSettings::RADIUS_PIXELS footprints; a footprint is about "
                         "7 mm on the pool's floor), 6 and 25 mm")
    a = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp())
    if a.keep:
        a.keep.mkdir(parents=True, exist_ok=True)
    print("scene,integrator,spp,time_s,rel_rmse,rel_mse,roi_rel_rmse,roi_rel_mse")
    for name in a.scenes.split(","):
        scene = REPO / "scenes" / f"{name}.toml"
        roi = ROI[name]
        halves = []
        for k in range(2):
            f = f"{name}-ref-half{k}.exr"
            if a.reference_from:
                halves.append(read_xyz(a.reference_from / f))
                continue
            out = tmp / f
            spp, t = render(a.heron, scene, "sppm", a.ref_seconds, 100000 + k, a.threads, out)
            print(f"# {name}: reference half {k}: {spp} iterations in {t:.0f} s", flush=True)
            halves.append(read_xyz(out))
            if a.keep:
                shutil.copyfile(out, a.keep / f)
        ref = 0.5 * (halves[0] + halves[1])
        own = reference_own_error(halves[0], halves[1])
        own_roi = reference_own_error(halves[0], halves[1], roi)
        print(f"{name},reference,,,{own[0]:.4f},{own[1]:.4f},{own_roi[0]:.4f},{own_roi[1]:.4f}",
              flush=True)
        for order in (["path", "bdpt", "sppm"], ["sppm", "bdpt", "path"]):
            for integ in order:
                out = tmp / f"{name}-{integ}.exr"
                spp, t = render(a.heron, scene, integ, a.seconds, 1, a.threads, out)
                row(name, integ, spp, t, read_xyz(out), ref, roi)
                if a.keep and order[0] == "path":
                    shutil.copyfile(out, a.keep / f"{name}-{integ}.exr")
        if name == "pool" and a.tune:
            for photons in (65536, 262144, 1048576):
                for radius in ("0", "0.006", "0.025"):
                    out = tmp / "tune.exr"
                    spp, t = render(a.heron, scene, "sppm", a.seconds, 1, a.threads, out,
                                    ["--sppm-photons", str(photons), "--sppm-radius", radius])
                    row(name, f"sppm-photons{photons}-radius{radius}", spp, t, read_xyz(out),
                        ref, roi)
        if name == "pool":
            points = []
            for s in [float(x) for x in a.sweep.split(",")]:
                out = tmp / "sweep.exr"
                spp, t = render(a.heron, scene, "sppm", s, 1, a.threads, out)
                points.append((t, row(name, "sppm-sweep", spp, t, read_xyz(out), ref, roi)))
            # The time at which the region's relMSE crosses 5%, between the sweep's points
            # (log-log), or beyond them by the last segment's slope.
            target = 0.05
            (t0, e0), (t1, e1) = points[-2], points[-1]
            for (ta, ea), (tb, eb) in zip(points, points[1:]):
                if eb <= target <= ea:
                    (t0, e0), (t1, e1) = (ta, ea), (tb, eb)
                    break
            if points[0][1] <= target:
                print(f"# pool: sppm below {target} relMSE over the region already at {points[0][0]:.0f} s")
            else:
                slope = math.log(e1 / e0) / math.log(t1 / t0)
                t_hit = t0 * math.exp(math.log(target / e0) / slope)
                print(f"# pool: sppm reaches relMSE {target} over the region at about {t_hit:.0f} s "
                      f"(slope {slope:.2f} between {t0:.0f} and {t1:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
