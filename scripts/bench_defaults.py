#!/usr/bin/env python3
"""Chooses heron's default sampler, lane count and wavelength sampler by measurement.

    .venv/bin/python scripts/bench_defaults.py [--size 128,128] [--reference-spp 2048] [--spp 16,64]

For each scene (the course's, the Cornell box under `path`, a rainbow sky) and each
setting (sampler × lanes × wavelengths), `heron converge` renders the scene at each spp
against one 2048-spp reference (8 lanes, independent numbers) and reports RMSE·√t, the
efficiency: it is constant for an unbiased estimator and lower is better. The table
lists each setting's median RMSE·√t over the spp values per scene, and the geometric
mean over the scenes of its ratio to the best setting of that scene.
"""
from __future__ import annotations

import argparse
import itertools
import math
import pathlib
import statistics
import subprocess

REPO = pathlib.Path(__file__).resolve().parents[1]
SCENES = ["default", "default-glass", "default-glossy", "default-mirror", "cornell",
          "cornell-box", "rainbow-descartes"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="128,128")
    ap.add_argument("--reference-spp", default="2048")
    ap.add_argument("--spp", default="16,64")
    ap.add_argument("--threads", default="2")
    a = ap.parse_args()
    heron = REPO / "target" / "release" / "heron"
    settings = list(itertools.product(["independent", "sobol"], ["uniform", "visible"]))
    table = {}
    for scene in SCENES:
        for sampler, wl in settings:
            out = subprocess.run(
                [str(heron), "converge", str(REPO / "scenes" / f"{scene}.toml"), "--size", a.size,
                 "--reference-spp", a.reference_spp, "--spp", a.spp, "--lanes", "4,8",
                 "--threads", a.threads, "--sampler", sampler, "--wavelengths", wl, "--seed", "3"],
                check=True, capture_output=True, text=True).stdout
            rows = [r.split(",") for r in out.splitlines() if r and r[0].isdigit()]
            for lanes in ("4", "8"):
                eff = [float(r[5]) for r in rows if r[0] == lanes]
                ns = [float(r[3]) for r in rows if r[0] == lanes]
                table[(scene, sampler, lanes, wl)] = (statistics.median(eff), statistics.median(ns))
            print(f"# {scene} {sampler} {wl} done", flush=True)
    configs = sorted({k[1:] for k in table})
    print("scene," + ",".join("/".join(c) for c in configs))
    ratios = {c: [] for c in configs}
    for scene in SCENES:
        best = min(table[(scene, *c)][0] for c in configs)
        print(scene + "," + ",".join(f"{table[(scene, *c)][0]:.5f}" for c in configs))
        for c in configs:
            ratios[c].append(table[(scene, *c)][0] / best)
    print("geomean ratio to best," + ",".join(
        f"{math.exp(statistics.mean(math.log(r) for r in ratios[c])):.2f}" for c in configs))
    print("ns per sample (median over scenes)," + ",".join(
        f"{statistics.median(table[(s, *c)][1] for s in SCENES):.0f}" for c in configs))


if __name__ == "__main__":
    main()
