#!/usr/bin/env python3
"""Cost of polarised against unpolarised transport per sample (BENCHMARKS.md,
"Polarised transport"): each scene rendered with and without --polarization, the two
interleaved round by round (this machine's timings drift by ±15% between runs, so each
ratio is taken within a round), at the same spp and seed: four scenes under the path
integrator (fogbow with its Lorenz–Mie fog), the default scene under whitted, the
Cornell box under light tracing and BDPT, and metals under BDPT.

    scripts/bench_polarization.py [--rounds 5] [--spp 16] [--heron target/release/heron]
                                  [--only cornell-box:bdpt,metals:bdpt]

Prints, per scene, the median wall time of each and the median of the per-round
ratios. heron's own "in X s" (the render loop, without loading) is what is timed.
"""
import argparse
import pathlib
import re
import statistics
import subprocess
import tempfile

REPO = pathlib.Path(__file__).resolve().parent.parent
SCENES = [("cornell-box", "path"), ("metals", "path"), ("brewster", "path"),
          ("fogbow", "path"), ("default", "whitted"), ("cornell-box", "lighttrace"),
          ("cornell-box", "bdpt"), ("metals", "bdpt")]


def render(heron, scene, integrator, spp, polarized, tmp):
    # A copy with [render] polarization as asked (brewster.toml turns it on itself);
    # mesh and table paths are relative to scenes/, so the copy lives there too.
    text = (REPO / "scenes" / f"{scene}.toml").read_text()
    text = re.sub(r"(?m)^polarization = \w+\n", "", text)
    text = text.replace("[render]\n", f"[render]\npolarization = {str(polarized).lower()}\n", 1)
    path = REPO / "scenes" / f".bench-polarization-{scene}.toml"
    path.write_text(text)
    cmd = [heron, "render", str(path), "-o", str(pathlib.Path(tmp) / "b.exr"),
           "--integrator", integrator, "--spp", str(spp), "--seed", "1", "--no-png"]
    try:
        log = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    finally:
        path.unlink()
    m = re.search(r" in ([0-9.]+) s", log)
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--heron", default=str(REPO / "target/release/heron"))
    ap.add_argument("--only", default="", help="scene:integrator pairs, comma-separated")
    a = ap.parse_args()
    only = {tuple(p.split(":")) for p in a.only.split(",") if p}
    with tempfile.TemporaryDirectory() as tmp:
        print(f"{'scene':<12} {'integrator':<10} {'unpolarised s':>14} {'polarised s':>12}"
              f" {'ratio':>7}")
        for scene, integrator in SCENES:
            if only and (scene, integrator) not in only:
                continue
            plain, pol, ratio = [], [], []
            for _ in range(a.rounds):
                t0 = render(a.heron, scene, integrator, a.spp, False, tmp)
                t1 = render(a.heron, scene, integrator, a.spp, True, tmp)
                plain.append(t0)
                pol.append(t1)
                ratio.append(t1 / t0)
            print(f"{scene:<12} {integrator:<10} {statistics.median(plain):>14.3f}"
                  f" {statistics.median(pol):>12.3f}"
                  f" {statistics.median(ratio):>7.2f}")


if __name__ == "__main__":
    main()
