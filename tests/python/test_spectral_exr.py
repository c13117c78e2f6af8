"""heron's optional EXR channels (`--xyz`, `--spectral-bins N`) read back with OpenEXR and
with colour-science's reader of Fichet, Pacanowski & Wilkie (2021, JCGT 10(3)) spectral
images, and held against heron's own X, Y, Z and R, G, B.

CLI contract: `--xyz` adds float32 channels X, Y, Z (the film's XYZ, D65-relative, a
constant spectrum 1 has Y = 1); `--spectral-bins N` adds N emissive channels
`S0.<λ>nm`, λ the centre of one of N equal bins over 360–830 nm written with a decimal
comma, each the mean spectral radiance over its bin (W·m⁻²·sr⁻¹·nm⁻¹), plus the
attributes spectralLayoutVersion = "1.0" and emissiveUnits = "W.m^-2.sr^-1". Without
the flags the EXR has R, G, B only.

Scene (scenes/spectral_exr.toml, 48×32): left half an orange RGB Lambertian quad under
an equal-energy directional light, right half the background 0.5 × D65(Y = 1).

Integrating the bins. heron's X is the Monte Carlo estimate of ∫ L x̄ dλ / Σ_λ ȳ(λ)·1 nm
(x̄ linear between the 1 nm samples); the bins give
    X_bins = Σ_k S_k · x̄_k · Δλ / Σ_λ ȳ(λ)·1 nm,   x̄_k = mean of x̄ over bin k
(colour-science's CIE 1931 2° CMFs, averaged exactly as the piecewise-linear function
heron evaluates). Both come from the very same samples, so X_bins − X is, per sample,
L(λ)(x̄_k − x̄(λ))/p(λ): not noise of the image, but the error of replacing x̄ by its bin
mean. It has
  - a mean (bias) Σ_k [∫_k L · ∫_k x̄ / Δλ − ∫_k L x̄] / Σȳ, which for a smooth L is tiny:
    for the background (0.5·D65, known here) it is −1.7e-5, −2.0e-5, −1.6e-4 of X, Y, Z
    with 5 nm bins, and it is predicted by colour-science and checked;
  - a spread per pixel, σ_lane/√(lanes·spp), with σ_lane = 0.056, 0.045, 0.107 of X, Y, Z
    for the background (5 nm bins): 8e-4 of Z at 4096 spp.
Measured (seed 1): per pixel |X_bins/X − 1| at most 1.7e-3, 1.5e-3, 4.1e-3 (X, Y, Z; RMS
≤ 8.9e-4) with 94 bins at 4096 spp; region means within 4.9e-4 in every configuration
tested (94 bins at 4096 spp; 100 bins, and 94 bins with --wavelengths visible, at 1024
spp); over the background the measured mean differences sit within 1.9 SE of the
predicted bias. The tolerances are PIXEL_REL_TOL = 1e-2 per pixel (≈ 10 σ of the spread
above) and REGION_REL_TOL = 1e-3 for region means (2 × the largest measured), both well
below 1%.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import heronref
from test_render_exr import read_exr

SCENE = "spectral_exr.toml"
WIDTH, HEIGHT = 48, 32
BINS = 94  # 5 nm bins
SPP = 4096
SEED = 1
LAMBDA_MIN, LAMBDA_MAX = 360.0, 830.0
PIXEL_REL_TOL = 1e-2
REGION_REL_TOL = 1e-3
N_SIGMA = 4.0  # for the predicted background bias (one comparison per channel)
Z_MAX_BINS = 4.5  # per-bin check of 94 bins: false alarm ≈ 94 × 7e-6 for Gaussian noise
# Columns of the two regions, 2 px clear of the quad's edge at x = 0 (between 23 and 24).
LEFT = np.s_[:, :22]
RIGHT = np.s_[:, 26:]
SPECTRAL_UNITS = "W.m^-2.sr^-1"


def spectral_flags(bins=BINS, wavelengths=None):
    flags = ("--xyz", "--spectral-bins", str(bins))
    return flags + (("--wavelengths", wavelengths) if wavelengths else ())


# ---------------------------------------------------------------------------- helpers


def bin_edges(n: int) -> np.ndarray:
    return LAMBDA_MIN + np.arange(n + 1) * (LAMBDA_MAX - LAMBDA_MIN) / n


def bin_centres(n: int) -> np.ndarray:
    e = bin_edges(n)
    return 0.5 * (e[:-1] + e[1:])


def _bin_integrals(values: np.ndarray, n: int) -> np.ndarray:
    """∫ over each of the n bins of the function linear between heron's 1 nm samples
    `values` (471 rows, any number of columns); exact: the trapezoid rule on a grid
    holding every 1 nm knot and every bin edge."""
    knots = heronref.cmfs().wavelengths
    v = values.reshape(len(knots), -1)
    edges = bin_edges(n)
    grid = np.union1d(knots, edges)
    f = np.stack([np.interp(grid, knots, v[:, j]) for j in range(v.shape[1])], axis=-1)
    out = np.empty((n, v.shape[1]))
    for k in range(n):
        m = (grid >= edges[k] - 1e-9) & (grid <= edges[k + 1] + 1e-9)
        out[k] = np.trapezoid(f[m], grid[m], axis=0)
    return out


def cmf_bin_means(n: int) -> np.ndarray:
    """(n, 3): x̄, ȳ, z̄ of colour-science's CIE 1931 2° observer averaged over each bin."""
    return _bin_integrals(heronref.cmfs().values, n) / ((LAMBDA_MAX - LAMBDA_MIN) / n)


