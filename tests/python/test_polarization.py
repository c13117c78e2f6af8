"""Polarised transport seen from outside heron: the EXR's Stokes channels, the Python
module's ``RenderResult.stokes``, the DoLP/AoLP previews, the analyser argument, and the
primary bow's degree of polarisation from the Mie sky against Lorenz–Mie theory
computed here with miepython (pinned in requirements.txt).

The bow check: a camera with a 0.3° field looks at the sky 40.6°-41.4° from the
antisolar point, where 50 µm drops make the primary bow; the sun is behind it. For an
unpolarised sun a sphere scatters S = (F11, F12, 0, 0) (Bohren & Huffman 1983, eq.
4.77): the light seen is ((|S1|² + |S2|²)/2, (|S1|² − |S2|²)/2) times constants, in the
frame perpendicular to the scattering plane, averaged over the solar disk. The film's Y
of S0 and of S1 are the integrals of those over λ weighted by the sun's spectrum (D65 for
a grey sun) and ȳ, so their ratio is computed here from miepython's S1, S2 with heron's
water index (``heron.ior("water")``), the solar disk's chord kernel and colour-science's
D65 and CIE 1931 ȳ. Here the scattering plane is the picture's horizontal plane, so the
bow's tangential polarisation is vertical in the picture: S1 < 0 in the camera's frame.
"""
from __future__ import annotations

import pathlib
import subprocess

import numpy as np
import pytest

import heron  # built and installed by scripts/setup-python.sh; never skipped

from heronrun import REPO, require_heron_bin

miepython = pytest.importorskip("miepython")
colour = pytest.importorskip("colour")
OpenEXR = pytest.importorskip("OpenEXR")
Imath = pytest.importorskip("Imath")
from PIL import Image  # noqa: E402

BREWSTER = REPO / "scenes" / "brewster.toml"
# Y of linear sRGB (the inverse of heron's XYZ → sRGB matrix, IEC 61966-2-1).
Y_OF_RGB = np.array([0.2126, 0.7152, 0.0722])


def read_exr(path: pathlib.Path) -> dict[str, np.ndarray]:
    f = OpenEXR.InputFile(str(path))
    dw = f.header()["dataWindow"]
    w, h = dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    return {
        name: np.frombuffer(f.channel(name, pt), dtype=np.float32).reshape(h, w)
        for name in f.header()["channels"]
    }


def test_stokes_equals_the_cli_exr_and_the_previews_are_written(tmp_path):
    out = tmp_path / "b.exr"
    subprocess.run(
        [str(require_heron_bin()), "render", str(BREWSTER), "-o", str(out), "--spp", "2", "--quiet"],
        check=True,
    )
    ch = read_exr(out)
    for k in (1, 2, 3):
        assert {f"S{k}.R", f"S{k}.G", f"S{k}.B"} <= set(ch)
    r = heron.load_scene(str(BREWSTER)).render(spp=2)
    st = r.stokes
    assert st.shape == (240, 320, 4, 3) and st.dtype == np.float32
    assert np.array_equal(st[..., 0, :], r.rgb)
    for c, name in enumerate("RGB"):
        assert np.array_equal(st[..., 0, c], ch[name])
        for k in (1, 2, 3):
            assert np.array_equal(st[..., k, c], ch[f"S{k}.{name}"]), (k, name)
    # The window's reflection is horizontally polarised (S1 > 0) in the picture.
    window = st[100:112, 140:152, :, :] @ Y_OF_RGB
    assert (window[..., 1].mean() / window[..., 0].mean()) > 0.9
    for which in ("dolp", "aolp"):
        png = tmp_path / f"b.{which}.png"
        im = Image.open(png)
        assert im.size[0] >= 320 and im.size[1] > 240, (which, im.size)
    # Unpolarised: no Stokes array, and no previews.
    plain = heron.load_scene(str(REPO / "scenes" / "cornell-box.toml")).render(spp=1, integrator="path")
    assert plain.stokes is None


