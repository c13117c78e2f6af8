"""`heron lens` (issue 22, part 3) against Optiland 0.6.3 (pinned), an optical design
program.

    heron lens PRESCRIPTION --out DIR --fields 0,14,20 --rays 64

writes DIR/paraxial.csv (EFL, BFL, f-number, entrance and exit pupil per F, d, C line),
DIR/focal_shift.csv (BFL(λ) − BFL(reference) for 400..700 nm every 5 nm) and
DIR/spots.csv (real-ray spot statistics per field and F, d, C). lensref.py computes the
same numbers for the same prescription with Optiland's paraxial module and real-ray
tracer, with heron's own glass data (spectra/ior_catalogue.toml) as an Optiland material,
Optiland's "float_by_stop_size" aperture (the entrance pupil found from the stop's
semi-aperture), the spec's pupil grid (Optiland's "uniform" distribution: linspace(-1, 1,
64)² inside the unit disc, 3096 rays) and paraxial ray aiming, and the image plane at
the reference wavelength's paraxial focus. Designs: lenses/cooke-triplet.toml,
lenses/dgauss.50mm.dat (pbrt-v4's lens file with glasses) and lenses/singlet-bk7.toml.

Tolerances, and what they are measured against. A renderer evaluates its refractive
indices in float32 (heron's Ior::eval); `python tests/python/lensref.py PRESCRIPTION
--f32` prints how far that alone moves every number. Measured on development copies of
the designs: the Zemax-sample Cooke triplet (N-SK16/F2/N-SK16, stop on surface 4 with
semi-aperture 3.804553 mm: EPD 10.000000 mm), pbrt's dgauss.50mm with N-BAF10 and F5
on three of its six elements (constant n on the others), and an f = 100 mm N-BK7
plano-convex singlet at f/4:

- paraxial (EFL, BFL, f-number, pupil positions and diameters): 1e-4 relative, the
  issue's bound (pupil positions: or 1e-4 mm, for a pupil at a vertex); float32 indices
  move them by at most 7.4e-7 relative.
- focal shift: 2e-4 mm. float32 indices move it by at most 5.0e-5 mm (the singlet;
  4.0e-5 mm the triplet). 2e-4 mm is 1/730 of the triplet's focal-shift range over
  400-700 nm (0.146 mm) and what a wavelength error of 0.05 nm makes where its curve is
  steepest (0.0040 mm/nm), so it sees a mislabelled grid or a different glass model; the
  BFL itself is held to 1e-4 relative, which for the triplet's 42.4 mm is 4.2e-3 mm.
- spots: `rays` exactly (it pins the pupil grid: cell centres instead of linspace give
  3228 rays, and RMS radii up to 1.2% larger on the triplet, which 2% would not see); RMS
  and geometric radius within 2% (the issue's bound; float32 indices move them by
  1.8e-4); centroid within 2% of the spot's RMS radius (float32: 1.0e-4 of it);
  vignetted_fraction within the share of rays that pass within 1e-4 mm of a rim
  (lensref's borderline_rays, 4 rays of 3096 at most on the triplet).

The reference's own model is checked first, without heron: thick and thin singlets
against the thick-lens (lensmaker's) formula and Gaussian imaging of the stop, real rays
against an exact meridional Snell trace written here, and heron's glasses through
Optiland's BaseMaterial.abbe().

Bad prescriptions (unknown glass, overlapping surfaces, a semi-aperture larger than the
surface's sphere) make `heron lens` exit non-zero with a one-line error that names the
file and the surface.
"""
from __future__ import annotations

import math
import os
import re
import subprocess

import numpy as np
import pytest

import lensref
from heronrun import REPO, require_heron_bin

LENSES = REPO / "lenses"
DESIGNS = ("cooke-triplet.toml", "dgauss.50mm.dat", "singlet-bk7.toml")
FIELDS = (0.0, 14.0, 20.0)
RAYS = 64
TIMEOUT_S = float(os.environ.get("HERON_TEST_TIMEOUT", "1200"))

