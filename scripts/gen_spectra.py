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

    # Ice's complex index n + ik, Warren & Brandt (2008), 350-900 nm: typed from the
    # compilation's table (not in colour-science). The catalogue's `ice`
    # (spectra/ior_catalogue.toml) reads n; the halo skies and ice media use it.
    write(out, "ice_warren_brandt2008.csv", ["wavelength_nm", "n", "k"], ICE_WARREN_BRANDT)


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


# Warren, S. G. & Brandt, R. E. (2008), "Optical constants of ice from the ultraviolet
# to the microwave: A revised compilation", J. Geophys. Res. 113, D14220,
# doi:10.1029/2007JD009744: ice Ih at -7 C, the rows from 350 to 900 nm (every 10 nm
# from 390 nm; the compilation has 350 and 390 nm below that). The same digits are in
# refractiveindex.info's H2O/nk/Warren-2008 table.
ICE_WARREN_BRANDT = [
    (350, 1.3249, 2.0e-11), (390, 1.3203, 2.0e-11), (400, 1.3194, 2.365e-11),
    (410, 1.3185, 2.669e-11), (420, 1.3177, 3.135e-11), (430, 1.317, 4.14e-11),
    (440, 1.3163, 6.268e-11), (450, 1.3157, 9.239e-11), (460, 1.3151, 1.325e-10),
    (470, 1.3145, 1.956e-10), (480, 1.314, 2.861e-10), (490, 1.3135, 4.172e-10),
    (500, 1.313, 5.889e-10), (510, 1.3126, 8.036e-10), (520, 1.3121, 1.076e-09),
    (530, 1.3117, 1.409e-09), (540, 1.3114, 1.813e-09), (550, 1.311, 2.289e-09),
    (560, 1.3106, 2.839e-09), (570, 1.3103, 3.461e-09), (580, 1.31, 4.159e-09),
    (590, 1.3097, 4.93e-09), (600, 1.3094, 5.73e-09), (610, 1.3091, 6.89e-09),
    (620, 1.3088, 8.58e-09), (630, 1.3085, 1.04e-08), (640, 1.3083, 1.22e-08),
    (650, 1.308, 1.43e-08), (660, 1.3078, 1.66e-08), (670, 1.3076, 1.89e-08),
    (680, 1.3073, 2.09e-08), (690, 1.3071, 2.4e-08), (700, 1.3069, 2.9e-08),
    (710, 1.3067, 3.44e-08), (720, 1.3065, 4.03e-08), (730, 1.3062, 4.3e-08),
    (740, 1.306, 4.92e-08), (750, 1.3059, 5.87e-08), (760, 1.3057, 7.08e-08),
    (770, 1.3055, 8.58e-08), (780, 1.3053, 1.02e-07), (790, 1.3051, 1.18e-07),
    (800, 1.3049, 1.34e-07), (810, 1.3047, 1.4e-07), (820, 1.3046, 1.43e-07),
    (830, 1.3044, 1.45e-07), (840, 1.3042, 1.51e-07), (850, 1.304, 1.83e-07),
    (860, 1.3039, 2.15e-07), (870, 1.3037, 2.65e-07), (880, 1.3035, 3.35e-07),
    (890, 1.3033, 3.92e-07), (900, 1.3032, 4.2e-07),
]


if __name__ == "__main__":
    main()