@pytest.mark.parametrize("integrator", ["bdpt", "lighttrace"])
def test_polarised_splatting_integrators_from_python_match_the_cli(integrator, tmp_path):
    # Light tracing and BDPT splat Stokes radiance; Python's .stokes is the CLI's EXR.
    out = tmp_path / "b.exr"
    subprocess.run(
        [str(require_heron_bin()), "render", str(BREWSTER), "-o", str(out), "--spp", "2",
         "--integrator", integrator, "--quiet", "--no-png"],
        check=True,
    )
    ch = read_exr(out)
    r = heron.load_scene(str(BREWSTER)).render(spp=2, integrator=integrator)
    st = r.stokes
    assert st.shape == (240, 320, 4, 3)
    for c, name in enumerate("RGB"):
        assert np.array_equal(st[..., 0, c], ch[name])
        for k in (1, 2, 3):
            assert np.array_equal(st[..., k, c], ch[f"S{k}.{name}"]), (k, name)
    if integrator == "bdpt":
        # Its camera subpaths see the window's reflection, horizontally polarised.
        window = st[100:112, 140:152, :, :] @ Y_OF_RGB
        assert (window[..., 1].mean() / window[..., 0].mean()) > 0.9


def test_the_analyser_removes_the_glare_and_halves_unpolarised_light():
    scene = heron.load_scene(str(BREWSTER))
    y = lambda r, rows, cols: float((r.rgb[rows, cols] @ Y_OF_RGB).mean())  # noqa: E731
    free = scene.render(spp=16)
    crossed = scene.render(spp=16, polarizer=90.0)
    window = (slice(100, 112), slice(140, 152))
    floor = (slice(5, 40), slice(0, 320))
    assert y(crossed, *window) < 0.05 * y(free, *window)
    # The floor around the plate scatters diffusely: unpolarised, so half passes.
    assert abs(y(crossed, *floor) / y(free, *floor) - 0.5) < 0.02
    assert "polarizer" in heron_error(scene.render, polarizer=90.0, polarization=False)


def heron_error(f, **kwargs) -> str:
    with pytest.raises(heron.HeronError) as e:
        f(**kwargs)
    return str(e.value)


def bow_scene(theta_deg: float, tmp_path: pathlib.Path) -> pathlib.Path:
    t = np.radians(theta_deg)
    text = f"""background = 0.0
[camera]
eye = [0.0, 0.0, 0.0]
look_at = [{np.sin(t)!r}, 0.0, {-np.cos(t)!r}]
d = 100.0
resolution = [8, 8]
[render]
integrator = "path"
polarization = true
spp = 32
[sky]
model = "mie"
droplet_radius = 0.05
[[lights]]
type = "sun"
direction = [0.0, 0.0, -1.0]
irradiance = 1.0
angular_radius = 0.2666
"""
    p = tmp_path / "bow.toml"
    p.write_text(text)
    return p


def mie_linear_fraction(theta_deg: float, sun_radius_deg: float = 0.2666) -> float:
    """(Y of S1)/(Y of S0) of the disk-averaged Mie light at θ from the antisolar point,
    in the frame perpendicular to the scattering plane."""
    lam = np.arange(360.0, 831.0, 5.0)
    n = heron.ior("water", lam)
    sd = colour.SpectralShape(360, 830, 5)
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(sd).values[:, 1]
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(sd).values
    # The solar disk's chord kernel K(u) = 2√(α² − u²)/(πα²), midpoint rule.
    a = np.radians(sun_radius_deg)
    u = (np.arange(200) + 0.5) / 200 * 2 * a - a
    k = 2 * np.sqrt(a * a - u * u) / (np.pi * a * a)
    k /= k.sum()
    scatter = np.pi - (np.radians(theta_deg) - u)  # the scattering angle
    num = den = 0.0
    for lam_i, n_i, w in zip(lam, n, ybar * d65):
        x = 2 * np.pi * 50e3 / lam_i
        s1, s2 = miepython.S1_S2(float(n_i), x, np.cos(scatter), norm="wiscombe")
        i_s, i_p = np.abs(s1) ** 2, np.abs(s2) ** 2
        # dσ/dΩ ∝ |S|²/k²: k² = (2π/λ)², the same factor for both components.
        scale = (lam_i / (2 * np.pi)) ** 2
        num += w * scale * np.sum(k * 0.5 * (i_s - i_p))
        den += w * scale * np.sum(k * 0.5 * (i_s + i_p))
    return num / den


@pytest.mark.parametrize("theta", [40.6, 41.0, 41.4])
def test_the_mie_bows_polarisation_is_mie_theorys(theta, tmp_path):
    r = heron.load_scene(str(bow_scene(theta, tmp_path))).render()
    st = r.stokes @ Y_OF_RGB  # H × W × 4, Y of each component
    s0, s1, s2, s3 = (float(st[..., k].mean()) for k in range(4))
    want = mie_linear_fraction(theta)
    assert s0 > 0
    # Tangential (perpendicular to the scattering plane) is vertical here: S1 = −fraction.
    assert abs(-s1 / s0 - want) < 0.01, f"θ {theta}°: heron {-s1 / s0:.4f}, Mie {want:.4f}"
    assert abs(s2) < 1e-3 * s0 and abs(s3) < 1e-6 * s0
    assert want > 0.5  # the bow is strongly polarised here: the check can tell a sign


