"""papers/descartes-rainbow: tables and figures (run by make.sh, which first writes the
`heron sky profile` CSVs into OUT/data and WORK).

  data/rainbow_angles.csv   θ₁(λ), θ₂(λ): Descartes' formula with heron's water n(λ),
                            heron trace's minimum deviation, heron sky profile's peak
  data/deviation_curve.csv  D(b) for k = 1, 2 at 400, 550, 700 nm (traced and formula)
  data/dark_band_srgb.csv   the colour of the 30°–60° sky (descartes, real sun, D65)
  figures/rainbow_angle.png, deviation_curve.png, dark_band.png, drop_size.png
"""
from __future__ import annotations

import argparse
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "common"))
sys.path.insert(0, str(HERE))

import numpy as np  # noqa: E402

import heronfig as hf  # noqa: E402
import trace_data as td  # noqa: E402

from heronfig import plt  # noqa: E402

TABLE_LAMBDAS = [float(l) for l in range(380, 781, 10)]   # as make.sh's $lams_table
CURVE_LAMBDAS = [400.0, 550.0, 700.0]
CURVE_NB = 200
DROP_LAMBDAS = [450.0, 550.0, 650.0]


def profile_peaks(path: pathlib.Path) -> tuple[np.ndarray, np.ndarray, float]:
    """(λ, θ at the largest value of each column, step) of a heron sky profile CSV."""
    header, data = hf.read_csv(path)
    lams = np.array(hf.profile_columns(header))
    theta = data[:, 0]
    return lams, theta[np.argmax(data[:, 1:], axis=0)], float(theta[1] - theta[0])


def rainbow_angle(heron: hf.Heron, out: pathlib.Path, work: pathlib.Path) -> None:
    tab = td.rainbow_angles(heron, TABLE_LAMBDAS, search_every=1)
    peaks = {}
    step = {}
    for k in (1, 2):
        lams, th, step[k] = profile_peaks(work / f"peak_k{k}.csv")
        assert np.allclose(lams, tab[:, 0]), (lams, tab[:, 0])
        peaks[k] = th
    rows = [(r[0], r[1], r[2], r[3], r[4], r[5], peaks[1][i], peaks[2][i])
            for i, r in enumerate(tab)]
    hf.write_csv(
        out / "data" / "rainbow_angles.csv",
        ["lambda_nm", "n_water", "theta1_formula_deg", "theta2_formula_deg",
         "theta1_trace_deg", "theta2_trace_deg", "theta1_profile_deg", "theta2_profile_deg"],
        rows, digits=[".1f", ".6f", ".5f", ".5f", ".5f", ".5f", ".3f", ".3f"],
        comments=[
            "Rainbow angle from the antisolar point, k = 1 (primary) and 2 (secondary).",
            "n_water: heron's water (Daimon & Masumura 2007, 20 C), read by heron trace.",
            "formula: Descartes' minimum deviation, cos^2 i = (n^2 - 1)/(k^2 + 2k).",
            "trace: minimum over b of heron trace's deviation (bounded Brent search).",
            f"profile: peak of heron sky profile --model descartes --sun-radius 0.001 "
            f"(step {step[1]:g} deg).",
        ])

    lam = tab[:, 0]
    fig, axes = plt.subplots(2, 2, figsize=(9.0, 5.6), sharex=True,
                             gridspec_kw={"height_ratios": [3, 1.3]})
    for col, k in enumerate((1, 2)):
        ax, res = axes[0, col], axes[1, col]
        f = tab[:, 1 + k]
        ax.plot(lam, f, "k-", lw=1.2, label="Descartes' formula, heron's n(λ)")
        ax.plot(lam, tab[:, 3 + k], "o", ms=4, mfc="none", color="tab:blue",
                label="heron trace: minimum deviation")
        ax.plot(lam, peaks[k], "x", ms=4, color="tab:red",
                label="heron sky profile (descartes, point sun): peak")
        ax.set_title(f"k = {k} ({'primary' if k == 1 else 'secondary'} bow)")
        ax.set_ylabel("angle from antisolar point (°)")
        res.axhline(0.0, color="k", lw=0.8)
        res.plot(lam, (tab[:, 3 + k] - f) * 1e3, "o", ms=3, mfc="none", color="tab:blue")
        res.plot(lam, (peaks[k] - f) * 1e3, "x", ms=3, color="tab:red")
        res.set_ylabel("minus formula (m°)")
        res.set_xlabel("wavelength (nm)")
    axes[0, 0].legend(loc="lower right")
    fig.suptitle("Rainbow angle against wavelength (water, 20 °C)")
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "rainbow_angle.png")