def y_sum() -> float:
    """Σ_λ ȳ(λ)·1 nm over 360–830 nm: heron's film normalisation (106.857)."""
    return float(heronref.cmfs().values[:, 1].sum())


def bins_to_xyz(s: np.ndarray) -> np.ndarray:
    """XYZ of spectral bins s (…, n): Σ_k S_k · x̄_k · Δλ / Σȳ."""
    n = s.shape[-1]
    return s.astype(np.float64) @ cmf_bin_means(n) * ((LAMBDA_MAX - LAMBDA_MIN) / n) / y_sum()


def bin_average_bias(sd, n: int) -> np.ndarray:
    """E[X_bins] − E[X] for spectral radiance sd: Σ_k [∫_k L ∫_k x̄ / Δλ − ∫_k L x̄] / Σȳ."""
    L = heronref.aligned(sd).values
    cm = heronref.cmfs().values
    dl = (LAMBDA_MAX - LAMBDA_MIN) / n
    # ∫_k L x̄ of the product of two piecewise-linear functions is not the trapezoid rule
    # of the product; do it on a 0.01 nm grid (error ~1e-9 relative, far below the bias).
    fine = np.linspace(LAMBDA_MIN, LAMBDA_MAX, 47001)
    knots = heronref.cmfs().wavelengths
    Lf = np.interp(fine, knots, L)
    cf = np.stack([np.interp(fine, knots, cm[:, j]) for j in range(3)], axis=-1)
    exact = np.zeros((n, 3))
    int_l = np.zeros(n)
    int_c = np.zeros((n, 3))
    # Split the grid at the bin edges (each edge point is shared by its two bins).
    for j in range(n):
        lo, hi = LAMBDA_MIN + j * dl, LAMBDA_MIN + (j + 1) * dl
        m = (fine >= lo - 1e-9) & (fine <= hi + 1e-9)
        exact[j] = np.trapezoid(Lf[m, None] * cf[m], fine[m], axis=0)
        int_l[j] = np.trapezoid(Lf[m], fine[m])
        int_c[j] = np.trapezoid(cf[m], fine[m], axis=0)
    return (int_l[:, None] * int_c / dl - exact).sum(axis=0) / y_sum()


def read_channels(path, names):
    """{name: H×W float64} for the given channels, after checking they are float32."""
    import OpenEXR

    _, pixels, types = read_exr(path)
    missing = [c for c in names if c not in pixels]
    assert not missing, f"{path}: channels {missing} missing; has {sorted(pixels)[:12]}…"
    for c in names:
        assert types[c] == OpenEXR.FLOAT, f"{path}: channel {c} is {types[c]}, expected FLOAT"
    return {c: pixels[c].astype(np.float64) for c in names}


def read_xyz(path) -> np.ndarray:
    ch = read_channels(path, "XYZ")
    return np.stack([ch[c] for c in "XYZ"], axis=-1)


def read_rgb(path) -> np.ndarray:
    ch = read_channels(path, "RGB")
    return np.stack([ch[c] for c in "RGB"], axis=-1)


def read_fichet(path):
    """colour.read_spectral_image_Fichet2021: (wavelengths, H×W×n float64, specification)."""
    components, spec = heronref.colour.read_spectral_image_Fichet2021(path, additional_data=True)
    assert list(components) == ["S0"], f"components {list(components)}, expected only S0"
    wl, values = components["S0"]
    return np.asarray(wl, dtype=np.float64), np.asarray(values, dtype=np.float64), spec


def spectral(render, bins=BINS, spp=SPP, wavelengths=None):
    return render(SCENE, spp=spp, seed=SEED, extra=spectral_flags(bins, wavelengths))


