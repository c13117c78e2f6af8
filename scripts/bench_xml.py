#!/usr/bin/env python3
"""Equal-error render time on a Mitsuba 3 XML scene that both renderers read themselves:
heron through its importer (`heron render scene.xml`), Mitsuba 3 through mi.load_file.

    .venv/bin/python scripts/bench_xml.py [--scene scenes/mitsuba/envmap.xml]
        [-D width=160 -D height=96] [--ref-spp 4096] [--spp 16,64,256] [--rounds 3]
        [--threads 2]

Each renderer is measured against its own high-sample reference, so neither is charged
for the other's small systematic differences (the two RGB uplifts, the films; see
tests/python/test_mitsuba_xml.py). Runs are interleaved (for each round and spp: heron,
then Mitsuba's llvm_ad_spectral, whose kernels a warm-up render compiles first), because
this machine's timings drift by ±15% over minutes; the reported time is the median over
the rounds. Time is the render alone: heron's own "in X s" (after loading the scene and
building Embree's BVH), and the wall time of mi.render. Error is the relative RMSE of
linear sRGB, sqrt(Σ(x − ref)²)/sqrt(Σ ref²). RMSE·√t is constant for an unbiased
estimator; heron's time to Mitsuba's error at the middle spp is
(RMSE·√t of heron / RMSE of Mitsuba)².
"""
from __future__ import annotations

import argparse
import pathlib
import re
import statistics
import subprocess
import tempfile
import time

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[1]


def read_rgb(path):
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def rel_rmse(x, ref):
    return float(np.sqrt(((x - ref) ** 2).sum() / (ref ** 2).sum()))


class Heron:
    name = "heron"

    def __init__(self, scene, defines, threads, tmp):
        self.scene, self.defines, self.threads, self.tmp = scene, defines, threads, tmp

    def render(self, spp, seed):
        out = pathlib.Path(self.tmp) / "h.exr"
        d = [a for kv in self.defines for a in ("-D", kv)]
        p = subprocess.run([str(REPO / "target" / "release" / "heron"), "render", str(self.scene),
                            "-o", str(out), "--spp", str(spp), "--seed", str(seed), "--threads",
                            str(self.threads), "--no-png", *d],
                           check=True, capture_output=True, text=True)
        t = float(re.search(r" in ([0-9.]+) s:", p.stderr).group(1))
        return read_rgb(out), t


class Mitsuba:
    name = "mitsuba llvm_ad_spectral"

    def __init__(self, scene, defines, threads):
        import drjit as dr
        import mitsuba as mi

        self.mi = mi
        mi.set_variant("llvm_ad_spectral")
        dr.set_thread_count(threads)
        params = dict(kv.split("=", 1) for kv in defines)
        self.scene = mi.load_file(str(scene), **params)
        self.render(4, 0)  # compile the kernels

    def render(self, spp, seed):
        t0 = time.perf_counter()
        img = np.array(self.mi.render(self.scene, spp=spp, seed=seed), dtype=np.float64)
        return img, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default=str(REPO / "scenes" / "mitsuba" / "envmap.xml"))
    ap.add_argument("-D", dest="defines", action="append", default=[])
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    defines = a.defines or ["width=160", "height=96"]
    spps = [int(s) for s in a.spp.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        heron = Heron(a.scene, defines, a.threads, tmp)
        mitsuba = Mitsuba(a.scene, defines, a.threads)
        t0 = time.perf_counter()
        refs = {heron.name: heron.render(a.ref_spp, 99_991)[0],
                mitsuba.name: mitsuba.render(a.ref_spp, 99_991)[0]}
        print(f"# references ({a.ref_spp} spp) took {time.perf_counter() - t0:.0f} s", flush=True)
        rows = {}
        for rnd in range(a.rounds):
            for spp in spps:
                for r in (heron, mitsuba):
                    img, t = r.render(spp, 1000 * rnd + spp)
                    rows.setdefault((r.name, spp), []).append((t, rel_rmse(img, refs[r.name])))
        print(f"# {a.scene} {' '.join(defines)}; median over {a.rounds} interleaved rounds")
        print("| renderer | spp | time (s) | rel. RMSE | RMSE·√t |")
        print("| --- | --- | --- | --- | --- |")
        eff = {}
        for (name, spp), v in sorted(rows.items()):
            t = statistics.median(x[0] for x in v)
            e = statistics.median(x[1] for x in v)
            eff.setdefault(name, []).append(e * np.sqrt(t))
            print(f"| {name} | {spp} | {t:.3f} | {e:.4f} | {e * np.sqrt(t):.4f} |")
        mid = spps[len(spps) // 2]
        m = rows[(mitsuba.name, mid)]
        t_m = statistics.median(x[0] for x in m)
        e_m = statistics.median(x[1] for x in m)
        h = statistics.median(eff[heron.name])
        t_eq = (h / e_m) ** 2
        print(f"# heron reaches Mitsuba's {mid}-spp error ({e_m:.4f}, {t_m:.3f} s) in {t_eq:.3f} s: "
              f"{t_eq / t_m:.2f}× Mitsuba's time")


if __name__ == "__main__":
    main()
