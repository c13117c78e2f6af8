"""Driving `heron view` for test_viewer.py and scripts/viewer_screenshots.py: small
renders to look at, the server started on a free loopback port, and Debian's chromium,
headless, through Debian's chromedriver (Selenium is given both paths, so Selenium
Manager never looks for, or downloads, a browser or a driver).
"""
from __future__ import annotations

import os
import pathlib
import re
import subprocess
import time

from heronrun import REPO, require_heron_bin

CHROMIUM = pathlib.Path("/usr/bin/chromium")
CHROMEDRIVER = pathlib.Path("/usr/bin/chromedriver")


def small_scene(src: str, dst: pathlib.Path, resolution=(96, 64), spp=None) -> pathlib.Path:
    """scenes/SRC with its [camera] resolution (and [render] spp) replaced: the image the
    tests look at is small, so that every pixel is quick to find and check."""
    text = (REPO / "scenes" / src).read_text()
    text, n = re.subn(r"(?m)^resolution = \[.*\]$", f"resolution = [{resolution[0]}, {resolution[1]}]", text)
    assert n == 1, f"scenes/{src}: expected one resolution line"
    if spp is not None:
        text, n = re.subn(r"(?m)^spp = \d+", f"spp = {spp}", text)
        assert n == 1, f"scenes/{src}: expected one spp line"
    dst.write_text(text)
    return dst


def render(scene: pathlib.Path, out: pathlib.Path, *flags: str) -> pathlib.Path:
    subprocess.run([str(require_heron_bin()), "render", str(scene), "-o", str(out), "--quiet", *flags],
                   check=True, capture_output=True, text=True, timeout=600)
    return out


class Server:
    """`heron view FILES --no-browser` (or another heron command that opens the viewer)
    on a free port; `url` is the address it printed."""

    def __init__(self, args: list[str], cwd: pathlib.Path | None = None, preexec_fn=None):
        self.proc = subprocess.Popen([str(require_heron_bin()), *args], cwd=cwd,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     preexec_fn=preexec_fn)
        line = self.proc.stdout.readline()
        m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        if not m:
            self.proc.kill()
            raise AssertionError(f"heron printed no address: {line!r} {self.proc.stderr.read()!r}")
        self.port = int(m.group(1))
        self.url = m.group(0)

    def close(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(timeout=30)


def browser(width: int = 1280, height: int = 800):
    """Headless Debian chromium under Selenium, at a fixed window size."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = str(CHROMIUM)
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              f"--window-size={width},{height}", "--force-device-scale-factor=1",
              "--force-color-profile=srgb", "--no-first-run"):
        opts.add_argument(a)
    os.environ.setdefault("SE_OFFLINE", "true")
    return webdriver.Chrome(service=Service(executable_path=str(CHROMEDRIVER)), options=opts)


def wait_for(driver, script: str, timeout: float = 30.0):
    """Polls a JavaScript expression until it is truthy; returns its value."""
    end = time.monotonic() + timeout
    while True:
        value = driver.execute_script(f"return {script};")
        if value:
            return value
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {script}")
        time.sleep(0.05)


def drawn(driver) -> int:
    return driver.execute_script("return window.heronViewer.drawn;")


def after_draw(driver, before: int, timeout: float = 30.0):
    """Waits until the page has drawn another picture since `before`, and nothing is in
    flight."""
    wait_for(driver, f"window.heronViewer.drawn > {before}", timeout)
