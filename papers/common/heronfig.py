"""Shared helpers for the figure sets in papers/: running heron, writing CSV with a
fixed precision, saving byte-identical PNGs, and spectra to sRGB (the last step, from XYZ
to the display's encoded sRGB, is heron's own: `heron display`, the transform of its PNG
previews, so no colour maths is written twice).

Every figure script imports this module (it sits next to them in papers/common) and
is run by the set's make.sh with the project's .venv Python. Nothing here reads the
clock, the environment's matplotlib settings or the random state, so the same heron
binary and the same pinned packages give the same bytes on every run.
"""
from __future__ import annotations

import csv
import io
import json
import math
import os
import pathlib
import subprocess
import tempfile
from typing import Iterable, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]

# One look for every figure, independent of any matplotlibrc on the machine.
STYLE = {
    "figure.figsize": (7.0, 4.5),
    "figure.dpi": 100,
    "savefig.dpi": 150,
    "font.size": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "lines.linewidth": 1.4,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "svg.hashsalt": "heron",
    "path.simplify": False,
}


def setup_matplotlib() -> None:
    matplotlib.rcdefaults()
    plt.rcParams.update(STYLE)


def save_png(fig, path: pathlib.Path) -> None:
    """Saves a figure as PNG without the Software tag (matplotlib writes no time stamp
    into PNGs), so a re-run gives the same bytes."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png", metadata={"Software": None})
    plt.close(fig)


def fmt(x, digits: int | str) -> str:
    """A number with `digits` significant digits ('%.{digits}g'), or formatted with the
    format spec `digits` when it is a string (e.g. ".6f"); -0 becomes 0, integers stay
    integers, NaN is written as an empty field."""
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    x = float(x)
    if not math.isfinite(x):
        return "" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    s = f"{x:{digits}}" if isinstance(digits, str) else f"{x:.{digits}g}"
    if s.startswith("-") and float(s) == 0.0:
        s = s[1:]
    return s


def write_csv(path: pathlib.Path, header: Sequence[str], rows: Iterable[Sequence],
              digits: int | str | Sequence[int | str] = 7, comments: Sequence[str] = ()) -> None:
    """Writes a CSV with '\\n' line ends; `comments` become leading '# ' lines; numbers
    are written with `digits` significant digits (one value, or one per column)."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ncol = len(header)
    dig = [digits] * ncol if isinstance(digits, (int, str)) else list(digits)
    out = io.StringIO()
    for c in comments:
        out.write(f"# {c}\n")
    w = csv.writer(out, lineterminator="\n")
    w.writerow(header)
    for row in rows:
        w.writerow([v if isinstance(v, str) else fmt(v, dig[i]) for i, v in enumerate(row)])
    path.write_text(out.getvalue(), encoding="utf-8")


def read_csv(path: pathlib.Path) -> tuple[list[str], np.ndarray]:
    """Reads a numeric CSV with one header line ('#' lines skipped)."""
    lines = [ln for ln in pathlib.Path(path).read_text().splitlines()
             if ln.strip() and not ln.startswith("#")]
    header = lines[0].split(",")
    data = np.array([[float(v) if v else float("nan") for v in ln.split(",")]
                     for ln in lines[1:]], dtype=float)
    return header, data.reshape(-1, len(header))


class Heron:
    """Runs the heron CLI (a release build) and returns its stdout."""

    def __init__(self, binary: str | os.PathLike):
        self.binary = str(binary)
        if not pathlib.Path(self.binary).is_file():
            raise SystemExit(f"heron binary not found at {self.binary}: run "
                             f"`cargo build --release` in {REPO} or set HERON_BIN")

    def run(self, *args: str) -> str:
        proc = subprocess.run([self.binary, *map(str, args)], capture_output=True,
                              text=True, cwd=REPO)
        if proc.returncode != 0:
            raise SystemExit(f"`heron {' '.join(map(str, args))}` failed "
                             f"(status {proc.returncode}):\n{proc.stderr}")
        return proc.stdout

    def display(self, xyz: np.ndarray) -> np.ndarray:
        """`heron display` of XYZ rows (shape (..., 3), heron's film convention, D65 white
        at Y = 1): encoded sRGB in [0, 1], same shape. Colours outside the sRGB gamut are
        brought in at constant hue (white added, then Oklab's projection toward mid-grey;
        heron's PNG preview transform, `--display hue`); colours inside are only encoded."""
        xyz = np.asarray(xyz, dtype=float)
        flat = xyz.reshape(-1, 3)
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "xyz.csv"
            path.write_text("X,Y,Z\n" + "".join(f"{x!r},{y!r},{z!r}\n" for x, y, z in flat))
            text = self.run("display", str(path))
        lines = text.splitlines()
        assert lines[0] == "sR,sG,sB", lines[0]
        rgb = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]], dtype=float)
        return rgb.reshape(xyz.shape)

    def trace(self, scene: str, origin, direction, lam_nm: float, path: str | None = None):
        args = ["trace", scene, "--origin", ",".join(repr(float(v)) for v in origin),
                "--dir", ",".join(repr(float(v)) for v in direction),
                "--lambda", repr(float(lam_nm))]
        if path:
            args += ["--path", path]
        return json.loads(self.run(*args))

    def sky_profile(self, model: str, lambdas: Sequence[float], start: float, stop: float,
                    step: float, **opts) -> tuple[list[str], np.ndarray]:
        """`heron sky profile`; opts become --flags (sun_radius -> --sun-radius)."""
        args = ["sky", "profile", "--model", model,
                "--lambda", ",".join(fmt(l, 10) for l in lambdas),
                "--from", fmt(start, 12), "--to", fmt(stop, 12), "--step", fmt(step, 12)]
        for k, v in opts.items():
            if v is not None:
                args += ["--" + k.replace("_", "-"), str(v)]
        text = self.run(*args)
        lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
        header = lines[0].split(",")
        data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]], dtype=float)
        return header, data.reshape(-1, len(header))


