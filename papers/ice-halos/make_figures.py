"""papers/ice-halos: tables and figures (run by make.sh, which first writes the random
crystals' profile into OUT/data).

  data/min_deviation.csv    n(λ) of ice and the minimum deviations of the 60° and 90°
                            prisms against the edges heron's table shows
  data/sun_dogs.csv         the sun dog's distance from the sun against the sun's
                            elevation: Bravais' effective index against the table's peak
  figures/random_halos.png, sun_dogs.png
"""
from __future__ import annotations

import argparse
import math
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "common"))

import numpy as np  # noqa: E402

import heronfig as hf  # noqa: E402
from heronfig import plt  # noqa: E402

LAMBDAS = [450.0, 550.0, 650.0]
ELEVATIONS = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0]


def ice_n(repo: pathlib.Path, lam: float) -> float:
    """Ice's n at lam nm: spectra/ice_warren_brandt2008.csv, linear between rows, as the
    catalogue's `ice`."""
    _, d = hf.read_csv(repo / "spectra" / "ice_warren_brandt2008.csv")
    return float(np.interp(lam, d[:, 0], d[:, 1]))


def min_deviation(n: float, apex_deg: float) -> float:
    a = math.radians(apex_deg)
    return math.degrees(2 * math.asin(n * math.sin(a / 2)) - a)


def edge(theta: np.ndarray, col: np.ndarray, lo: float, hi: float) -> float:
    """The angle of the steepest rise of a profile column within [lo, hi], after a 0.5°
    running mean (10 samples), which keeps the table's cell-to-cell noise from posing as
    an edge."""
    m = (theta >= lo) & (theta <= hi)
    t, v = theta[m], col[m]
    k = 10
    s = np.convolve(v, np.ones(k) / k, mode="valid")
    ts = np.convolve(t, np.ones(k) / k, mode="valid")
    i = int(np.argmax(np.diff(s)))
    return float(0.5 * (ts[i] + ts[i + 1]))


