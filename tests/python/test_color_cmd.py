"""`heron color` against colour-science 0.4.7.

`heron color FILE.csv --illuminant D65|D50|A|E|none --observer 1931|1964
[--interpolation cie167|linear]` prints XYZ, xy and linear sRGB as JSON
(src/colorimetry.rs). colour-science's answer for the same
distribution (heronref.color_xyz):

    XYZ = colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration") / 100

with an all-ones illuminant for `none`, xy = colour.XYZ_to_xy(XYZ), and linear sRGB =
colour.XYZ_to_RGB(XYZ, "sRGB", chromatic_adaptation_transform=None) (heronref).

So that the comparison is about colorimetry and not about interpolation, every test
distribution is first put on heron's grid (1 nm, 360–830 nm) BY COLOUR-SCIENCE and
written to a CSV at those 471 wavelengths, where heron's linear interpolation
(DenseSpectrum::from_samples) returns the values unchanged:

- D65 and A (as emitters, `--illuminant none`): SDS_ILLUMINANTS aligned with their own
  interpolator, LinearInterpolator, constant beyond 780 nm (heronref.aligned);
- the 24 ColorChecker N Ohta patches (reflectances under D65, A and E): aligned with
  their own interpolator, colour-science's default SpragueInterpolator, held constant
  (Extrapolator, method "Constant") outside their 380–780 nm;
- monochromatic lines at 450, 532.5, 589.3 and 632.8 nm (emitters): triangles of
  half-width 1 nm built directly on the 1 nm grid (weights 1 − |λ − λ0| / 1 nm), so
  each is the CMFs linearly interpolated at λ0.

Native data (issue 10, part 6): the 24 BabelColor Average patches at their own 10 nm
(380–730 nm)
and the N Ohta patches at their own 5 nm, and N Ohta patches at irregular wavelengths,
are written as they are; heron must interpolate them as colour-science does
(`colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration")` aligns a distribution
off its grid with its own interpolator: Sprague for uniform data, a cubic spline for
irregular) and agree to 1e-6 relative.

Every CIE illuminant (issue 24, part 2): each illuminant of colour-science's
SDS_ILLUMINANTS that covers the visible range 380–780 nm, written at its own rows, as an
emitter (`--illuminant none --interpolation linear`) against
`colour.sd_to_XYZ(sd, cmfs, method="Integration")` at 1e-6 relative; the reflectances
under A, D50 and D65 (`--illuminant`) against `colour.sd_to_XYZ(sd, cmfs,
SDS_ILLUMINANTS[name], method="Integration")` at 1e-6 too. Why `linear`: colour-science
makes every illuminant with LinearInterpolator and keeps it when aligning to the CMFs,
where a plain distribution gets Sprague (src/spectrum/interp.rs); heron's default,
cie167, misses the illuminants by 1e-4 to 1e-3, which a test checks as well.

Each case runs with both observers. Agreement: |heron − ref| ≤ 1e-4·|ref| + 1e-6·max|ref|
per component of XYZ, xy and linear sRGB (the floor, 1e-6 of the vector's largest
component, is for components near 0, e.g. z̄ at 632.8 nm or an sRGB channel that is
almost 0). heron's tables are float32 and its sums float64, so the deviations are
~1e-7 relative; the tests also check that the tolerance is tight enough to catch the
wrong observer, the wrong illuminant and a line shifted by 0.1 nm.
"""
from __future__ import annotations

import json
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

import heronref
from heronref import SHAPE, colour
from heronrun import REPO, require_heron_bin