def wavelength_colour(lam_nm: float) -> tuple[float, float, float]:
    """A line colour for a wavelength (matplotlib's turbo map, 400 nm blue to 700 nm
    red); a plotting aid, not colorimetry."""
    t = min(max((float(lam_nm) - 400.0) / 300.0, 0.0), 1.0)
    r, g, b, _ = matplotlib.colormaps["turbo"](0.1 + 0.85 * t)
    return (0.85 * float(r), 0.85 * float(g), 0.85 * float(b))


def cmfs_xyz(lam_nm: np.ndarray) -> np.ndarray:
    """CIE 1931 2° colour-matching functions (colour-science's table) at lam_nm, linear
    in between, zero outside the table: shape (len, 3)."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = np.asarray(cmfs.wavelengths, dtype=float)
    val = np.asarray(cmfs.values, dtype=float)
    lam = np.asarray(lam_nm, dtype=float)
    return np.stack([np.interp(lam, wl, val[:, j], left=0.0, right=0.0) for j in range(3)],
                    axis=-1)


# IEC 61966-2-1: XYZ -> linear sRGB (no chromatic adaptation; the same matrix heron uses).
XYZ_TO_SRGB = np.array([
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
])


def xyz_to_linear_srgb(xyz: np.ndarray) -> np.ndarray:
    return np.asarray(xyz, dtype=float) @ XYZ_TO_SRGB.T


def spectra_to_xyz(lam_nm: np.ndarray, radiance: np.ndarray) -> np.ndarray:
    """XYZ = Σ L(λ) x̄(λ) Δλ / Σ ȳ(λ) Δλ over the given wavelengths (trapezoid weights),
    heron's film convention. radiance: shape (..., len(lam_nm))."""
    lam = np.asarray(lam_nm, dtype=float)
    w = np.gradient(lam) if len(lam) > 1 else np.ones(1)
    cmf = cmfs_xyz(lam) * w[:, None]
    # Normalise by ∫ȳ over the whole visible range so a sub-range keeps absolute scale.
    full = np.arange(360.0, 831.0)
    norm = float(np.sum(cmfs_xyz(full)[:, 1]))
    return np.asarray(radiance, dtype=float) @ cmf / norm


def d65(lam_nm: np.ndarray) -> np.ndarray:
    """CIE D65 relative spectral power (colour-science's table, linear in between)."""
    import colour

    sd = colour.SDS_ILLUMINANTS["D65"]
    return np.interp(np.asarray(lam_nm, float), np.asarray(sd.wavelengths, float),
                     np.asarray(sd.values, float), left=0.0, right=0.0)


def display_srgb(xyz: np.ndarray, heron: Heron,
                 white_y: float | None = None) -> tuple[np.ndarray, float]:
    """Encoded sRGB in [0, 1] for display, from XYZ: XYZ divided by scale, with scale the
    largest linear sRGB channel (or `white_y` if given), then `heron display` (colours
    outside the sRGB gamut brought in at constant hue, as heron's PNG previews do).
    Returns (rgb, scale)."""
    lin = xyz_to_linear_srgb(xyz)
    scale = float(white_y) if white_y is not None else float(np.max(lin))
    if scale <= 0.0:
        scale = 1.0
    return heron.display(np.asarray(xyz, dtype=float) / scale), scale


def profile_columns(header: Sequence[str]) -> list[float]:
    """The wavelengths of a `heron sky profile` header: theta_deg,<λ>nm,…"""
    assert header[0] == "theta_deg", header
    return [float(h.removesuffix("nm")) for h in header[1:]]
