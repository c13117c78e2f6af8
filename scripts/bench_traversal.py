#!/usr/bin/env python3
"""heron's Embree queries against a raw C program on identical rays, Embree 3 and 4.

    python3 scripts/bench_traversal.py [--size 1024,1024] [--rounds 9] [--runs 2]

Builds heron against Debian's Embree 3 (target/release) and against the Embree 4.4 of
the pinned embreex wheel in .venv (target/embree4, as scripts/test.sh does), writes
the ~1M-triangle test mesh, then runs `heron bench traversal --raw` with each build,
alternating E3, E4, E3, E4, … `--runs` times. Each run already interleaves heron's
passes with the C program's, `--rounds` timed rounds per (ray set, width); the table
gives, per row and build, every run's heron / raw Mrays/s and heron ÷ raw (the
median over rounds of raw time ÷ heron time), and the median ratio over all runs.

Prints a Markdown table (BENCHMARKS.md "heron bench traversal against raw Embree").
Timing drifts on a shared machine: compare ratios, which are measured back to back.
"""
from __future__ import annotations

import argparse
import glob
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[1]


def build(embree4: bool) -> pathlib.Path:
    env = dict(os.environ)
    target = REPO / "target"
    if embree4:
        libs = glob.glob(str(REPO / ".venv/lib/python3*/site-packages/embreex.libs"))
        if not libs:
            sys.exit("bench_traversal.py: no embreex wheel in .venv (scripts/setup-python.sh)")
        env["HERON_EMBREE4_LIB"] = libs[0]
        target = target / "embree4"
        env["CARGO_TARGET_DIR"] = str(target)
    subprocess.run(["cargo", "build", "--release", "--locked", "--quiet", "--bin", "heron"],
                   cwd=REPO, env=env, check=True)
    return target / "release" / "heron"


def run(binary, mesh, size, rounds):
    out = subprocess.run([str(binary), "bench", "traversal", "--mesh", str(mesh),
                          "--eye", "0,0.3,3", "--look-at", "0,0,0", "--fov", "45",
                          "--size", size, "--rounds", str(rounds), "--raw"],
                         check=True, capture_output=True, text=True).stdout
    rows = {}
    header = ""
    for line in out.splitlines():
        if line.startswith("#"):
            header = line
        f = line.split(",")
        if f[0] in ("coherent", "incoherent"):
            rows[(f[0], f[1])] = (f[4], f[5], f[6])
    return header, rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="1024,1024")
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--runs", type=int, default=2)
    a = ap.parse_args()
    bins = {"Embree 3": build(False), "Embree 4": build(True)}
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-trav-"))
    mesh = tmp / "bumpy.obj"
    subprocess.run([str(bins["Embree 3"]), "bench", "mesh", "-o", str(mesh)], check=True)
    results = {k: [] for k in bins}
    for _ in range(a.runs):
        for name, b in bins.items():
            header, rows = run(b, mesh, a.size, a.rounds)
            print(f"# {name}: {header.lstrip('# ')}", flush=True)
            results[name].append(rows)
    mesh.unlink()
    tmp.rmdir()
    keys = list(results["Embree 3"][0].keys())
    print()
    print("| rays | width | " + " | ".join(
        f"{n}: heron / raw Mrays/s per run | {n}: heron ÷ raw per run (median)" for n in bins) + " |")
    print("| --- | --- | " + " | ".join("--- | ---" for _ in bins) + " |")
    for key in keys:
        cells = []
        for name in bins:
            runs = [r.get(key) for r in results[name]]
            if any(r is None or r[2] == "-" for r in runs):
                cells += ["no stream API", "—"]
                continue
            cells.append("; ".join(f"{h} / {w}" for h, w, _ in runs))
            ratios = [float(x[2]) for x in runs]
            cells.append(", ".join(f"{x:.3f}" for x in ratios)
                         + f" (**{statistics.median(ratios):.3f}**)")
        print(f"| {key[0]} | {key[1]} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