OBSERVERS = ["1931", "1964"]
RTOL = 1e-4
FLOOR = 1e-6  # times the largest |component| of the reference vector
LINES_NM = [450.0, 532.5, 589.3, 632.8]
PATCHES = list(colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"])


# --- test distributions, on heron's grid ------------------------------------------------

def patch_sd(name):
    return heronref.aligned(colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"][name])


def line_sd(lambda0):
    wl = SHAPE.wavelengths
    return colour.SpectralDistribution(np.clip(1 - np.abs(wl - lambda0), 0, None), wl,
                                       name=f"line {lambda0} nm")


def write_csv(path: pathlib.Path, sd) -> pathlib.Path:
    assert sd.shape == SHAPE, f"{sd.name}: {sd.shape} is not heron's grid"
    np.testing.assert_array_equal(sd.wavelengths, np.arange(360, 831))
    with path.open("w", newline="\n") as f:
        f.write(f"# {sd.name}, aligned by colour-science {colour.__version__}\n")
        f.write("wavelength_nm,value\n")
        for w, v in zip(sd.wavelengths, sd.values):
            f.write(f"{int(w)},{float(v)!r}\n")
    return path


# --- running heron -----------------------------------------------------------------------

def heron_color(csv: pathlib.Path, illuminant: str, observer: str) -> dict:
    cmd = [str(require_heron_bin()), "color", str(csv), "--illuminant", illuminant,
           "--observer", observer]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, timeout=60)
    if proc.returncode != 0:
        pytest.fail(f"`{' '.join(cmd)}` exited with {proc.returncode}:\n{proc.stderr}",
                    pytrace=False)
    out = json.loads(proc.stdout)
    assert list(out) == ["file", "observer", "illuminant", "interpolation", "XYZ", "xy",
                         "linear_srgb"], out
    assert out["file"] == str(csv)
    assert out["observer"] == observer
    assert out["illuminant"] == illuminant
    assert out["interpolation"] == "cie167"
    # The CSVs cover 360–830 nm, so heron has nothing to say on stderr.
    assert proc.stderr == "", proc.stderr
    return out


def reference(sd, illuminant, observer) -> dict:
    xyz = heronref.color_xyz(sd, observer, illuminant)
    return {"XYZ": xyz, "xy": colour.XYZ_to_xy(xyz),
            "linear_srgb": heronref.xyz_to_linear_srgb(xyz)}


def deviation(got, want):
    """max over components of |got − want| / (RTOL·|want| + FLOOR·max|want|): ≤ 1 passes."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    tol = RTOL * np.abs(want) + FLOOR * np.abs(want).max()
    return float((np.abs(got - want) / tol).max())


def assert_agrees(out, ref, what):
    for key in ("XYZ", "xy", "linear_srgb"):
        d = deviation(out[key], ref[key])
        assert d <= 1, (f"{what}: {key} heron {out[key]} vs colour-science "
                        f"{list(ref[key])} ({d:.3g} × tolerance)")


@pytest.fixture(scope="module")
def csvs(tmp_path_factory):
    """Name -> (CSV path, the SD written to it)."""
    d = tmp_path_factory.mktemp("color_csv")
    sds = {"D65": heronref.aligned(colour.SDS_ILLUMINANTS["D65"]),
           "A": heronref.aligned(colour.SDS_ILLUMINANTS["A"])}
    sds.update({f"patch {i:02d}": patch_sd(p) for i, p in enumerate(PATCHES, start=1)})
    sds.update({f"line {l}": line_sd(l) for l in LINES_NM})
    return {name: (write_csv(d / f"{name.replace(' ', '_')}.csv", sd), sd)
            for name, sd in sds.items()}


# --- the checks --------------------------------------------------------------------------

def test_colour_science_is_the_pinned_one():
    assert colour.__version__ == "0.4.7"
    assert len(PATCHES) == 24


def test_test_distributions_are_what_the_docstring_says(csvs):
    sd = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"][PATCHES[0]]
    assert sd.shape == colour.SpectralShape(380, 780, 5)
    assert sd.interpolator is colour.SpragueInterpolator
    assert colour.SDS_ILLUMINANTS["A"].interpolator is colour.LinearInterpolator
    # Each line has unit area and its centroid at λ0.
    for l in LINES_NM:
        v = csvs[f"line {l}"][1].values
        assert v.sum() == pytest.approx(1, abs=1e-12)
        assert (v * SHAPE.wavelengths).sum() == pytest.approx(l, abs=1e-9)
    # heronref's illuminants on the grid are what colour.sd_to_XYZ uses for the native
    # data: passing the aligned or the native SD gives identical XYZ.
    p = csvs["patch 01"][1]
    for name in ("D65", "A"):
        cmfs = heronref.cmfs_for("1931")
        with warnings.catch_warnings():  # "Aligning ... illuminant shape": expected here
            warnings.simplefilter("ignore", colour.utilities.ColourRuntimeWarning)
            native = colour.sd_to_XYZ(p, cmfs, colour.SDS_ILLUMINANTS[name],
                                      method="Integration")
        np.testing.assert_array_equal(native / 100, heronref.color_xyz(p, "1931", name))


@pytest.mark.parametrize("observer", OBSERVERS)
@pytest.mark.parametrize("name", ["D65", "A"])
def test_illuminants_as_emitters(csvs, name, observer):
    path, sd = csvs[name]
    assert_agrees(heron_color(path, "none", observer), reference(sd, "none", observer),
                  f"{name} as emitter, {observer}")


@pytest.mark.parametrize("observer", OBSERVERS)
@pytest.mark.parametrize("illuminant", ["D65", "A", "E"])
def test_colorchecker_patches_as_reflectances(csvs, illuminant, observer):
    for i, patch in enumerate(PATCHES, start=1):
        path, sd = csvs[f"patch {i:02d}"]
        assert_agrees(heron_color(path, illuminant, observer),
                      reference(sd, illuminant, observer),
                      f"ColorChecker N Ohta {i:02d} {patch!r} under {illuminant}, {observer}")


@pytest.mark.parametrize("observer", OBSERVERS)
@pytest.mark.parametrize("lambda0", LINES_NM)
def test_monochromatic_lines(csvs, lambda0, observer):
    path, sd = csvs[f"line {lambda0}"]
    assert_agrees(heron_color(path, "none", observer), reference(sd, "none", observer),
                  f"line at {lambda0} nm, {observer}")


def test_white_reflector_is_the_illuminant_white(tmp_path):
    # A perfect reflector has Y = 1 and the illuminant's own chromaticity.
    path = write_csv(tmp_path / "white.csv", colour.sd_ones(SHAPE))
    for observer in OBSERVERS:
        for name in ("D65", "A"):
            out = heron_color(path, name, observer)
            ill = heronref.illuminant_sd(name)
            ref = reference(ill, "none", observer)
            ref = {k: v / ref["XYZ"][1] if k != "xy" else v for k, v in ref.items()}
            assert out["XYZ"][1] == pytest.approx(1, abs=1e-6)
            assert_agrees(out, ref, f"white under {name}, {observer}")


def test_tolerance_catches_wrong_observer_illuminant_and_wavelength(csvs):
    """The comparison has power: plausible mistakes fail it by a wide margin."""
    path, sd = csvs["patch 13"]  # blue
    out = heron_color(path, "D65", "1964")
    assert deviation(out["XYZ"], reference(sd, "D65", "1931")["XYZ"]) > 10
    assert deviation(out["XYZ"], reference(sd, "A", "1964")["XYZ"]) > 10
    path, sd = csvs["D65"]
    out = heron_color(path, "none", "1931")
    assert deviation(out["XYZ"], reference(sd, "none", "1964")["XYZ"]) > 10
    # A line 0.1 nm off is outside the tolerance.
    for l in LINES_NM:
        path, _ = csvs[f"line {l}"]
        out = heron_color(path, "none", "1931")
        shifted = reference(line_sd(l + 0.1), "none", "1931")
        assert deviation(out["XYZ"], shifted["XYZ"]) > 2, l


# --- native data: heron interpolates as colour-science does (issue 10, part 6) -----------

NATIVE_RTOL = 1e-6
NATIVE_FLOOR = 1e-7


def write_native_csv(path: pathlib.Path, wavelengths, values, name) -> pathlib.Path:
    with path.open("w", newline="\n") as f:
        f.write(f"# {name}, native wavelengths\nwavelength_nm,value\n")
        for w, v in zip(wavelengths, values):
            f.write(f"{float(w)!r},{float(v)!r}\n")
    return path


def heron_color_native(csv, illuminant, observer, interpolation="cie167") -> dict:
    # Data short of 360–830 nm draws a remark on stderr; the JSON is what is compared.
    cmd = [str(require_heron_bin()), "color", str(csv), "--illuminant", illuminant,
           "--observer", observer, "--interpolation", interpolation]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, timeout=60)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["interpolation"] == interpolation
    return out


def native_reference(sd, illuminant, observer) -> np.ndarray:
    """colour.sd_to_XYZ on the native distribution under the native illuminant of
    SDS_ILLUMINANTS, through colour-science's own alignment of both (checked here to be
    heronref.aligned, i.e. each one's own interpolator)."""
    xyz = heronref.color_xyz(heronref.aligned(sd), observer, illuminant)
    ill = colour.sd_ones(SHAPE) if illuminant == "none" else colour.SDS_ILLUMINANTS[illuminant]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", colour.utilities.ColourRuntimeWarning)
        direct = colour.sd_to_XYZ(sd, heronref.cmfs_for(observer), illuminant=ill,
                                  method="Integration") / 100.0
    np.testing.assert_allclose(direct, xyz, rtol=1e-12)
    return xyz


def native_deviation(got, want) -> float:
    got, want = np.asarray(got, float), np.asarray(want, float)
    tol = NATIVE_RTOL * np.abs(want) + NATIVE_FLOOR * np.abs(want).max()
    return float((np.abs(got - want) / tol).max())


def irregular(sd):
    """sd at irregular wavelengths: every third sample dropped, so steps alternate."""
    keep = [i for i in range(len(sd.wavelengths)) if i % 3 != 1]
    out = colour.SpectralDistribution(sd.values[keep], sd.wavelengths[keep], name=sd.name)
    assert not out.is_uniform() and out.interpolator is colour.CubicSplineInterpolator
    return out


NATIVE_SETS = {
    "BabelColor Average (10 nm)": lambda: [
        colour.SDS_COLOURCHECKERS["BabelColor Average"][p]
        for p in colour.SDS_COLOURCHECKERS["BabelColor Average"]],
    "ColorChecker N Ohta (5 nm)": lambda: [
        colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"][p] for p in PATCHES],
    "ColorChecker N Ohta (irregular)": lambda: [
        irregular(colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"][p]) for p in PATCHES],
}


@pytest.mark.parametrize("observer", OBSERVERS)
@pytest.mark.parametrize("dataset", list(NATIVE_SETS))
def test_native_data_interpolates_as_colour_science(tmp_path, dataset, observer):
    sds = NATIVE_SETS[dataset]()
    assert len(sds) == 24
    if "10 nm" in dataset:
        assert sds[0].shape == colour.SpectralShape(380, 730, 10)
    worst = 0.0
    for i, sd in enumerate(sds):
        path = write_native_csv(tmp_path / f"p{i}.csv", sd.wavelengths, sd.values, sd.name)
        for illuminant in ("A", "D50", "D65"):
            out = heron_color_native(path, illuminant, observer)
            ref = native_reference(sd, illuminant, observer)
            d = native_deviation(out["XYZ"], ref)
            worst = max(worst, d)
            assert d <= 1, (f"{dataset} {sd.name!r} under {illuminant}, {observer}: heron "
                            f"{out['XYZ']} vs colour-science {list(ref)} ({d:.3g} × tolerance)")
    print(f"{dataset}, {observer}: worst deviation {worst:.3g} of 1e-6 relative")


def test_native_tolerance_would_catch_linear_interpolation(tmp_path):
    """The 1e-6 comparison has power: linear interpolation of the 10 nm data (heron
    before this change) misses colour-science by far more."""
    sd = colour.SDS_COLOURCHECKERS["BabelColor Average"]["dark skin"]
    path = write_native_csv(tmp_path / "p.csv", sd.wavelengths, sd.values, sd.name)
    out = heron_color_native(path, "D65", "1931")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", colour.utilities.ColourRuntimeWarning)
        linear = sd.copy().align(SHAPE, interpolator=colour.LinearInterpolator)
    assert native_deviation(out["XYZ"], heronref.color_xyz(linear, "1931", "D65")) > 100


# --- every CIE illuminant at its own rows (issue 24, part 2) ------------------------------

VISIBLE_NM = (380.0, 780.0)


def illuminants_covering_visible():
    """(names kept, {name skipped: why}) over colour-science's SDS_ILLUMINANTS."""
    kept, skipped = [], {}
    for name, sd in colour.SDS_ILLUMINANTS.items():
        lo, hi = sd.shape.start, sd.shape.end
        if lo <= VISIBLE_NM[0] and hi >= VISIBLE_NM[1]:
            kept.append(name)
        else:
            skipped[name] = f"tabulated over {lo:g}–{hi:g} nm only"
    return kept, skipped


ILLUMINANTS, SKIPPED_ILLUMINANTS = illuminants_covering_visible()


def test_illuminant_list_is_every_cie_one():
    """The list the next test runs: all CIE illuminants (A, B, C, the D series, E, the
    FL, HP and LED series, ID50 and ID65). Only the seven ISO 7589 photographic
    illuminants are skipped: they are tabulated over 350–690 nm (350–560 nm for the
    Sensitometric Printer), so most of their colour would come from holding the last
    row over 690–830 nm, not from data."""
    for name in ["A", "B", "C", "D50", "D55", "D60", "D65", "D75", "E", "ID50", "ID65",
                 *[f"FL{i}" for i in range(1, 13)], *[f"FL3.{i}" for i in range(1, 16)],
                 *[f"HP{i}" for i in range(1, 6)], *[f"LED-B{i}" for i in range(1, 6)],
                 "LED-BH1", "LED-RGB1", "LED-V1", "LED-V2"]:
        assert name in ILLUMINANTS, name
    assert len(ILLUMINANTS) == 52
    assert sorted(SKIPPED_ILLUMINANTS) == sorted(
        n for n in colour.SDS_ILLUMINANTS if n.startswith("ISO 7589")), SKIPPED_ILLUMINANTS
    assert len(SKIPPED_ILLUMINANTS) == 7
    # What makes `--interpolation linear` the match: colour-science made every one of
    # them with a linear interpolator, which SpectralDistribution.align keeps.
    for name in ILLUMINANTS:
        assert colour.SDS_ILLUMINANTS[name].interpolator is colour.LinearInterpolator, name


@pytest.fixture(scope="module")
def illuminant_csvs(tmp_path_factory):
    d = tmp_path_factory.mktemp("illuminants")
    out = {}
    for i, name in enumerate(ILLUMINANTS):
        sd = colour.SDS_ILLUMINANTS[name]
        out[name] = write_native_csv(d / f"ill{i:02d}.csv", sd.wavelengths, sd.values, name)
    return out


def colour_science_emitter(name, observer) -> np.ndarray:
    """colour.sd_to_XYZ(sd, cmfs, method="Integration") / 100 on the illuminant's own
    rows (illuminant E by default: Σ S x̄ / Σ ȳ, heron's `--illuminant none`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", colour.utilities.ColourRuntimeWarning)
        return colour.sd_to_XYZ(colour.SDS_ILLUMINANTS[name], heronref.cmfs_for(observer),
                                method="Integration") / 100.0


@pytest.mark.parametrize("observer", OBSERVERS)
def test_every_cie_illuminant_as_emitter(illuminant_csvs, observer):
    worst = (0.0, None)
    for name in ILLUMINANTS:
        out = heron_color_native(illuminant_csvs[name], "none", observer, "linear")
        ref = colour_science_emitter(name, observer)
        d = max(native_deviation(out["XYZ"], ref),
                # normalised by Y, as the issue measured, and the chromaticity
                native_deviation(np.divide(out["XYZ"], out["XYZ"][1]), ref / ref[1]),
                native_deviation(out["xy"], colour.XYZ_to_xy(ref)))
        worst = max(worst, (d, name))
        assert d <= 1, (f"{name}, {observer}: heron {out['XYZ']} vs colour-science {list(ref)} "
                        f"({d:.3g} × tolerance of 1e-6 relative)")
    print(f"{len(ILLUMINANTS)} illuminants, {observer}: worst {worst[0]:.3g} of 1e-6 ({worst[1]})")


def test_cie167_misses_the_illuminants_as_the_issue_measured(illuminant_csvs):
    """The cause, and the power of the test above: interpolated by CIE 167's rules
    (Sprague through the 5 nm rows), the illuminants miss colour-science by the amounts
    issue 24 measured (relative, XYZ normalised by Y, CIE 1931 2°), far outside 1e-6."""
    measured = {"A": 1.6e-4, "D50": 1.0e-4, "FL2": 1.2e-3}
    for name, want in measured.items():
        out = heron_color_native(illuminant_csvs[name], "none", "1931")
        ref = colour_science_emitter(name, "1931")
        got = np.divide(out["XYZ"], out["XYZ"][1])
        rel = float(np.abs(got / (ref / ref[1]) - 1).max())
        assert rel == pytest.approx(want, rel=0.05), (name, rel)
        assert native_deviation(got, ref / ref[1]) > 50
