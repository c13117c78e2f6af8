#!/usr/bin/env python3
"""Specialised kernels against the general kernel and against builds without the code.

For each case (a scene, its integrator, and the features it does not use), this builds
heron once more with HERON_STRIP naming those features, so that their code is not in
the binary at all, and then renders the scene, interleaved run by run:

- auto:     the normal build, the kernel specialised to the scene (`--kernel auto`);
- general:  the normal build, every feature compiled in (`--kernel general`);
- stripped: the HERON_STRIP build (its general kernel lacks the stripped features,
            so it is the same code as `auto`, in a binary without the rest).

It prints the median render time of each (the `in X s` of heron's summary line, which
excludes loading and writing) and two ratios: auto / stripped (the issue's goal: within
2%, i.e. a scene does not pay for features it lacks) and general / auto (what the
specialisation saves). One thread, so that the machine's second core absorbs noise.

Usage: python3 scripts/bench_kernels.py [--runs 7]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (scene, integrator, what it lacks, spp); each at the scene's own resolution.
CASES = [
    ("default", "whitted", "specular,emitters", 64),
    ("prism", "whitted", "shadows,emitters", 64),
    ("cornell-box", "path", "escape", 16),
]

TIME = re.compile(r" in ([0-9.]+) s: ")


def build(strip):
    env = dict(os.environ)
    target = os.path.join(ROOT, "target")
    if strip:
        env["HERON_STRIP"] = strip
        target = os.path.join(ROOT, "target", "strip-" + strip.replace(",", "-"))
    env["CARGO_TARGET_DIR"] = target
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, env=env, check=True)
    return os.path.join(target, "release", "heron")


def render(exe, scene, integrator, spp, kernel, out):
    cmd = [exe, "render", os.path.join(ROOT, "scenes", scene + ".toml"), "-o", out,
           "--spp", str(spp), "--threads", "1", "--integrator", integrator,
           "--kernel", kernel, "--quiet", "--no-png"]
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    m = TIME.search(r.stderr)
    if not m:
        sys.exit("no time in: " + r.stderr)
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=7)
    a = ap.parse_args()
    main_exe = build(None)
    print(f"# {a.runs} interleaved runs per variant, one thread, median render time")
    print("scene,integrator,stripped,spp,auto_s,general_s,stripped_s,auto_over_stripped,general_over_auto")
    with tempfile.TemporaryDirectory() as tmp:
        for scene, integ, strip, spp in CASES:
            strip_exe = build(strip)
            out = os.path.join(tmp, "o.exr")
            times = {"auto": [], "general": [], "stripped": []}
            runs = [("auto", main_exe, "auto"), ("general", main_exe, "general"),
                    ("stripped", strip_exe, "general")]
            # Warm-up: page cache, CPU frequency.
            render(main_exe, scene, integ, spp, "auto", out)
            for i in range(a.runs):
                order = runs if i % 2 == 0 else runs[::-1]
                for name, exe, k in order:
                    times[name].append(render(exe, scene, integ, spp, k, out))
            med = {k: statistics.median(v) for k, v in times.items()}
            print(f"{scene},{integ},{strip.replace(',', '+')},{spp},{med['auto']:.3f},{med['general']:.3f},"
                  f"{med['stripped']:.3f},{med['auto'] / med['stripped']:.3f},"
                  f"{med['general'] / med['auto']:.3f}", flush=True)


if __name__ == "__main__":
    main()