PARAXIAL_REL = 1e-4
PUPIL_Z_ABS_MM = 1e-4
FOCAL_SHIFT_MM = 2e-4
SPOT_REL = 0.02
CENTROID_OVER_RMS = 0.02


# ---------------------------------------------------------------------------------------
# Running heron and the reference (cached per session)

_heron_cache: dict = {}
_ref_cache: dict = {}


def heron_lens(prescription, outdir, *extra) -> subprocess.CompletedProcess:
    cmd = [str(require_heron_bin()), "lens", str(prescription), *map(str, extra)]
    if outdir is not None:
        cmd += ["--out", str(outdir)]
    try:
        return subprocess.run(cmd, capture_output=True, text=True, cwd=REPO,
                              timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"`{' '.join(cmd)}` did not finish within {TIMEOUT_S:.0f} s "
                    f"(HERON_TEST_TIMEOUT)", pytrace=False)


@pytest.fixture(scope="session")
def heron_csv(tmp_path_factory):
    """heron_csv(design) -> {"paraxial": rows, "focal_shift": rows, "spots": rows}."""

    def get(design: str) -> dict:
        if design not in _heron_cache:
            path = LENSES / design
            assert path.is_file(), f"{path} is missing"
            out = tmp_path_factory.mktemp("lens-" + design.replace(".", "-"))
            proc = heron_lens(path, out, "--fields", ",".join(f"{f:g}" for f in FIELDS),
                              "--rays", RAYS)
            if proc.returncode != 0:
                pytest.fail(f"`heron lens {path} --out {out}` exited with status "
                            f"{proc.returncode}\n--- stderr ---\n{proc.stderr[-3000:]}",
                            pytrace=False)
            _heron_cache[design] = {
                "paraxial": lensref.read_csv(out / "paraxial.csv",
                                             lensref.PARAXIAL_COLUMNS),
                "focal_shift": lensref.read_csv(out / "focal_shift.csv",
                                                lensref.FOCAL_SHIFT_COLUMNS),
                "spots": lensref.read_csv(out / "spots.csv", lensref.SPOT_COLUMNS),
            }
        return _heron_cache[design]

    return get


@pytest.fixture(scope="session")
def reference():
    """reference(design) -> Optiland's rows, as heron_csv's."""

    def get(design: str) -> dict:
        if design not in _ref_cache:
            path = LENSES / design
            assert path.is_file(), f"{path} is missing"
            p = lensref.load_prescription(path)
            _ref_cache[design] = {
                "prescription": p,
                "paraxial": lensref.paraxial_table(p),
                "focal_shift": lensref.focal_shift(p),
                "spots": lensref.spots(p, FIELDS, rays=RAYS),
            }
        return _ref_cache[design]

    return get


def by_key(rows, *keys, digits=3):
    return {tuple(round(r[k], digits) for k in keys): r for r in rows}


# ---------------------------------------------------------------------------------------
# The reference's own model, checked by hand formulas (no heron needed)


def singlet_toml(r1: float, r2: float, t: float, glass: str, stop_gap: float) -> str:
    """A flat stop (semi-aperture 5 mm) stop_gap mm before a singlet r1/t/r2 in glass."""
    return f"""name = "singlet"
source = "test_lens.py"
[[surface]]
radius = 0
thickness = {stop_gap!r}
stop = true
semi_aperture = 5.0
[[surface]]
radius = {r1!r}
thickness = {t!r}
medium = "{glass}"
semi_aperture = 12.0
[[surface]]
radius = {r2!r}
thickness = 50.0
semi_aperture = 12.0
"""


def thick_lens(n: float, r1: float, r2: float, t: float) -> tuple[float, float]:
    """(EFL, BFL) of a thick lens in air: 1/f = φ1 + φ2 − φ1 φ2 t/n,
    BFL = f (1 − φ1 t/n)."""
    p1 = (n - 1.0) / r1 if r1 else 0.0
    p2 = (1.0 - n) / r2 if r2 else 0.0
    f = 1.0 / (p1 + p2 - p1 * p2 * t / n)
    return f, f * (1.0 - p1 * t / n)


