"""heron's polarised path tracer against Mitsuba 3's `scalar_spectral_polarized` variant
(the `stokes` integrator around `volpath`), the independent reference pinned in the test
environment, on tests/python/scenes/polarized/glass-metal-polarizer.toml: a smooth glass
sphere and a smooth metal sphere (n = 1, k = 2.5) on a floor of the same metal, a grey
Lambertian wall, an area light and a constant sky, and an ideal linear polariser strip
in front of the camera, its axis 30° counter-clockwise from the picture's horizontal.

What is compared. heron writes S0 as R, G, B and S1–S3 as S1.R … S3.B, each in linear
sRGB (heron's IEC 61966-2-1 matrix, src/spectrum/color.rs); Mitsuba's `stokes`
integrator writes S0–S3 as the AOVs S0.R … S3.B after its R, G, B, each the spectral
Stokes component divided by its wavelength pdf, taken through CIE 1931 to XYZ and then
to linear sRGB with Mitsuba's own matrix (`xyz_to_srgb`, mitsuba/core/spectrum.h,
3.240479 …, which differs from heron's in the fourth digit). Each image is taken back to
XYZ with the inverse of its own renderer's matrix (for heron this reproduces its `--xyz`
channels to float rounding, checked on every render; Mitsuba's film R, G, B equal its
S0 AOV, also checked), Mitsuba's scaled by mitsuba_scene.xyz_normalisation as in
test_mitsuba.py, and the four XYZ images S0, S1, S2, S3 are compared one by one with
`heron.compare`. Every spectrum in the scene is flat (E) and every index constant, so
each component is one spectrum times a signed factor per pixel, and converting a signed
component is the same linear map as converting S0.

Conventions (the mapping between the two renderers; all measured here).
  * Both use Collett 2005: S1 > 0 along x̂, S2 > 0 along (x̂ + ŷ)/√2, S3 > 0 right-handed,
    in a frame (x̂, ŷ = k̂ × x̂) across the direction of travel k̂ (toward the camera).
  * The image's frame. heron: x̂ = the camera's right vector made perpendicular to the
    ray (Camera::stokes_x). Mitsuba (stokes.cpp): x̂ = d × up, d the camera ray's
    direction, up the sensor's up vector. On the optical axis both are the picture's
    horizontal (rightward) and ŷ its up: test_the_image_frames_agree_on_the_axis renders
    a polariser sheet alone in front of the sky at 0°, +45° and −45° and gets S1 = S0,
    S2 = S0, S2 = −S0 from both. Off the axis the two frames differ by a turn about the
    ray of about u·v/d² (image coordinates u, v), 1.13° at this picture's corners, so
    Mitsuba's S1, S2 are turned into heron's frame pixel by pixel (`heron_frame_turn`)
    before comparing; without that turn the floor's S2 in the lower corners differs by
    up to 105 standard errors.
  * The sheet. heron's axis is `axis` projected onto the sheet and turned by `angle`
    about edge1 × edge2, counter-clockwise seen from the side the normal points to;
    Mitsuba's `polarizer` absorbs along (sin θ, cos θ, 0) of the rectangle's shading
    frame (edge1, n × edge1), so it transmits along (cos θ, −sin θ, 0): θ = −30° here
    (mitsuba_scene.py, `_polarizer`; the sheet test above checks the sign).
  * Depth. heron counts the sheet as a scattering event, Mitsuba's volpath does not
    count a null (polariser) interface; both run at max_depth 32 (33 in Mitsuba), where
    the cut-off paths are negligible (at 10 and at 32 the images agree region by region).

Why they should agree. Both are unbiased estimators of the same Stokes pixel integrals
(box filter in both), with the same geometry, spectra from `heron spectra`, the same
Fresnel matrices for the glass and the metal (the sign of their retardance, S3's
handedness, is Mitsuba's: `optics::mueller`, unit test `retardance_has_mitsubas_sign`),
and the same tilted-polariser model: for a ray meeting the sheet obliquely (here up to
11.3° from its normal: the sheet's half-width over the long lens, and the camera looks
down by 3.8°) both transmit across the absorption axis projected perpendicular to the
ray (Korger et al. 2013; `bsdf::polarization::polarizer_axis`).

Statistics. `heron.compare` averages the per-pixel difference over 8-pixel regions
and holds every region and channel, and the whole image, to a Bonferroni-corrected
family level: α = 0.01 over the four components together (0.0025 per component, then
Bonferroni over that component's tests; regions exactly zero in both images, such as S3
away from the metal, are left out). The standard errors come from per-pixel variances:
each renderer makes 8 independent passes of 128 spp (1024 in all) and the variance of
their mean is passed as the image's variance. The spread of the differences inside a
region, which test_mitsuba.py uses, does not work here: S3 changes sign within a region,
so under a wrong S3 the spread grows with the error itself, and at 1024 spp that test
saw S3 of the wrong sign at |z| 3.9 only, under its critical value. With the variances,
measured at 64×48 and 1024 spp, a region's standard error in Y (median / largest) is:
S0 1.1e-3 / 2.9e-3 (0.46% / 1.1% of the region's S0), S1 4.0e-4 / 1.5e-3, S2 6.0e-4 /
1.1e-3 (0.2% / 0.6% of S0), S3 3.3e-5 / 2.5e-4, against region means of S3 up to
2.3e-3; the critical |z| is 4.0–4.3. A 1° error of the sheet's angle moves the strip's
S1 by about 5e-3 in Y, 10 or more standard errors; test_the_comparison_can_fail's 40°
sheet is rejected at |z| 214 (S1) and 20 (S2), heron's S1 of the wrong sign at |z| 564.
Run time on this 2-core machine: heron 7 s, Mitsuba 12 s; the file about 21 s.

What it found when first written (both fixed in heron since): S3 of the opposite sign
on the metal sphere and in the floor's reflections (|z| up to 205, whole image 25; heron
put Born & Wolf's e^(−iωt) amplitudes into the Collett matrix, which needs their
conjugates), and S1 up to 5.6% high in the lower part of the strip (|z| 12.9; heron
projected the transmission axis across the ray instead of Korger's absorption axis).
"""
from __future__ import annotations

