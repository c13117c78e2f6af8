"""heron's Lorenz–Mie series (src/optics/mie.rs) against miepython 3.3.0 (pinned).

heron prints the amplitude functions of a sphere through a hidden debug subcommand,

    heron sky mie-phase --m M --x X --from DEG --to DEG --step DEG

as CSV `angle_deg,s1_re,s1_im,s2_re,s2_im` (scattering angle; Bohren & Huffman's S1, S2,
unnormalised). miepython's `S1_S2(m, x, mu, norm="wiscombe")` returns the same
unnormalised amplitudes. The sky's profile is built from |S1|² and |S2|² only (the
phase convention of S does not matter), so those are compared, and the unpolarised
phase function (|S1|² + |S2|²)/2.

Water, m = 1.3330 (n at about 589 nm; real: absorption is neglected in heron's sky) and
m = 1.3435 (about 400 nm), at size parameters x = 1, 10, 100, 1000 and 5000 (a 0.5 mm
drop in red light is x ≈ 5000), over 0–180° every 0.5° plus the rainbow region
130–145° every 0.01°.

Agreement: |heron − miepython| ≤ 1e-6·|miepython| + 1e-9·max over angles, for |S1|²,
|S2|² and the phase function (the floor is for the deep minima of the patterns, where
the relative error of two float64 series is meaningless).
"""
from __future__ import annotations

import subprocess

import numpy as np
import pytest

miepython = pytest.importorskip("miepython")

from heronrun import require_heron_bin  # noqa: E402

REL = 1e-6
FLOOR = 1e-9


