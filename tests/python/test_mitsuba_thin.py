"""Thin dielectric sheets side by side with Mitsuba 3: scenes/mitsuba/thin.xml (a pane,
one rectangle turned 40°, of index 1.5 and a sphere whose surface is a sheet of index
1.8, in front of a tiled wall under a white sky and a small light; 160×96, 256 spp),
loaded by Mitsuba 3 (`scalar_spectral`, its `thindielectric`) and by heron through its
importer (heron's `thin-dielectric`), the two linear sRGB images held to each other
region by region: every 16-pixel region's mean difference beyond FLOOR (0.5%) of its
mean must pass a z-test on the spread of its pixels' differences (Bonferroni 1% over 60
regions × 3 channels: |z| < 4.0), and the whole image's mean difference its own
(test_mitsuba_xml.agreement: beyond the films' 0.2%).

Measured at 256 spp: whole-image z 0, 0, 0 (within the films' floor), largest region
|z| 1.5, largest region difference 3.4% (noise: the same regions agree within 0.5% at
1024 spp). The regions' z-test is used rather than test_mitsuba_xml's flat 3% per region
because each sheet's Bernoulli choice between reflection and transmission makes the
regions noisier than those of the other XML scenes at this sample count. Given a solid
dielectric for both sheets instead (what the importer did before), heron's image is
rejected: whole-image z about −53 and region |z| up to ~4000 (the sphere becomes a lens
that turns the wall upside down, the pane a half-space of glass). Runtime ~50 s (Mitsuba
once, heron twice).
"""
from __future__ import annotations

import numpy as np
import pytest

from heronrun import REPO
from test_mitsuba_xml import agreement, render_heron, render_mitsuba

XML = REPO / "scenes" / "mitsuba" / "thin.xml"
PARAMS, SPP = {"width": "160", "height": "96"}, 256


# The part of a region's mean difference that the z-test ignores, relative to the
# region's mean: the films' own 0.1–0.2% (test_mitsuba_xml.FILM_FLOOR) and the two RGB
# uplifts of the tiles' texels. Measured at 1024 spp over the 60 regions × 3 channels:
# largest |z| 4.5 with no floor, 0.87 beyond 0.2%, 0.10 beyond 0.5%.
FLOOR = 0.005
N = 16


def region_z(a: np.ndarray, b: np.ndarray, n: int = N) -> np.ndarray:
    """Each n×n region's mean per-pixel difference beyond FLOOR of its mean, over its
    standard error. The pixels' differences are independent (the same texture cancels
    in them), so their spread within the region is the noise of both renders."""
    h, w, c = a.shape
    d = (a - b).reshape(h // n, n, w // n, n, c).transpose(0, 2, 1, 3, 4)
    d = d.reshape(h // n, w // n, n * n, c)
    m = d.mean(2)
    ref = b.reshape(h // n, n, w // n, n, c).mean((1, 3))
    excess = np.sign(m) * np.maximum(np.abs(m) - FLOOR * np.abs(ref), 0)
    se = d.std(2, ddof=1) / np.sqrt(n * n)
    return excess / np.maximum(se, 1e-12)


def agree(a: np.ndarray, b: np.ndarray):
    """The whole image's z (test_mitsuba_xml.agreement), the regions' z, and whether
    both pass at 1% (Bonferroni over the channels, and over regions × channels)."""
    from scipy.stats import norm

    z, worst = agreement(a, b)
    rz = region_z(a, b)
    ok = (np.all(np.abs(z) < norm.ppf(1.0 - 0.01 / 6))
          and np.all(np.abs(rz) < norm.ppf(1.0 - 0.01 / (2 * rz.size))))
    return z, rz, worst, bool(ok)


@pytest.fixture(scope="module")
def mitsuba_image():
    return render_mitsuba(XML, PARAMS, SPP)


def test_thin_sheets_render_in_heron_as_in_mitsuba(tmp_path, mitsuba_image):
    a = render_heron(XML, tmp_path, PARAMS, SPP)
    assert a.shape == mitsuba_image.shape
    z, rz, worst, ok = agree(a, mitsuba_image)
    print(f"thin: whole-image z {z}, largest region |z| {np.abs(rz).max():.2f}, largest "
          f"region difference {worst:.2%}; means heron {a.mean((0, 1))} Mitsuba "
          f"{mitsuba_image.mean((0, 1))}")
    assert ok, (z, rz, worst)


def test_a_solid_dielectric_instead_fails_the_comparison(tmp_path, mitsuba_image):
    """heron given `dielectric` where the file says `thindielectric`."""
    tiles = (XML.parent / ".." / "textures" / "tiles.png").resolve()
    text = (XML.read_text().replace('type="thindielectric"', 'type="dielectric"')
            .replace('value="../textures/tiles.png"', f'value="{tiles}"'))
    assert text.count('type="dielectric"') == 2
    changed = tmp_path / "thin-solid.xml"
    changed.write_text(text)
    a = render_heron(changed, tmp_path, PARAMS, SPP)
    z, rz, worst, ok = agree(a, mitsuba_image)
    print(f"solid dielectric: whole-image z {z}, largest region |z| {np.abs(rz).max():.2f}, "
          f"largest region difference {worst:.2%}")
    assert not ok, (z, rz, worst)
