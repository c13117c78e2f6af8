#!/usr/bin/env python3
"""What the lens camera costs against the pinhole, and what its pupil sampling gains.

    .venv/bin/python scripts/bench_lens.py [--scenes cooke-triplet,double-gauss,singlet-chromatic]
        [--spp 16] [--ref-spp 512] [--runs 5] [--threads 2] [--baseline EXE]

For each lens scene, interleaved run by run (the order reversed every other run, so a
drift of the machine's speed falls on every variant alike):

- pinhole:      the scene with `type = "pinhole"` and the camera constant d = EFL(d line) /
                film height, the same field of view as the lens at infinity focus, so the
                same objects are in view (the lens scenes focus at 1–2 m, which
                magnifies by about 3% more; the scene's cost hardly depends on it);
- bounds:       the lens, rays aimed at the exit pupil's bounds (the default);
- rear-element: the lens, rays aimed at the whole square behind the rear element;
- baseline:     (with --baseline EXE) the default of another heron binary, e.g. one
                built before a change to the pupil bounds.

Time is heron's own render time ("in X s": tracing only; the bounds' construction at
load time is not in it and is printed separately as the difference of wall-clock and
render time, median over runs). `through` is the fraction of camera samples that the
lens lets through (heron's ray count over width × height × spp: the lens scenes are
lit only by emitters seen directly, so every ray is a camera ray). The error of each
lens variant is the relative RMSE of linear sRGB against a reference rendered with the
bounds at --ref-spp (another seed); its own error inflates the figures by about
sqrt(1 + spp/ref_spp), 1.6% at the defaults. RMSE²·t is constant for an unbiased
estimator: `eq_err_time` is its ratio to the bounds' (the time rear-element or the
baseline needs to reach the bounds' error, as a multiple of the bounds' time).
"""
from __future__ import annotations

import argparse
import csv
import pathlib
import re
import statistics
import subprocess
import tempfile
import time
import tomllib

from exr_error import read_xyz, rel_rmse

REPO = pathlib.Path(__file__).resolve().parents[1]
HERON = REPO / "target" / "release" / "heron"
SUMMARY = re.compile(r" in ([0-9.]+) s: ([0-9]+) rays")
LENS_KEYS = ("type", "lens", "surface", "film_diagonal", "film_distance", "focus_distance",
             "focus_wavelength", "mm_per_unit", "f_number", "pupil")



def render(exe, scene, spp, seed, threads, out):
    t0 = time.perf_counter()
    p = subprocess.run([str(exe), "render", str(scene), "-o", str(out), "--spp", str(spp),
                        "--seed", str(seed), "--threads", str(threads), "--xyz", "--no-png",
                        "--quiet"], check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    m = SUMMARY.search(p.stderr)
    if not m:
        raise SystemExit("no summary line in: " + p.stderr)
    return float(m.group(1)), int(m.group(2)), wall


def variants(name, tmp):
    """The scene files of the variants: (label, path)."""
    src = REPO / "scenes" / f"{name}.toml"
    text = src.read_text()
    cam = tomllib.loads(text)["camera"]
    out = tmp / "paraxial"
    subprocess.run([str(HERON), "lens", str((src.parent / cam["lens"]).resolve()), "--out",
                    str(out)], check=True, capture_output=True)
    with open(out / "paraxial.csv") as f:
        rows = list(csv.DictReader(f))
    efl = float(min(rows, key=lambda r: abs(float(r["wavelength_nm"]) - 587.5618))["efl_mm"])
    w, h = cam["resolution"]
    fh = cam.get("film_diagonal", 43.266615305567875) * h / (w * w + h * h) ** 0.5
    # The pinhole: the [camera] table without the lens keys, with d.
    lines, in_camera = [], False
    for line in text.splitlines():
        if line.startswith("["):
            in_camera = line.strip() == "[camera]"
            lines.append(line)
            if in_camera:
                lines.append(f"d = {efl / fh!r}")
            continue
        if in_camera and line.split("=")[0].strip() in LENS_KEYS:
            continue
        lines.append(line)
    paths = {}
    for label, body in (("pinhole", "\n".join(lines) + "\n"), ("bounds", text),
                        ("rear-element", text.replace("[camera]\n", "[camera]\npupil = \"rear-element\"\n", 1))):
        p = src.parent / f".bench-lens-{label}-{name}.toml"
        p.write_text(body)
        paths[label] = p
    return paths, (w, h)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="cooke-triplet,double-gauss,singlet-chromatic")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--ref-spp", type=int, default=512)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--baseline", type=pathlib.Path)
    a = ap.parse_args()
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-bench-lens-"))
    print(f"# {a.runs} interleaved runs per variant, {a.spp} spp, {a.threads} threads; "
          f"median render time; reference: bounds at {a.ref_spp} spp")
    print("scene,variant,render_s,setup_s,through,rel_rmse,time_over_pinhole,eq_err_time_over_bounds")
    for name in a.scenes.split(","):
        paths, (w, h) = variants(name, tmp)
        try:
            render(HERON, paths["bounds"], a.ref_spp, 100_000, a.threads, tmp / "ref.exr")
            ref = read_xyz(tmp / "ref.exr")
            runs = [(label, HERON, p) for label, p in paths.items()]
            if a.baseline:
                runs.append(("baseline", a.baseline, paths["bounds"]))
            stats = {label: {"t": [], "setup": [], "e": []} for label, _, _ in runs}
            rays = {}
            render(HERON, paths["bounds"], a.spp, 1, a.threads, tmp / "w.exr")  # warm-up
            for i in range(a.runs):
                for label, exe, p in (runs if i % 2 == 0 else runs[::-1]):
                    out = tmp / f"{label}.exr"
                    t, n, wall = render(exe, p, a.spp, 1 + i, a.threads, out)
                    s = stats[label]
                    s["t"].append(t)
                    s["setup"].append(wall - t)
                    rays[label] = n
                    if label != "pinhole":
                        s["e"].append(rel_rmse(read_xyz(out), ref))
        finally:
            for p in paths.values():
                p.unlink()
        med = {k: statistics.median(v["t"]) for k, v in stats.items()}
        err = {k: statistics.median(v["e"]) for k, v in stats.items() if v["e"]}
        for label, s in stats.items():
            through = rays[label] / (w * h * a.spp) if label != "pinhole" else 1.0
            e = err.get(label)
            eq = e * e * med[label] / (err["bounds"] ** 2 * med["bounds"]) if e else float("nan")
            print(f"{name},{label},{med[label]:.3f},{statistics.median(s['setup']):.3f},"
                  f"{through:.3f},{e if e else float('nan'):.5f},"
                  f"{med[label] / med['pinhole']:.3f},{eq:.3f}", flush=True)


if __name__ == "__main__":
    main()