def deviation_curve(heron: hf.Heron, out: pathlib.Path) -> None:
    rows = td.deviation_curves(heron, CURVE_LAMBDAS, CURVE_NB)
    hf.write_csv(
        out / "data" / "deviation_curve.csv",
        ["k", "lambda_nm", "b", "n_water", "D_trace_deg", "D_formula_deg", "theta_trace_deg"],
        rows, digits=[0, ".1f", ".4f", ".6f", ".5f", ".5f", ".5f"],
        comments=[
            "Deviation D(b) of the k-th order ray through a water drop against impact "
            "parameter b (drop radius 1).",
            "trace: heron trace scenes/droplet.toml --origin 0,b,-5 --dir 0,0,1 --path "
            "TRT (k = 1) or TRRT (k = 2).",
            "formula: D = k*180 + 2i - 2(k+1)r, sin i = b, sin r = b/n.  theta = |180 - D| "
            "from the antisolar point.",
        ])
    arr = np.array(rows, dtype=float)
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.2))
    for ax, k in zip(axes, (1, 2)):
        inset = ax.inset_axes([0.5, 0.5, 0.45, 0.4])
        mins = []
        for lam in CURVE_LAMBDAS:
            sel = (arr[:, 0] == k) & (arr[:, 1] == lam)
            b, d_t, d_f = arr[sel, 2], arr[sel, 4], arr[sel, 5]
            c = hf.wavelength_colour(lam)
            for a in (ax, inset):
                a.plot(b, d_t, "-", color=c, label=f"{lam:g} nm (heron trace)" if a is ax else None)
                a.plot(b, d_f, "--", color="k", lw=0.7,
                       label="formula" if (a is ax and lam == CURVE_LAMBDAS[-1]) else None)
            imin = int(np.argmin(d_t))
            mins.append((b[imin], d_t[imin]))
            for a in (ax, inset):
                a.plot(b[imin], d_t[imin], "o", ms=3, color=c)
        bmin = float(np.mean([m[0] for m in mins]))
        dlo = min(m[1] for m in mins)
        dhi = max(m[1] for m in mins)
        inset.set_xlim(bmin - 0.05, bmin + 0.04)
        inset.set_ylim(dlo - 0.6, dhi + 1.5)
        inset.tick_params(labelsize=7)
        inset.xaxis.set_major_locator(plt.MaxNLocator(4))
        inset.yaxis.set_major_locator(plt.MaxNLocator(4))
        inset.set_title("near the minimum", fontsize=7)
        ax.set_xlabel("impact parameter b (drop radius 1)")
        ax.set_ylabel("deviation D (°)")
        ax.set_title(f"k = {k}: " + ("D = 180° + 2i − 4r" if k == 1 else "D = 360° + 2i − 6r"))
        ax.set_xlim(0, 1)
        ax.legend(loc="lower left")
    fig.suptitle(f"Deviation against impact parameter ({CURVE_NB} b values per curve)")
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "deviation_curve.png")


