"""heron's path tracer against Mitsuba 3 (`scalar_spectral`, `path` integrator), the
independent reference renderer pinned in the test environment.

Both renderers get the same scene: geometry and camera from the heron file, and every
spectrum from `heron spectra` (mitsuba_scene.py), with box pixel filters in both. Both
are unbiased estimators of the same pixel integrals, so the per-pixel difference of their
images has expectation zero everywhere. `heron.compare` (`heron compare`'s test) averages
that difference over regions (a z-test on a downsampled image, as Mitsuba's own render
tests do) with the standard error from the spread of the differences inside each region
(Mitsuba's image has no variance channels), and requires every region and channel, and
the whole image, to pass at a Bonferroni-corrected level: α = 0.0135 over the 195 (183)
tests puts the critical |t| (255 degrees of freedom) at the |z| ≈ 4.04 this test held
before heron.compare, with its normal approximation, at 1% over the regions alone.

Sample counts: at 128×128 (Cornell) and 160×96 (metals) with 512 spp in each renderer,
a 16×16 region's mean difference has a standard error of 0.30–0.45% of its value (median
over the regions; measured), so a region that differs by more than about 2% fails at
the critical z ≈ 4; the whole image's mean difference has a standard error near 0.05%,
and its own z-test detects a difference of about 0.2%. Mitsuba's scalar variant takes
6–7 s per scene on this 2-core machine, heron 3–4 s.
"""
from __future__ import annotations

import pathlib
import re
import subprocess

import numpy as np
import pytest

import heron
from heronrun import REPO, require_heron_bin
from mitsuba_scene import heron_spectra, mitsuba_dict, xyz_normalisation

SCENES = REPO / "scenes"


def _read_xyz(path: pathlib.Path) -> np.ndarray:
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "XYZ"], -1)


def _resized(scene: pathlib.Path, tmp: pathlib.Path, w: int, h: int) -> pathlib.Path:
    text = scene.read_text()
    text, n = re.subn(r"^resolution\s*=\s*\[[^\]]*\]", f"resolution = [{w}, {h}]", text,
                      flags=re.M)
    assert n == 1, f"{scene}: expected one resolution line"
    out = tmp / scene.name
    out.write_text(text)
    return out


def render_heron(scene: pathlib.Path, tmp: pathlib.Path, spp: int, seed: int) -> np.ndarray:
    exr = tmp / f"{scene.stem}-heron.exr"
    subprocess.run([str(require_heron_bin()), "render", str(scene), "-o", str(exr), "--spp",
                    str(spp), "--seed", str(seed), "--xyz", "--no-png", "--quiet"],
                   check=True, capture_output=True, text=True)
    return _read_xyz(exr)


def render_mitsuba(scene: pathlib.Path, spp: int, seed: int) -> np.ndarray:
    import colour
    import mitsuba as mi

    mi.set_variant("scalar_spectral")
    spectra = heron_spectra(require_heron_bin(), scene)
    d = mitsuba_dict(mi, scene, spectra, spp=spp)
    img = np.array(mi.render(mi.load_dict(d), spp=spp, seed=seed), dtype=np.float64)
    return img * xyz_normalisation(mi, colour)


def compare(name: str, w: int, h: int, spp: int, tmp_path) -> None:
    from scipy.stats import norm

    scene = _resized(SCENES / name, tmp_path, w, h)
    a = render_heron(scene, tmp_path, spp, seed=1)
    b = render_mitsuba(scene, spp, seed=2)
    assert a.shape == b.shape == (h, w, 3)
    r = heron.compare(a, b, region=16, alpha=0.0135, correction="bonferroni")
    msg = (f"{name} (channels X, Y, Z; A heron, B Mitsuba):\n{r['report']}"
           f"image means heron {a.mean((0, 1))} vs Mitsuba {b.mean((0, 1))}")
    print(msg)
    assert r["variance_from"] == "spread" and r["tests"] == 3 * (w // 16) * (h // 16) + 3, msg
    assert r["same"], msg
    # The whole image's mean difference also at its own level, as before: within the
    # Bonferroni-corrected 1% of its three channels (|z| < 2.94, where the family's
    # level alone would allow about 4).
    z_all = np.array(r["mean_difference"]) / np.array(r["standard_error"])
    print(f"{name}: whole image z = {z_all}")
    assert np.all(np.abs(z_all) < norm.ppf(1.0 - 0.01 / 6)), f"whole image z = {z_all}; {msg}"


def test_cornell_box_matches_mitsuba(tmp_path):
    compare("cornell-box.toml", 128, 128, 512, tmp_path)


def test_metals_match_mitsuba(tmp_path):
    compare("metals.toml", 160, 96, 512, tmp_path)


def test_the_comparison_can_fail(tmp_path):
    """The same z-test sees a 3% change in one material's reflectance."""
    scene = _resized(SCENES / "cornell-box.toml", tmp_path, 64, 64)
    a = render_heron(scene, tmp_path, 256, seed=1)
    text = scene.read_text().replace("rho_d = [0.885809, 0.698859, 0.666422]",
                                     "rho_d = [0.859235, 0.677893, 0.646429]")
    scene.write_text(text)
    b = render_heron(scene, tmp_path, 256, seed=2)
    r = heron.compare(a, b, region=16, alpha=0.0135, correction="bonferroni")
    assert not r["same"] and np.nanmax(np.abs(r["z"])) > 6.0, r["report"]
