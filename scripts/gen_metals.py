#!/usr/bin/env python3
"""Generate heron's metal tables in spectra/metals/ (complex refractive index n + i k).

Run from the repository root with plain Python 3 (standard library only):

    python3 scripts/gen_metals.py

`--out DIR` writes the tables somewhere else (to compare a fresh run with the committed
files).

Writes four CSVs, each a block of `#` comment lines (source, citation, conversion), a
header line `wavelength_nm,n,k`, then rows in increasing wavelength:

- Au.csv, Ag.csv, Cu.csv: Johnson & Christy (1972), Table I, typed in below as
  (photon energy in eV, n, k). Each energy E is converted to a wavelength with
  lambda[nm] = 1239.841984 / E[eV]; n and k are written as tabulated. Only the points
  in 300-900 nm are kept, plus the first point beyond each end, so that heron's
  interpolation in wavelength is bracketed over all of 300-900 nm (and so 360-830 nm).
- Al.csv: the Lorentz-Drude (LD) model of Rakic, Djurisic, Elazar & Majewski (1998)
  with their parameters for Al, evaluated every 5 nm from 300 to 900 nm.

heron puts n and k (separately) onto its 1 nm grid as it does every spectral CSV
(`DenseSpectrum::from_table`, src/spectrum/interp.rs), the way colour-science aligns a
distribution: the Sprague interpolating polynomial for uniformly spaced rows (Al.csv), a
not-a-knot cubic spline for irregular ones (Au.csv, Ag.csv, Cu.csv).

Number format: every value with 6 significant digits ("%.6g"), so the output is the same
on every run and platform. spectra/README.md describes the tables.
"""
import argparse
import cmath
import pathlib

OUT = pathlib.Path(__file__).resolve().parent.parent / "spectra" / "metals"

# h c / e in eV nm (CODATA 2018 exact h, c, e: 1239.841984... eV nm).
HC_EV_NM = 1239.841984

# The wavelength range the tables must cover (nm).
LAMBDA_MIN = 300.0
LAMBDA_MAX = 900.0

