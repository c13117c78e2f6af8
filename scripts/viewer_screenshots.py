"""The guide's pictures of `heron view` (docs/viewer.md, README.md): two renders of the
Airy bow (seeds 0 and 7, 16 spectral bins, XYZ and variance) in the viewer, in Debian's
chromium, headless, at 1280×720:

- docs/images/viewer.png: a pixel of the primary bow pinned, its spectrum plotted;
- docs/images/viewer-zmap.png: heron compare's z-map of the two renders over the image.

Run from the repository's root with the test environment's Python, after
`cargo build --release`:

    .venv/bin/python scripts/viewer_screenshots.py

It renders at the scene's own settings (768×432, 16 spp; about a minute on two cores).
"""
from __future__ import annotations

import pathlib
import shutil
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "python"))

import viewerdriver as vd  # noqa: E402
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402

# A pixel of the primary bow in rainbow-airy.toml's 768×432 image, at the fit zoom.
PIXEL = (384, 168)


def main() -> None:
    images = REPO / "docs" / "images"
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp)
        scene = REPO / "scenes" / "rainbow-airy.toml"
        flags = ("--spectral-bins", "16", "--xyz", "--variance")
        a = vd.render(scene, d / "airy.exr", *flags)
        b = vd.render(scene, d / "airy-seed7.exr", *flags, "--seed", "7")
        server = vd.Server(["view", a.name, b.name, "--no-browser"], cwd=d)
        driver = vd.browser(1280, 720)
        try:
            driver.get(server.url)
            vd.wait_for(driver, "window.heronViewer && window.heronViewer.drawn > 0")
            s = driver.execute_script("const S = window.heronViewer; "
                                      "return {zoom: S.zoom, ox: S.ox, oy: S.oy};")
            canvas = driver.find_element(By.ID, "canvas")
            x = s["ox"] + (PIXEL[0] + 0.5) * s["zoom"] - canvas.size["width"] / 2
            y = s["oy"] + (PIXEL[1] + 0.5) * s["zoom"] - canvas.size["height"] / 2
            ActionChains(driver).move_to_element_with_offset(canvas, int(x), int(y)).click().perform()
            vd.wait_for(driver, "document.getElementById('px-pinned').textContent === 'pinned'")
            driver.execute_script("document.querySelector('#spectrum-table').parentElement.open = true;")
            driver.save_screenshot(str(d / "viewer.png"))
            n = vd.drawn(driver)
            driver.find_element(By.ID, "zmap").click()
            vd.after_draw(driver, n)
            driver.save_screenshot(str(d / "viewer-zmap.png"))
        finally:
            driver.quit()
            server.close()
        for name in ("viewer.png", "viewer-zmap.png"):
            shutil.copyfile(d / name, images / name)
            print(f"wrote docs/images/{name}")


if __name__ == "__main__":
    main()
