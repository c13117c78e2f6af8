#!/usr/bin/env python3
"""Two threads against one: heron's render time on the default scene and the Cornell box.

    python3 scripts/bench_scaling.py [--spp 64] [--rounds 5] [--binary target/release/heron]
        [--packets auto,camera]

The scenes are those of scripts/bench_mitsuba.py and scripts/bench_limit.sh: the
course's default scene with a black background under `whitted`, and the Cornell box
under `path`, each with heron's defaults, or with each `--packets` value given. Every round renders each scene with 1 and
with 2 threads, alternating which goes first, so that the machine's drift (±15% over
minutes here) falls on both alike. Time is heron's own "in X s" (the render, after the
scene is loaded and the BVH built).

Prints, per scene, the median and spread (min–max) of each thread count's time and
the speed-up: the median over rounds of t(1 thread) / t(2 threads), each pair measured
back to back. Uses only Python's standard library.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import re
import statistics
import subprocess
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[1]


def render(binary, scene, integrator, spp, threads, out, packets="auto"):
    p = subprocess.run([str(binary), "render", str(scene), "-o", str(out), "--spp", str(spp),
                        "--integrator", integrator, "--threads", str(threads), "--no-png",
                        "--packets", packets, "--quiet"],
                       check=True, capture_output=True, text=True)
    return float(re.search(r" in ([0-9.]+) s:", p.stderr).group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--binary", default=str(REPO / "target" / "release" / "heron"))
    ap.add_argument("--packets", default="auto",
                    help="comma-separated --packets values, each measured as its own rows "
                         "(e.g. auto,paths,camera)")
    a = ap.parse_args()
    default = REPO / "scenes" / "default.toml"
    text = re.sub(r"(?m)^background\s*=.*$", "background = 0.0", default.read_text())
    # Beside the original, so that relative paths still resolve.
    black = default.with_name(f".default-black-{os.getpid()}.toml")
    black.write_text(text)
    scenes = [(f"{name} --packets {p}", path, integ, p)
              for p in a.packets.split(",")
              for name, path, integ in [
                  ("default scene (black background)", black, "whitted"),
                  ("Cornell box", REPO / "scenes" / "cornell-box.toml", "path")]]
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-scaling-"))
    out = tmp / "s.exr"
    times = {}
    try:
        for name, scene, integ, p in scenes:  # one warm-up render each (page cache)
            render(a.binary, scene, integ, 1, 1, out, p)
        for rnd in range(a.rounds):
            for name, scene, integ, p in scenes:
                order = (1, 2) if rnd % 2 == 0 else (2, 1)
                for threads in order:
                    t = render(a.binary, scene, integ, a.spp, threads, out, p)
                    times.setdefault((name, threads), []).append(t)
    finally:
        black.unlink()
        out.unlink(missing_ok=True)
        tmp.rmdir()
    print(f"# heron {a.spp} spp, {a.rounds} interleaved rounds, {os.cpu_count()} cores")
    print("scene,integrator,t1_median_s,t1_min_s,t1_max_s,t2_median_s,t2_min_s,t2_max_s,"
          "speedup_median,speedup_min,speedup_max")
    for name, _, integ, _ in scenes:
        t1, t2 = times[(name, 1)], times[(name, 2)]
        sp = [x / y for x, y in zip(t1, t2)]
        cells = []
        for v in (t1, t2):
            cells += [statistics.median(v), min(v), max(v)]
        cells += [statistics.median(sp), min(sp), max(sp)]
        print(f"{name},{integ}," + ",".join(f"{c:.3f}" for c in cells))


if __name__ == "__main__":
    main()