# ---------------------------------------------------------------------------------------
# P. B. Johnson and R. W. Christy, "Optical Constants of the Noble Metals",
# Phys. Rev. B 6, 4370-4379 (1972), doi:10.1103/PhysRevB.6.4370, Table I.
# Columns as in the paper: photon energy (eV); n, k of copper; n, k of silver; n, k of gold.
# 49 energies, 0.64-6.60 eV. Values transcribed as published (trailing zeros dropped by
# Python's float literals do not change them).
# ---------------------------------------------------------------------------------------
JC_TABLE_I = (
    # E_eV   Cu n   Cu k    Ag n   Ag k    Au n   Au k
    (0.64, 1.09, 13.43, 0.24, 14.08, 0.92, 13.78),
    (0.77, 0.76, 11.12, 0.15, 11.85, 0.56, 11.21),
    (0.89, 0.60, 9.439, 0.13, 10.10, 0.43, 9.519),
    (1.02, 0.48, 8.245, 0.09, 8.828, 0.35, 8.145),
    (1.14, 0.36, 7.217, 0.04, 7.795, 0.27, 7.150),
    (1.26, 0.32, 6.421, 0.04, 6.992, 0.22, 6.350),
    (1.39, 0.30, 5.768, 0.04, 6.312, 0.17, 5.663),
    (1.51, 0.26, 5.180, 0.04, 5.727, 0.16, 5.083),
    (1.64, 0.24, 4.665, 0.03, 5.242, 0.14, 4.542),
    (1.76, 0.21, 4.205, 0.04, 4.838, 0.13, 4.103),
    (1.88, 0.22, 3.747, 0.05, 4.483, 0.14, 3.697),
    (2.01, 0.30, 3.205, 0.06, 4.152, 0.21, 3.272),
    (2.13, 0.70, 2.704, 0.05, 3.858, 0.29, 2.863),
    (2.26, 1.02, 2.577, 0.06, 3.586, 0.43, 2.455),
    (2.38, 1.18, 2.608, 0.05, 3.324, 0.62, 2.081),
    (2.50, 1.22, 2.564, 0.05, 3.093, 1.04, 1.833),
    (2.63, 1.25, 2.483, 0.05, 2.869, 1.31, 1.849),
    (2.75, 1.24, 2.397, 0.04, 2.657, 1.38, 1.914),
    (2.88, 1.25, 2.305, 0.04, 2.462, 1.45, 1.948),
    (3.00, 1.28, 2.207, 0.05, 2.275, 1.46, 1.958),
    (3.12, 1.32, 2.116, 0.05, 2.070, 1.47, 1.952),
    (3.25, 1.33, 2.045, 0.05, 1.864, 1.46, 1.933),
    (3.37, 1.36, 1.975, 0.07, 1.657, 1.48, 1.895),
    (3.50, 1.37, 1.916, 0.10, 1.419, 1.50, 1.866),
    (3.62, 1.36, 1.864, 0.14, 1.142, 1.48, 1.871),
    (3.74, 1.34, 1.821, 0.17, 0.829, 1.48, 1.883),
    (3.87, 1.38, 1.783, 0.81, 0.392, 1.54, 1.898),
    (3.99, 1.38, 1.729, 1.13, 0.616, 1.53, 1.893),
    (4.12, 1.40, 1.679, 1.34, 0.964, 1.53, 1.889),
    (4.24, 1.42, 1.633, 1.39, 1.161, 1.49, 1.878),
    (4.36, 1.45, 1.633, 1.41, 1.264, 1.47, 1.869),
    (4.49, 1.46, 1.646, 1.41, 1.331, 1.43, 1.847),
    (4.61, 1.45, 1.668, 1.38, 1.372, 1.38, 1.803),
    (4.74, 1.41, 1.691, 1.35, 1.387, 1.35, 1.749),
    (4.86, 1.41, 1.741, 1.33, 1.393, 1.33, 1.688),
    (4.98, 1.37, 1.783, 1.31, 1.389, 1.33, 1.631),
    (5.11, 1.34, 1.799, 1.30, 1.378, 1.32, 1.577),
    (5.23, 1.28, 1.802, 1.28, 1.367, 1.32, 1.536),
    (5.36, 1.23, 1.792, 1.28, 1.357, 1.30, 1.497),
    (5.48, 1.18, 1.768, 1.26, 1.344, 1.31, 1.460),
    (5.60, 1.13, 1.737, 1.25, 1.342, 1.30, 1.427),
    (5.73, 1.08, 1.699, 1.22, 1.336, 1.30, 1.387),
    (5.85, 1.04, 1.651, 1.20, 1.325, 1.30, 1.350),
    (5.98, 1.01, 1.599, 1.18, 1.312, 1.30, 1.304),
    (6.10, 0.99, 1.550, 1.15, 1.296, 1.33, 1.277),
    (6.22, 0.98, 1.493, 1.14, 1.277, 1.33, 1.251),
    (6.35, 0.97, 1.440, 1.12, 1.255, 1.34, 1.226),
    (6.47, 0.95, 1.388, 1.10, 1.232, 1.32, 1.203),
    (6.60, 0.94, 1.337, 1.07, 1.212, 1.28, 1.188),
)
JC_COLUMNS = {"Cu": (1, 2), "Ag": (3, 4), "Au": (5, 6)}
JC_NAMES = {"Cu": "Copper", "Ag": "Silver", "Au": "Gold"}
JC_CITATION = [
    'P. B. Johnson and R. W. Christy, "Optical Constants of the Noble Metals",',
    "  Phys. Rev. B 6, 4370-4379 (1972), doi:10.1103/PhysRevB.6.4370, Table I",
    "  (photon energy in eV, n, k; 49 energies 0.64-6.60 eV).",
]

# ---------------------------------------------------------------------------------------
# A. D. Rakic, A. B. Djurisic, J. M. Elazar and M. L. Majewski, "Optical properties of
# metallic films for vertical-cavity optoelectronic devices", Applied Optics 37(22),
# 5271-5283 (1998), doi:10.1364/AO.37.005271: Lorentz-Drude (LD) parameters for Al.
# All frequencies in eV; the f are dimensionless.
# ---------------------------------------------------------------------------------------
AL_OMEGA_P = 14.98
AL_F0 = 0.523
AL_GAMMA0 = 0.047
AL_OSCILLATORS = (  # (f_j, Gamma_j in eV, omega_j in eV)
    (0.227, 0.333, 0.162),
    (0.050, 0.312, 1.544),
    (0.166, 1.351, 1.808),
    (0.030, 3.382, 3.473),
)
AL_STEP_NM = 5


def fmt(v):
    return "%.6g" % v


def al_epsilon(e_ev):
    """LD dielectric function of Al at photon energy e_ev (eV):
    eps = 1 - f0 wp^2 / (w (w + i G0)) + sum_j f_j wp^2 / ((w_j^2 - w^2) - i w G_j)."""
    w = e_ev
    wp2 = AL_OMEGA_P * AL_OMEGA_P
    eps = 1 - AL_F0 * wp2 / (w * (w + 1j * AL_GAMMA0))
    for f, gamma, w0 in AL_OSCILLATORS:
        eps += f * wp2 / ((w0 * w0 - w * w) - 1j * w * gamma)
    return eps


