"""`heron view` (issue 43): the loopback server checked over HTTP against OpenEXR's own
reading of the files, and the page checked in a real browser (Debian's chromium,
headless, through Selenium and Debian's chromedriver).

The renders are small (96×64, a few spp): the checks are of values and behaviour, not of
noise, and every one of them compares exact numbers or bytes.
"""
from __future__ import annotations

import http.client
import json
import os
import pathlib
import signal
import subprocess
import urllib.request

import numpy as np
import OpenEXR
import pytest
from PIL import Image

import viewerdriver as vd
from heronrun import REPO, require_heron_bin


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two renders of the course's default scene (different seeds, with XYZ, 8 spectral
    bins and the variance) and a polarised Brewster render with spectral bins."""
    d = tmp_path_factory.mktemp("view")
    scene = vd.small_scene("default.toml", d / "default.toml")
    a = vd.render(scene, d / "a.exr", "--spp", "8", "--xyz", "--spectral-bins", "8", "--variance")
    b = vd.render(scene, d / "b.exr", "--spp", "8", "--seed", "7", "--xyz", "--spectral-bins", "8",
                  "--variance")
    pol = vd.render(vd.small_scene("brewster.toml", d / "brewster.toml", spp=4), d / "pol.exr",
                    "--spectral-bins", "4")
    return d, a, b, pol


@pytest.fixture(scope="module")
def server(files):
    d, a, b, pol = files
    s = vd.Server(["view", str(a), str(b), str(pol), "--no-browser"], cwd=d)
    yield s
    s.close()


def channels(path: pathlib.Path) -> dict[str, np.ndarray]:
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {name: np.asarray(c.pixels, dtype=np.float32)
                for name, c in f.channels().items()}


def get(server, path: str, host: str | None = None):
    """A GET with the path sent as written (no client-side normalisation of `..`)."""
    c = http.client.HTTPConnection("127.0.0.1", server.port, timeout=30)
    c.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
    c.putheader("Host", host or f"127.0.0.1:{server.port}")
    c.endheaders()
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, dict(r.getheaders()), body


def test_the_api_serves_each_exr_channel_as_openexr_reads_it(server, files):
    _, a, _, pol = files
    listing = json.loads(get(server, "/api/images")[2])
    imgs = listing["images"]
    assert [pathlib.Path(i["name"]).name for i in imgs] == ["a.exr", "b.exr", "pol.exr"]
    for index, path in ((0, a), (2, pol)):
        ref = channels(path)
        img = imgs[index]
        assert sorted(img["channels"]) == sorted(ref), "the same channels as OpenEXR lists"
        h, w = next(iter(ref.values())).shape
        assert (img["width"], img["height"]) == (w, h) == (96, 64)
        for k, name in enumerate(img["channels"]):
            status, _, body = get(server, f"/api/image/{index}/channel/{k}")
            assert status == 200
            got = np.frombuffer(body, dtype="<f4").reshape(h, w)
            np.testing.assert_array_equal(got, ref[name], err_msg=name)
    assert imgs[0]["variance"] and not imgs[0]["polarised"] and len(imgs[0]["bins"]) == 8
    assert imgs[2]["polarised"] and len(imgs[2]["bins"]) == 4
    views = {v["id"] for v in imgs[2]["views"]}
    assert {"rgb", "s1", "s2", "s3", "dolp", "aolp"} <= views
    # The provenance is heron info's.
    info = subprocess.run([str(require_heron_bin()), "info", str(a)], capture_output=True,
                          text=True, check=True).stdout
    prov = dict(imgs[0]["provenance"])
    assert prov["spp"] == "8" and f"spp: {prov['spp']}" in info


def test_the_rgb_view_is_heron_displays_png(server, files):
    """The server draws a view with heron's own display transform: at +1.5 EV it is the
    PNG `heron display --exposure 1.5` writes, byte for byte."""
    d, a, _, _ = files
    out = d / "display.png"
    subprocess.run([str(require_heron_bin()), "display", str(a), "-o", str(out), "--exposure", "1.5"],
                   check=True, capture_output=True)
    want = np.asarray(Image.open(out).convert("RGB"))
    status, headers, body = get(server, "/api/image/0/view?view=rgb&ev=1.5&mode=hue")
    assert status == 200 and headers["X-Width"] == "96"
    got = np.frombuffer(body, dtype=np.uint8).reshape(64, 96, 4)
    np.testing.assert_array_equal(got[..., :3], want)
    assert (got[..., 3] == 255).all()


def test_requests_outside_the_page_and_the_files_are_refused(server, files):
    d, a, _, _ = files
    secret = (REPO / "Cargo.toml").read_bytes()
    for path in ["/../Cargo.toml", "/../../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd",
                 "/api/image/0/../../../Cargo.toml", "/Cargo.toml", "/etc/passwd", str(a),
                 "/a.exr", "/api/image/3/channel/0", "/api/image/0/channel/999"]:
        status, _, body = get(server, path)
        assert status in (403, 404), f"{path}: {status}"
        assert b"root:" not in body and secret not in body and len(body) < 400, path
    # Another site's page reaching 127.0.0.1 through a rebound DNS name is refused.
    assert get(server, "/api/images", host="attacker.example")[0] == 403
    # Bad numbers get a 400 that says what was expected.
    status, _, body = get(server, "/api/image/0/view?ev=bright")
    assert status == 400 and b"ev: expected a number" in body
    status, _, body = get(server, "/api/image/0/pixel?x=96&y=0")
    assert status == 400 and b"0..96" in body
    # The server listens on the loopback address only (/proc/net/tcp: 0100007F).
    listening = [line.split() for line in pathlib.Path("/proc/net/tcp").read_text().splitlines()[1:]]
    mine = [f[1] for f in listening if f[3] == "0A" and int(f[1].split(":")[1], 16) == server.port]
    assert mine == [f"0100007F:{server.port:04X}"]


def test_bad_files_get_an_error_naming_them_and_no_server(tmp_path):
    text = tmp_path / "notes.exr"
    text.write_text("not an image")
    for args, expect in [([str(tmp_path / "missing.exr")], "missing.exr"),
                         ([str(text)], "notes.exr: cannot read it as OpenEXR")]:
        r = subprocess.run([str(require_heron_bin()), "view", *args, "--no-browser"],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 1, r
        assert expect in r.stderr and "heron view: http" not in r.stdout, r.stderr


def test_ctrl_c_ends_the_viewer_with_status_0(files):
    """Also when SIGINT comes in ignored, as in a background job of a script."""
    _, a, _, _ = files
    import signal as sig

    s = vd.Server(["view", str(a), "--no-browser"],
                  preexec_fn=lambda: sig.signal(sig.SIGINT, sig.SIG_IGN))
    try:
        assert json.loads(get(s, "/api/images")[2])["images"]
        s.proc.send_signal(sig.SIGINT)
        assert s.proc.wait(timeout=30) == 0
    finally:
        s.close()


@pytest.fixture(scope="module")
def page(server):
    driver = vd.browser()
    driver.get(server.url)
    vd.wait_for(driver, "window.heronViewer && window.heronViewer.drawn > 0")
    yield driver
    driver.quit()


def canvas_rgba(driver, sx: int, sy: int) -> list[int]:
    return driver.execute_script(
        "return Array.from(document.getElementById('canvas').getContext('2d')"
        f".getImageData({sx}, {sy}, 1, 1).data);")


def canvas_hash(driver) -> int:
    return driver.execute_script(
        "const c = document.getElementById('canvas');"
        "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
        "let h = 0; for (let i = 0; i < d.length; i++) h = (h * 31 + d[i]) | 0; return h;")


def test_the_page_shows_a_clicked_pixels_values_and_spectrum(page, files):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    _, a, _, _ = files
    ref = channels(a)
    assert page.title == "heron view"
    page.find_element(By.ID, "one").click()
    assert page.execute_script("return window.heronViewer.zoom;") == 1
    # 8 screen pixels per image pixel from the viewport's corner: a click lands on the
    # middle of its pixel whatever the rounding of the pointer's position.
    page.execute_script("const S = window.heronViewer; S.ox = 0; S.oy = 0; S.zoomTo(8, 0, 0);")
    canvas = page.find_element(By.ID, "canvas")
    x, y = 41, 37  # on the sphere, lit
    ActionChains(page).move_to_element_with_offset(
        canvas, 8 * x + 4 - canvas.size["width"] // 2, 8 * y + 4 - canvas.size["height"] // 2
    ).click().perform()
    vd.wait_for(page, f"document.getElementById('px-xy').dataset.x === '{x}' && "
                      f"document.getElementById('px-xy').dataset.y === '{y}' && "
                      "document.getElementById('px-pinned').textContent === 'pinned'")
    rgb = [float(v) for v in page.find_element(By.ID, "px-rgb").text.split(",")]
    np.testing.assert_allclose(rgb, [ref[c][y, x] for c in "RGB"], rtol=1e-5)
    xyz = [float(v) for v in page.find_element(By.ID, "px-xyz").text.split(",")]
    np.testing.assert_allclose(xyz, [ref[c][y, x] for c in "XYZ"], rtol=1e-5)
    se = [float(v) for v in page.find_element(By.ID, "px-stderr").text.split(",")]
    np.testing.assert_allclose(se, [np.sqrt(ref[f"variance.{c}"][y, x]) for c in "RGB"], rtol=1e-5)
    rows = page.execute_script(
        "return Array.from(document.querySelectorAll('#spectrum-table tr'))"
        ".map(r => [Number(r.dataset.lambda), Number(r.dataset.s0)]);")
    bins = sorted((float(n[3:-2].replace(",", ".")), n) for n in ref if n.startswith("S0."))
    assert [r[0] for r in rows] == pytest.approx([l for l, _ in bins])
    assert [r[1] for r in rows] == [float(ref[n][y, x]) for _, n in bins]
    plotted = page.execute_script(
        "return document.querySelector('#spectrum polyline[data-series=s0]')"
        ".getAttribute('points').split(' ').length;")
    assert plotted == 8
    # The canvas shows the server's picture at 0 EV under the pixel.
    want0 = np.frombuffer(urllib.request.urlopen(
        f"{page.current_url}api/image/0/view?view=rgb&ev=0&mode=hue").read(), np.uint8).reshape(64, 96, 4)
    assert canvas_rgba(page, 8 * x + 4, 8 * y + 4) == list(want0[y, x])


def test_exposure_changes_the_canvas_as_heron_display_does(page, files):
    d, a, _, _ = files
    assert page.execute_script("return window.heronViewer.zoom;") == 8
    x, y = 20, 50  # the green ground
    sx, sy = 8 * x + 4, 8 * y + 4
    before = canvas_rgba(page, sx, sy)
    n = vd.drawn(page)
    page.execute_script("const e = document.getElementById('ev'); e.value = 2; "
                        "e.dispatchEvent(new Event('input'));")
    vd.after_draw(page, n)
    after = canvas_rgba(page, sx, sy)
    assert after != before
    out = d / "display-2.png"
    subprocess.run([str(require_heron_bin()), "display", str(a), "-o", str(out), "--exposure", "2"],
                   check=True, capture_output=True)
    assert after[:3] == list(np.asarray(Image.open(out).convert("RGB"))[y, x])
    n = vd.drawn(page)
    page.execute_script("const e = document.getElementById('ev'); e.value = 0; "
                        "e.dispatchEvent(new Event('input'));")
    vd.after_draw(page, n)
    assert canvas_rgba(page, sx, sy) == before


def test_ab_flip_and_the_z_map(page):
    from selenium.webdriver.common.by import By

    a_hash = canvas_hash(page)
    n = vd.drawn(page)
    page.find_element(By.ID, "flip").click()
    vd.after_draw(page, n)
    assert page.find_element(By.ID, "status").text.startswith("B: ")
    assert "b.exr" in page.find_element(By.ID, "status").text
    assert canvas_hash(page) != a_hash, "B is another render: other noise"
    n = vd.drawn(page)
    page.find_element(By.ID, "flip").click()
    vd.after_draw(page, n)
    assert page.find_element(By.ID, "status").text.startswith("A: ")
    assert canvas_hash(page) == a_hash
    n = vd.drawn(page)
    page.find_element(By.ID, "zmap").click()
    vd.after_draw(page, n)
    # Two seeds of one scene: heron compare calls them the same up to noise.
    assert "same up to noise" in page.find_element(By.ID, "compare-status").text
    assert canvas_hash(page) != a_hash, "the overlay is drawn"
    n = vd.drawn(page)
    page.find_element(By.ID, "zmap").click()
    vd.after_draw(page, n)
    assert canvas_hash(page) == a_hash


def test_polarised_views_and_a_refused_path_in_the_browser(page, server, files):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    n = vd.drawn(page)
    page.find_elements(By.CSS_SELECTOR, "#files button")[2].click()
    vd.after_draw(page, n)
    options = [o.get_attribute("value") for o in Select(page.find_element(By.ID, "view")).options]
    assert {"s1", "dolp", "aolp"} <= set(options)
    for view in ("dolp", "s1"):
        n = vd.drawn(page)
        Select(page.find_element(By.ID, "view")).select_by_value(view)
        vd.after_draw(page, n)
        assert view in page.find_element(By.ID, "status").text
    page.save_screenshot(str(files[0] / "viewer.png"))
    assert Image.open(files[0] / "viewer.png").size[0] > 0
    # The browser resolves the dots itself and asks for /etc/passwd: not served.
    page.get(server.url + "%2e%2e/%2e%2e/etc/passwd")
    body = page.find_element(By.TAG_NAME, "body").text
    assert "the viewer serves only its page and the images it was given" in body
    assert "root:" not in body


def test_render_view_shows_the_passes_then_the_file(tmp_path):
    """`heron render --view`: the viewer holds the render in progress (a preview at every
    pass boundary here, --preview-every 0.001), then the finished EXR with its
    provenance; Ctrl-C ends it with status 0. At 256×256 a Whitted pass is 64 spp
    (2²² pixel samples, render/mod.rs), so 160 spp are three passes: two previews."""
    scene = vd.small_scene("default.toml", tmp_path / "default.toml", resolution=(256, 256), spp=160)
    out = tmp_path / "live.exr"
    s = vd.Server(["render", str(scene), "-o", str(out), "--view", "--no-browser", "--quiet",
                   "--preview-every", "0.001"], cwd=tmp_path)
    try:
        # The render reports when it has put the finished file in the viewer.
        err = ""
        while "the viewer shows" not in err:
            line = s.proc.stderr.readline()
            assert line, f"heron render ended early: {err}"
            err += line
        listing = json.loads(get(s, "/api/images")[2])
        assert listing["generation"] == 3, "two previews during the render, then the file"
        img = listing["images"][0]
        assert img["name"].endswith("live.exr") and dict(img["provenance"])["spp"] == "160"
        ref = channels(out)
        k = img["channels"].index("R")
        got = np.frombuffer(get(s, f"/api/image/0/channel/{k}")[2], "<f4").reshape(256, 256)
        np.testing.assert_array_equal(got, ref["R"])
        s.proc.send_signal(signal.SIGINT)
        assert s.proc.wait(timeout=30) == 0
    finally:
        s.close()
    bad = subprocess.run([str(require_heron_bin()), "render", str(scene), "-o",
                          str(tmp_path / "x.heronfilm"), "--view", "--no-browser"],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 1 and "--view: a .heronfilm output" in bad.stderr
