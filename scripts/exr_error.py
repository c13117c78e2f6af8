"""What the benchmark scripts share: an EXR's XYZ channels read back with the OpenEXR
package (the independent reader of the tests), and the error measures of linear sRGB
as `heron converge` and `heron compare` define them (src/compare.rs, `errors`):

- relative RMSE  sqrt(Σ(x − r)²) / sqrt(Σ r²)  over pixels and channels;
- relMSE  mean over pixels and channels of (x − r)² / (r² + ε), ε = 10⁻²
  (Rousselle, Knaus & Zwicker 2011; `heron::compare::REL_MSE_EPSILON`);

each over the whole image or over a region of interest `roi` = (x0, y0, x1, y1), the
pixels x0 ≤ x < x1, y0 ≤ y < y1 from the top-left (`heron converge --roi X0,Y0,X1,Y1`).
"""
from __future__ import annotations

import numpy as np

# XYZ to linear sRGB (IEC 61966-2-1, D65), the matrix heron's film uses.
XYZ_TO_SRGB = np.array([[3.2404542, -1.5371385, -0.4985314],
                        [-0.9692660, 1.8760108, 0.0415560],
                        [0.0556434, -0.2040259, 1.0572252]])

# The relMSE's ε, in linear sRGB (heron::compare::REL_MSE_EPSILON).
REL_MSE_EPSILON = 1e-2


def read_xyz(path):
    """The X, Y, Z channels of an EXR written with `heron render --xyz`, H × W × 3."""
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "XYZ"], -1)


def parse_roi(text):
    """(x0, y0, x1, y1) from "X0,Y0,X1,Y1"; ValueError naming what was expected."""
    try:
        v = [int(p) for p in text.split(",")]
    except ValueError:
        v = []
    if len(v) != 4 or min(v) < 0:
        raise ValueError(f"expected X0,Y0,X1,Y1 (four whole numbers of pixels), got {text!r}")
    x0, y0, x1, y1 = v
    if x0 >= x1 or y0 >= y1:
        raise ValueError(f"expected X0 < X1 and Y0 < Y1, got {text!r}")
    return x0, y0, x1, y1


def crop(img, roi):
    """`img` (H × W × …) inside `roi`, or all of it for None; ValueError when the
    rectangle reaches outside the image."""
    if roi is None:
        return img
    x0, y0, x1, y1 = roi
    h, w = img.shape[:2]
    if x1 > w or y1 > h:
        raise ValueError(f"roi {x0},{y0},{x1},{y1} reaches outside the {w}x{h} image: "
                         f"expected X1 <= {w} and Y1 <= {h}")
    return img[y0:y1, x0:x1]


def _srgb(xyz, ref_xyz, roi):
    return crop(xyz, roi) @ XYZ_TO_SRGB.T, crop(ref_xyz, roi) @ XYZ_TO_SRGB.T


def _rel_rmse(d2, r2):
    if d2 == 0.0:
        return 0.0
    return float(np.sqrt(d2 / r2)) if r2 > 0.0 else float("inf")


def rel_rmse(xyz, ref_xyz, roi=None):
    """Relative RMSE of linear sRGB of `xyz` against `ref_xyz` (over `roi`)."""
    a, r = _srgb(xyz, ref_xyz, roi)
    return _rel_rmse(((a - r) ** 2).sum(), (r ** 2).sum())


def rel_mse(xyz, ref_xyz, roi=None):
    """relMSE of linear sRGB of `xyz` against `ref_xyz` (over `roi`)."""
    a, r = _srgb(xyz, ref_xyz, roi)
    return float(((a - r) ** 2 / (r ** 2 + REL_MSE_EPSILON)).mean())


def reference_own_error(half_a, half_b, roi=None):
    """The error of the reference (half_a + half_b)/2 made of two independent halves
    of equal samples: E(h₁ − h₂)² is 4 times the whole reference's squared error per
    value, so (h₁ − h₂)/2 stands for its error (as `heron converge` estimates it).
    Returns (relative RMSE, relMSE)."""
    ref = 0.5 * (half_a + half_b)
    err = ref + 0.5 * (half_a - half_b)
    return rel_rmse(err, ref, roi), rel_mse(err, ref, roi)
