"""The committed tables in spectra/ are colour-science's data, exactly.

Tables: CIE 1931 2° and CIE 1964 10° observers, illuminants D65, D50 and A, Smits (1999).

Three layers: (1) every number equals colour-science 0.4.7's value (the CSVs are written
with repr(float), so parsing them gives the float64 back; compared at 1e-12 relative);
(2) the claims spectra/README.md makes about grids, interpolation and extrapolation hold;
(3) scripts/gen_spectra.py reproduces the committed files byte for byte.
"""
from __future__ import annotations

import csv
import filecmp
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import heronref
from heronref import colour

REPO = pathlib.Path(__file__).resolve().parents[2]
SPECTRA = REPO / "spectra"
WL_1NM = np.arange(360, 831, dtype=float)
RTOL = 1e-12
SMITS_NAMES = ["white", "cyan", "magenta", "yellow", "red", "green", "blue"]


def read_csv(name):
    with (SPECTRA / name).open(newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    assert all(len(r) == len(header) for r in body), f"{name}: ragged rows"
    return header, np.array([[float(v) for v in r] for r in body])


def assert_same(actual, expected, what):
    np.testing.assert_allclose(actual, expected, rtol=RTOL, atol=0, err_msg=what)


def test_colour_science_version_is_the_pinned_one():
    # The tables (and spectra/README.md) are tied to this version.
    assert colour.__version__ == "0.4.7"


def test_cie1931_header_and_grid():
    header, data = read_csv("cie1931_2deg.csv")
    assert header == ["wavelength_nm", "x_bar", "y_bar", "z_bar"]
    assert data.shape == (471, 4)
    np.testing.assert_array_equal(data[:, 0], WL_1NM)


def test_cie1931_values_are_colour_science_cmfs():
    _, data = read_csv("cie1931_2deg.csv")
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    np.testing.assert_array_equal(cmfs.wavelengths, WL_1NM)
    assert_same(data[:, 1:], cmfs.values, "CIE 1931 2° x̄ ȳ z̄ vs colour-science")
    # The raw table and colour-science's alignment to the same grid agree (the script
    # writes the raw one; align() only adds round-off).
    aligned = cmfs.copy().align(heronref.SHAPE).values
    np.testing.assert_allclose(data[:, 1:], aligned, rtol=1e-12, atol=1e-14)
    # Spot values from the CVRL CIE 1931 2° table.
    row = {int(r[0]): r[1:] for r in data}
    np.testing.assert_array_equal(row[360], [0.0001299, 0.000003917, 0.0006061])
    np.testing.assert_array_equal(row[555], [0.5120501, 1.0, 0.005749999])
    assert (data[:, 1:] >= 0).all()


def test_cie1931_film_normalisation():
    # Numbers quoted in spectra/README.md: Σȳ and the XYZ of equal energy.
    _, data = read_csv("cie1931_2deg.csv")
    sums = data[:, 1:].sum(axis=0)
    assert sums[1] == pytest.approx(106.856917101, rel=1e-10)
    np.testing.assert_allclose(sums / sums[1], [1.00008004, 1.0, 1.00033067], rtol=1e-8)


def test_d65_header_and_grid():
    header, data = read_csv("cie_d65.csv")
    assert header == ["wavelength_nm", "value"]
    assert data.shape == (471, 2)
    np.testing.assert_array_equal(data[:, 0], WL_1NM)


def test_d65_values_are_colour_science_d65_aligned():
    _, data = read_csv("cie_d65.csv")
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(heronref.SHAPE)
    np.testing.assert_array_equal(d65.wavelengths, WL_1NM)
    assert_same(data[:, 1], d65.values, "D65 vs colour-science D65 aligned to 1 nm 360-830")


def test_d65_alignment_is_linear_inside_and_constant_beyond_780nm():
    # What spectra/README.md says about the alignment, checked against the native data.
    _, data = read_csv("cie_d65.csv")
    native = colour.SDS_ILLUMINANTS["D65"]
    assert native.shape == colour.SpectralShape(300, 780, 5)
    wl, values = native.wavelengths, native.values
    inside = data[:, 0] <= 780
    # Tabulated values at multiples of 5 nm, straight lines in between.
    expected = np.interp(data[inside, 0], wl, values)
    np.testing.assert_allclose(data[inside, 1], expected, rtol=1e-12)
    at5 = inside & (data[:, 0] % 5 == 0)
    native_at = dict(zip(wl, values))
    np.testing.assert_array_equal(data[at5, 1], [native_at[w] for w in data[at5, 0]])
    # 781-830 nm hold the 780 nm value.
    assert native_at[780.0] == 63.3828
    np.testing.assert_array_equal(data[~inside, 1], np.full((~inside).sum(), 63.3828))
    assert data[data[:, 0] == 560, 1] == [100.0]


def test_d50_values_are_colour_science_d50_aligned():
    header, data = read_csv("cie_d50.csv")
    assert header == ["wavelength_nm", "value"]
    d50 = colour.SDS_ILLUMINANTS["D50"].copy().align(heronref.SHAPE)
    np.testing.assert_array_equal(d50.wavelengths, WL_1NM)
    np.testing.assert_array_equal(data[:, 0], WL_1NM)
    assert_same(data[:, 1], d50.values, "D50 vs colour-science D50 aligned to 1 nm 360-830")
    # Linear between the 5 nm rows, the 780 nm value held beyond (spectra/README.md).
    native = colour.SDS_ILLUMINANTS["D50"]
    inside = data[:, 0] <= 780
    np.testing.assert_allclose(data[inside, 1], np.interp(data[inside, 0], native.wavelengths,
                                                          native.values), rtol=1e-12)
    np.testing.assert_array_equal(data[~inside, 1], np.full((~inside).sum(), 78.274))
    assert data[data[:, 0] == 560, 1] == [100.0]


def test_d65_luminance_as_quoted():
    _, d = read_csv("cie_d65.csv")
    _, c = read_csv("cie1931_2deg.csv")
    y = (d[:, 1] * c[:, 2]).sum() / c[:, 2].sum()
    assert y == pytest.approx(98.8899736097, rel=1e-10)
    xyz = (d[:, 1:2] * c[:, 1:]).sum(axis=0) / c[:, 2].sum() / y
    np.testing.assert_allclose(xyz, [0.95047076, 1.0, 1.08882842], rtol=1e-8)


def test_cie1964_header_and_grid():
    header, data = read_csv("cie1964_10deg.csv")
    assert header == ["wavelength_nm", "x_bar", "y_bar", "z_bar"]
    assert data.shape == (471, 4)
    np.testing.assert_array_equal(data[:, 0], WL_1NM)


def test_cie1964_values_are_colour_science_cmfs():
    _, data = read_csv("cie1964_10deg.csv")
    cmfs = colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"]
    np.testing.assert_array_equal(cmfs.wavelengths, WL_1NM)
    assert_same(data[:, 1:], cmfs.values, "CIE 1964 10° x̄ ȳ z̄ vs colour-science")
    aligned = cmfs.copy().align(heronref.SHAPE).values
    np.testing.assert_allclose(data[:, 1:], aligned, rtol=1e-12, atol=1e-14)
    # Spot values quoted in spectra/README.md (CVRL's CIE 1964 10° table).
    row = {int(r[0]): r[1:] for r in data}
    np.testing.assert_array_equal(row[360], [1.222e-07, 1.3398e-08, 5.35027e-07])
    np.testing.assert_array_equal(row[555], [0.616053, 0.99911, 0.001091])
    assert row[557][1] == 1.0 and data[:, 2].max() == 1.0
    assert (data[data[:, 0] >= 560, 3] == 0).all() and row[559][2] > 0
    assert (data[:, 1:] >= 0).all()
    # It is a different observer from the 1931 one.
    _, d2 = read_csv("cie1931_2deg.csv")
    assert np.abs(data[:, 1:] - d2[:, 1:]).max() > 0.1


def test_cie1964_film_normalisation():
    _, data = read_csv("cie1964_10deg.csv")
    sums = data[:, 1:].sum(axis=0)
    assert sums[1] == pytest.approx(116.661877102, rel=1e-10)
    np.testing.assert_allclose(sums / sums[1], [0.99988550, 1.0, 1.00010375], rtol=1e-8)


def test_a_header_and_grid():
    header, data = read_csv("cie_a.csv")
    assert header == ["wavelength_nm", "value"]
    assert data.shape == (471, 2)
    np.testing.assert_array_equal(data[:, 0], WL_1NM)


def test_a_values_are_colour_science_a_aligned():
    _, data = read_csv("cie_a.csv")
    a = colour.SDS_ILLUMINANTS["A"].copy().align(heronref.SHAPE)
    np.testing.assert_array_equal(a.wavelengths, WL_1NM)
    assert_same(data[:, 1], a.values, "A vs colour-science A aligned to 1 nm 360-830")


def test_a_alignment_is_linear_inside_and_constant_beyond_780nm():
    _, data = read_csv("cie_a.csv")
    native = colour.SDS_ILLUMINANTS["A"]
    assert native.shape == colour.SpectralShape(300, 780, 5)
    wl, values = native.wavelengths, native.values
    assert (values[0], values[1]) == (0.930483, 1.12821)
    inside = data[:, 0] <= 780
    np.testing.assert_allclose(data[inside, 1], np.interp(data[inside, 0], wl, values),
                               rtol=1e-12)
    at5 = inside & (data[:, 0] % 5 == 0)
    native_at = dict(zip(wl, values))
    np.testing.assert_array_equal(data[at5, 1], [native_at[w] for w in data[at5, 0]])
    assert native_at[780.0] == 241.675
    np.testing.assert_array_equal(data[~inside, 1], np.full((~inside).sum(), 241.675))
    assert data[data[:, 0] == 560, 1] == [100.0]


def test_a_against_the_planckian_formula_as_quoted():
    # spectra/README.md: the 5 nm table is the formula to 4.1e-6; the 1 nm alignment is
    # above it by up to 0.13 % (at 362 nm) and, held at 241.675, 8.2 % below at 830 nm.
    from colour.colorimetry import sd_CIE_standard_illuminant_A as formula
    native = colour.SDS_ILLUMINANTS["A"]
    assert np.abs(formula(native.shape).values / native.values - 1).max() < 4.1e-6
    _, data = read_csv("cie_a.csv")
    f = formula(heronref.SHAPE).values
    rel = f / data[:, 1] - 1
    inside = data[:, 0] <= 780
    assert np.abs(rel[inside]).max() == pytest.approx(0.0013, abs=5e-5)
    assert data[np.argmax(np.abs(rel[inside])), 0] == 362
    assert f[-1] == pytest.approx(261.602, abs=1e-3)
    assert rel[-1] == pytest.approx(0.082, abs=5e-4)
    # The formula's colour at 1 nm, quoted next to the table's.
    for table, xyz_quoted, xy_quoted in (
            ("cie1931_2deg.csv", [1.098503376, 1, 0.355849388], [0.447574, 0.407439]),
            ("cie1964_10deg.csv", [1.111439587, 1, 0.351999521], [0.451174, 0.405937])):
        _, c = read_csv(table)
        xyz = (f[:, None] * c[:, 1:]).sum(axis=0) / (f * c[:, 2]).sum()
        np.testing.assert_allclose(xyz, xyz_quoted, rtol=1e-8, err_msg=table)
        np.testing.assert_allclose(xyz[:2] / xyz.sum(), xy_quoted, atol=6e-7, err_msg=table)


def test_a_luminance_and_colour_as_quoted():
    _, a = read_csv("cie_a.csv")
    for table, y_quoted, xyz_quoted, xy_quoted in (
            ("cie1931_2deg.csv", 100.973920764, [1.098493831, 1, 0.355907946],
             [0.447561, 0.407431]),
            ("cie1964_10deg.csv", 97.542671224, [1.111428277, 1, 0.352060094],
             [0.451160, 0.405928])):
        _, c = read_csv(table)
        y = (a[:, 1] * c[:, 2]).sum() / c[:, 2].sum()
        assert y == pytest.approx(y_quoted, rel=1e-10), table
        xyz = (a[:, 1:2] * c[:, 1:]).sum(axis=0) / c[:, 2].sum() / y
        np.testing.assert_allclose(xyz, xyz_quoted, rtol=1e-8, err_msg=table)
        np.testing.assert_allclose(xyz[:2] / xyz.sum(), xy_quoted, atol=6e-7, err_msg=table)
    # The un-adapted linear sRGB of A at Y = 1 (1931 observer).
    np.testing.assert_allclose(heronref.xyz_to_linear_srgb([1.098493831, 1, 0.355907946]),
                               [1.8451234, 0.8262395, 0.2333808], atol=6e-8)


def test_smits_header_and_layout():
    header, data = read_csv("smits1999.csv")
    assert header == ["wavelength_nm"] + SMITS_NAMES
    assert data.shape == (10, 8)
    # 380 + k·340/9 nm, to colour-science's four decimals.
    np.testing.assert_allclose(data[:, 0], 380 + np.arange(10) * 340 / 9, atol=6e-5)
    assert data[0, 0] == 380 and data[-1, 0] == 720


def test_smits_values_are_colour_science_basis():
    _, data = read_csv("smits1999.csv")
    basis = colour.recovery.SDS_SMITS1999
    for i, name in enumerate(SMITS_NAMES, start=1):
        sd = basis[name]
        np.testing.assert_array_equal(data[:, 0], sd.wavelengths, err_msg=f"Smits {name} wavelengths")
        assert_same(data[:, i], sd.values, f"Smits {name}")
    # Smits' white is not exactly 1 (the table is kept, unused: heron uplifts RGB with
    # Jakob & Hanika 2019 now, whose white is exactly 1).
    assert data[:, 1].min() == 0.9992


def test_generator_reproduces_committed_tables(tmp_path):
    script = REPO / "scripts" / "gen_spectra.py"
    proc = subprocess.run([sys.executable, str(script), "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    for name in ("cie1931_2deg.csv", "cie1964_10deg.csv", "cie_d65.csv", "cie_d50.csv", "cie_a.csv",
                 "smits1999.csv"):
        assert filecmp.cmp(tmp_path / name, SPECTRA / name, shallow=False), (
            f"spectra/{name} differs from what scripts/gen_spectra.py writes now; "
            f"regenerate with: .venv/bin/python scripts/gen_spectra.py")
    # aristotle_bow.csv is derived by heron's own code (src/sky/aristotle.rs), and
    # tests/sky.rs checks that the committed file is exactly that derivation.
    other_generators = {"aristotle_bow.csv"}
    assert sorted(p.name for p in SPECTRA.glob("*.csv") if p.name not in other_generators) == sorted(
        p.name for p in tmp_path.glob("*.csv")), "spectra/ has CSVs the generator does not write"