import pathlib
import re
import subprocess
import tomllib

import numpy as np
import pytest

import heron
from heronrun import require_heron_bin
from mitsuba_scene import heron_spectra, mitsuba_dict, xyz_normalisation

SCENE = (pathlib.Path(__file__).resolve().parent / "scenes" / "polarized"
         / "glass-metal-polarizer.toml")
SPP = 1024  # in each renderer, as PASSES independent renders
PASSES = 8
MAX_DEPTH = 32
REGION = 8
ALPHA = 0.01  # family-wise, over the four components

# XYZ -> linear sRGB as each renderer writes its EXR / AOVs.
HERON_XYZ_TO_SRGB = np.array([[3.2406, -1.5372, -0.4986],
                              [-0.9689, 1.8758, 0.0415],
                              [0.0557, -0.2040, 1.0570]])  # src/spectrum/color.rs
MITSUBA_XYZ_TO_SRGB = np.array([[3.240479, -1.537150, -0.498535],
                                [-0.969256, 1.875991, 0.041556],
                                [0.055648, -0.204043, 1.057311]])  # mitsuba/core/spectrum.h

CHANNELS = [["R", "G", "B"]] + [[f"S{i}.{c}" for c in "RGB"] for i in (1, 2, 3)]


def _copy(tmp: pathlib.Path, name: str, angle: float | None = None) -> pathlib.Path:
    """The scene, its polariser's angle replaced when `angle` is given."""
    text = SCENE.read_text()
    if angle is not None:
        text, n = re.subn(r"^angle\s*=\s*30\.0\s*$", f"angle = {angle}", text, flags=re.M)
        assert n == 1, f"{SCENE}: expected one `angle = 30.0` line"
    out = tmp / name
    out.write_text(text)
    return out


def render_heron(scene: pathlib.Path, tmp: pathlib.Path, spp: int, seed: int) -> np.ndarray:
    """heron's Stokes image as H × W × 4 (S0..S3) × 3 (X, Y, Z), float64."""
    import OpenEXR

    exr = tmp / f"{scene.stem}-heron-{seed}.exr"
    subprocess.run([str(require_heron_bin()), "render", str(scene), "-o", str(exr), "--spp",
                    str(spp), "--seed", str(seed), "--max-depth", str(MAX_DEPTH), "--xyz",
                    "--no-png", "--quiet"], check=True, capture_output=True, text=True)
    with OpenEXR.File(str(exr), separate_channels=True) as f:
        ch = f.channels()
        rgb = np.stack([np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in comp], -1)
                        for comp in CHANNELS], -2)
        xyz_s0 = np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "XYZ"], -1)
    xyz = rgb @ np.linalg.inv(HERON_XYZ_TO_SRGB).T
    # The inverse of heron's matrix is the conversion heron made: S0 back in XYZ is its
    # own X, Y, Z channels (float32 rounding apart).
    np.testing.assert_allclose(xyz[:, :, 0], xyz_s0, rtol=0, atol=2e-6 * np.abs(xyz_s0).max())
    return xyz


