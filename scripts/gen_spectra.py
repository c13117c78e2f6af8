#!/usr/bin/env python3
"""Generate heron's spectral tables in spectra/ from colour-science.

Run once (from the repository root, in the project's virtual environment):

    .venv/bin/python scripts/gen_spectra.py

The tables are committed; heron embeds them at compile time, so nothing is read or
downloaded at run time. spectra/README.md names the source of every table.
"""
import pathlib
import warnings

import colour
import numpy as np

warnings.filterwarnings("ignore")
OUT = pathlib.Path(__file__).resolve().parent.parent / "spectra"
SHAPE = colour.SpectralShape(360, 830, 1)


def write(name, header, rows):
    path = OUT / name
    with path.open("w", newline="\n") as f:
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(repr(float(v)) if i else f"{v:g}" for i, v in enumerate(row)) + "\n")
    print("wrote", path)


def main():
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(SHAPE)
    write("cie1931_2deg.csv", ["wavelength_nm", "x_bar", "y_bar", "z_bar"],
          np.column_stack([cmfs.wavelengths, cmfs.values]))

    # CIE D65 relative spectral power (5 nm, 300-780 nm in colour-science), aligned to
    # 1 nm over 360-830 nm with colour-science's default interpolation and extrapolation.
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE)
    write("cie_d65.csv", ["wavelength_nm", "value"], np.column_stack([d65.wavelengths, d65.values]))

    # Smits (1999) RGB-to-spectrum basis: 10 bins over 380-720 nm.
    basis = colour.recovery.SDS_SMITS1999
    names = ["white", "cyan", "magenta", "yellow", "red", "green", "blue"]
    wl = basis["white"].wavelengths
    write("smits1999.csv", ["wavelength_nm"] + names,
          np.column_stack([wl] + [basis[n].values for n in names]))


if __name__ == "__main__":
    main()
