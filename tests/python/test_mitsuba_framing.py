"""Framing against Mitsuba 3: a perspective sensor without `fov` (Mitsuba's default 50 mm
focal length, measured on the diagonal of 36 × 24 mm film) frames the same view in heron
and in Mitsuba 3 (`scalar_spectral`, pinned in the test environment) at 1:1, 4:3 and
16:9, to a pixel (issue 38, #7: heron once took the focal length along the longer image
side, which agrees only at 3:2 and drew a square image's objects 15% too small).

The scene, written here, is a white emitting rectangle off the image centre on black.
Each renderer's image becomes a coverage map (pixel over the rectangle's plateau); the
rectangle's width, height and centre in pixels come from the coverage sums. With box
pixel filters and 64 samples per pixel, a coverage sum across an edge has a standard
deviation below 0.1 pixel, so 0.5 pixel is a safe tolerance. Measured (2026-12-07):
heron and Mitsuba within 0.13 pixel in all four numbers at the three sizes; the old
heron build was off by 2.4–8.4 pixels (test_the_old_framing_would_fail shows the
measure seeing it without the old build).
"""
from __future__ import annotations

import pathlib
import subprocess

import numpy as np
import pytest

from heronrun import require_heron_bin

SPP = 64
SIZES = [(96, 96), (128, 96), (160, 90)]

# The emitting rectangle both framing tests measure (off centre, 1.8 × 1.2, black
# where light falls on it), and the scene's end.
RECTANGLE = """    <shape type="rectangle">
        <transform name="to_world"><scale x="0.9" y="0.6" z="1"/><translate x="0.6" y="0.35" z="0"/></transform>
        <emitter type="area"><rgb name="radiance" value="1, 1, 1"/></emitter>
        <bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>
    </shape>
</scene>
"""

SCENE = """<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        {camera}
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="{w}"/><integer name="height" value="{h}"/>
            <rfilter type="box"/>
        </film>
    </sensor>
""" + RECTANGLE


def _write(tmp: pathlib.Path, w: int, h: int, camera: str = "") -> pathlib.Path:
    xml = tmp / f"frame-{w}x{h}.xml"
    xml.write_text(SCENE.format(w=w, h=h, spp=SPP, camera=camera))
    return xml


def _heron(xml: pathlib.Path, tmp: pathlib.Path) -> np.ndarray:
    import OpenEXR

    exr = tmp / (xml.stem + ".exr")
    subprocess.run([str(require_heron_bin()), "render", str(xml), "-o", str(exr), "--spp",
                    str(SPP), "--seed", "1", "--no-png", "--quiet"],
                   check=True, capture_output=True, text=True)
    with OpenEXR.File(str(exr), separate_channels=True) as f:
        return np.array(f.channels()["G"].pixels, dtype=np.float64)


def _mitsuba(xml: pathlib.Path) -> np.ndarray:
    import mitsuba as mi

    mi.set_variant("scalar_spectral")
    return np.array(mi.render(mi.load_file(str(xml)), spp=SPP, seed=2), dtype=np.float64)[..., 1]


def frame(img: np.ndarray) -> np.ndarray:
    """The rectangle's width, height and centre (x, y) in pixels, from its coverage."""
    cov = np.clip(img / np.median(img[img > 0.5 * img.max()]), 0.0, 1.0)
    area = cov.sum()
    ys, xs = np.indices(cov.shape) + 0.5
    cx, cy = (cov * xs).sum() / area, (cov * ys).sum() / area
    # Rows and columns wholly inside the rectangle give its extent along the other axis.
    width = np.median(cov.sum(1)[cov.max(1) > 0.99][1:-1])
    height = np.median(cov.sum(0)[cov.max(0) > 0.99][1:-1])
    return np.array([width, height, cx, cy])


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_default_focal_length_frames_as_in_mitsuba(size, tmp_path):
    xml = _write(tmp_path, *size)
    fh, fm = frame(_heron(xml, tmp_path)), frame(_mitsuba(xml))
    assert np.all(np.abs(fh - fm) < 0.5), (
        f"{size}: heron (w, h, cx, cy) {np.round(fh, 2)}, Mitsuba {np.round(fm, 2)}")


def test_the_old_framing_would_fail(tmp_path):
    """heron's old reading of a 1:1 image, 36 mm along the longer side, is a horizontal
    field of 2·atan(18/50); given to Mitsuba as that fov, the measure sees it."""
    w, h = SIZES[0]
    old = np.degrees(2 * np.arctan(18 / 50))
    fm = frame(_mitsuba(_write(tmp_path, w, h)))
    fo = frame(_mitsuba(_write(tmp_path, w, h, f'<float name="fov" value="{old}"/>')))
    assert np.any(np.abs(fo - fm) > 2.0), (np.round(fo, 2), np.round(fm, 2))