def gaussian_image(z_obj: float, surfaces) -> tuple[float, float]:
    """Paraxial image of an axial point at z_obj (relative to the first vertex) through
    surfaces [(radius, thickness after, n before, n after)]: (z of the image relative to
    the last vertex, transverse magnification), by n'/s' = n/s + (n' − n)/R surface by
    surface."""
    s = z_obj
    m = 1.0
    for i, (r, t, n, n2) in enumerate(surfaces):
        power = (n2 - n) / r if r else 0.0
        s2 = n2 / (n / s + power)
        m *= (n * s2) / (n2 * s)
        s = s2 - t if i < len(surfaces) - 1 else s2
    return s, m


@pytest.mark.parametrize("r1,r2,t", [(60.0, -80.0, 6.0), (60.0, -80.0, 0.0),
                                     (51.68, 0.0, 5.0)])
def test_reference_singlet_against_thick_lens_formula(tmp_path, r1, r2, t):
    """EFL and BFL at F, d, C and the focal shift curve from the thick-lens formula (the
    lensmaker's equation for t = 0); entrance pupil = the stop (first surface, in air);
    exit pupil = the stop imaged through the lens by Gaussian imaging."""
    path = tmp_path / "singlet.toml"
    path.write_text(singlet_toml(r1, r2, t, "N-BK7", 10.0))
    p = lensref.load_prescription(path)
    glass = p.surfaces[1].medium
    for row in lensref.paraxial_table(p):
        n = float(glass.n_nm(row["wavelength_nm"]))
        f, bfl = thick_lens(n, r1, r2, t)
        assert row["efl_mm"] == pytest.approx(f, rel=1e-10)
        assert row["bfl_mm"] == pytest.approx(bfl, rel=1e-10)
        assert row["entrance_pupil_z_mm"] == pytest.approx(0.0, abs=1e-12)
        assert row["entrance_pupil_diameter_mm"] == pytest.approx(10.0, rel=1e-12)
        assert row["f_number"] == pytest.approx(f / 10.0, rel=1e-10)
        # Stop at z = 0, lens vertices at 10 and 10 + t: image the stop through both.
        xp_z, m = gaussian_image(-10.0, [(r1, t, 1.0, n), (r2, 0.0, n, 1.0)])
        assert row["exit_pupil_z_mm"] == pytest.approx(xp_z, rel=1e-10)
        assert row["exit_pupil_diameter_mm"] == pytest.approx(10.0 * abs(m), rel=1e-10)
    ref_bfl = thick_lens(float(glass.n_nm(lensref.D_LINE)), r1, r2, t)[1]
    rows = lensref.focal_shift(p)
    assert [r["wavelength_nm"] for r in rows] == [400.0 + 5 * i for i in range(61)]
    for row in rows:
        bfl = thick_lens(float(glass.n_nm(row["wavelength_nm"])), r1, r2, t)[1]
        assert row["bfl_mm"] == pytest.approx(bfl, rel=1e-10)
        assert row["focal_shift_mm"] == pytest.approx(bfl - ref_bfl, abs=1e-9)


def meridional_trace(surfaces, z_image, theta_deg, y_pupil):
    """Exact real-ray trace in the y-z plane (Snell's law in vector form), independent
    of Optiland: rays of direction (sin θ, cos θ) through (y_pupil, z = 0), surfaces
    [(z vertex, radius, n after)] starting in air; returns y on the plane z = z_image."""
    s, c = math.sin(math.radians(theta_deg)), math.cos(math.radians(theta_deg))
    out = []
    for y0 in y_pupil:
        p = np.array([y0, 0.0])
        d = np.array([s, c])
        n1 = 1.0
        for zv, r, n2 in surfaces:
            if r == 0.0:
                p = p + (zv - p[1]) / d[1] * d
                normal = np.array([0.0, -1.0])
            else:
                centre = np.array([0.0, zv + r])
                q = p - centre
                b = q @ d
                disc = b * b - (q @ q - r * r)
                p = p + (-b - math.copysign(math.sqrt(disc), r)) * d
                normal = (p - centre) / r          # faces the incoming ray
            mu = n1 / n2
            cos_i = -(normal @ d)
            cos_t = math.sqrt(1.0 - mu * mu * (1.0 - cos_i * cos_i))
            d = mu * d + (mu * cos_i - cos_t) * normal
            n1 = n2
        out.append(p[0] + (z_image - p[1]) / d[1] * d[0])
    return np.array(out)


