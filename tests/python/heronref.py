"""Reference colours for heron's renders, computed with colour-science.

heron's film convention (src/spectrum/cie.rs):

    XYZ = Σ_λ L(λ) x̄(λ) Δλ / Σ_λ ȳ(λ) Δλ      over 360–830 nm at 1 nm (CIE 1931 2°),

so a constant spectrum L = 1 has Y = 1; linear sRGB is the IEC 61966-2-1 XYZ→sRGB matrix
applied to that XYZ with no chromatic adaptation (XYZ is D65-relative).

That convention is exactly colour-science's `sd_to_XYZ(..., method="Integration")` with
an equal-energy illuminant, divided by 100 (k = 100 / Σ S ȳ Δλ with S = 1), so the
references below use colour-science's own integration, colour matching functions,
illuminant data and sRGB colourspace.

RGB uplift (src/spectrum/uplift.rs) is Jakob & Hanika (2019). The references need it only
for greys, where it is exact: a grey reflectance g is the constant g, and a grey emitter
g·(1, 1, 1) is g × D65 scaled to film Y = 1 (`d65_unit`), so RGB white renders as
XYZ_to_sRGB(D65 at Y = 1) = (1.0000057, 1.0000753, 0.9998329), not (1, 1, 1).
"""
from __future__ import annotations

import functools
import warnings

import numpy as np

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import colour

SHAPE = colour.SpectralShape(360, 830, 1)
CMFS_NAME = "CIE 1931 2 Degree Standard Observer"


@functools.cache
def cmfs():
    c = colour.MSDS_CMFS[CMFS_NAME]
    assert c.shape == SHAPE, c.shape
    return c


def aligned(sd):
    """sd on heron's grid, with sd's own interpolator and extrapolator (as heron does).

    Colour-science's runtime warnings about the source grid are silenced.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", colour.utilities.ColourRuntimeWarning)
        return sd.copy().align(SHAPE)


def film_xyz(sd) -> np.ndarray:
    """XYZ of a spectral radiance under heron's film convention, by colour-science."""
    return colour.sd_to_XYZ(aligned(sd), cmfs(), illuminant=colour.sd_ones(SHAPE),
                            method="Integration") / 100.0


def xyz_to_linear_srgb(xyz) -> np.ndarray:
    """IEC 61966-2-1 XYZ -> linear sRGB, no chromatic adaptation (XYZ is D65-relative)."""
    return colour.XYZ_to_RGB(np.asarray(xyz, dtype=float), "sRGB", illuminant=None,
                             chromatic_adaptation_transform=None)


def spectrum_e():
    return colour.sd_ones(SHAPE)


@functools.cache
def d65_unit():
    """CIE D65 as heron uses it: aligned to 1 nm 360–830 nm, scaled to film Y = 1."""
    d65 = aligned(colour.SDS_ILLUMINANTS["D65"])
    return d65 / film_xyz(d65)[1]


def grey_emitter(g: float):
    """heron's uplift of the RGB emitter (g, g, g): exactly g × D65 at film Y = 1.

    Jakob & Hanika's model gives the constant spectrum for a grey, and
    rgb_to_illuminant multiplies by D65(Y = 1) (src/spectrum/uplift.rs). Only greys have
    a closed form; a coloured RGB would need heron's coefficient table.
    """
    return d65_unit() * float(g)


def expected_srgb(sd) -> np.ndarray:
    """Linear sRGB heron's film should converge to for spectral radiance sd."""
    return xyz_to_linear_srgb(film_xyz(sd))


def uniform_sampling_sigma(sd) -> np.ndarray:
    """Per-sample standard deviation of each linear sRGB channel when every camera sample
    carries ONE wavelength drawn uniformly on 360–830 nm (the crudest spectral estimator).

    Estimator per sample: f(λ) = L(λ) · (M · x̄ȳz̄(λ)) / (Σ ȳ Δλ) / p(λ), p = 1/N_λ per
    1 nm bin. Hero-wavelength sampling, importance sampling or stratification only lower
    it, so it bounds the noise a correct renderer may have; the render tests require
    their measured standard error to be below a multiple of σ/√N, which is what gives
    them power.
    """
    L = aligned(sd).values
    xyz = cmfs().values
    m = colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB
    w = (xyz @ m.T) / xyz[:, 1].sum()  # per-bin weight of each sRGB channel
    n = len(L)
    f = L[:, None] * w * n  # value of the estimator for each bin, p = 1/n
    mean = f.mean(axis=0)
    return np.sqrt(((f - mean) ** 2).mean(axis=0))


# --- `heron color` (tests/python/test_color_cmd.py) ------------------------------------

OBSERVER_CMFS = {
    "1931": "CIE 1931 2 Degree Standard Observer",
    "1964": "CIE 1964 10 Degree Standard Observer",
}


@functools.cache
def cmfs_for(observer: str):
    """colour-science's CMFS for heron's --observer value ("1931" or "1964")."""
    c = colour.MSDS_CMFS[OBSERVER_CMFS[observer]]
    assert c.shape == SHAPE, c.shape
    return c


@functools.cache
def illuminant_sd(name: str):
    """The illuminant heron color uses for --illuminant name, on heron's grid: D65 and A
    from SDS_ILLUMINANTS aligned as spectra/README.md says (linear, constant beyond
    780 nm), E the constant 1 (scale cancels)."""
    if name == "E":
        return colour.sd_ones(SHAPE)
    return aligned(colour.SDS_ILLUMINANTS[name])


def color_xyz(sd, observer: str, illuminant: str) -> np.ndarray:
    """XYZ `heron color` should print, by colour-science's own integration:

    with an illuminant I, colour.sd_to_XYZ(R, cmfs, I, method="Integration") / 100
    = Σ R I x̄ / Σ I ȳ (a perfect reflector has Y = 1); with "none", the same with an
    all-ones illuminant, = Σ S x̄ / Σ ȳ (heron's film convention).
    sd must already be on heron's grid (1 nm, 360–830 nm).
    """
    assert sd.shape == SHAPE, sd.shape
    ill = colour.sd_ones(SHAPE) if illuminant == "none" else illuminant_sd(illuminant)
    return colour.sd_to_XYZ(sd, cmfs_for(observer), illuminant=ill,
                            method="Integration") / 100.0