def fog_scene(theta_deg: float, radius_um: float, density: float,
              tmp_path: pathlib.Path) -> pathlib.Path:
    """A sphere (radius 1 m, 100 m away, seen in a 0.3° field) of water drops of radius
    `radius_um`, optical depth about 0.01 across, lit by a directional light of flat spectrum
    travelling at θ from the direction toward the camera (+z), in the horizontal plane."""
    t = np.radians(theta_deg)
    text = f"""background = 0.0
[camera]
eye = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -100.0]
d = 200.0
resolution = [8, 8]
[render]
integrator = "path"
polarization = true
spp = 64
max_depth = 8
[[shapes]]
type = "sphere"
center = [0.0, 0.0, -100.0]
radius = 1.0
medium = {{ type = "mie", radius_mm = {radius_um * 1e-3!r}, number_density = {density!r}, absorption = false }}
[[lights]]
type = "directional"
direction = [{np.sin(t)!r}, 0.0, {np.cos(t)!r}]
radiance = {{ spectrum = "E", scale = 1.0 }}
"""
    p = tmp_path / f"fog-{theta_deg}-{radius_um}.toml"
    p.write_text(text)
    return p


def mie_fraction_single(theta_deg: float, radius_nm: float) -> float:
    """(Y of F12)/(Y of F11) of single scattering by one drop size at scattering angle
    θ, under a flat spectrum, in the frame x̂ ⊥ the scattering plane."""
    lam = np.arange(360.0, 831.0, 5.0)
    n = heron.ior("water", lam)
    sd = colour.SpectralShape(360, 830, 5)
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(sd).values[:, 1]
    mu = np.array([np.cos(np.radians(theta_deg))])
    f11 = f12 = 0.0
    for lam_i, n_i, w in zip(lam, n, ybar):
        s1, s2 = miepython.S1_S2(float(n_i), 2 * np.pi * radius_nm / lam_i, mu, norm="wiscombe")
        # σ_s p ∝ N |S|²/k², k = 2π/λ.
        scale = w * (lam_i / (2 * np.pi)) ** 2
        f11 += scale * 0.5 * (abs(s1[0]) ** 2 + abs(s2[0]) ** 2)
        f12 += scale * 0.5 * (abs(s1[0]) ** 2 - abs(s2[0]) ** 2)
    return f12 / f11


# (radius µm, drops per m³ for an optical depth near 0.01 across the sphere)
FOGS = {"0.1 µm": (0.1, 3e11), "0.25 µm": (0.25, 1.3e10)}


@pytest.mark.parametrize("fog", sorted(FOGS))
@pytest.mark.parametrize("theta", [60.0, 90.0, 130.0])
def test_light_scattered_by_a_thin_fog_is_polarised_as_mie_theory_says(theta, fog, tmp_path):
    """Polarised transport through a Lorenz–Mie medium (the phase matrix of
    `Medium::phase_matrix`, through the path tracer's media estimators): single
    scattering of unpolarised light by drops of one radius at scattering angle θ gives
    S = F11 (1, F12/F11, 0, 0) in the frame perpendicular to the scattering plane, which
    here is the picture's vertical: S1/S0 = −F12/F11 in the camera's frame, S2 = 0, and
    S3 = 0 (unpolarised light gains no circular part). The 0.1 µm drops (size parameter
    0.8-1.7) are nearly Rayleigh scatterers, polarised 0.99 at 90°; the 0.25 µm ones
    (1.9-4.4) are Mie's, −0.08 at 90° (polarised in the scattering plane) and 0.37 at
    130°.

    Optical depth 0.01: light scattered twice is about 0.5% of the image, so it moves
    S1/S0 by less than 0.005; 8 × 8 pixels × 64 spp put the statistical error of the
    ratio near 1e-4 (forced next-event estimation samples every camera ray's segment;
    measured heron − Mie: −0.0001, −0.0003, −0.0001 for 0.1 µm, 0.0000, +0.0030,
    −0.0035 for 0.25 µm, whose double scattering is less depolarised). The
    tolerance, 0.01, is below the difference between the angles' fractions, and a sign
    or frame error (S1 ↔ −S1, or S1 ↔ S2) fails by many times it."""
    radius, density = FOGS[fog]
    r = heron.load_scene(str(fog_scene(theta, radius, density, tmp_path))).render()
    st = r.stokes @ Y_OF_RGB
    s0, s1, s2, s3 = (float(st[..., k].mean()) for k in range(4))
    want = mie_fraction_single(theta, radius * 1e3)
    assert s0 > 0
    assert abs(-s1 / s0 - want) < 0.01, f"θ {theta}°: heron {-s1 / s0:.4f}, Mie {want:.4f}"
    assert abs(s2) < 0.003 * s0 and abs(s3) < 0.003 * s0, (s2 / s0, s3 / s0)
    if fog == "0.1 µm" and theta == 90.0:
        assert want > 0.95


