"""Rainbows of three drop sizes against Descartes' geometric bow, with the heron module.

Descartes' rainbow (geometric optics: rays through a water drop, Fresnel factors, the
solar disk) does not depend on the drop's size; Airy's theory (the wave of rays near the
rainbow ray, Airy 1838) does: for drops of radius a the main maximum of the primary bow
sits inside Descartes' angle by an amount that shrinks as a^(-2/3) (Nussenzveig 1977,
Sci. Am. 236(4); van de Hulst 1957, Light Scattering by Small Particles, §13.24), and
supernumerary bows appear inside it. This script computes, with `heron.sky_profile`
(the numbers of `heron sky profile`), the radiance against the angle θ from the antisolar
point for `airy` at three drop radii and for `descartes`, at three wavelengths, plots
them with matplotlib to a PNG and prints where each primary bow peaks.

    .venv/bin/python examples/python/descartes_sweep.py [--out rainbow_sweep.png]
        [--radii 0.1,0.3,1.0] [--wavelengths 450,550,650]

Output (stdout): one line per (model, radius, wavelength), `peak <model> <radius_mm>
<λ nm> <θ of the maximum in degrees>`, with radius "-" for descartes.
"""
from __future__ import annotations

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import heron

# θ from the antisolar point: the primary bow (about 40.5-42.5° across the visible)
# and the supernumeraries inside it.
THETA = np.round(np.arange(36.0, 44.0 + 1e-9, 0.02), 9)
# The primary bow only (k = 1), seen with the real sun's angular radius (heron's default).
ORDERS = "1"


def profiles(radii_mm, wavelengths_nm):
    """{(model, radius or None): array len(THETA) x len(wavelengths)}."""
    out = {("descartes", None): heron.sky_profile("descartes", wavelengths_nm, THETA, k=ORDERS)}
    for a in radii_mm:
        out[("airy", a)] = heron.sky_profile(
            "airy", wavelengths_nm, THETA, k=ORDERS, droplet_radius=a
        )
    return out


def peaks(table):
    """θ (degrees) of the largest radiance in each column."""
    return THETA[np.argmax(table, axis=0)]


def plot(curves, wavelengths_nm, out: pathlib.Path):
    fig, axes = plt.subplots(1, len(wavelengths_nm), figsize=(4.2 * len(wavelengths_nm), 3.6), sharey=True)
    axes = np.atleast_1d(axes)
    for j, (ax, lam) in enumerate(zip(axes, wavelengths_nm)):
        for (model, a), table in curves.items():
            label = "Descartes (any a)" if model == "descartes" else f"Airy, a = {a:g} mm"
            style = dict(color="black", lw=1.2, ls="--") if model == "descartes" else dict(lw=1.0)
            ax.plot(THETA, table[:, j], label=label, **style)
        ax.set_title(f"λ = {lam:g} nm")
        ax.set_xlabel("θ from the antisolar point (°)")
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 1.0)
    axes[0].set_ylabel("dσ/dΩ / (πa²) per sr")
    axes[-1].legend(fontsize=8)
    fig.suptitle("Primary rainbow: Airy theory for three drop radii against Descartes")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("rainbow_sweep.png"))
    p.add_argument("--radii", default="0.1,0.3,1.0", help="drop radii in mm, comma-separated")
    p.add_argument("--wavelengths", default="450,550,650", help="nm, comma-separated")
    a = p.parse_args(argv)
    radii = [float(x) for x in a.radii.split(",")]
    lams = [float(x) for x in a.wavelengths.split(",")]
    curves = profiles(radii, lams)
    for (model, r), table in curves.items():
        for lam, t in zip(lams, peaks(table)):
            print(f"peak {model} {'-' if r is None else f'{r:g}'} {lam:g} {t:.2f}")
    plot(curves, lams, a.out)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
