"""heron's texture trees against Mitsuba 3's textures, side by side.

One scene (written here, 160×96): a rectangle with a JPEG bitmap (scenes/textures/
tiles.png written as a JPEG by PIL without chroma subsampling) and one with a checkerboard of two colours
whose to_uv scales uv by (4, 2) and shifts it, both diffuse, under a constant grey sky
and a small spherical light. heron renders the XML through its importer (the bitmap
with to_uv and the checkerboard become [textures] tables). The comparison is
test_mitsuba_xml.py's: the whole image's z per channel beyond the films' own 0.2%
(FILM_FLOOR), Šidák-corrected at 1%, and every 16×16 region within 3%.

Why 4:4:4: with tests/corpus/mitsuba/textures/tiles.jpg (4:2:0 chroma) the bitmap's
half of the image differed by 0.5% in R and B (z 14 and 8): the two JPEG decoders
(the `image` crate's and Mitsuba's libjpeg) upsample chroma differently; the texture
code is not what differs (the checkerboard half agreed to 0.1–0.2%, z 0).

Measured at 64 spp (the constant sky leaves little noise), 7 s for both tests: whole-
image z 0, 0, 0 (the mean differences, 0.14%, 0.14%, 0.09%, are within the floor),
largest region difference 1.16%. With the colours swapped the whole-image z stays 0
(the squares come in equal numbers) and the largest region difference is 114%: the
regions catch it. The same scene with the checkerboard's colours
swapped on heron's side fails (test_swapped_checkerboard_colours_fail).
"""
import pathlib

from test_mitsuba_xml import agreement, render_heron, render_mitsuba, same
from heronrun import REPO

PNG = REPO / "scenes" / "textures" / "tiles.png"
PARAMS = {"width": "160", "height": "96"}
SPP = 64

C0, C1 = "0.75, 0.3, 0.1", "0.1, 0.25, 0.6"


def two_panels(left: str, right: str, sky: str = "0.8, 0.8, 0.8", light=(2, 3, 4)) -> str:
    """A Mitsuba scene of two 2.2-wide rectangles side by side (centres x = −1.2 and 1.2)
    with the BSDFs `left` and `right`, under a constant sky of radiance `sky` and a
    sphere light of radius 0.3 at `light`, seen from z = 4 (160×96, 64 spp, the path
    tracer to depth 5); the texture side by sides share it."""
    x, y, z = light
    return f"""<scene version="3.0.0">
    <default name="width" value="160"/>
    <default name="height" value="96"/>
    <default name="spp" value="64"/>
    <integrator type="path"><integer name="max_depth" value="5"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/><integer name="height" value="$height"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="{sky}"/></emitter>
    <shape type="sphere">
        <point name="center" x="{x}" y="{y}" z="{z}"/><float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="30, 30, 30"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="1.1" y="1.1"/><translate x="-1.2"/></transform>
{left}
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="1.1" y="1.1"/><translate x="1.2"/></transform>
{right}
    </shape>
</scene>
"""


def scene(jpeg: pathlib.Path, color0: str, color1: str) -> str:
    return two_panels(f"""        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="{jpeg}"/>
            </texture>
        </bsdf>""", f"""        <bsdf type="diffuse">
            <texture type="checkerboard" name="reflectance">
                <rgb name="color0" value="{color0}"/>
                <rgb name="color1" value="{color1}"/>
                <transform name="to_uv"><scale x="4" y="2"/><translate x="0.1"/></transform>
            </texture>
        </bsdf>""")


def _jpeg(tmp: pathlib.Path) -> pathlib.Path:
    from PIL import Image

    p = tmp / "tiles.jpg"
    Image.open(PNG).convert("RGB").save(p, quality=95, subsampling=0)
    return p


def _write(tmp: pathlib.Path, name: str, text: str) -> pathlib.Path:
    p = tmp / name
    p.write_text(text)
    return p


def test_a_jpeg_bitmap_and_a_checkerboard_render_as_in_mitsuba(tmp_path):
    xml = _write(tmp_path, "textures.xml", scene(_jpeg(tmp_path), C0, C1))
    a = render_heron(xml, tmp_path, PARAMS, SPP)
    b = render_mitsuba(xml, PARAMS, SPP)
    z, worst = agreement(a, b)
    print(f"textures: whole-image z {z}, largest region difference {worst:.2%}; means "
          f"heron {a.mean((0, 1))} Mitsuba {b.mean((0, 1))}")
    assert same(z, worst), (z, worst)


def test_swapped_checkerboard_colours_fail(tmp_path):
    jpeg = _jpeg(tmp_path)
    xml = _write(tmp_path, "textures.xml", scene(jpeg, C0, C1))
    swapped = _write(tmp_path, "swapped.xml", scene(jpeg, C1, C0))
    a = render_heron(swapped, tmp_path, PARAMS, SPP)
    b = render_mitsuba(xml, PARAMS, SPP)
    z, worst = agreement(a, b)
    print(f"swapped colours: whole-image z {z}, largest region difference {worst:.2%}")
    assert not same(z, worst), (z, worst)