def nk_from_epsilon(eps):
    """n + i k = sqrt(eps), the principal root, with k >= 0."""
    nk = cmath.sqrt(eps)
    if nk.imag < 0:
        nk = -nk
    return nk.real, nk.imag


def jc_rows(metal):
    """(wavelength nm, n, k) for one metal, sorted by wavelength, cut to 300-900 nm plus
    the first point beyond each end."""
    ni, ki = JC_COLUMNS[metal]
    rows = sorted((HC_EV_NM / r[0], r[ni], r[ki]) for r in JC_TABLE_I)
    lo = max(i for i, r in enumerate(rows) if r[0] < LAMBDA_MIN)
    hi = min(i for i, r in enumerate(rows) if r[0] > LAMBDA_MAX)
    return rows[lo:hi + 1]


def al_rows():
    rows = []
    for lam in range(int(LAMBDA_MIN), int(LAMBDA_MAX) + 1, AL_STEP_NM):
        n, k = nk_from_epsilon(al_epsilon(HC_EV_NM / lam))
        rows.append((float(lam), n, k))
    return rows


def write(path, comments, rows):
    with path.open("w", newline="\n") as f:
        for c in comments:
            f.write("# " + c + "\n" if c else "#\n")
        f.write("wavelength_nm,n,k\n")
        for row in rows:
            f.write(",".join(fmt(v) for v in row) + "\n")
    print("wrote %s (%d rows, %s-%s nm)" % (path, len(rows), fmt(rows[0][0]), fmt(rows[-1][0])))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=pathlib.Path, default=OUT,
                    help="output folder (default: spectra/metals/)")
    out = ap.parse_args().out
    out.mkdir(parents=True, exist_ok=True)

    for metal in ("Au", "Ag", "Cu"):
        rows = jc_rows(metal)
        comments = [
            "%s (%s): complex refractive index n + i k." % (JC_NAMES[metal], metal),
            "Source:",
        ] + ["  " + c for c in JC_CITATION] + [
            "Conversion: wavelength_nm = 1239.841984 / E_eV; n and k as tabulated.",
            "Rows: the %d table points from %s to %s nm, sorted by wavelength (those in"
            % (len(rows), fmt(rows[0][0]), fmt(rows[-1][0])),
            "  300-900 nm plus the first point beyond each end). heron interpolates between",
            "  rows with a not-a-knot cubic spline in wavelength (irregular rows).",
            "Generated by scripts/gen_metals.py (python3 scripts/gen_metals.py); do not edit.",
        ]
        write(out / (metal + ".csv"), comments, rows)

    rows = al_rows()
    osc = ["  f%d=%s G%d=%s w%d=%s" % (j, fmt(f), j, fmt(g), j, fmt(w))
           for j, (f, g, w) in enumerate(AL_OSCILLATORS, start=1)]
    comments = [
        "Aluminium (Al): complex refractive index n + i k.",
        "Source:",
        '  A. D. Rakic, A. B. Djurisic, J. M. Elazar and M. L. Majewski, "Optical properties of',
        '  metallic films for vertical-cavity optoelectronic devices", Applied Optics 37(22),',
        "  5271-5283 (1998), doi:10.1364/AO.37.005271: Lorentz-Drude (LD) model, Al parameters",
        "  (eV): wp=%s f0=%s G0=%s;" % (fmt(AL_OMEGA_P), fmt(AL_F0), fmt(AL_GAMMA0)),
    ] + [o + ";" for o in osc[:-1]] + [osc[-1] + "."] + [
        "Model: eps(w) = 1 - f0 wp^2 / (w (w + i G0)) + sum_j fj wp^2 / ((wj^2 - w^2) - i w Gj),",
        "  w = 1239.841984 / wavelength_nm (eV); n + i k = sqrt(eps), principal root (k >= 0).",
        "Rows: the model every %d nm from %s to %s nm (%d rows). heron interpolates between"
        % (AL_STEP_NM, fmt(rows[0][0]), fmt(rows[-1][0]), len(rows)),
        "  rows with the Sprague polynomial in wavelength (uniform rows).",
        "Generated by scripts/gen_metals.py (python3 scripts/gen_metals.py); do not edit.",
    ]
    write(out / "Al.csv", comments, rows)


if __name__ == "__main__":
    main()
