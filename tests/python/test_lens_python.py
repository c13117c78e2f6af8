"""`heron.lens` (issue 22: "The Python module gets the same") against `heron lens`.

    heron.lens(prescription, fields=(0, 14, 20), rays=64, reference_wavelength=None)

returns `heron lens`'s report as a dict: "paraxial" (a record per F, d, C line with the
columns of paraxial.csv), "focal_shift" (numpy arrays with the columns of
focal_shift.csv), "spots" (a record per field and line with the columns of spots.csv,
plus "points_mm", the image-plane points), "name", "reference_wavelength_nm" and
"summary" (the text the CLI prints). Both front ends call `heron::lensdesign::analyse`,
and the CSV files print each f64 in its shortest round-trip form, so the numbers must be
equal exactly, not within a tolerance:

- lenses/cooke-triplet.toml with the defaults (so the defaults agree too), and
  lenses/dgauss.50mm.dat (a pbrt-v4 lens file, as an os.PathLike) with other fields, a
  coarser grid and another reference wavelength: every CSV cell, every spot point
  (spot_points.csv writes them minus the centroid), and the printed summary.
- A singlet given as a list of surface dicts (a stop in air, then a biconvex lens
  0.6 mm thick), in N-BK7, F2 and a Cauchy glass: at every F, d, C line the EFL is the
  lensmaker's equation 1/f = (n − 1) [1/R1 − 1/R2 + (n − 1) t / (n R1 R2)] with n(λ)
  from `heron.ior` (the float32 index heron's lens code uses), within 1e-12 relative;
  the BFL is f (1 − (n − 1) t / (n R1)); the thin-lens value (t = 0) differs from the
  EFL by the thickness term only; the entrance pupil is the stop (it is in air, in front
  of the lens) and f-number = EFL / EPD; the focal-shift curve is BFL(λ) − BFL(d) from
  the same formula at each of its 61 wavelengths.
- A lens scene (scenes/singlet-chromatic.toml) rendered by `Scene.render` has the
  pixels `heron render` writes for the same spp and seed.
- Bad input raises heron.HeronError (a ValueError), never a panic, with a one-line
  message naming the file or argument: the CLI's message with the flag renamed where
  the CLI has the same mistake, and "prescription: surface N" for a list.

The module must be installed in the interpreter running pytest (scripts/setup-python.sh);
the CLI is HERON_BIN (default target/release/heron). Runs in about a second.
"""
from __future__ import annotations

import csv
import math
import pathlib
import subprocess

import heron  # built and installed by scripts/setup-python.sh; never skipped
import numpy as np
import pytest

from heronrun import REPO, require_heron_bin
# The CSV columns of the spec (lensref.py, the Optiland reference, defines them).
from lensref import FDC, FOCAL_SHIFT_COLUMNS, PARAXIAL_COLUMNS, SPOT_COLUMNS

LENSES = REPO / "lenses"


def run_cli(*args, check=True) -> subprocess.CompletedProcess:
    p = subprocess.run([str(require_heron_bin()), "lens", *map(str, args)],
                       capture_output=True, text=True, cwd=REPO, timeout=300)
    if check:
        assert p.returncode == 0, f"heron lens {' '.join(map(str, args))} failed:\n{p.stderr}"
    return p


def cli_error(*args) -> str:
    """The CLI's one-line error, without `error: `."""
    p = run_cli(*args, check=False)
    assert p.returncode == 1, f"expected status 1 from heron lens {args}: {p.stderr}"
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    return lines[0].removeprefix("error: ")


def py_error(*args, **kwargs) -> str:
    with pytest.raises(heron.HeronError) as e:
        heron.lens(*args, **kwargs)
    assert isinstance(e.value, ValueError)
    msg = str(e.value)
    assert "\n" not in msg and "internal error" not in msg, msg
    return msg


def read_csv(path: pathlib.Path) -> tuple[list[str], list[list[float]]]:
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]


# --------------------------------------------------------------------------- the CLI's numbers

