"""papers/lee-diagram: figures from data/lee_primary.csv (written by make.sh with
`heron sky lee`).

  data/lee_bow_angle.csv      per radius: the angle of the brightest Y and its colour
  figures/lee_diagram.png     the bow's colour against drop radius and angle
  figures/lee_luminance.png   its luminance Y (log scale) and the bow angle against radius
"""
from __future__ import annotations

import argparse
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "common"))

import numpy as np  # noqa: E402

import heronfig as hf  # noqa: E402

from heronfig import plt  # noqa: E402


def load(path: pathlib.Path):
    """(radii, thetas, XYZ[r, t, 3], sRGB[r, t, 3]) of a heron sky lee CSV."""
    header, data = hf.read_csv(path)
    assert header == ["radius_mm", "theta_deg", "X", "Y", "Z", "R", "G", "B"], header
    radii = np.unique(data[:, 0])
    thetas = np.unique(data[:, 1])
    shape = (len(radii), len(thetas), 3)
    return radii, thetas, data[:, 2:5].reshape(shape), data[:, 5:8].reshape(shape)


def diagram(out: pathlib.Path, radii, thetas, rgb) -> None:
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    # One cell per (radius, θ): radius index along x (the radii are log-spaced, so the
    # axis is logarithmic in radius), θ along y.
    img = np.transpose(rgb, (1, 0, 2))
    ax.imshow(img, origin="lower", aspect="auto", interpolation="nearest",
              extent=(0, len(radii), thetas[0] - 0.025, thetas[-1] + 0.025))
    ticks = [10, 20, 50, 100, 200, 500, 1000]
    pos = np.interp(np.log10(ticks), np.log10(radii * 1000.0), np.arange(len(radii)) + 0.5)
    ax.set_xticks(pos)
    ax.set_xticklabels([str(t) for t in ticks])
    ax.set_xlim(0, len(radii))
    ax.grid(False)
    ax.set_xlabel("drop radius (µm, log scale)")
    ax.set_ylabel("angle from the antisolar point θ (°)")
    ax.set_title("Lee diagram of the primary bow (Lorenz–Mie, D65 sun, solar disk)")
    hf.save_png(fig, out / "figures" / "lee_diagram.png")


def luminance(out: pathlib.Path, radii, thetas, xyz) -> list[tuple]:
    y = xyz[:, :, 1]
    peak_i = np.argmax(y, axis=1)
    rows = []
    for r, i in enumerate(peak_i):
        c = xyz[r, i]
        s = c.sum()
        rows.append((radii[r], thetas[i], c[1], c[0] / s, c[1] / s))
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(7.0, 6.5), sharex=True)
    for theta in (38.0, 40.0, 41.0, 42.0):
        j = int(np.argmin(np.abs(thetas - theta)))
        ax0.loglog(radii * 1000.0, y[:, j], label=f"θ = {thetas[j]:g}°")
    ax0.set_ylabel("luminance Y (relative to the sun, sr⁻¹)")
    ax0.legend()
    ax1.semilogx(radii * 1000.0, thetas[peak_i], "o-", ms=3)
    ax1.set_ylabel("θ of the brightest Y (°)")
    ax1.set_xlabel("drop radius (µm)")
    hf.save_png(fig, out / "figures" / "lee_luminance.png")
    return rows


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", type=pathlib.Path, required=True)
    a = ap.parse_args()
    hf.setup_matplotlib()
    radii, thetas, xyz, rgb = load(a.out / "data" / "lee_primary.csv")
    diagram(a.out, radii, thetas, rgb)
    rows = luminance(a.out, radii, thetas, xyz)
    hf.write_csv(a.out / "data" / "lee_bow_angle.csv",
                 ["radius_mm", "theta_peak_deg", "Y_peak", "x", "y"], rows,
                 digits=[9, ".2f", 6, ".5f", ".5f"],
                 comments=["Per drop radius: the angle of the largest luminance Y in",
                           "lee_primary.csv, that Y and its CIE 1931 chromaticity (x, y)."])


if __name__ == "__main__":
    main()