def mean_and_variance(passes: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The mean of independent passes and the variance of that mean, per pixel."""
    x = np.stack(passes)
    return x.mean(0), x.var(0, ddof=1) / len(passes)


def heron_passes(scene: pathlib.Path, tmp: pathlib.Path, spp: int, passes: int,
                 seed: int) -> tuple[np.ndarray, np.ndarray]:
    return mean_and_variance([render_heron(scene, tmp, spp, seed + 1000 * k)
                              for k in range(passes)])


def heron_frame_turn(scene: pathlib.Path) -> np.ndarray:
    """Per pixel (H × W), the angle φ about the ray toward the camera from Mitsuba's
    image Stokes frame (x̂ = d × up, stokes.cpp) to heron's (x̂ = the camera's right made
    perpendicular to d, Camera::stokes_x), counter-clockwise from x̂ toward ŷ, at the
    pixel's centre (both cameras: a pinhole, vertical field of view 2 atan(1/(2d)))."""
    cam = tomllib.loads(scene.read_text())["camera"]
    w, h = cam["resolution"]
    eye, look_at = np.array(cam["eye"], float), np.array(cam["look_at"], float)
    up = np.array(cam.get("up", [0.0, 1.0, 0.0]), float)
    v = (look_at - eye) / np.linalg.norm(look_at - eye)
    b1 = np.cross(v, up)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(b1, v)  # the orthonormal up both cameras use
    u = ((np.arange(w) + 0.5) / w - 0.5) * w / h
    t = 0.5 - (np.arange(h) + 0.5) / h
    d = float(cam.get("d", 1.0)) * v + u[None, :, None] * b1 + t[:, None, None] * b2
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    x_heron = b1 - np.sum(b1 * d, -1, keepdims=True) * d
    x_heron /= np.linalg.norm(x_heron, axis=-1, keepdims=True)
    x_mitsuba = np.cross(d, b2)
    x_mitsuba /= np.linalg.norm(x_mitsuba, axis=-1, keepdims=True)
    k = -d
    return np.arctan2(np.sum(np.cross(x_mitsuba, x_heron) * k, -1),
                      np.sum(x_mitsuba * x_heron, -1))


