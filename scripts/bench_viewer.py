"""How long `heron view` takes to open a 4K spectral EXR (issue 43's "under 2 s"), in
two ways, ROUNDS times each, interleaved:

- server: from starting `heron view FILE --no-browser` to the page's first picture
  received by a plain HTTP client (the page, its script, /api/images, the RGB view at
  step 4, which the page asks for when it fits a 4K image into a window narrower than
  960 pixels): the file's decoding plus drawing the picture;
- open browser: Debian's chromium (headless, through Selenium) already running, as a
  desktop's browser is when `heron view` hands it the address: from starting `heron
  view` to the page having drawn its first picture (window.heronViewer.drawn > 0);
- browser started with it: the same, with chromium started at the same moment as
  `heron view` (both share the two cores while the file decodes);
- chromium alone: starting the same browser and loading about:blank, the part of
  "browser" that is not heron's.

The EXR: the course's default scene at 3840×2160, 2 spp, with 16 spectral bins, X, Y,
Z and the variance (25 float channels, about 660 MB), rendered once into the folder given
(or the system's temporary folder).

    .venv/bin/python scripts/bench_viewer.py [--rounds 5] [--dir DIR]
"""
from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import tempfile
import threading
import time
import urllib.request

REPO = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "python"))

import viewerdriver as vd  # noqa: E402


def exr_4k(folder: pathlib.Path) -> pathlib.Path:
    out = folder / "default-4k-spectral.exr"
    if not out.exists():
        scene = vd.small_scene("default.toml", folder / "default-4k.toml", resolution=(3840, 2160), spp=2)
        vd.render(scene, out, "--spectral-bins", "16", "--xyz", "--variance")
    return out


def server_round(exr: pathlib.Path) -> float:
    t0 = time.monotonic()
    s = vd.Server(["view", str(exr), "--no-browser"])
    try:
        for path in ("", "viewer.js", "api/images", "api/image/0/view?view=rgb&ev=0&mode=hue&step=4"):
            urllib.request.urlopen(s.url + path, timeout=60).read()
        return time.monotonic() - t0
    finally:
        s.close()


def browser_round(exr: pathlib.Path) -> float:
    t0 = time.monotonic()
    box = {}
    t = threading.Thread(target=lambda: box.setdefault("driver", vd.browser()))
    t.start()
    s = vd.Server(["view", str(exr), "--no-browser"])
    try:
        t.join()
        d = box["driver"]
        d.get(s.url)
        vd.wait_for(d, "window.heronViewer && window.heronViewer.drawn > 0", timeout=120)
        return time.monotonic() - t0
    finally:
        if "driver" in box:
            box["driver"].quit()
        s.close()


def open_browser_round(exr: pathlib.Path) -> float:
    d = vd.browser()
    try:
        d.get("about:blank")
        t0 = time.monotonic()
        s = vd.Server(["view", str(exr), "--no-browser"])
        try:
            d.get(s.url)
            vd.wait_for(d, "window.heronViewer && window.heronViewer.drawn > 0", timeout=120)
            return time.monotonic() - t0
        finally:
            s.close()
    finally:
        d.quit()


def blank_round() -> float:
    t0 = time.monotonic()
    d = vd.browser()
    try:
        d.get("about:blank")
        return time.monotonic() - t0
    finally:
        d.quit()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--dir", type=pathlib.Path)
    a = ap.parse_args()
    folder = a.dir or pathlib.Path(tempfile.gettempdir())
    exr = exr_4k(folder)
    print(f"{exr}: {exr.stat().st_size / 1e6:.0f} MB")
    times = {"server": [], "open browser": [], "browser started with it": [],
             "chromium alone": []}
    for _ in range(a.rounds):
        times["server"].append(server_round(exr))
        times["open browser"].append(open_browser_round(exr))
        times["browser started with it"].append(browser_round(exr))
        times["chromium alone"].append(blank_round())
    for k, v in times.items():
        print(f"{k}: median {statistics.median(v):.2f} s, min {min(v):.2f} s, max {max(v):.2f} s "
              f"({', '.join(f'{x:.2f}' for x in v)})")


if __name__ == "__main__":
    main()