def random_halos(out: pathlib.Path, repo: pathlib.Path) -> None:
    header, raw = hf.read_csv(out / "data" / "random_profile.csv")
    theta = raw[:, 0]
    # Columns ψ-major (psi<ψ>_<λ>nm): the mean over the seven circles per wavelength.
    nl = len(LAMBDAS)
    cols = raw[:, 1:].reshape(len(theta), -1, nl)
    d = np.column_stack([theta, cols.mean(axis=1)])
    rows = []
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    for j, lam in enumerate(LAMBDAS):
        n = ice_n(repo, lam)
        d60, d90 = min_deviation(n, 60), min_deviation(n, 90)
        e60, e90 = edge(theta, d[:, 1 + j], 20, 24), edge(theta, d[:, 1 + j], 43, 49)
        rows.append((lam, n, d60, e60, d90, e90))
        c = hf.wavelength_colour(lam)
        ax.plot(theta, d[:, 1 + j], color=c, label=f"{lam:g} nm")
        for x in (d60, d90):
            ax.axvline(x, color=c, ls=":", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel("angle from the sun (°)")
    ax.set_ylabel("radiance per unit solar irradiance (sr⁻¹)")
    ax.set_title("Randomly oriented ice crystals: the 22° and 46° halos\n"
                 "(dotted: minimum deviation of the 60° and 90° prisms)")
    ax.legend()
    hf.save_png(fig, out / "figures" / "random_halos.png")
    hf.write_csv(out / "data" / "min_deviation.csv",
                 ["wavelength_nm", "n", "min_dev_60_deg", "table_edge_60_deg",
                  "min_dev_90_deg", "table_edge_90_deg"], rows,
                 digits=[".0f", ".6f", ".4f", ".3f", ".4f", ".3f"],
                 comments=["ice n(λ): Warren & Brandt 2008; edges: the steepest rise of "
                           "heron halo profile's column (0.05° steps, 0.5° running mean, "
                           "solar disk 0.2666°)"])


def sun_dog_direction(n: float, h: float) -> tuple[float, float]:
    """(θ, ψ) in degrees of the sun dog for a sun at h degrees: level with the sun, the
    60° prism's minimum deviation for Bravais' index away in azimuth."""
    hr = math.radians(h)
    npr = math.sqrt(n * n - math.sin(hr) ** 2) / math.cos(hr)
    daz = math.radians(min_deviation(npr, 60))
    sun = np.array([math.cos(hr), 0.0, math.sin(hr)])
    v = np.array([math.cos(hr) * math.cos(daz), math.cos(hr) * math.sin(daz), math.sin(hr)])
    theta = math.degrees(math.atan2(np.linalg.norm(np.cross(v, sun)), v @ sun))
    z = np.array([0.0, 0.0, 1.0])
    e1 = z - sun * (z @ sun)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(sun, e1)
    psi = math.degrees(math.atan2(abs(v @ e2), v @ e1))
    return theta, psi


def sun_dogs(heron: hf.Heron, out: pathlib.Path, repo: pathlib.Path) -> None:
    rows = []
    lams = (450.0, 650.0)
    for h in ELEVATIONS:
        aspect = "0.3" if h <= 30 else "1"
        # One table per elevation: both wavelengths' great circles in one call (its
        # columns are ψ-major: psi1_450nm, psi1_650nm, psi2_450nm, …), each searched
        # over its own 6° about the predicted sun dog.
        dogs = [(lam, *sun_dog_direction(ice_n(repo, lam), h)) for lam in lams]
        psis = list(dict.fromkeys(psi for _, _, psi in dogs))
        los = [math.floor((theta - 3) * 20) / 20 for _, theta, _ in dogs]
        text = heron.run("halo", "profile", "--sun-elevation", hf.fmt(h, 6),
                         "--crystals", f"plates:aspect={aspect},tilt_deg=0.2",
                         "--lambda", ",".join(hf.fmt(lam, 6) for lam in lams),
                         "--psi", ",".join(hf.fmt(psi, 8) for psi in psis),
                         "--from", hf.fmt(min(los), 8), "--to", hf.fmt(max(los) + 6, 8),
                         "--step", "0.05", "--rays", "262144")
        d = np.array([[float(x) for x in ln.split(",")] for ln in text.splitlines()[1:]])
        for (lam, theta, psi), lo in zip(dogs, los):
            col = 1 + psis.index(psi) * len(lams) + lams.index(lam)
            rows_in = np.nonzero((d[:, 0] > lo - 1e-9) & (d[:, 0] < lo + 6 + 1e-9))[0]
            peak = float(d[rows_in[int(np.argmax(d[rows_in, col]))], 0])
            rows.append((h, lam, theta, psi, peak))
    hf.write_csv(out / "data" / "sun_dogs.csv",
                 ["sun_elevation_deg", "wavelength_nm", "bravais_theta_deg", "psi_deg",
                  "table_peak_theta_deg"], rows,
                 digits=[".0f", ".0f", ".4f", ".3f", ".2f"],
                 comments=["plates (tilt 0.2°), solar disk 0.2666°; the peak along the "
                           "great circle through the predicted sun dog, 0.05° steps"])
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    hs = np.linspace(0, 60, 200)
    for lam in (450.0, 650.0):
        c = hf.wavelength_colour(lam)
        n = ice_n(repo, lam)
        ax.plot(hs, [sun_dog_direction(n, h)[0] for h in hs], color=c,
                label=f"Bravais, {lam:g} nm")
        pts = [(r[0], r[4]) for r in rows if r[1] == lam]
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color=c, mfc="none",
                label=f"heron's table, {lam:g} nm")
    ax.set_xlabel("sun elevation (°)")
    ax.set_ylabel("sun dog's distance from the sun (°)")
    ax.set_title("Sun dogs move out as the sun climbs; none above 60.7°")
    ax.legend()
    hf.save_png(fig, out / "figures" / "sun_dogs.png")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--heron", required=True)
    ap.add_argument("--out", required=True, type=pathlib.Path)
    ap.add_argument("--repo", required=True, type=pathlib.Path)
    a = ap.parse_args()
    hf.setup_matplotlib()
    heron = hf.Heron(a.heron)
    random_halos(a.out, a.repo)
    sun_dogs(heron, a.out, a.repo)


if __name__ == "__main__":
    main()
