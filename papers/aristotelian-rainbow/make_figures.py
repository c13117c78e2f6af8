"""papers/aristotelian-rainbow: tables and figures (run by make.sh, which first writes
the `heron sky profile --model aristotle` CSVs into OUT/data and WORK).

  data/colour_strip_point_sun.csv, data/colour_strip_solar_disk.csv
                        θ against the colour (XYZ, display sRGB) of the bow
  data/texture_colour.csv
                        each row of spectra/aristotle_bow.csv: t, coverage, peak
                        wavelength, XYZ, display sRGB
  figures/profiles.png, colour_strip.png, texture.png
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

BOW_DEG = 42.0
SUNS = {  # name: (angular radius in degrees, label)
    "point_sun": (0.001, "point-like sun (radius 0.001°)"),
    "solar_disk": (0.2666, "solar disk (radius 0.2666°)"),
}


def read_texture(path: pathlib.Path):
    """(t, alpha, λ grid, R[t, λ]) of spectra/aristotle_bow.csv."""
    header, data = hf.read_csv(path)
    assert header[:2] == ["t", "alpha"], header
    lams = np.array([float(h) for h in header[2:]])
    return data[:, 0], data[:, 1], lams, data[:, 2:]


def colour_rows(lams: np.ndarray, radiance: np.ndarray, scale: float, heron: hf.Heron):
    """XYZ (heron's film convention) and display sRGB (XYZ / scale through `heron
    display`: out-of-gamut colours brought in at constant hue) of spectra sampled at lams."""
    xyz = hf.spectra_to_xyz(lams, radiance)
    rgb, _ = hf.display_srgb(xyz, heron, white_y=scale)
    return xyz, rgb


def texture_figure(tex, out: pathlib.Path, scale: float, heron: hf.Heron) -> None:
    t, alpha, lams, R = tex
    xyz, rgb = colour_rows(lams, R, scale, heron)
    peak = lams[np.argmax(R, axis=1)]
    peak = np.where(alpha > 0, peak, np.nan)
    hf.write_csv(out / "data" / "texture_colour.csv",
                 ["t", "alpha", "peak_nm", "X", "Y", "Z", "sR", "sG", "sB"],
                 [(t[i], alpha[i], peak[i], *xyz[i], *rgb[i]) for i in range(len(t))],
                 digits=[".3f", ".6f", ".0f", 7, 7, 7, ".5f", ".5f", ".5f"],
                 comments=[
                     "Rows of spectra/aristotle_bow.csv (derivation: src/sky/aristotle.rs, "
                     "derive_texture_csv): t = smoothstep lookup coordinate (0 inner edge, "
                     "1 outer edge), alpha = coverage.",
                     "XYZ = sum R(t, l) xbar(l) dl / int ybar dl (CIE 1931 2 deg, "
                     "colour-science, 5 nm trapezoid); sRGB: XYZ divided by "
                     f"{scale:.6g} (same scale in every figure here), heron display "
                     "(IEC 61966-2-1 matrix, out-of-gamut colours brought in at constant hue, "
                     "encoded).",
                 ])
    fig = plt.figure(figsize=(8.0, 6.0))
    gs = fig.add_gridspec(3, 2, height_ratios=[3.0, 1.3, 0.5], width_ratios=[40, 1])
    ax = fig.add_subplot(gs[0, 0])
    cax = fig.add_subplot(gs[0, 1])
    im = ax.imshow(R, origin="lower", aspect="auto", interpolation="nearest", cmap="magma",
                   extent=(lams[0] - 2.5, lams[-1] + 2.5, t[0] - 0.0125, t[-1] + 0.0125))
    fig.colorbar(im, cax=cax, label="R(t, λ)")
    ax.set_xlabel("wavelength λ (nm)")
    ax.set_ylabel("t = smoothstep(a, b, cos 42°)")
    ax.set_title("spectra/aristotle_bow.csv: the seed's 1D texture, one spectrum per t "
                 "(41 rows × 95 wavelengths)", fontsize=9)
    ax.grid(False)
    ax.set_xlim(380, 780)
    ax2 = fig.add_subplot(gs[1, 0])
    ax2.plot(t, alpha, "k-", label="coverage α(t)")
    ax2.plot(t, xyz[:, 1], "-", color="tab:orange", label="luminance Y(t)")
    ax2.set_xlim(t[0] - 0.0125, t[-1] + 0.0125)
    ax2.set_ylabel("α, Y")
    ax2.legend(loc="lower center", ncol=2)
    ax2.tick_params(labelbottom=False)
    ax3 = fig.add_subplot(gs[2, 0], sharex=ax2)
    ax3.imshow(rgb[None, :, :], aspect="auto", interpolation="nearest",
               extent=(t[0] - 0.0125, t[-1] + 0.0125, 0, 1))
    ax3.set_yticks([])
    ax3.grid(False)
    ax3.set_xlabel("t (0: inner edge of the bow, violet; 1: outer edge, red)")
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "texture.png")


def profiles_figure(out: pathlib.Path) -> None:
    curves = {name: hf.read_csv(out / "data" / f"profiles_{name}.csv") for name in SUNS}
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 4.0))
    for ax, name, unit, mult in ((axes[0], "point_sun", "10⁻³ °", 1e3),
                                 (axes[1], "solar_disk", "°", 1.0)):
        header, data = curves[name]
        for j, lam in enumerate(hf.profile_columns(header)):
            ax.plot((data[:, 0] - BOW_DEG) * mult, data[:, 1 + j],
                    color=hf.wavelength_colour(lam), label=f"{lam:g} nm")
        alpha = SUNS[name][0]
        ax.axvline(-alpha * mult, color="0.5", lw=0.8, ls=":")
        ax.axvline(alpha * mult, color="0.5", lw=0.8, ls=":")
        ax.set_xlabel(f"θ − 42° ({unit})")
        ax.set_title(SUNS[name][1], fontsize=9)
    axes[0].set_ylabel("spectral radiance (texture units)")
    axes[0].legend(loc="upper left", fontsize=7)
    ax = axes[2]
    for name, ls in (("solar_disk", "-"), ("point_sun", "--")):
        header, data = curves[name]
        alpha = SUNS[name][0]
        lams = hf.profile_columns(header)
        for lam in (450.0, 550.0, 650.0):
            j = lams.index(lam)
            ax.plot((data[:, 0] - BOW_DEG) / alpha, data[:, 1 + j], ls,
                    color=hf.wavelength_colour(lam), lw=1.4 if ls == "-" else 1.0,
                    label=f"{lam:g} nm, {name.replace('_', ' ')}")
    ax.set_xlabel("(θ − 42°) / sun radius")
    ax.set_title("both, against θ in units of the sun's radius", fontsize=9)
    ax.legend(loc="upper left", fontsize=6)
    fig.suptitle("The Aristotelian bow (heron sky profile --model aristotle): it lies "
                 "within 42° ± the sun's radius, violet inside, red outside", fontsize=10)
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "profiles.png")


def colour_strip_figure(out: pathlib.Path, work: pathlib.Path, scale: float,
                        heron: hf.Heron) -> None:
    fig, axes = plt.subplots(len(SUNS), 1, figsize=(8.0, 3.4))
    for ax, (name, (alpha, label)) in zip(axes, SUNS.items()):
        header, data = hf.read_csv(work / f"spectral_{name}.csv")
        lams = np.array(hf.profile_columns(header))
        theta = data[:, 0]
        xyz, rgb = colour_rows(lams, data[:, 1:], scale, heron)
        hf.write_csv(out / "data" / f"colour_strip_{name}.csv",
                     ["theta_deg", "X", "Y", "Z", "sR", "sG", "sB"],
                     [(theta[i], *xyz[i], *rgb[i]) for i in range(len(theta))],
                     digits=[".6f", 7, 7, 7, ".5f", ".5f", ".5f"],
                     comments=[
                         f"Colour of the Aristotelian bow, {label}, background 0: "
                         "heron sky profile --model aristotle at 360-830 nm every 5 nm.",
                         "XYZ = sum L xbar dl / int ybar dl (CIE 1931 2 deg, colour-science); "
                         f"sRGB: XYZ divided by {scale:.6g}, heron display (out-of-gamut "
                         "colours brought in at constant hue, encoded).",
                     ])
        half = 0.5 * (theta[1] - theta[0])
        x = (theta - BOW_DEG) / alpha
        ax.imshow(rgb[None, :, :], aspect="auto", interpolation="nearest",
                  extent=(x[0] - half / alpha, x[-1] + half / alpha, 0, 1))
        ax.set_yticks([])
        ax.grid(False)
        ax.set_xlim(-1.3, 1.3)
        ax.set_title(f"{label}: θ from {BOW_DEG - alpha:g}° to {BOW_DEG + alpha:g}°",
                     fontsize=9)
    axes[-1].set_xlabel("(θ − 42°) / sun radius   (inside the bow ← → outside)")
    fig.suptitle("Colour of the Aristotelian bow against the angle from the antisolar point",
                 fontsize=10)
    fig.tight_layout()
    hf.save_png(fig, out / "figures" / "colour_strip.png")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--heron", required=True, type=pathlib.Path)
    ap.add_argument("--texture", required=True, type=pathlib.Path)
    ap.add_argument("--out", required=True, type=pathlib.Path)
    ap.add_argument("--work", required=True, type=pathlib.Path)
    args = ap.parse_args()
    hf.setup_matplotlib()
    heron = hf.Heron(args.heron)
    tex = read_texture(args.texture)
    # One display scale for every colour here: the largest linear sRGB channel of any
    # texture row (the profiles only ever return texture values).
    scale = float(np.max(hf.xyz_to_linear_srgb(hf.spectra_to_xyz(tex[2], tex[3]))))
    texture_figure(tex, args.out, scale, heron)
    profiles_figure(args.out)
    colour_strip_figure(args.out, args.work, scale, heron)


if __name__ == "__main__":
    main()