CASES = {
    "cooke-defaults": (LENSES / "cooke-triplet.toml", {}, []),
    "dgauss-options": (
        LENSES / "dgauss.50mm.dat",
        dict(fields=np.array([0.0, 7.5, -3.0]), rays=17, reference_wavelength=550.0),
        ["--fields", "0,7.5,-3", "--rays", "17", "--reference-wavelength", "550"],
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_lens_equals_cli(tmp_path, case):
    path, kwargs, flags = CASES[case]
    out = tmp_path / "out"
    printed = run_cli(path, "--out", out, *flags).stdout
    r = heron.lens(pathlib.Path(path) if case.startswith("dgauss") else str(path), **kwargs)
    assert set(r) == {"name", "reference_wavelength_nm", "paraxial", "focal_shift",
                      "spots", "summary"}
    assert r["summary"] == printed
    assert printed.startswith(r["name"] + "\n")
    want_ref = kwargs.get("reference_wavelength", 587.5618)
    assert r["reference_wavelength_nm"] == want_ref

    header, rows = read_csv(out / "paraxial.csv")
    assert tuple(header) == PARAXIAL_COLUMNS
    assert [list(p) for p in r["paraxial"]] == [list(PARAXIAL_COLUMNS)] * 3
    assert [[p[c] for c in PARAXIAL_COLUMNS] for p in r["paraxial"]] == rows
    assert [p["wavelength_nm"] for p in r["paraxial"]] == list(FDC)

    header, rows = read_csv(out / "focal_shift.csv")
    assert tuple(header) == FOCAL_SHIFT_COLUMNS and list(r["focal_shift"]) == header
    for k, c in enumerate(FOCAL_SHIFT_COLUMNS):
        a = r["focal_shift"][c]
        assert isinstance(a, np.ndarray) and a.dtype == np.float64 and a.shape == (61,)
        assert a.tolist() == [row[k] for row in rows], c
    assert r["focal_shift"]["wavelength_nm"].tolist() == [400.0 + 5 * i for i in range(61)]

    header, rows = read_csv(out / "spots.csv")
    assert tuple(header) == SPOT_COLUMNS
    fields = kwargs.get("fields", (0.0, 14.0, 20.0))
    assert [(s["field_deg"], s["wavelength_nm"]) for s in r["spots"]] == [
        (float(f), l) for f in fields for l in FDC]
    assert [[s[c] for c in SPOT_COLUMNS] for s in r["spots"]] == rows
    for s in r["spots"]:
        assert list(s) == list(SPOT_COLUMNS) + ["points_mm"]
        assert isinstance(s["rays"], int)
        p = s["points_mm"]
        assert p.dtype == np.float64 and p.shape == (s["rays"], 2)
    header, rows = read_csv(out / "spot_points.csv")
    assert header == ["field_deg", "wavelength_nm", "x_mm", "y_mm"]
    want = np.array(rows)
    got = np.concatenate([
        np.column_stack([np.full(s["rays"], s["field_deg"]),
                         np.full(s["rays"], s["wavelength_nm"]),
                         s["points_mm"] - [s["centroid_x_mm"], s["centroid_y_mm"]]])
        for s in r["spots"]])
    np.testing.assert_array_equal(got, want)


# --------------------------------------------------------------------------- a dict singlet

R1, R2, T, STOP_GAP, STOP_RADIUS = 100.0, -150.0, 0.6, 2.0, 4.0


def singlet(medium) -> list[dict]:
    """A stop in air STOP_GAP mm in front of a biconvex R1/T/R2 lens; edge thickness at
    the 5 mm rim: 0.6 − 0.125 − 0.083 = 0.39 mm."""
    return [
        {"radius": 0.0, "thickness": STOP_GAP, "semi_aperture": STOP_RADIUS, "stop": True},
        {"radius": R1, "thickness": T, "medium": medium, "semi_aperture": 5.0},
        {"radius": R2, "thickness": 140.0, "semi_aperture": 5.0},
    ]


def lensmaker(n: float, t: float = T) -> tuple[float, float]:
    """(EFL, BFL) of a lens in air, Hecht, Optics, 5th ed., eq. 6.2 (the lensmaker's
    equation with the thickness term) and eq. 6.3 (back focal length)."""
    f = 1.0 / ((n - 1.0) * (1.0 / R1 - 1.0 / R2 + (n - 1.0) * t / (n * R1 * R2)))
    return f, f * (1.0 - (n - 1.0) * t / (n * R1))


MEDIA = {
    "N-BK7": "N-BK7",
    "F2": "F2",
    "cauchy": {"cauchy": [1.55, 0.0062]},
}


@pytest.mark.parametrize("name", sorted(MEDIA))
def test_dict_singlet_is_the_lensmaker(name):
    medium = MEDIA[name]
    r = heron.lens(singlet(medium), fields=[0.0], rays=8)
    assert r["name"] == "<list>"
    n = heron.ior(medium, list(FDC)).astype(np.float64)
    for p, n_l in zip(r["paraxial"], n):
        f, bfl = lensmaker(float(n_l))
        assert p["efl_mm"] == pytest.approx(f, rel=1e-12, abs=0)
        assert p["bfl_mm"] == pytest.approx(bfl, rel=1e-12, abs=0)
        # The thin lens (t = 0) misses only the thickness term b = (n − 1) t / (n R1 R2)
        # beside a = 1/R1 − 1/R2 (b/a = −8.2e-4 for N-BK7): f/f_thin = a / (a + b).
        thin = lensmaker(float(n_l), 0.0)[0]
        a, b = 1.0 / R1 - 1.0 / R2, (n_l - 1.0) * T / (n_l * R1 * R2)
        assert p["efl_mm"] / thin - 1.0 == pytest.approx(-b / (a + b), rel=1e-8)
        # The stop is in air in front of the lens: it is the entrance pupil.
        assert p["entrance_pupil_z_mm"] == pytest.approx(0.0, abs=1e-12)
        assert p["entrance_pupil_diameter_mm"] == pytest.approx(2 * STOP_RADIUS, rel=1e-12)
        assert p["f_number"] == pytest.approx(f / (2 * STOP_RADIUS), rel=1e-12)
    # Normal dispersion: n falls with λ, so the focal length grows from F to C.
    assert r["paraxial"][0]["efl_mm"] < r["paraxial"][1]["efl_mm"] < r["paraxial"][2]["efl_mm"]
    fs = r["focal_shift"]
    lam = fs["wavelength_nm"]
    bfl = np.array([lensmaker(float(x))[1] for x in heron.ior(medium, lam)])
    bfl_d = lensmaker(float(n[1]))[1]
    np.testing.assert_allclose(fs["bfl_mm"], bfl, rtol=1e-12, atol=0)
    np.testing.assert_allclose(fs["focal_shift_mm"], bfl - bfl_d, rtol=0, atol=1e-11)
    assert [s["rays"] for s in r["spots"]] == [32] * 3  # of the 8 × 8 grid, in the disc


def test_dict_singlet_equals_the_same_toml(tmp_path):
    """A list of surface dicts is read as the same [[surface]] tables in a file."""
    lines = ['name = "singlet"', 'source = "test_lens_python.py"']
    for s in singlet("N-BK7"):
        lines.append("[[surface]]")
        lines += [f"{k} = {str(v).lower() if isinstance(v, bool) else repr(v)}"
                  for k, v in s.items()]
    path = tmp_path / "singlet.toml"
    path.write_text("\n".join(lines) + "\n")
    a = heron.lens(singlet("N-BK7"), fields=(0, 3), rays=12)
    b = heron.lens(path, fields=(0, 3), rays=12)
    assert a["paraxial"] == b["paraxial"]
    for c in FOCAL_SHIFT_COLUMNS:
        np.testing.assert_array_equal(a["focal_shift"][c], b["focal_shift"][c])
    for sa, sb in zip(a["spots"], b["spots"], strict=True):
        np.testing.assert_array_equal(sa.pop("points_mm"), sb.pop("points_mm"))
        assert sa == sb


# --------------------------------------------------------------------------- errors

TRIPLET = str(LENSES / "cooke-triplet.toml")


def test_errors_are_the_clis(tmp_path):
    """Where the CLI can make the same mistake, the message is its own with the flag
    renamed to the argument."""
    missing = str(REPO / "lenses" / "no-such-lens.toml")
    want = cli_error(missing)
    assert want.startswith(missing + ": cannot read the lens prescription")
    assert py_error(missing) == want
    assert py_error(pathlib.Path(missing)) == want
    assert py_error(TRIPLET, rays=1) == cli_error(TRIPLET, "--rays", "1").replace("--rays", "rays")
    assert py_error(TRIPLET, fields=[0, 95]) == cli_error(TRIPLET, "--fields", "0,95").replace(
        "--fields", "fields")
    assert py_error(TRIPLET, reference_wavelength=900) == cli_error(
        TRIPLET, "--reference-wavelength", "900").replace("--reference-wavelength",
                                                         "reference_wavelength")
    # A bad file: the message names the file and the surface.
    bad = tmp_path / "bad.toml"
    bad.write_text((LENSES / "singlet-bk7.toml").read_text().replace(
        "semi_aperture = 12.7", "semi_aperture = 26", 1))
    want = cli_error(bad)
    assert want.startswith(f"{bad}: surface 2: semi-aperture 26 mm is larger"), want
    assert py_error(str(bad)) == want


@pytest.mark.parametrize("kwargs,want", [
    (dict(rays=-3), "rays: expected at least 2 points across the pupil, got -3"),
    (dict(rays=0), "rays: expected at least 2 points across the pupil, got 0"),
    (dict(fields=[]), "fields: expected at least one field angle (degrees)"),
    (dict(fields=[0, -90]), "fields: expected field angles in (−90°, 90°), got -90"),
    (dict(fields=[0, math.nan]), "fields: expected field angles in (−90°, 90°), got NaN"),
    (dict(fields="0,14"), "fields: expected a number or a sequence of numbers, got '0,14'"),
    (dict(fields=[0, "x"]), "fields[1]: expected a number, got 'x'"),
    (dict(reference_wavelength=300.0),
     "reference_wavelength: expected a wavelength in 360–830 nm, got 300"),
])
def test_argument_errors(kwargs, want):
    assert py_error(TRIPLET, **kwargs) == want


def test_prescription_errors(tmp_path):
    good = singlet("N-BK7")
    heron.lens(good, fields=0, rays=4)  # the control
    bad_glass = [good[0], {**good[1], "medium": "N-BK8"}, good[2]]
    assert py_error(bad_glass).startswith(
        'prescription: surface 2: medium: unknown refractive-index model "N-BK8"')
    assert py_error([good[0], {**good[1], "colour": 2}, good[2]]).startswith(
        "prescription: surface 2: unknown field `colour`")
    assert py_error([good[0], {**good[1], "thickness": "0.6"}, good[2]]).startswith(
        'prescription: surface 2: invalid type: string "0.6"')
    missing = {k: v for k, v in good[1].items() if k != "radius"}
    assert py_error([good[0], missing, good[2]]) == "prescription: surface 2: missing field `radius`"
    assert py_error([good[0], {**good[1], "medium": None}, good[2]]).startswith(
        "prescription: surface 2: medium: expected a bool, int, float, str, list or dict")
    # The lens checks name the surface: a semi-aperture beyond the sphere, crossing
    # surfaces, the stop, the medium behind the last surface.
    assert py_error([good[0], {**good[1], "radius": 4.5}, good[2]]).startswith(
        "prescription: surface 2: semi-aperture 5 mm is larger than the radius")
    assert py_error([good[0], {**good[1], "thickness": 0.1}, good[2]]).startswith(
        "prescription: surface 2: crosses surface 3")
    assert py_error([{**good[0], "stop": False}, good[1], good[2]]).startswith(
        "prescription: no aperture stop")
    assert py_error([good[0], good[1], {**good[2], "medium": "F2"}]).startswith(
        "prescription: surface 3: the medium behind the last surface must be air")
    assert py_error([]) == "prescription: expected at least one surface"
    assert py_error([good[0], 3]) == (
        "prescription: surface 2: expected a dict with radius, thickness, semi_aperture "
        "and optionally medium and stop (a [[surface]] table), got 3 (int)")
    assert py_error(3).startswith("prescription: expected a path to a lens prescription")
    assert py_error({"surface": good}).startswith(
        "prescription: expected a path to a lens prescription")
    # Files: errors start with the path, then the surface or line.
    f = tmp_path / "bad.toml"
    f.write_text((LENSES / "singlet-bk7.toml").read_text().replace('"N-BK7"', '"N-BK8"'))
    assert py_error(f).startswith(f"{f}: surface 2: medium: unknown refractive-index model")
    d = tmp_path / "bad.dat"
    d.write_text("0 1 0 8\n50 5 1.5 10 N-SF99\n0 90 1 10\n")
    assert py_error(d).startswith(f"{d}: line 2 (surface 2): unknown glass \"N-SF99\"")


def test_documented_and_typed():
    assert heron.lens.__doc__ and "points_mm" in heron.lens.__doc__
    assert heron.lens.__text_signature__ == (
        "(prescription, fields=(0, 14, 20), rays=64, reference_wavelength=None)")
    stub = (pathlib.Path(heron.__file__).parent / "__init__.pyi").read_text()
    for name in ("def lens(", "class LensReport(", "class LensSpot(", "class LensParaxial(",
                 "class LensFocalShift("):
        assert name in stub, f"{name} missing in the stub"


def test_lens_scene_renders_from_python_as_from_the_cli(tmp_path):
    """The issue's "the scenes render from the CLI and Python": a lens scene rendered by
    `Scene.render` has the pixels of `heron render` with the same spp and seed (both
    run the same renderer; the image does not depend on the thread count), and the
    lights in view are bright where the lens images them."""
    import OpenEXR

    scene = REPO / "scenes" / "singlet-chromatic.toml"
    out = tmp_path / "s.exr"
    p = subprocess.run([str(require_heron_bin()), "render", str(scene), "-o", str(out),
                        "--spp", "2", "--seed", "7", "--no-png", "--quiet"],
                       capture_output=True, text=True, cwd=REPO, timeout=300)
    assert p.returncode == 0, p.stderr
    with OpenEXR.File(str(out), separate_channels=True) as f:
        ch = f.channels()
        cli = np.stack([np.asarray(ch[c].pixels, dtype=np.float32) for c in "RGB"], -1)
    py = heron.load_scene(scene).render(spp=2, seed=7, threads=1).rgb
    assert py.shape == cli.shape == (240, 480, 3)
    np.testing.assert_array_equal(py, cli)
    # The light in focus sits at the film's centre.
    assert py[110:130, 230:250].max() > 100 * max(py[:20, :20].max(), 1e-6)