def heron_amplitudes(m: float, x: float, start: float, stop: float, step: float):
    out = subprocess.run(
        [
            str(require_heron_bin()),
            "sky",
            "mie-phase",
            "--m",
            repr(m),
            "--x",
            repr(x),
            "--from",
            repr(start),
            "--to",
            repr(stop),
            "--step",
            repr(step),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    lines = out.stdout.strip().splitlines()
    assert lines[0] == "angle_deg,s1_re,s1_im,s2_re,s2_im"
    a = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return a[:, 0], a[:, 1] + 1j * a[:, 2], a[:, 3] + 1j * a[:, 4]


def check(name: str, got: np.ndarray, want: np.ndarray) -> float:
    tol = REL * np.abs(want) + FLOOR * np.max(np.abs(want))
    err = np.abs(got - want)
    worst = int(np.argmax(err / tol))
    assert np.all(err <= tol), (
        f"{name}: worst at index {worst}: heron {got[worst]!r} vs miepython {want[worst]!r}"
    )
    return float(np.max(err / np.maximum(np.abs(want), 1e-300)))


@pytest.mark.parametrize("m", [1.3330, 1.3435])
@pytest.mark.parametrize("x", [1.0, 10.0, 100.0, 1000.0, 5000.0])
@pytest.mark.parametrize("grid", [(0.0, 180.0, 0.5), (130.0, 145.0, 0.01)])
def test_mie_amplitudes_match_miepython(m: float, x: float, grid) -> None:
    angles, s1, s2 = heron_amplitudes(m, x, *grid)
    expected_n = int(round((grid[1] - grid[0]) / grid[2])) + 1
    assert len(angles) == expected_n
    mu = np.cos(np.radians(angles))
    r1, r2 = miepython.S1_S2(m, x, mu, norm="wiscombe")
    check(f"|S1|² m={m} x={x}", np.abs(s1) ** 2, np.abs(r1) ** 2)
    check(f"|S2|² m={m} x={x}", np.abs(s2) ** 2, np.abs(r2) ** 2)
    check(
        f"phase m={m} x={x}",
        0.5 * (np.abs(s1) ** 2 + np.abs(s2) ** 2),
        0.5 * (np.abs(r1) ** 2 + np.abs(r2) ** 2),
    )


def test_tolerance_catches_a_wrong_index() -> None:
    """A 1e-4 change of m at x = 1000 must fail the comparison."""
    angles, s1, _ = heron_amplitudes(1.3330, 1000.0, 130.0, 145.0, 0.01)
    r1, _ = miepython.S1_S2(1.3331, 1000.0, np.cos(np.radians(angles)), norm="wiscombe")
    with pytest.raises(AssertionError):
        check("wrong m", np.abs(s1) ** 2, np.abs(r1) ** 2)


def test_mie_phase_rejects_bad_values() -> None:
    for args in (["--m", "0.5", "--x", "10"], ["--m", "1.33", "--x", "-1"]):
        out = subprocess.run(
            [str(require_heron_bin()), "sky", "mie-phase", *args],
            capture_output=True,
            text=True,
        )
        assert out.returncode == 1
        assert len(out.stderr.strip().splitlines()) == 1


def heron_matrix(radius_um: float, lambda_nm: int):
    out = subprocess.run(
        [
            str(require_heron_bin()),
            "sky",
            "mie-matrix",
            "--radius-um",
            repr(radius_um),
            "--lambda",
            str(lambda_nm),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    lines = out.stdout.strip().splitlines()
    head = dict(kv.split("=") for kv in lines[0].lstrip("# ").split(","))
    assert lines[1] == "theta0_deg,theta1_deg,p,f12,f33,f34"
    a = np.array([[float(v) for v in line.split(",")] for line in lines[2:]])
    return float(head["m_re"]), float(head["x"]), a


@pytest.mark.parametrize(
    "radius_um,lambda_nm", [(0.1, 550), (1.0, 400), (1.0, 550), (10.0, 700)]
)
def test_medium_phase_matrix_matches_miepython(radius_um: float, lambda_nm: int) -> None:
    """The Lorenz–Mie medium's table for polarised transport (src/medium/homogeneous.rs,
    `PhaseTable::with_matrix`): per bin of its angle grid, the phase function p and the
    shape F12/F11, F33/F11, F34/F11, against the same bins built from miepython's S1, S2
    at the bin edges (trapezoid averages; p normalised over the sphere as the table
    is). One drop radius, no absorption; size parameters 1.1 to 99 at 400–700 nm.

    Conventions: heron's matrix is written with x̂ perpendicular to the scattering
    plane, F12 = (|S1|² − |S2|²)/2, F33 = Re(S1 S2*), F34 = −Im(S1 S2*) in Bohren &
    Huffman's amplitudes (e^{−iωt}; their eq. 4.77's S34, and the sign Mitsuba's
    Fresnel matrices give S3). miepython's amplitudes are their complex conjugates
    (van de Hulst's e^{+iωt}; checked against `heron sky mie-phase` below).

    Tolerances: p within 1e-5 relative (+1e-9 of its peak, the deep minima), the shapes
    within 1e-5 absolute; they are f32 in the table, and heron's and miepython's series
    agree to 1e-6 (test_mie_amplitudes_match_miepython). A sign error in any element, a
    parallel/perpendicular swap (F12 → −F12) or a 0.5% error in x fails by orders of
    magnitude.
    """
    m, x, a = heron_matrix(radius_um, lambda_nm)
    t0, t1 = np.radians(a[:, 0]), np.radians(a[:, 1])
    edges = np.append(t0, t1[-1])
    assert np.all(np.diff(edges) > 0) and edges[0] == 0.0 and abs(edges[-1] - np.pi) < 1e-12
    s1, s2 = miepython.S1_S2(m, x, np.cos(edges), norm="wiscombe")
    s1, s2 = np.conj(s1), np.conj(s2)  # to Bohren & Huffman's convention
    f11 = 0.5 * (np.abs(s1) ** 2 + np.abs(s2) ** 2)
    f12 = 0.5 * (np.abs(s1) ** 2 - np.abs(s2) ** 2)
    c = s1 * np.conj(s2)
    v = 2.0 * np.sin(0.5 * edges) ** 2
    bin_f11 = 0.5 * (f11[:-1] + f11[1:])
    p = bin_f11 / np.sum(bin_f11 * 2.0 * np.pi * np.diff(v))
    tol = 1e-5 * p + 1e-9 * p.max()
    worst = int(np.argmax(np.abs(a[:, 2] - p) / tol))
    assert np.all(np.abs(a[:, 2] - p) <= tol), (
        f"p at {a[worst, 0]:.4f}°: heron {a[worst, 2]} vs {p[worst]}"
    )
    for col, name, f in ((3, "F12", f12), (4, "F33", c.real), (5, "F34", -c.imag)):
        want = (f[:-1] + f[1:]) / (f11[:-1] + f11[1:])
        err = np.abs(a[:, col] - want)
        worst = int(np.argmax(err))
        assert err[worst] <= 1e-5, (
            f"{name}/F11 at {a[worst, 0]:.4f}°: heron {a[worst, col]} vs miepython {want[worst]}"
        )
    # The bow's tangential polarisation in the rainbow region for the larger drops.
    if x > 50:
        bow = (a[:, 0] > 135.0) & (a[:, 0] < 140.0)
        assert np.mean(a[bow, 3]) > 0.5


def test_miepython_amplitudes_are_conjugates_of_herons() -> None:
    """The convention test_medium_phase_matrix_matches_miepython relies on: miepython's
    S1, S2 are the complex conjugates of heron's (Bohren & Huffman's)."""
    angles, s1, s2 = heron_amplitudes(1.3330, 10.0, 5.0, 175.0, 5.0)
    r1, r2 = miepython.S1_S2(1.3330, 10.0, np.cos(np.radians(angles)), norm="wiscombe")
    assert np.max(np.abs(np.conj(r1) - s1) / np.abs(s1)) < 1e-6
    assert np.max(np.abs(np.conj(r2) - s2) / np.abs(s2)) < 1e-6
    assert np.max(np.abs(r1 - s1) / np.abs(s1)) > 0.1
