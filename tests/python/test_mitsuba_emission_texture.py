"""A textured area light read by both renderers: scenes/mitsuba/emission-texture.xml (a
rectangle emitting a coloured checkerboard inside Mitsuba's `d65` texture, scale 4,
standing on a grey floor and seen directly, under a dim constant sky), loaded by Mitsuba
3 (`scalar_spectral`) itself and by heron through its importer (`emission = { texture,
scale }`), the two linear sRGB images held to each other region by region with the
helpers and criterion of test_mitsuba_xml.py (whole-image z beyond the films' 0.2% floor
per channel, Bonferroni 1% over the three; every 16-pixel region within 3%).

128 × 96 at 128 spp: measured whole-image z 0 (within the films' floor) in each channel
and the largest region difference 2.2% (a region straddling the light's edge and the
squares' saturated colours, where the two uplifts' metamerism shows); both renders and
the comparison take 5 s. With heron given the squares swapped (color0 ↔ color1) the same
measures reject it (test_swapped_squares_fail_the_comparison; measured largest region
difference 571%).

The light has no BSDF: Mitsuba 3 makes such an emitter's surface black
(src/render/shape.cpp), and so does heron's importer.
"""
from __future__ import annotations

import pathlib

import pytest

from heronrun import REPO
from test_mitsuba_xml import agreement, render_heron, render_mitsuba, same

XML = REPO / "scenes" / "mitsuba" / "emission-texture.xml"
PARAMS = {"width": "128", "height": "96"}
SPP = 128


@pytest.fixture(scope="module")
def mitsuba_image():
    return render_mitsuba(XML, PARAMS, SPP)


def test_a_checkerboard_light_renders_in_heron_as_in_mitsuba(tmp_path, mitsuba_image):
    a = render_heron(XML, tmp_path, PARAMS, SPP)
    b = mitsuba_image
    assert a.shape == b.shape
    z, worst = agreement(a, b)
    print(f"emission texture: whole-image z {z}, largest region difference {worst:.2%}; "
          f"means heron {a.mean((0, 1))} Mitsuba {b.mean((0, 1))}")
    assert same(z, worst), (z, worst)


def test_swapped_squares_fail_the_comparison(tmp_path: pathlib.Path, mitsuba_image):
    text = XML.read_text()
    swapped = (text.replace('name="color0"', 'name="colorX"')
               .replace('name="color1"', 'name="color0"')
               .replace('name="colorX"', 'name="color1"'))
    assert swapped != text
    xml = tmp_path / "emission-texture-swapped.xml"
    xml.write_text(swapped)
    a = render_heron(xml, tmp_path, PARAMS, SPP)
    z, worst = agreement(a, mitsuba_image)
    print(f"squares swapped: whole-image z {z}, largest region difference {worst:.2%}")
    assert not same(z, worst), (z, worst)