@pytest.mark.parametrize("theta", [0.0, 10.0, 20.0])
def test_reference_real_rays_against_exact_meridional_trace(tmp_path, theta):
    """Optiland's real rays (through the model lensref builds) land where an exact Snell
    trace puts them: a biconvex N-BK7 singlet behind a stop, meridional rays across the
    pupil at the d line, image plane at the paraxial focus; also the spot statistics of
    lensref.spots on axis, where symmetry makes them a function of the meridional
    aberration alone."""
    path = tmp_path / "singlet.toml"
    path.write_text(singlet_toml(60.0, -80.0, 6.0, "N-BK7", 10.0))
    p = lensref.load_prescription(path)
    n = float(p.surfaces[1].medium.n_nm(lensref.D_LINE))
    bfl = thick_lens(n, 60.0, -80.0, 6.0)[1]
    lens = lensref.build_optic(p, lensref.D_LINE, image_distance=bfl, max_field_deg=20.0)
    py = np.linspace(-1.0, 1.0, 11)
    rays = lens.trace_generic(0.0, theta / 20.0, np.zeros_like(py), py,
                              lensref.D_LINE * 1e-3)
    got = np.asarray(lensref.be.to_numpy(rays.y), dtype=float)
    want = meridional_trace([(0.0, 0.0, 1.0), (10.0, 60.0, n), (16.0, -80.0, 1.0)],
                            16.0 + bfl, theta, 5.0 * py)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    if theta == 0.0:
        # On axis the image of pupil point (px, py) lies at y(ρ)·(px, py)/ρ, with y(ρ)
        # the meridional ray's image height for pupil radius ρ.
        g = np.linspace(-1.0, 1.0, RAYS)
        px, py2 = np.meshgrid(g, g)
        rho = np.hypot(px, py2)[np.hypot(px, py2) <= 1.0]
        r_img = np.abs(meridional_trace([(0.0, 0.0, 1.0), (10.0, 60.0, n),
                                         (16.0, -80.0, 1.0)], 16.0 + bfl, 0.0, 5.0 * rho))
        row = lensref.spots(p, (0.0,), (lensref.D_LINE,), rays=RAYS)[0]
        assert row["rays"] == rho.size == 3096
        assert row["rms_radius_mm"] == pytest.approx(np.sqrt(np.mean(r_img**2)), rel=1e-9)
        assert row["geo_radius_mm"] == pytest.approx(r_img.max(), rel=1e-9)
        assert abs(row["centroid_x_mm"]) < 1e-12 and abs(row["centroid_y_mm"]) < 1e-12


def test_reference_glasses_through_optiland():
    """Every catalogue glass with a data-sheet V_d, as the Optiland material lensref
    builds: n at the d line within 1e-5 of the data sheet's n_d and Optiland's own
    BaseMaterial.abbe() within 0.015 of V_d (the catalogue tests' bound). And the
    { n_d, v_d } model: a Cauchy through n_d with exactly that Abbe number."""
    cat = lensref.load_catalogue()
    glasses = [k for k, e in cat.items() if "v_d" in e]
    assert len(glasses) >= 10
    for name in glasses:
        m = lensref.material(name, cat, name)
        n_d = float(m.n(lensref.D_LINE * 1e-3))
        assert n_d == pytest.approx(cat[name]["n_d"], abs=1e-5)
        assert float(np.ravel(m.abbe())[0]) == pytest.approx(cat[name]["v_d"], abs=0.015)
    m = lensref.material({"n_d": 1.67, "v_d": 47.1}, cat, "test")
    assert float(m.n(lensref.D_LINE * 1e-3)) == pytest.approx(1.67, abs=1e-14)
    assert float(np.ravel(m.abbe())[0]) == pytest.approx(47.1, rel=1e-12)
    a, b = lensref.cauchy_from_abbe(1.67, 47.1)
    assert float(m.n(0.5)) == pytest.approx(a + b / 0.25, rel=1e-15)
    assert float(lensref.material(1.5, cat, "x").n(0.4)) == 1.5
    assert float(lensref.material("air", cat, "x").n(0.4)) == 1.0
    c = lensref.material({"cauchy": [1.5, 0.0042]}, cat, "x")
    assert float(c.n(0.5)) == pytest.approx(1.5 + 0.0042 / 0.25, rel=1e-15)