def dark_band(out: pathlib.Path, heron: hf.Heron) -> None:
    header, data = hf.read_csv(out / "data" / "dark_band_unpolarised.csv")
    lams = np.array(hf.profile_columns(header))
    theta, p = data[:, 0], data[:, 1:]
    # Colour of the drop-scattered sunlight: p(θ, λ) · D65(λ) → XYZ → display sRGB.
    xyz = hf.spectra_to_xyz(lams, p * hf.d65(lams)[None, :] / 100.0)
    rgb, scale = hf.display_srgb(xyz, heron)
    hf.write_csv(out / "data" / "dark_band_srgb.csv",
                 ["theta_deg", "X", "Y", "Z", "sR", "sG", "sB"],
                 [(theta[i], *xyz[i], *rgb[i]) for i in range(len(theta))],
                 digits=[".1f", 7, 7, 7, ".5f", ".5f", ".5f"],
                 comments=[
                     "Colour of the descartes sky (k = 1 and 2, sun radius 0.2666 deg) lit "
                     "by D65/100, from data/dark_band_unpolarised.csv.",
                     "XYZ = sum p(theta, l) D65(l)/100 xbar(l) dl / int ybar dl (CIE 1931 "
                     "2 deg, colour-science); sRGB: IEC 61966-2-1 matrix, divided by "
                     f"{scale:.6g} (the largest linear channel), heron display "
                     "(out-of-gamut colours brought in at constant hue, encoded).",
                 ])
    sp = {pol: hf.read_csv(out / "data" / f"dark_band_550nm_{pol}.csv")[1] for pol in "sp"}

    fig, axes = plt.subplots(3, 1, figsize=(8.0, 7.0), sharex=True,
                             gridspec_kw={"height_ratios": [3, 2.2, 0.7]})
    ax = axes[0]
    h012, d012 = hf.read_csv(out / "data" / "dark_band_k012.csv")
    for lam in (450.0, 550.0, 650.0):
        j = int(np.flatnonzero(lams == lam)[0])
        ax.plot(theta, p[:, j], color=hf.wavelength_colour(lam), label=f"{lam:g} nm")
    j = 1 + hf.profile_columns(h012).index(550.0)
    ax.plot(d012[:, 0], d012[:, j], ":", color="k", lw=1.0,
            label="550 nm with external reflection (k = 0, 1, 2)")
    ax.set_yscale("log")
    ax.set_ylim(5e-4, 3.0)
    ax.set_ylabel("p(θ) = dσ/dΩ / πa²  (sr⁻¹)")
    ax.set_title("Descartes sky, k = 1 and 2, solar disk 0.2666°: Alexander's dark band "
                 "(p = 0 between the bows)", fontsize=9)
    dark = theta[np.all(p == 0.0, axis=1)]
    ax.axvspan(dark[0], dark[-1], color="0.85", lw=0)
    ax.text(0.5 * (dark[0] + dark[-1]), 1.4e-2,
            f"k = 1, 2: p = 0 at every\nwavelength, {dark[0]:.1f}°–{dark[-1]:.1f}°", ha="center",
            fontsize=8)
    ax.legend(loc="upper right")
    ax = axes[1]
    j550 = int(np.flatnonzero(lams == 550.0)[0])
    ax.plot(sp["s"][:, 0], sp["s"][:, 1], color="tab:blue", label="s (⊥ scattering plane)")
    ax.plot(sp["p"][:, 0], sp["p"][:, 1], color="tab:orange", label="p (∥ scattering plane)")
    ax.plot(theta, p[:, j550], "k--", lw=0.9, label="unpolarised = (s + p)/2")
    ax.set_yscale("log")
    ax.set_ylim(1e-4, 3.0)
    ax.set_ylabel("p(θ) at 550 nm")
    ax.legend(loc="upper right")
    ax = axes[2]
    ax.imshow(rgb[None, :, :], extent=(theta[0] - 0.05, theta[-1] + 0.05, 0, 1),
              aspect="auto", interpolation="nearest")
    ax.set_yticks([])
    ax.grid(False)
    ax.set_xlabel("angle from the antisolar point θ (°)")
    ax.set_xlim(30, 60)
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "dark_band.png")


def drop_size(out: pathlib.Path) -> None:
    fig, axes = plt.subplots(2, 3, figsize=(11.0, 6.0), sharex=True)
    styles = {"descartes": ("-", 1.0, "geometric (descartes)"),
              "airy": ("-", 1.2, "Airy"),
              "mie": ("-", 0.9, "Lorenz–Mie")}
    colours = {"descartes": "k", "airy": "tab:blue", "mie": "tab:red"}
    for row, a in enumerate(("0.1", "1")):
        curves = {m: hf.read_csv(out / "data" / f"drop_a{a}mm_{m}.csv") for m in styles}
        for col, lam in enumerate(DROP_LAMBDAS):
            ax = axes[row, col]
            for m, (ls, lw, label) in styles.items():
                header, data = curves[m]
                j = 1 + hf.profile_columns(header).index(lam)
                ax.plot(data[:, 0], data[:, j], ls, lw=lw, color=colours[m], label=label)
            ax.set_title(f"a = {a} mm, λ = {lam:g} nm", fontsize=9)
            if col == 0:
                ax.set_ylabel("p(θ) (sr⁻¹)")
            if row == 1:
                ax.set_xlabel("θ (°)")
            ax.set_xlim(38, 43.5)
    axes[0, 0].legend(loc="upper left", fontsize=7)
    fig.suptitle("Primary bow: geometric optics, Airy theory and Lorenz–Mie, solar disk "
                 "0.2666° (descartes and airy: k = 1 only; mie: every order)", fontsize=9)
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "drop_size.png")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--heron", required=True)
    ap.add_argument("--out", required=True, type=pathlib.Path)
    ap.add_argument("--work", required=True, type=pathlib.Path)
    args = ap.parse_args()
    hf.setup_matplotlib()
    heron = hf.Heron(args.heron)
    rainbow_angle(heron, args.out, args.work)
    deviation_curve(heron, args.out)
    dark_band(args.out, heron)
    drop_size(args.out)


if __name__ == "__main__":
    main()
