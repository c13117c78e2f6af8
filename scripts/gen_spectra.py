#!/usr/bin/env python3
"""Generate heron's spectral tables in spectra/ from colour-science.

Run from the repository root, in the project's virtual environment
(scripts/setup-python.sh creates it):

    .venv/bin/python scripts/gen_spectra.py

`--out DIR` writes the tables somewhere else (tests/python/test_spectra_tables.py uses
it to check that the committed tables are exactly what this script produces).

The tables are committed; heron embeds them at compile time, so nothing is read or
downloaded at run time. spectra/README.md names the source of every table.

Number format: every value is written with Python's repr(float), the shortest decimal
string that parses back to the same float64, so the CSVs hold colour-science's numbers
exactly. Wavelengths that are whole numbers are written without a decimal point.
"""
import argparse
import pathlib
import warnings

import colour
import numpy as np

warnings.filterwarnings("ignore")
OUT = pathlib.Path(__file__).resolve().parent.parent / "spectra"
SHAPE = colour.SpectralShape(360, 830, 1)
SMITS_NAMES = ["white", "cyan", "magenta", "yellow", "red", "green", "blue"]


def fmt(v):
    v = float(v)
    return str(int(v)) if v.is_integer() else repr(v)


def write(out, name, header, rows):
    path = out / name
    with path.open("w", newline="\n") as f:
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(fmt(v) for v in row) + "\n")
    print("wrote", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=pathlib.Path, default=OUT, help="output folder (default: spectra/)")
    out = ap.parse_args().out
    out.mkdir(parents=True, exist_ok=True)

    # CIE 1931 2° observer: colour-science holds it at 1 nm over 360-830 nm already, so
    # the values are written as tabulated. (Calling .align(SHAPE) would re-evaluate them
    # through the Sprague interpolator and add float round-off of up to 1.3e-15, one
    # value of it negative, so it is not called.)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    if cmfs.shape != SHAPE:
        raise SystemExit(f"expected the CIE 1931 observer on {SHAPE}, got {cmfs.shape}")
    write(out, "cie1931_2deg.csv", ["wavelength_nm", "x_bar", "y_bar", "z_bar"],
          np.column_stack([cmfs.wavelengths, cmfs.values]))

    # CIE 1964 10° observer: like the 1931 one, colour-science holds it at 1 nm over
    # 360-830 nm, so it is written as tabulated (no .align(), for the same reason).
    cmfs10 = colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"]
    if cmfs10.shape != SHAPE:
        raise SystemExit(f"expected the CIE 1964 observer on {SHAPE}, got {cmfs10.shape}")
    write(out, "cie1964_10deg.csv", ["wavelength_nm", "x_bar", "y_bar", "z_bar"],
          np.column_stack([cmfs10.wavelengths, cmfs10.values]))

    # CIE D65 relative spectral power: 5 nm over 300-780 nm in colour-science, aligned
    # to 1 nm over 360-830 nm with the distribution's own interpolator (linear) and
    # colour-science's default extrapolator (constant: 781-830 nm repeat the 780 nm value).
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE)
    write(out, "cie_d65.csv", ["wavelength_nm", "value"],
          np.column_stack([d65.wavelengths, d65.values]))

    # CIE D50 (`heron color --illuminant D50`, the reference white of print and of ICC
    # profiles): 5 nm over 300-780 nm in colour-science, aligned exactly like D65.
    d50 = colour.SDS_ILLUMINANTS["D50"].copy().align(SHAPE)
    write(out, "cie_d50.csv", ["wavelength_nm", "value"],
          np.column_stack([d50.wavelengths, d50.values]))

    # CIE standard illuminant A relative spectral power: 5 nm over 300-780 nm in
    # colour-science (the CIE 15:2004 table), aligned exactly like D65: linear
    # interpolation (the distribution's own interpolator) and constant extrapolation
    # (781-830 nm repeat the 780 nm value, 241.675). This is colour-science's tabulated A,
    # not the Planckian formula of colour.colorimetry.sd_CIE_standard_illuminant_A;
    # spectra/README.md says how far apart they are.
    a = colour.SDS_ILLUMINANTS["A"].copy().align(SHAPE)
    write(out, "cie_a.csv", ["wavelength_nm", "value"],
          np.column_stack([a.wavelengths, a.values]))

    # Smits (1999) RGB-to-spectrum basis: 10 samples over 380-720 nm, as tabulated.
    basis = colour.recovery.SDS_SMITS1999
    wl = basis["white"].wavelengths
    write(out, "smits1999.csv", ["wavelength_nm"] + SMITS_NAMES,
          np.column_stack([wl] + [basis[n].values for n in SMITS_NAMES]))

    # Water's imaginary index k(λ), Hale & Querry (1973), Table I, 350-850 nm: typed
    # from the paper's table (not from colour-science, which has no such table). Used
    # by the Lorenz-Mie media (src/medium/homogeneous.rs) for absorption in the drops.
    write(out, "water_k_hale_querry1973.csv", ["wavelength_nm", "k"], WATER_K_HALE_QUERRY)


# Hale, G. M. & Querry, M. R. (1973), "Optical constants of water in the 200-nm to
# 200-um wavelength region", Appl. Opt. 12(3), 555-563, Table I (k at 25 C), every
# 25 nm from 350 to 850 nm. The same digits are in the 6S radiative-transfer code's
# `indwat` table (which lists the 350 and 450 nm rows at 345 and 445 nm).
WATER_K_HALE_QUERRY = [
    (350, 6.5e-9), (375, 3.5e-9), (400, 1.86e-9), (425, 1.3e-9), (450, 1.02e-9),
    (475, 9.35e-10), (500, 1.0e-9), (525, 1.32e-9), (550, 1.96e-9), (575, 3.6e-9),
    (600, 1.09e-8), (625, 1.39e-8), (650, 1.64e-8), (675, 2.23e-8), (700, 3.35e-8),
    (725, 9.15e-8), (750, 1.56e-7), (775, 1.48e-7), (800, 1.25e-7), (825, 1.82e-7),
    (850, 2.93e-7),
]


if __name__ == "__main__":
    main()