@pytest.mark.parametrize("design", DESIGNS)
def test_reference_model_of_design(reference, design):
    """The Optiland model of each design: its indices are the prescription's media,
    surface by surface, and every traced ray reaches the image (lensref.spots raises
    otherwise)."""
    ref = reference(design)
    p = ref["prescription"]
    lens = lensref.build_optic(p, lensref.D_LINE)
    n = lensref.be.to_numpy(lens.surfaces.n(lensref.D_LINE * 1e-3))
    n = np.asarray(n, dtype=float).ravel()
    want = [float(s.medium.n_nm(lensref.D_LINE)) for s in p.surfaces]
    np.testing.assert_allclose(n[1:1 + len(want)], want, rtol=1e-15)
    assert len(ref["spots"]) == len(FIELDS) * 3


# ---------------------------------------------------------------------------------------
# heron lens against Optiland


def close(a: float, b: float, rel: float, abs_: float = 0.0) -> bool:
    return abs(a - b) <= max(rel * abs(b), abs_)


@pytest.mark.parametrize("design", DESIGNS)
def test_paraxial(heron_csv, reference, design):
    heron = by_key(heron_csv(design)["paraxial"], "wavelength_nm")
    ref = by_key(reference(design)["paraxial"], "wavelength_nm")
    assert sorted(heron) == sorted(ref), "paraxial.csv must have the F, d, C rows"
    bad = []
    for key, r in ref.items():
        h = heron[key]
        for col in lensref.PARAXIAL_COLUMNS[1:]:
            floor = PUPIL_Z_ABS_MM if col.endswith("_z_mm") else 0.0
            if not close(h[col], r[col], PARAXIAL_REL, floor):
                rel = h[col] / r[col] - 1 if r[col] else float("nan")
                bad.append(f"{key[0]} nm {col}: heron {h[col]!r}, Optiland {r[col]!r} "
                           f"(relative {rel:.2e})")
    assert not bad, f"{design}: paraxial.csv differs from Optiland:\n" + "\n".join(bad)


@pytest.mark.parametrize("design", DESIGNS)
def test_focal_shift(heron_csv, reference, design):
    heron = heron_csv(design)["focal_shift"]
    ref = reference(design)["focal_shift"]
    assert ([round(r["wavelength_nm"], 6) for r in heron]
            == [r["wavelength_nm"] for r in ref]), "focal_shift.csv: 400..=700 nm, 5 nm"
    bad = []
    for h, r in zip(heron, ref):
        if not close(h["bfl_mm"], r["bfl_mm"], PARAXIAL_REL):
            bad.append(f"{r['wavelength_nm']} nm bfl: heron {h['bfl_mm']!r}, "
                       f"Optiland {r['bfl_mm']!r}")
        if abs(h["focal_shift_mm"] - r["focal_shift_mm"]) > FOCAL_SHIFT_MM:
            bad.append(f"{r['wavelength_nm']} nm focal shift: heron "
                       f"{h['focal_shift_mm']!r}, Optiland {r['focal_shift_mm']!r}")
    assert not bad, f"{design}: focal_shift.csv differs from Optiland:\n" + "\n".join(bad)


