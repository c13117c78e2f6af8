"""scripts/exr_error.py, the benchmark scripts' error measures, against hand-worked
values and against heron's own (src/compare.rs, which `heron converge` calls):

- on synthetic XYZ images (the identity of linear sRGB's matrix undone, so the sRGB
  values are chosen): the relative RMSE, the relMSE with ε = 0.01 and both over a
  region of interest, the half-open rectangle x0 ≤ x < x1, y0 ≤ y < y1;
- bad rectangles raise ValueError saying what was expected;
- the reference's own error from two halves: (h₁ − h₂)/2 measured as a run's error;
- on two renders of the Cornell box, `heron compare`'s relative RMSE and relMSE (from
  the EXRs' R, G, B) equal exr_error's (from X, Y, Z) to the printed digits.
"""
from __future__ import annotations

import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

from heronrun import REPO, require_heron_bin

sys.path.insert(0, str(REPO / "scripts"))
import exr_error  # noqa: E402

SRGB_TO_XYZ = np.linalg.inv(exr_error.XYZ_TO_SRGB)


def _xyz(srgb):
    """XYZ whose linear sRGB is `srgb` (H × W × 3)."""
    return np.asarray(srgb, dtype=np.float64) @ SRGB_TO_XYZ.T


def test_measures_have_their_hand_worked_values():
    # A 2 × 3 image against a reference of 1 everywhere but one black pixel.
    ref = np.ones((2, 3, 3))
    ref[1, 2] = 0.0
    run = ref.copy()
    run[0, 1] = [2.0, 1.0, 1.0]   # (x 1, y 0): one channel off by 1
    run[1, 2] = [0.1, 0.1, 0.1]   # (x 2, y 1): black in the reference
    x, r = _xyz(run), _xyz(ref)
    # Σd² = 1 + 3·0.01, Σr² = 15; relMSE (1/1.01 + 3·0.01/0.01) / 18 values.
    assert exr_error.rel_rmse(x, r) == pytest.approx(np.sqrt(1.03 / 15), rel=1e-9)
    assert exr_error.rel_mse(x, r) == pytest.approx((1 / 1.01 + 3) / 18, rel=1e-9)
    assert exr_error.REL_MSE_EPSILON == 0.01
    # The region x 1–2, y 0: pixels (1, 0) and (2, 0).
    roi = exr_error.parse_roi("1,0,3,1")
    assert roi == (1, 0, 3, 1)
    assert exr_error.rel_rmse(x, r, roi) == pytest.approx(np.sqrt(1 / 6), rel=1e-9)
    assert exr_error.rel_mse(x, r, roi) == pytest.approx(1 / 1.01 / 6, rel=1e-9)
    # The black pixel alone: no relative RMSE, the relMSE of 0.1 over √ε.
    black = (2, 1, 3, 2)
    assert exr_error.rel_rmse(x, r, black) == float("inf")
    assert exr_error.rel_mse(x, r, black) == pytest.approx(1.0, rel=1e-9)
    assert exr_error.rel_rmse(r, r) == 0.0 and exr_error.rel_mse(r, r) == 0.0


@pytest.mark.parametrize("text, expected", [
    ("1,2,3", "expected X0,Y0,X1,Y1"),
    ("a,0,1,1", "expected X0,Y0,X1,Y1"),
    ("-1,0,1,1", "expected X0,Y0,X1,Y1"),
    ("3,0,3,1", "expected X0 < X1"),
])
def test_bad_rectangles_say_what_was_expected(text, expected):
    with pytest.raises(ValueError, match=expected):
        exr_error.parse_roi(text)


def test_a_rectangle_outside_the_image_is_refused():
    img = np.zeros((4, 5, 3))
    with pytest.raises(ValueError, match=r"outside the 5x4 image: expected X1 <= 5"):
        exr_error.crop(img, (0, 0, 6, 4))
    assert exr_error.crop(img, (0, 0, 5, 4)).shape == (4, 5, 3)


def test_reference_own_error_from_halves():
    # Halves 1.2 and 0.8 in every value: E(h₁ − h₂)² = 2 Var(half) = 4 Var(whole), so
    # the whole reference 1 has an error of about |h₁ − h₂|/2 = 0.2.
    a, b = np.full((2, 2, 3), 1.2), np.full((2, 2, 3), 0.8)
    own_rmse, own_mse = exr_error.reference_own_error(_xyz(a), _xyz(b))
    assert own_rmse == pytest.approx(0.2, rel=1e-9)
    assert own_mse == pytest.approx(0.04 / 1.01, rel=1e-9)
    # Over a region: the same, as every value is.
    assert exr_error.reference_own_error(_xyz(a), _xyz(b), (1, 1, 2, 2))[0] == \
        pytest.approx(0.2, rel=1e-9)


def _scene(tmp: pathlib.Path) -> pathlib.Path:
    text = (REPO / "scenes" / "cornell-box.toml").read_text()
    assert "resolution = [256, 256]" in text
    p = tmp / "box.toml"
    p.write_text(text.replace("resolution = [256, 256]", "resolution = [40, 32]"))
    return p


def _render(scene, out, seed):
    subprocess.run([str(require_heron_bin()), "render", str(scene), "-o", str(out), "--spp",
                    "8", "--seed", str(seed), "--xyz", "--no-png", "--quiet"],
                   check=True, capture_output=True, text=True)
    return out


def test_the_same_numbers_as_heron_compare(tmp_path):
    scene = _scene(tmp_path)
    a, b = _render(scene, tmp_path / "a.exr", 1), _render(scene, tmp_path / "b.exr", 2)
    p = subprocess.run([str(require_heron_bin()), "compare", str(a), str(b)],
                       capture_output=True, text=True)
    m = re.search(r"relative RMSE (\S+), relMSE (\S+) \(B as the reference\)", p.stdout)
    assert m, p.stdout + p.stderr
    xa, xb = exr_error.read_xyz(a), exr_error.read_xyz(b)
    # heron prints 5 significant digits.
    assert exr_error.rel_rmse(xa, xb) == pytest.approx(float(m.group(1)), rel=2e-4)
    assert exr_error.rel_mse(xa, xb) == pytest.approx(float(m.group(2)), rel=2e-4)
