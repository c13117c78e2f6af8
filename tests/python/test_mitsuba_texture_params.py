"""Textured material parameters beyond the diffuse reflectance, against Mitsuba 3.

One scene (written here, 160×96): on the left a rough metal (constant eta 0.2, k 3, GGX)
whose `alpha` is a checkerboard of 0.05 and 0.35 (4 × 4 squares over the rectangle), on
the right a smooth `plastic` whose `diffuse_reflectance` is a bitmap
(scenes/textures/tiles.png), under a constant grey sky and a small spherical light
whose highlight crosses both. heron renders the XML through its importer: the alpha
checkerboard becomes a table with its colours swapped (Mitsuba reads a float
checkerboard with `eval_1`, which puts color1 where `eval` puts color0), the bitmap an
image table on the coated material's `reflectance`. The comparison is
test_mitsuba_xml.py's: the whole image's z per channel beyond the films' own 0.2%
(FILM_FLOOR), Šidák-corrected at 1%, and every 16×16 region within 3% (the rough
metals' Smith shadowing differs by up to 1.4% between the two, as materials.xml
measures).

Measured at 64 spp (the constant sky leaves little noise), 11 s for both tests:
whole-image z 0, 0, 0 (mean differences 0.17%, 0.19%, 0.08%, within the floor), largest
region difference 1.5%. The same scene with the checkerboard's colours swapped on
heron's side (heron's squares then hold the other α: what the importer would render
without the swap) fails: whole-image z 6.7, 6.7, 6.5 and a region 140% off
(test_unswapped_alpha_checkerboard_fails). The light is kept out of the view and away
from the camera: with a sphere light 1 unit in front of the camera, large in the view,
the two renderers parted by 1.7–2% on both rectangles and up to 3% near the light
(not looked into here).
"""
import pathlib

from test_mitsuba_textures import two_panels
from test_mitsuba_xml import agreement, render_heron, render_mitsuba, same
from heronrun import REPO

PNG = REPO / "scenes" / "textures" / "tiles.png"
PARAMS = {"width": "160", "height": "96"}
SPP = 64


def scene(a0: str, a1: str) -> str:
    return two_panels(f"""        <bsdf type="roughconductor">
            <float name="eta" value="0.2"/>
            <float name="k" value="3.0"/>
            <string name="distribution" value="ggx"/>
            <texture type="checkerboard" name="alpha">
                <float name="color0" value="{a0}"/>
                <float name="color1" value="{a1}"/>
                <transform name="to_uv"><scale x="2" y="2"/></transform>
            </texture>
        </bsdf>""", f"""        <bsdf type="plastic">
            <texture type="bitmap" name="diffuse_reflectance">
                <string name="filename" value="{PNG}"/>
            </texture>
        </bsdf>""", sky="0.5, 0.5, 0.5", light=(-1, 2, 3))


def _write(tmp: pathlib.Path, name: str, text: str) -> pathlib.Path:
    p = tmp / name
    p.write_text(text)
    return p


def test_a_checkerboard_alpha_and_a_bitmap_plastic_render_as_in_mitsuba(tmp_path):
    xml = _write(tmp_path, "params.xml", scene("0.05", "0.35"))
    a = render_heron(xml, tmp_path, PARAMS, SPP)
    b = render_mitsuba(xml, PARAMS, SPP)
    z, worst = agreement(a, b)
    print(f"texture params: whole-image z {z}, largest region difference {worst:.2%}; "
          f"means heron {a.mean((0, 1))} Mitsuba {b.mean((0, 1))}")
    assert same(z, worst), (z, worst)


def test_unswapped_alpha_checkerboard_fails(tmp_path):
    xml = _write(tmp_path, "params.xml", scene("0.05", "0.35"))
    swapped = _write(tmp_path, "swapped.xml", scene("0.35", "0.05"))
    a = render_heron(swapped, tmp_path, PARAMS, SPP)
    b = render_mitsuba(xml, PARAMS, SPP)
    z, worst = agreement(a, b)
    print(f"unswapped alpha: whole-image z {z}, largest region difference {worst:.2%}")
    assert not same(z, worst), (z, worst)