# ------------------------------------------------------------- the helpers themselves


def test_cmf_bin_means_integrate_like_the_film():
    # Averaged CMFs keep the CMF integrals: Σ_k x̄_k Δλ = ∫ x̄ (trapezoid of the 1 nm
    # table), so the constant spectrum 1 has Y_bins = ∫ȳ/Σȳ = 1 − (ȳ(360)+ȳ(830))/2/Σȳ.
    for n in (7, 94, 100):
        xyz = bins_to_xyz(np.ones(n))
        cm = heronref.cmfs().values
        np.testing.assert_allclose(xyz, np.trapezoid(cm, dx=1.0, axis=0) / y_sum(), rtol=1e-12)
    np.testing.assert_allclose(y_sum(), 106.856917101, rtol=1e-10)
    # And the expected bias of the background is as small as the module docstring says.
    bias = bin_average_bias(heronref.d65_unit() * 0.5, BINS)
    xyz = heronref.film_xyz(heronref.d65_unit() * 0.5)
    np.testing.assert_allclose(bias / xyz, [-1.725e-5, -2.047e-5, -1.562e-4], rtol=1e-3)


# ------------------------------------------------------------------- channel layouts


@pytest.mark.parametrize("flags, extra_channels", [
    ((), []),
    (("--xyz",), ["X", "Y", "Z"]),
    (("--spectral-bins", "94"), ["S0." + f"{c:.6f}".replace(".", ",") + "nm"
                                 for c in bin_centres(94)]),
])
def test_channel_layout(render, flags, extra_channels):
    import OpenEXR

    r = render(SCENE, spp=16, seed=SEED, extra=flags)
    header, pixels, types = read_exr(r.exr)
    assert sorted(pixels) == sorted(["R", "G", "B", *extra_channels]), (
        f"flags {flags}: channels {sorted(pixels)[:8]}… ({len(pixels)}), "
        f"expected R, G, B + {extra_channels[:4]}… ({3 + len(extra_channels)})")
    for name, t in types.items():
        assert t == OpenEXR.FLOAT, f"channel {name} is {t}, expected FLOAT"
        assert pixels[name].shape == (HEIGHT, WIDTH)
    spectral_attrs = {"spectralLayoutVersion", "emissiveUnits"}
    if "--spectral-bins" in flags:
        assert header.get("spectralLayoutVersion") == "1.0", header.get("spectralLayoutVersion")
        assert header.get("emissiveUnits") == SPECTRAL_UNITS, header.get("emissiveUnits")
    else:
        assert not spectral_attrs & set(header), f"{flags}: spectral attributes in {sorted(header)}"
    # The extra channels never change the image.
    plain = read_rgb(render(SCENE, spp=16, seed=SEED).exr)
    assert np.array_equal(read_rgb(r.exr), plain), f"{flags} changed R, G, B"


def test_channel_names_use_a_decimal_comma_for_non_integer_centres(render):
    # 100 bins of 4.7 nm: centres 362.35, 367.05, …; heron writes them with 6 decimals.
    _, pixels, _ = read_exr(render(SCENE, spp=16, seed=SEED, extra=spectral_flags(100)).exr)
    names = sorted(c for c in pixels if c.startswith("S0."))
    assert len(names) == 100
    assert names[0].startswith("S0.362,35") and names[0].endswith("nm"), names[0]
    assert all("." not in n[3:] for n in names), names[:3]


# --------------------------------------------------- (a) colour-science reads it


@pytest.mark.parametrize("bins", [BINS, 100])
def test_fichet2021_reader_reads_the_spectral_exr(render, bins):
    r = spectral(render, bins=bins, spp=64)
    wl, s, spec = read_fichet(r.exr)
    assert spec.is_emissive and not spec.is_polarised and not spec.is_bispectral
    attrs = {a.name: a.value for a in spec.attributes}
    assert attrs.get("spectralLayoutVersion") == "1.0", attrs
    assert attrs.get("emissiveUnits") == SPECTRAL_UNITS, attrs
    # Bin centres (written from float32 with 6 decimals: 1e-4 covers the rounding).
    np.testing.assert_allclose(wl, bin_centres(bins), atol=1e-4, rtol=0)
    assert s.shape == (HEIGHT, WIDTH, bins), s.shape
    # The reader's values are the EXR's S0 channels, in wavelength order.
    _, pixels, _ = read_exr(r.exr)
    names = sorted((c for c in pixels if c.startswith("S0.")),
                   key=lambda c: float(c[3:-2].replace(",", ".")))
    np.testing.assert_array_equal(s, np.stack([pixels[c] for c in names], axis=-1))
    assert np.isfinite(s).all() and (s >= 0).all()


