#!/usr/bin/env python3
"""Error against time of the path tracer's estimators in media (issue 21).

For each scene: one reference (independent sampler, seed 1000, many samples, rendered
once with the default estimators: every estimator here is unbiased, so they share its
expected value), then rounds in which every configuration renders at every spp with the
round's seed, interleaved (config A, B, C, ... then the next round), so that the
machine's drift hits all alike. Per configuration and spp: the median render time
(`RenderResult.wall_seconds`: tracing only, the scene and its Lorenz-Mie tables are
loaded once), the relative RMSE over linear sRGB (sqrt(sum (a - r)^2 / sum r^2), as
`heron converge`) as the root mean square over the rounds, RMSE * sqrt(t), and the time
to 5% relative RMSE at 480x270 extrapolated as t5 = (RMSE sqrt(t) / 0.05)^2 * pixels
ratio (time per sample and variance per pixel both scale with the pixel count). The
reference's own error is estimated from the best configuration's error, scaled by
sqrt(spp / reference spp), and printed: it adds in quadrature to every row.

    .venv/bin/python scripts/bench_media.py --scenes fogbow,rain-curtain \
        --size 160,90 --spp 64,256 --reference-spp 8192 --rounds 3
"""
import argparse
import pathlib
import re
import statistics
import sys
import tempfile

import numpy as np

import heron

ROOT = pathlib.Path(__file__).resolve().parent.parent
CONFIGS = {
    "collision, no guide (before)": ("collision", 0.0),
    "forced, no guide": ("forced", 0.0),
    "collision, guide 0.5": ("collision", 0.5),
    "forced, guide 0.125": ("forced", 0.125),
    "forced, guide 0.25 (default)": ("forced", 0.25),
    "forced, guide 0.5": ("forced", 0.5),
    "forced, guide 0.75": ("forced", 0.75),
}


def scene_at(name, w, h, tmp):
    """The scene file `scenes/NAME.toml` at w x h pixels (its meshes found from tmp)."""
    src = ROOT / "scenes" / f"{name}.toml"
    text = src.read_text()
    text, n = re.subn(r"resolution = \[\d+, \d+\]", f"resolution = [{w}, {h}]", text)
    if n != 1:
        sys.exit(f"{src}: expected one resolution line")
    text = text.replace('file = "meshes/', f'file = "{ROOT}/scenes/meshes/')
    path = pathlib.Path(tmp) / f"{name}-{w}x{h}.toml"
    path.write_text(text)
    return heron.load_scene(str(path))


def rel_rmse(a, r):
    return float(np.sqrt(((a.astype(np.float64) - r) ** 2).sum() / (r.astype(np.float64) ** 2).sum()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="fogbow,rain-curtain")
    ap.add_argument("--size", default="160,90")
    ap.add_argument("--spp", default="64,256")
    ap.add_argument("--reference-spp", type=int, default=8192)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--configs", default="", help="comma-separated indices into the list (default: all)")
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.split(","))
    spps = [int(x) for x in a.spp.split(",")]
    names = list(CONFIGS)
    if a.configs:
        names = [names[int(i)] for i in a.configs.split(",")]
    scale = 480 * 270 / (w * h)
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.scenes.split(","):
            scene = scene_at(name, w, h, tmp)
            ref = scene.render(
                spp=a.reference_spp, seed=1000, sampler="independent", threads=a.threads
            )
            r = ref.rgb.astype(np.float64)
            print(f"# {name}: {w}x{h}, reference {a.reference_spp} spp (independent, default"
                  f" estimators) in {ref.wall_seconds:.1f} s", flush=True)
            times = {(c, s): [] for c in names for s in spps}
            errs = {(c, s): [] for c in names for s in spps}
            means = {c: [] for c in names}
            for k in range(a.rounds):
                for c in names:
                    nee, guide = CONFIGS[c]
                    for s in spps:
                        res = scene.render(spp=s, seed=k, threads=a.threads,
                                           medium_nee=nee, sun_guide=guide)
                        times[(c, s)].append(res.wall_seconds)
                        errs[(c, s)].append(rel_rmse(res.rgb, r))
                        means[c].append(float(res.rgb.mean()))
            print("| configuration | spp | time (s) | relative RMSE | RMSE·√t | t to 5% at 480×270 (s) |")
            print("| --- | --- | --- | --- | --- | --- |")
            best = None
            for c in names:
                for s in spps:
                    t = statistics.median(times[(c, s)])
                    e = float(np.sqrt(np.mean(np.square(errs[(c, s)]))))
                    k = e * np.sqrt(t)
                    if s == spps[-1] and (best is None or e < best[0]):
                        best = (e, s)
                    print(f"| {c} | {s} | {t:.3f} | {e:.4f} | {k:.4f} | {(k / 0.05) ** 2 * scale:.1f} |")
            print(f"(reference's own error about {best[0] * np.sqrt(best[1] / a.reference_spp):.4f};"
                  f" image means: reference {r.mean():.5f}, "
                  + ", ".join(f"{c} {np.mean(means[c]):.5f}" for c in names) + ")", flush=True)


if __name__ == "__main__":
    main()
