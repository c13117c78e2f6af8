"""A heterogeneous medium in Mitsuba 3's form, read by both renderers (issue 39): the
test writes a density grid as a Mitsuba `.vol` file (24³ cells: an off-centre blob
brightening upward, so a grid read in the wrong axis order or mirrored is seen) and an
XML scene with a `heterogeneous` medium whose σ_t is that `gridvolume` (grey extinction,
`scale` 5, albedo 0.8, Henyey–Greenstein g = 0.4) in a null cube, on a grey floor under a
white sky and a small area light (the cube 0.1 above the floor: a medium's boundary on
the floor's plane is rendered differently by the two, 20% apart where they touch, with a
homogeneous medium too). Mitsuba 3 (`scalar_spectral`, `volpath`) renders it
itself, heron through its importer (the gridvolume becomes a `grid` density placed in
the box its `to_world` maps the unit cube to), and the linear sRGB images are held to
each other with test_mitsuba_xml.py's measures (whole-image z per channel beyond the
films' 0.2% floor, Bonferroni-corrected 1%; every 16-pixel region within 3%).

The second test gives heron the grid mirrored in x: the measures must reject it.
"""
from __future__ import annotations

import pathlib

import numpy as np
import pytest

from test_mitsuba_xml import agreement, render_heron, render_mitsuba, same

PARAMS = {"width": "160", "height": "96"}
SPP = 256
N = 24

XML = """<?xml version="1.0" encoding="utf-8"?>
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <default name="width" value="160"/>
    <default name="height" value="96"/>
    <integrator type="volpath">
        <integer name="max_depth" value="-1"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 1.6, 4.5" target="0, 0.6, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/>
            <integer name="height" value="$height"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant">
        <rgb name="radiance" value="0.6, 0.6, 0.6"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="0.5"/>
            <rotate x="1" angle="90"/>
            <translate x="1.0" y="3.0" z="1.0"/>
        </transform>
        <emitter type="area">
            <rgb name="radiance" value="15, 15, 15"/>
        </emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="5"/>
            <rotate x="1" angle="-90"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.4, 0.4, 0.4"/>
        </bsdf>
    </shape>
    <shape type="cube">
        <transform name="to_world">
            <scale value="0.7"/>
            <translate x="0" y="0.8" z="0"/>
        </transform>
        <bsdf type="null"/>
        <medium type="heterogeneous" name="interior">
            <volume type="gridvolume" name="sigma_t">
                <string name="filename" value="blob.vol"/>
                <transform name="to_world">
                    <translate x="-0.5" y="-0.5" z="-0.5"/>
                    <scale value="1.4"/>
                    <translate x="0" y="0.8" z="0"/>
                </transform>
            </volume>
            <float name="scale" value="5"/>
            <float name="albedo" value="0.8"/>
            <phase type="hg">
                <float name="g" value="0.4"/>
            </phase>
        </medium>
    </shape>
</scene>
"""


def blob(mirror: bool = False) -> np.ndarray:
    """Densities at the cell centres, indexed [z, y, x]: a blob left of centre, denser
    upward."""
    c = (np.arange(N) + 0.5) / N
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    if mirror:
        x = 1.0 - x
    r2 = (x - 0.35) ** 2 + (y - 0.5) ** 2 + (z - 0.5) ** 2
    return (np.exp(-r2 / 0.06) * (0.3 + 0.7 * y)).astype("<f4")


def write_vol(path: pathlib.Path, d: np.ndarray) -> None:
    """Mitsuba's .vol (src/render/volumegrid.cpp): "VOL", version 3, encoding 1, the
    resolution and channel count as int32, the box as 6 float32, the values x fastest."""
    header = b"VOL" + bytes([3]) + np.array([1, N, N, N, 1], "<i4").tobytes()
    header += np.array([0, 0, 0, 1, 1, 1], "<f4").tobytes()
    path.write_bytes(header + d.tobytes())


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    d = tmp_path_factory.mktemp("grid-medium")
    write_vol(d / "blob.vol", blob())
    xml = d / "grid-medium.xml"
    xml.write_text(XML)
    return xml


@pytest.fixture(scope="module")
def mitsuba_grid(scene):
    return render_mitsuba(scene, PARAMS, SPP)


def test_a_grid_medium_renders_in_heron_as_in_mitsuba(tmp_path, scene, mitsuba_grid):
    a = render_heron(scene, tmp_path, PARAMS, SPP)
    assert a.shape == mitsuba_grid.shape
    z, worst = agreement(a, mitsuba_grid)
    print(f"grid medium: whole-image z {z}, largest region difference {worst:.2%}; means "
          f"heron {a.mean((0, 1))} Mitsuba {mitsuba_grid.mean((0, 1))}")
    assert same(z, worst), (z, worst)


def test_a_mirrored_grid_fails_the_comparison(tmp_path, scene, mitsuba_grid):
    d = tmp_path / "mirrored"
    d.mkdir()
    write_vol(d / "blob.vol", blob(mirror=True))
    xml = d / "grid-medium.xml"
    xml.write_text(scene.read_text())
    a = render_heron(xml, tmp_path, PARAMS, SPP)
    z, worst = agreement(a, mitsuba_grid)
    print(f"mirrored grid: whole-image z {z}, largest region difference {worst:.2%}")
    assert not same(z, worst), (z, worst)