@pytest.mark.parametrize("design", DESIGNS)
def test_spots(heron_csv, reference, design):
    heron = by_key(heron_csv(design)["spots"], "field_deg", "wavelength_nm")
    ref = by_key(reference(design)["spots"], "field_deg", "wavelength_nm")
    assert sorted(heron) == sorted(ref), "spots.csv must have every field × F, d, C"
    bad = []
    for key, r in ref.items():
        h = heron[key]
        where = f"{key[0]}°, {key[1]} nm"
        if h["rays"] != r["rays"]:
            bad.append(f"{where}: {h['rays']:.0f} rays, Optiland's grid has {r['rays']}")
        for col in ("rms_radius_mm", "geo_radius_mm"):
            if not close(h[col], r[col], SPOT_REL):
                bad.append(f"{where} {col}: heron {h[col]!r}, Optiland {r[col]!r} "
                           f"({h[col] / r[col] - 1:+.2%})")
        d = math.hypot(h["centroid_x_mm"] - r["centroid_x_mm"],
                       h["centroid_y_mm"] - r["centroid_y_mm"])
        if d > CENTROID_OVER_RMS * r["rms_radius_mm"]:
            bad.append(f"{where} centroid: heron ({h['centroid_x_mm']!r}, "
                       f"{h['centroid_y_mm']!r}), Optiland ({r['centroid_x_mm']!r}, "
                       f"{r['centroid_y_mm']!r}), {d / r['rms_radius_mm']:.2%} of the RMS "
                       f"radius")
        allowed = r["borderline_rays"] / r["rays"] + 1e-9
        if abs(h["vignetted_fraction"] - r["vignetted_fraction"]) > allowed:
            bad.append(f"{where} vignetted_fraction: heron {h['vignetted_fraction']!r}, "
                       f"Optiland {r['vignetted_fraction']!r} ({r['borderline_rays']} rays "
                       f"within {lensref.RIM_MARGIN_MM} mm of a rim)")
    assert not bad, f"{design}: spots.csv differs from Optiland:\n" + "\n".join(bad)


# ---------------------------------------------------------------------------------------
# Bad prescriptions

GOOD = """name = "test doublet"
source = "test_lens.py"
[[surface]]
radius = 40.0
thickness = 4.0
medium = "N-BK7"
semi_aperture = 8.0
[[surface]]
radius = -40.0
thickness = 2.0
semi_aperture = 8.0
stop = true
[[surface]]
radius = {r3}
thickness = {t3}
medium = "{glass3}"
semi_aperture = {a3}
[[surface]]
radius = -60.0
thickness = 40.0
semi_aperture = 8.0
"""
GOOD_ARGS = {"r3": "60.0", "t3": "3.0", "glass3": "F2", "a3": "8.0"}
BAD = {
    # An unknown glass on surface 3.
    "unknown-glass": ({"glass3": "NO-SUCH-GLASS"}, (3,)),
    # Surfaces 3 and 4 cross inside the clear aperture: sags at 8 mm are 0.54 mm each
    # (60 − sqrt(60² − 8²)), on a centre thickness of 0.5 mm.
    "overlapping-surfaces": ({"t3": "0.5"}, (3, 4)),
    # Surface 3's semi-aperture (8 mm) is larger than its sphere's radius (6 mm).
    "aperture-beyond-sphere": ({"r3": "6.0", "t3": "6.0"}, (3,)),
}


def test_good_prescription_runs(tmp_path):
    """The control for the bad ones: the same lens, unbroken, runs."""
    path = tmp_path / "good.toml"
    path.write_text(GOOD.format(**GOOD_ARGS))
    proc = heron_lens(path, None)
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_prescription(tmp_path, case):
    """Exit status non-zero, one line on stderr naming the file and the surface (for
    overlapping surfaces either of the two; the wording is otherwise free)."""
    change, surfaces = BAD[case]
    path = tmp_path / f"{case}.toml"
    path.write_text(GOOD.format(**{**GOOD_ARGS, **change}))
    proc = heron_lens(path, tmp_path / "out")
    assert proc.returncode != 0, f"{case}: heron lens accepted it\n{proc.stdout}"
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, f"{case}: expected a one-line error, got:\n{proc.stderr}"
    assert path.name in lines[0], f"{case}: the error does not name the file: {lines[0]}"
    named = re.findall(r"\bsurfaces?\s+(\d+)(?:\s*(?:and|,|-|–)\s*(\d+))?", lines[0])
    numbers = {int(x) for pair in named for x in pair if x}
    assert numbers & set(surfaces), (
        f"{case}: the error does not name surface {' or '.join(map(str, surfaces))}: "
        f"{lines[0]}")
