"""What the benchmark scripts share: an EXR's XYZ channels read back with the OpenEXR
package (the independent reader of the tests), and the relative RMSE of linear sRGB,
sqrt(Σ(x − ref)²) / sqrt(Σ ref²), as `heron converge` defines it."""
from __future__ import annotations

import numpy as np

# XYZ to linear sRGB (IEC 61966-2-1, D65), the matrix heron's film uses.
XYZ_TO_SRGB = np.array([[3.2404542, -1.5371385, -0.4985314],
                        [-0.9692660, 1.8760108, 0.0415560],
                        [0.0556434, -0.2040259, 1.0572252]])


def read_xyz(path):
    """The X, Y, Z channels of an EXR written with `heron render --xyz`, H × W × 3."""
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "XYZ"], -1)


def rel_rmse(xyz, ref_xyz):
    """Relative RMSE of linear sRGB of `xyz` against `ref_xyz`."""
    a, r = xyz @ XYZ_TO_SRGB.T, ref_xyz @ XYZ_TO_SRGB.T
    return float(np.sqrt(((a - r) ** 2).sum() / (r ** 2).sum()))