# ------------------------------ (b) the spectral channels integrate to heron's X, Y, Z


def test_spectral_bins_integrate_to_xyz_per_pixel(render):
    r = spectral(render)
    _, s, _ = read_fichet(r.exr)
    xyz = read_xyz(r.exr)
    assert (xyz > 0.05).all(), "every pixel of the scene should be lit"
    rel = bins_to_xyz(s) / xyz - 1
    worst = np.abs(rel).max(axis=(0, 1))
    rms = np.sqrt((rel ** 2).mean(axis=(0, 1)))
    assert (worst <= PIXEL_REL_TOL).all(), (
        f"per pixel, Σ S_k x̄_k Δλ / Σȳ differs from heron's X, Y, Z by up to {worst} "
        f"(RMS {rms}); allowed {PIXEL_REL_TOL}")


@pytest.mark.parametrize("bins, spp, wavelengths", [
    (BINS, SPP, None), (100, 1024, None), (BINS, 1024, "visible")])
def test_spectral_bins_integrate_to_xyz_over_regions(render, bins, spp, wavelengths):
    r = spectral(render, bins=bins, spp=spp, wavelengths=wavelengths)
    _, s, _ = read_fichet(r.exr)
    xyz = read_xyz(r.exr)
    xb = bins_to_xyz(s)
    for name, reg in (("quad (left)", LEFT), ("background (right)", RIGHT), ("image", np.s_[:, :])):
        got = xb[reg].reshape(-1, 3).mean(axis=0)
        want = xyz[reg].reshape(-1, 3).mean(axis=0)
        rel = got / want - 1
        assert (np.abs(rel) <= REGION_REL_TOL).all(), (
            f"{name}, {bins} bins, {wavelengths or 'uniform'}: mean XYZ from the bins {got} vs "
            f"heron's {want}: relative {rel}, allowed {REGION_REL_TOL}")


def test_background_bin_average_bias_is_the_predicted_one(render):
    # Over the background, X_bins − X must average to colour-science's prediction of the
    # bin-average bias within N_SIGMA standard errors (from the pixel spread), and the
    # standard error must be small enough to tell the bias from zero in Z.
    r = spectral(render)
    _, s, _ = read_fichet(r.exr)
    diff = (bins_to_xyz(s) - read_xyz(r.exr))[RIGHT].reshape(-1, 3)
    sd = heronref.d65_unit() * 0.5
    bias = bin_average_bias(sd, BINS)
    mean = diff.mean(axis=0)
    se = diff.std(axis=0, ddof=1) / math.sqrt(len(diff))
    floor = 1e-6 * heronref.film_xyz(sd)  # float32 storage of S_k and X
    assert (np.abs(mean - bias) <= N_SIGMA * se + floor).all(), (
        f"background: mean X_bins − X {mean} vs predicted bias {bias} (SE {se})")
    assert se[2] < abs(bias[2]) / 2, f"SE {se} too large to see the Z bias {bias[2]:.2e}"


def test_background_bins_are_the_mean_spectral_radiance_of_half_d65(render):
    # Each S_k over the background estimates the mean of 0.5 × D65(Y=1) over bin k.
    r = spectral(render)
    wl, s, _ = read_fichet(r.exr)
    px = s[RIGHT].reshape(-1, BINS)
    mean = px.mean(axis=0)
    se = px.std(axis=0, ddof=1) / math.sqrt(len(px))
    want = _bin_integrals((heronref.d65_unit() * 0.5).values, BINS)[:, 0] / (470.0 / BINS)
    z = (mean - want) / se
    assert (se / want).max() < 1e-2, f"relative SE up to {(se / want).max():.2e}"
    k = int(np.abs(z).argmax())
    assert np.abs(z).max() <= Z_MAX_BINS, (
        f"bin {wl[k]:.1f} nm: mean {mean[k]:.6f} vs 0.5·D65 bin mean {want[k]:.6f} "
        f"({z[k]:+.1f} SE); allowed {Z_MAX_BINS} SE")


# ------------------------------------------------- (c) X, Y, Z → sRGB is heron's R, G, B


def test_xyz_channels_convert_to_the_rgb_channels(render):
    r = spectral(render)
    xyz = read_xyz(r.exr)
    rgb = read_rgb(r.exr)
    converted = heronref.colour.XYZ_to_RGB(xyz, "sRGB", illuminant=None,
                                           chromatic_adaptation_transform=None)
    diff = np.abs(converted - rgb).max()
    assert diff <= 1e-5, f"XYZ_to_RGB(sRGB) of the X, Y, Z channels differs from R, G, B by {diff:.2e}"