def turned(stokes: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Stokes images (H × W × 4 × 3) re-expressed in frames turned by φ (H × W)."""
    c, s = np.cos(2 * phi)[:, :, None], np.sin(2 * phi)[:, :, None]
    out = stokes.copy()
    out[:, :, 1] = c * stokes[:, :, 1] + s * stokes[:, :, 2]
    out[:, :, 2] = -s * stokes[:, :, 1] + c * stokes[:, :, 2]
    return out


def mitsuba_passes(scene: pathlib.Path, spp: int, passes: int,
                   seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Mitsuba's Stokes image in heron's image frame, H × W × 4 × 3 (X, Y, Z), as the mean
    of `passes` independent renders of `spp` samples, and the variance of that mean."""
    import colour
    import mitsuba as mi

    mi.set_variant("scalar_spectral_polarized")
    spectra = heron_spectra(require_heron_bin(), scene)
    d = mitsuba_dict(mi, scene, spectra, spp=spp, integrator={
        "type": "stokes", "nested": {"type": "volpath", "max_depth": MAX_DEPTH + 1}})
    d["sensor"]["film"]["pixel_format"] = "rgb"
    loaded = mi.load_dict(d)
    phi = heron_frame_turn(scene)
    out = []
    for k in range(passes):
        img = np.array(mi.render(loaded, spp=spp, seed=seed + 1000 * k), dtype=np.float64)
        assert img.shape[-1] == 15, "expected R, G, B and the AOVs S0.R … S3.B"
        # The film's own R, G, B are the S0 AOV (the same conversion): the layout's check.
        np.testing.assert_allclose(img[:, :, 0:3], img[:, :, 3:6], rtol=0, atol=1e-5)
        rgb = img[:, :, 3:15].reshape(img.shape[0], img.shape[1], 4, 3)
        xyz = rgb @ np.linalg.inv(MITSUBA_XYZ_TO_SRGB).T * xyz_normalisation(mi, colour)
        out.append(turned(xyz, phi))
    return mean_and_variance(out)


def compare_stokes(a, b) -> tuple[bool, dict, str]:
    """heron.compare on each of S0..S3, a (heron) and b (Mitsuba) each (mean, variance of
    the mean), at α/4 each."""
    results, lines, same = {}, [], True
    for i in range(4):
        r = heron.compare((a[0][:, :, i], a[1][:, :, i]), (b[0][:, :, i], b[1][:, :, i]),
                          region=REGION, alpha=ALPHA / 4, correction="bonferroni")
        results[i] = r
        z_whole = np.array(r["mean_difference"]) / np.array(r["standard_error"])
        lines.append(f"--- S{i} (X, Y, Z; A heron, B Mitsuba): {r['tests']} tests, "
                     f"critical |z| {r['critical_z']:.2f}, largest region |z| "
                     f"{np.nanmax(np.abs(r['z'])):.2f}, whole image z {np.round(z_whole, 2)}\n"
                     f"{r['report']}")
        same &= bool(r["same"])
    return same, results, "\n".join(lines)


@pytest.fixture(scope="module")
def mitsuba_image(tmp_path_factory):
    scene = _copy(tmp_path_factory.mktemp("mitsuba"), SCENE.name)
    return mitsuba_passes(scene, SPP // PASSES, PASSES, seed=2)


@pytest.fixture(scope="module")
def heron_image(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("heron")
    return heron_passes(_copy(tmp, SCENE.name), tmp, SPP // PASSES, PASSES, seed=1)


def test_stokes_images_match_mitsuba(heron_image, mitsuba_image):
    a, b = heron_image, mitsuba_image
    assert a[0].shape == b[0].shape == (48, 64, 4, 3)
    same, results, msg = compare_stokes(a, b)
    print(msg)
    assert all(r["variance_from"] == "channels" for r in results.values()), msg
    assert same, msg


def test_the_comparison_can_fail(heron_image, mitsuba_image, tmp_path):
    """The same comparison rejects heron's image with the sheet at 40° instead of 30°
    (S1 and S2 of the strip), and heron's image with the sign of S1 changed."""
    scene = _copy(tmp_path, "turned.toml", angle=40.0)
    a = heron_passes(scene, tmp_path, SPP // PASSES, 2, seed=3)
    same, results, msg = compare_stokes(a, mitsuba_image)
    for i in (1, 2):
        assert not results[i]["same"] and np.nanmax(np.abs(results[i]["z"])) > 6.0, msg
    flipped = heron_image[0].copy()
    flipped[:, :, 1] *= -1.0
    same, results, msg = compare_stokes((flipped, heron_image[1]), mitsuba_image)
    assert not results[1]["same"] and np.nanmax(np.abs(results[1]["z"])) > 6.0, msg


def test_the_image_frames_agree_on_the_axis(tmp_path):
    """A polariser sheet alone, facing the camera on its axis, in front of the sky: at 0°
    both renderers give S1 = S0, at +45° (counter-clockwise as the camera sees it) S2 = S0,
    at −45° S2 = −S0; so x̂ is the picture's horizontal and ŷ its up in both."""
    import mitsuba as mi

    mi.set_variant("scalar_spectral_polarized")
    for angle, component, sign in ((0.0, 1, 1.0), (45.0, 2, 1.0), (-45.0, 2, -1.0)):
        scene = tmp_path / f"sheet-{angle:g}.toml"
        scene.write_text(f"""
background = {{ spectrum = "E", scale = 1.0 }}
[camera]
eye = [0.0, 0.0, 12.0]
look_at = [0.0, 0.0, 0.0]
d = 4.0
resolution = [8, 6]
[render]
integrator = "path"
polarization = true
spp = 16
max_depth = 4
[materials.sheet]
type = "polarizer"
axis = [1.0, 0.0, 0.0]
angle = {angle}
[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 8.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 2.0, 0.0]
material = "sheet"
""")
        for name, img in (("heron", render_heron(scene, tmp_path, 16, seed=1)),
                          ("Mitsuba", mitsuba_passes(scene, 16, 2, seed=1)[0])):
            s = img[3, 4, :, 1]  # Y of S0..S3 at a pixel near the centre
            assert s[0] > 0.1 and abs(sign * s[component] - s[0]) < 1e-3 * s[0], (name, angle, s)
