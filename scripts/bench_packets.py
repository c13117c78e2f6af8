#!/usr/bin/env python3
"""Packets of paths against one path at a time: render time of `--packets paths` over
`--packets camera` per scene and integrator, interleaved.

    .venv/bin/python scripts/bench_packets.py [--scenes default,cornell-box]
        [--integrators whitted,path] [--spp 64] [--rounds 5] [--threads 2]

For each round, scene and integrator the two engines run back to back (their order
alternating between rounds), because this machine's timings drift by ±15% over
minutes; the table gives each engine's median over the rounds of heron's own
"in X s" (the render after the scene is loaded and Embree's BVH built), the median of
the per-round ratios paths/camera and their range. The two images agree up to the last
bits of Embree's hits (tests/packets.rs); the script checks the ray counts agree to
0.5%.

Needs a release build of heron (cargo build --release).
"""
from __future__ import annotations

import argparse
import pathlib
import re
import statistics
import subprocess
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[1]
LINE = re.compile(r" in ([0-9.]+) s: (\d+) rays")


def run(binary, scene, integrator, packets, spp, threads, out):
    p = subprocess.run(
        [str(binary), "render", str(scene), "--integrator", integrator, "--packets", packets,
         "--spp", str(spp), "--threads", str(threads), "--no-png", "-o", str(out)],
        capture_output=True, text=True, check=True)
    m = LINE.search(p.stderr)
    return float(m.group(1)), int(m.group(2))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="default,cornell-box")
    ap.add_argument("--integrators", default="whitted,path")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    binary = REPO / "target" / "release" / "heron"
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="heron-packets-"))
    cases = [(s, i) for s in a.scenes.split(",") for i in a.integrators.split(",")]
    times = {(c, e): [] for c in cases for e in ("paths", "camera")}
    ratios = {c: [] for c in cases}
    for r in range(a.rounds):
        for (scene, integ) in cases:
            path = REPO / "scenes" / f"{scene}.toml"
            order = ("paths", "camera") if r % 2 == 0 else ("camera", "paths")
            got = {}
            for e in order:
                got[e] = run(binary, path, integ, e, a.spp, a.threads, tmp / f"{e}.exr")
                times[((scene, integ), e)].append(got[e][0])
            rays_p, rays_c = got["paths"][1], got["camera"][1]
            if abs(rays_p - rays_c) * 200 > rays_c:
                raise SystemExit(f"{scene} {integ}: rays {rays_p} and {rays_c} differ by >0.5%")
            ratios[(scene, integ)].append(got["paths"][0] / got["camera"][0])
    print(f"{a.spp} spp, {a.threads} threads, median of {a.rounds} interleaved rounds\n")
    print("| scene | integrator | camera (s) | paths (s) | paths ÷ camera (range) |")
    print("| --- | --- | --- | --- | --- |")
    for (scene, integ) in cases:
        tc = statistics.median(times[((scene, integ), "camera")])
        tp = statistics.median(times[((scene, integ), "paths")])
        rs = ratios[(scene, integ)]
        print(f"| {scene} | {integ} | {tc:.3f} | {tp:.3f} | "
              f"{statistics.median(rs):.3f} ({min(rs):.3f}–{max(rs):.3f}) |")


if __name__ == "__main__":
    main()