def test_trace_reports_the_stokes_vector_from_python():
    """heron.trace(stokes=...) is `heron trace --stokes`: unpolarised light reflected by
    the Brewster scene's glass at Brewster's angle leaves as (R, R, 0, 0) in the s frame
    (R = R_s/2), and the argument is checked."""
    tb = np.arctan(1.5)
    c, s = np.cos(tb), np.sin(tb)
    ev = heron.trace(str(BREWSTER), [0.0, 4.0 * c, -4.0 * s], [0.0, -c, s], 550.0,
                     path="R", stokes=[1.0, 0.0, 0.0, 0.0])
    first = ev[0]
    assert first["kind"] == "reflect"
    s0, s1, s2, s3 = first["stokes"]
    ct = np.sqrt(1.0 - (s / 1.5) ** 2)
    r_s = ((c - 1.5 * ct) / (c + 1.5 * ct)) ** 2
    assert abs(s0 - 0.5 * r_s) < 1e-5 and abs(s1 - s0) < 1e-5, first["stokes"]
    assert abs(s2) < 1e-6 and abs(s3) < 1e-6
    assert len(first["stokes_x"]) == 3
    assert "stokes" not in heron.trace(str(BREWSTER), [0.0, 4.0 * c, -4.0 * s],
                                       [0.0, -c, s], 550.0)[0]
    msg = heron_error(heron.trace, scene=str(BREWSTER), origin=[0, 1, 0], direction=[0, -1, 0],
                      wavelength=550.0, stokes=[1.0, 0.0])
    assert "stokes" in msg and "four numbers" in msg, msg
    msg = heron_error(heron.trace, scene=str(BREWSTER), origin=[0, 1, 0], direction=[0, -1, 0],
                      wavelength=550.0, stokes=[1.0, 2.0, 0.0, 0.0])
    assert "stokes" in msg and "physical" in msg, msg


def test_spectral_stokes_bins_are_fichets_polarised_layout(tmp_path):
    """With spectral bins a polarised render writes S0-S3 per bin in the layout of
    Fichet, Pacanowski & Wilkie 2021, read back by colour-science's own reader
    (`colour.read_spectral_image_Fichet2021`, which reads the S1-S3 components of a
    polarised image); they are RenderResult.stokes_spectral, [..., 0, :] is .spectral,
    and the window's reflection near Brewster's angle is s-polarised (S1 close to S0,
    horizontal in the picture) bin by bin."""
    out = tmp_path / "b.exr"
    subprocess.run(
        [str(require_heron_bin()), "render", str(BREWSTER), "-o", str(out), "--spp", "4",
         "--spectral-bins", "8", "--quiet", "--no-png"],
        check=True,
    )
    components, spec = colour.read_spectral_image_Fichet2021(str(out), additional_data=True)
    assert sorted(components) == ["S0", "S1", "S2", "S3"]
    assert spec.is_polarised and spec.is_emissive
    attrs = {a.name: a.value for a in spec.attributes}
    assert attrs.get("polarisationHandedness") == "right", attrs
    wl, s0 = components["S0"]
    assert len(wl) == 8
    r = heron.load_scene(str(BREWSTER)).render(spp=4, spectral_bins=8)
    st = r.stokes_spectral
    assert st.shape == (240, 320, 4, 8)
    assert np.array_equal(st[..., 0, :], r.spectral)
    for k in range(4):
        wl_k, v = components[f"S{k}"]
        assert np.allclose(wl_k, wl)
        assert np.array_equal(np.asarray(v, dtype=np.float32), st[..., k, :]), k
    window = st[100:112, 140:152].mean(axis=(0, 1))  # 4 × 8
    assert np.all(window[0] > 0)
    # As the XYZ test above: the scene's wide field sees the plate from 50° to 62°.
    assert np.all(window[1] / window[0] > 0.9), window[1] / window[0]
    assert np.all(np.abs(window[3]) < 1e-3 * window[0])
