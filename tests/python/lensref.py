"""Optiland's answer for a heron lens prescription: the reference for `heron lens`.

`heron lens PRESCRIPTION --out DIR` (issue 22, part 3) writes paraxial.csv,
focal_shift.csv and spots.csv (the formats of /work/notes/lens-spec.md, repeated in
test_lens.py). This module computes the same numbers with Optiland (pinned in
requirements.txt), an independent optical design program:

- the prescription (heron's TOML, or a pbrt-v4 `*.dat` lens file with an optional fifth
  column naming a catalogue glass) is parsed here with tomllib and turned into an
  `optiland.optic.Optic`: an object surface at infinity, one standard (spherical)
  surface per prescription surface, the prescription's stop as Optiland's stop, and an
  image surface;
- every medium is a `HeronIor`, a subclass of Optiland's `BaseMaterial` that evaluates
  heron's own model: the Sellmeier coefficients of spectra/ior_catalogue.toml for a
  catalogue name, a Sellmeier or Cauchy dict, a constant, or the two-term Cauchy heron
  makes from { n_d, v_d } (n = A + B/λ² through n_d at 587.5618 nm with
  n_F − n_C = (n_d − 1)/V_d, F = 486.1327 nm, C = 656.2725 nm). "air" is n = 1 exactly.
  So both programs see the same n(λ) and any difference is the optics;
- the aperture is Optiland's "float_by_stop_size" with the stop's diameter
  (2 × its semi_aperture): Optiland finds the entrance pupil diameter itself by a
  paraxial trace through the stop (FloatByStopAperture.compute_epd);
- paraxial numbers per wavelength come from `Optic.paraxial` (f2, F2, EPL, EPD, XPL,
  XPD) with that wavelength made the primary one (Optiland computes every first-order
  quantity at its primary wavelength);
- spots: real rays traced by Optiland's ray tracer (`Optic.trace` with the "uniform"
  pupil distribution, which is the spec's square grid `linspace(-1, 1, rays)` masked to
  the unit disc, and Optiland's default paraxial ray aiming: rays of direction
  (0, sin θ, cos θ) through the points of the d-line paraxial entrance pupil). The
  primary wavelength is the d line for the spots, so the pupil is the d line's for
  every wavelength, as the spec says. The image surface is put at the reference
  wavelength's paraxial focus (last vertex + BFL(ref)). Surfaces get no clear aperture
  in Optiland, so no ray is clipped; the statistics (centroid, RMS radius about the
  spot's own centroid, geometric radius = largest distance from it) are computed here
  from the image-plane coordinates, and vignetted_fraction from the ray heights Optiland
  records at every surface (a ray counts when its height exceeds the surface's
  semi_aperture anywhere, the stop included).

Where Optiland's own conventions differ from the spec (and are not used here): its
XPL is measured from the image surface (the spec: from the last lens vertex; here
exit_pupil_z = image distance + XPL), its F2 likewise (BFL = image distance + F2), its
XPD is signed (here its absolute value), and its SpotDiagram analysis centres every
spot on the primary wavelength's chief ray (or the primary wavelength's centroid), not on
each spot's own centroid, with a hexapolar pupil by default.

Run alone: `python tests/python/lensref.py lenses/cooke-triplet.toml [--out DIR]` prints
the numbers (and with --out writes the three CSV files in heron's format).
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import pathlib
import sys
import tomllib
import warnings

import numpy as np
from numba.core.errors import NumbaIRAssumptionWarning

import optiland.backend as be
from optiland.materials import BaseMaterial
from optiland.optic import Optic

# numba 0.68.1 warns "variable ... is not in scope" (an internal pedantic check, by its
# own words) each time it compiles Optiland's conic intersection kernels; the results
# are unaffected.
warnings.filterwarnings("ignore", category=NumbaIRAssumptionWarning)

REPO = pathlib.Path(__file__).resolve().parents[2]
CATALOGUE = REPO / "spectra" / "ior_catalogue.toml"

# Fraunhofer lines (nm), as in the spec and Optiland's BaseMaterial.abbe().
F_LINE = 486.1327
D_LINE = 587.5618
C_LINE = 656.2725
FDC = (F_LINE, D_LINE, C_LINE)
FOCAL_SHIFT_NM = tuple(float(w) for w in range(400, 701, 5))
DEFAULT_FIELDS = (0.0, 14.0, 20.0)
DEFAULT_RAYS = 64
RIM_MARGIN_MM = 1e-4

PARAXIAL_COLUMNS = ("wavelength_nm", "efl_mm", "bfl_mm", "f_number", "entrance_pupil_z_mm",
                    "entrance_pupil_diameter_mm", "exit_pupil_z_mm",
                    "exit_pupil_diameter_mm")
FOCAL_SHIFT_COLUMNS = ("wavelength_nm", "bfl_mm", "focal_shift_mm")
SPOT_COLUMNS = ("field_deg", "wavelength_nm", "rays", "rms_radius_mm", "geo_radius_mm",
                "centroid_x_mm", "centroid_y_mm", "vignetted_fraction")


# ---------------------------------------------------------------------------------------
# Refractive indices: heron's models, as an Optiland material


class HeronIor(BaseMaterial):
    """An Optiland material that evaluates one of heron's refractive-index models.

    kind: "constant" (coeffs = (n,)), "sellmeier" (coeffs = (B..., C...), λ in µm, C
    in µm²: n² = 1 + Σ B λ²/(λ² − C)) or "cauchy" (coeffs = (A, B, C):
    n = A + B/λ² + C/λ⁴, λ in µm). Optiland passes wavelengths in µm, as these formulas
    take them.
    """

    def __init__(self, label: str, kind: str, coeffs: tuple[float, ...]):
        super().__init__()
        if kind not in ("constant", "sellmeier", "cauchy"):
            raise ValueError(f"unknown model kind {kind!r}")
        self.label = label
        self.kind = kind
        self.coeffs = tuple(float(c) for c in coeffs)

    @property
    def display_name(self) -> str:
        return self.label

    def _cache_state(self) -> tuple | None:
        return self._state_key((self.kind, self.coeffs))

    def n_nm(self, wavelength_nm):
        """n at wavelength(s) in nm (numpy), the same function without Optiland."""
        return self._formula(np.asarray(wavelength_nm, dtype=float) * 1e-3)

    def _formula(self, lam_um):
        if self.kind == "constant":
            return self.coeffs[0] + 0.0 * lam_um
        l2 = lam_um * lam_um
        if self.kind == "sellmeier":
            k = len(self.coeffs) // 2
            n2 = 1.0 + 0.0 * l2
            for b, c in zip(self.coeffs[:k], self.coeffs[k:]):
                n2 = n2 + b * l2 / (l2 - c)
            return be.sqrt(n2)
        a, b, c = self.coeffs
        return a + b / l2 + c / (l2 * l2)

    def _calculate_n(self, wavelength, **kwargs):
        return self._formula(be.asarray(wavelength))

    def _calculate_k(self, wavelength, **kwargs):
        return 0.0 * be.asarray(wavelength)

    def to_dict(self):
        d = super().to_dict()
        d.update(label=self.label, kind=self.kind, coeffs=list(self.coeffs))
        return d

    @classmethod
    def from_dict(cls, data):
        return cls(data["label"], data["kind"], tuple(data["coeffs"]))


def load_catalogue(path: pathlib.Path = CATALOGUE) -> dict:
    with open(path, "rb") as f:
        return tomllib.load(f)


def cauchy_from_abbe(n_d: float, v_d: float) -> tuple[float, float]:
    """(A, B) of n = A + B/λ² (λ in µm) through n_d at the d line with
    n_F − n_C = (n_d − 1)/V_d."""
    lf, ld, lc = (w * 1e-3 for w in FDC)
    b = (n_d - 1.0) / v_d / (1.0 / lf**2 - 1.0 / lc**2)
    return n_d - b / ld**2, b


def material(spec, catalogue: dict, where: str) -> HeronIor:
    """The HeronIor for a prescription's medium value (see the module docstring)."""
    if spec is None or (isinstance(spec, str) and spec.lower() == "air"):
        return HeronIor("air", "constant", (1.0,))
    if isinstance(spec, bool):
        raise ValueError(f"{where}: medium must be a name, a number or a table, "
                         f"got {spec!r}")
    if isinstance(spec, (int, float)):
        if not spec > 0:
            raise ValueError(f"{where}: medium must be positive, got {spec!r}")
        return HeronIor(repr(float(spec)), "constant", (float(spec),))
    if isinstance(spec, str):
        entry = catalogue.get(spec)
        if entry is None:
            raise ValueError(f"{where}: unknown glass {spec!r} (not in {CATALOGUE.name})")
        return _from_table(entry, where, label=spec)
    if isinstance(spec, dict):
        return _from_table(spec, where, label=None)
    raise ValueError(f"{where}: cannot read medium {spec!r}")


def _from_table(t: dict, where: str, label: str | None) -> HeronIor:
    if "sellmeier" in t:
        b, c = list(t["sellmeier"]["b"]), list(t["sellmeier"]["c"])
        if len(b) != len(c) or not 1 <= len(b) <= 4:
            raise ValueError(f"{where}: sellmeier needs 1 to 4 b and as many c")
        return HeronIor(label or f"sellmeier{b}", "sellmeier", tuple(b + c))
    if "cauchy" in t:
        c = list(t["cauchy"])
        if not 2 <= len(c) <= 3:
            raise ValueError(f"{where}: cauchy needs [A, B] or [A, B, C]")
        c = (c + [0.0])[:3]
        return HeronIor(label or f"cauchy{c}", "cauchy", tuple(c))
    if "n_d" in t and "v_d" in t and label is None:
        a, b = cauchy_from_abbe(float(t["n_d"]), float(t["v_d"]))
        return HeronIor(f"n_d={t['n_d']},v_d={t['v_d']}", "cauchy", (a, b, 0.0))
    raise ValueError(f"{where}: cannot read medium {t!r}")


# ---------------------------------------------------------------------------------------
# Prescriptions


@dataclasses.dataclass(frozen=True)
class Surface:
    number: int             # 1-based, from the object side
    radius: float           # mm, 0 = flat
    thickness: float        # mm to the next surface (last: to the film)
    medium: HeronIor        # after the surface
    semi_aperture: float    # mm
    stop: bool


@dataclasses.dataclass(frozen=True)
class Prescription:
    path: pathlib.Path
    name: str
    reference_nm: float
    surfaces: tuple[Surface, ...]

    @property
    def stop(self) -> Surface:
        return next(s for s in self.surfaces if s.stop)


def load_prescription(path, catalogue: dict | None = None) -> Prescription:
    path = pathlib.Path(path)
    catalogue = load_catalogue() if catalogue is None else catalogue
    if path.suffix == ".dat":
        return _load_dat(path, catalogue)
    with open(path, "rb") as f:
        doc = tomllib.load(f)
    surfaces = []
    for i, s in enumerate(doc.get("surface", []), 1):
        where = f"{path.name}: surface {i}"
        surfaces.append(Surface(i, float(s.get("radius", 0.0)), float(s["thickness"]),
                                material(s.get("medium"), catalogue, where),
                                float(s["semi_aperture"]), bool(s.get("stop", False))))
    ref = float(doc.get("reference_wavelength", D_LINE))
    return _checked(Prescription(path, str(doc.get("name", path.stem)), ref,
                                 tuple(surfaces)))


def _load_dat(path: pathlib.Path, catalogue: dict) -> Prescription:
    """pbrt-v4 lens file: rows `radius thickness ior aperture_diameter [glass]`, object
    side first, ior of the medium after the surface, ior 0 = the stop (in air)."""
    surfaces = []
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].split()
        if not line:
            continue
        i = len(surfaces) + 1
        where = f"{path.name}: surface {i}"
        radius, thickness, ior, diameter = (float(x) for x in line[:4])
        stop = ior == 0.0
        if len(line) >= 5:
            medium = material(line[4], catalogue, where)
        else:
            medium = material(1.0 if stop else ior, catalogue, where)
        surfaces.append(Surface(i, radius, thickness, medium, diameter / 2.0, stop))
    return _checked(Prescription(path, path.stem, D_LINE, tuple(surfaces)))


def _checked(p: Prescription) -> Prescription:
    if not p.surfaces:
        raise ValueError(f"{p.path.name}: no surfaces")
    stops = [s.number for s in p.surfaces if s.stop]
    if len(stops) != 1:
        raise ValueError(f"{p.path.name}: exactly one stop surface needed, got {stops}")
    return p


# ---------------------------------------------------------------------------------------
# The Optiland model


def build_optic(p: Prescription, primary_nm: float, image_distance: float | None = None,
                wavelengths_nm=(), max_field_deg: float = 1.0) -> Optic:
    """Optiland Optic for prescription p: object at infinity, angle fields (one field at
    max_field_deg so that normalised field Hy = θ / max_field_deg), primary wavelength
    primary_nm (the one Optiland's first-order numbers and pupil use), the image surface
    image_distance after the last vertex (default: the last thickness)."""
    lens = Optic(name=p.name)
    lens.surfaces.add(index=0, radius=be.inf, thickness=be.inf)
    last = len(p.surfaces)
    for s in p.surfaces:
        t = s.thickness if (s.number < last or image_distance is None) else image_distance
        lens.surfaces.add(index=s.number, radius=s.radius if s.radius != 0 else be.inf,
                          thickness=t, material=s.medium, is_stop=s.stop)
    lens.surfaces.add(index=last + 1)
    lens.set_aperture(aperture_type="float_by_stop_size", value=2.0 * p.stop.semi_aperture)
    lens.fields.set_type(field_type="angle")
    lens.fields.add(y=0.0)
    lens.fields.add(y=float(max_field_deg))
    lens.wavelengths.add(value=primary_nm * 1e-3, is_primary=True)
    for w in wavelengths_nm:
        if w != primary_nm:
            lens.wavelengths.add(value=w * 1e-3, is_primary=False)
    return lens


def _f(x) -> float:
    return float(np.asarray(be.to_numpy(x)).ravel()[0])


def paraxial_row(p: Prescription, wavelength_nm: float) -> dict:
    """One paraxial.csv row computed by Optiland's paraxial module at wavelength_nm."""
    lens = build_optic(p, wavelength_nm)
    par = lens.paraxial
    t_img = p.surfaces[-1].thickness           # image surface distance from last vertex
    efl = _f(par.f2())
    epd = _f(par.EPD())
    return {
        "wavelength_nm": wavelength_nm,
        "efl_mm": efl,
        "bfl_mm": t_img + _f(par.F2()),
        "f_number": efl / epd,
        "entrance_pupil_z_mm": _f(par.EPL()),
        "entrance_pupil_diameter_mm": epd,
        "exit_pupil_z_mm": t_img + _f(par.XPL()),
        "exit_pupil_diameter_mm": abs(_f(par.XPD())),
    }


def paraxial_table(p: Prescription, wavelengths_nm=FDC) -> list[dict]:
    return [paraxial_row(p, w) for w in wavelengths_nm]


def bfl(p: Prescription, wavelength_nm: float) -> float:
    """Last vertex to paraxial focus (Optiland's F2 + the image surface distance)."""
    return p.surfaces[-1].thickness + _f(build_optic(p, wavelength_nm).paraxial.F2())


def focal_shift(p: Prescription, wavelengths_nm=FOCAL_SHIFT_NM) -> list[dict]:
    ref = bfl(p, p.reference_nm)
    rows = []
    for w in wavelengths_nm:
        b = bfl(p, w)
        rows.append({"wavelength_nm": w, "bfl_mm": b, "focal_shift_mm": b - ref})
    return rows


def spots(p: Prescription, fields_deg=DEFAULT_FIELDS, wavelengths_nm=FDC,
          rays: int = DEFAULT_RAYS) -> list[dict]:
    """spots.csv rows: real rays traced by Optiland (see the module docstring), each
    with one more key, borderline_rays: how many rays pass within RIM_MARGIN_MM of a
    surface's semi-aperture (their vignetting is a matter of rounding)."""
    image = bfl(p, p.reference_nm)
    max_field = max(max(abs(f) for f in fields_deg), 1.0)
    lens = build_optic(p, D_LINE, image_distance=image, wavelengths_nm=wavelengths_nm,
                       max_field_deg=max_field)
    semi = np.array([s.semi_aperture for s in p.surfaces])
    rows = []
    for field in fields_deg:
        for w in wavelengths_nm:
            r = lens.trace(0.0, field / max_field, w * 1e-3, num_rays=rays,
                           distribution="uniform")
            x = np.asarray(be.to_numpy(r.x), dtype=float)
            y = np.asarray(be.to_numpy(r.y), dtype=float)
            # Heights at every lens surface (index 0 is the object, the last the image).
            sx = np.asarray(be.to_numpy(lens.surfaces.x), dtype=float)[1:-1]
            sy = np.asarray(be.to_numpy(lens.surfaces.y), dtype=float)[1:-1]
            h = np.hypot(sx, sy)
            ok = np.isfinite(x) & np.isfinite(y) & np.all(np.isfinite(h), axis=0)
            if not ok.all():
                raise RuntimeError(f"{p.path.name}: {np.count_nonzero(~ok)} of {x.size} "
                                   f"rays failed at {field} deg, {w} nm (missed a "
                                   f"surface or were totally reflected)")
            vignetted = np.any(h > semi[:, None], axis=0)
            # Rays that pass within RIM_MARGIN_MM of a rim: another program's rounding
            # may put them on the other side.
            borderline = np.any(np.abs(h - semi[:, None]) < RIM_MARGIN_MM, axis=0)
            cx, cy = x.mean(), y.mean()
            d2 = (x - cx) ** 2 + (y - cy) ** 2
            rows.append({
                "field_deg": field, "wavelength_nm": w, "rays": int(x.size),
                "rms_radius_mm": float(np.sqrt(d2.mean())),
                "geo_radius_mm": float(np.sqrt(d2.max())),
                "centroid_x_mm": float(cx), "centroid_y_mm": float(cy),
                "vignetted_fraction": float(vignetted.mean()),
                "borderline_rays": int(np.count_nonzero(borderline)),
            })
    return rows


# ---------------------------------------------------------------------------------------
# Reading heron's CSV files, writing ours


def read_csv(path, columns) -> list[dict]:
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames or ()) == tuple(columns), (
            f"{path}: header {reader.fieldnames}, expected {list(columns)}")
        return [{k: float(v) for k, v in row.items()} for row in reader]


def write_csv(path, columns, rows) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow([repr(float(r[c])) if c != "rays" else int(r[c]) for c in columns])


class Float32Ior(HeronIor):
    """HeronIor evaluated as heron's Ior::eval does, in float32 (λ nm → µm, the
    formula), for `--f32`: how much a renderer's float32 indices alone move the numbers."""

    def _calculate_n(self, wavelength, **kwargs):
        lam = np.asarray(be.to_numpy(wavelength), dtype=np.float64)
        lam_um = (lam * 1e3).astype(np.float32) * np.float32(1e-3)
        l2 = lam_um * lam_um
        c = [np.float32(x) for x in self.coeffs]
        if self.kind == "constant":
            n = c[0] + 0 * l2
        elif self.kind == "cauchy":
            n = c[0] + c[1] / l2 + c[2] / (l2 * l2)
        else:
            k = len(c) // 2
            n2 = np.float32(1.0) + 0 * l2
            for b, cc in zip(c[:k], c[k:]):
                n2 = n2 + b * l2 / (l2 - cc)
            n = np.sqrt(n2)
        return np.asarray(n, dtype=np.float64)


def as_float32(p: Prescription) -> Prescription:
    """p with every medium evaluated in float32 (Float32Ior)."""
    return dataclasses.replace(p, surfaces=tuple(
        dataclasses.replace(s, medium=Float32Ior(s.medium.label, s.medium.kind,
                                                 s.medium.coeffs))
        for s in p.surfaces))


def float32_effect(p: Prescription, fields_deg=DEFAULT_FIELDS,
                   rays: int = DEFAULT_RAYS) -> dict:
    """Largest changes of the outputs when the indices are evaluated in float32."""
    q = as_float32(p)
    pa, pb = paraxial_table(p), paraxial_table(q)
    fa, fb = focal_shift(p), focal_shift(q)
    sa, sb = spots(p, fields_deg, rays=rays), spots(q, fields_deg, rays=rays)
    return {
        "paraxial_relative": max(abs(b[k] / a[k] - 1) for a, b in zip(pa, pb)
                                 for k in PARAXIAL_COLUMNS[1:] if abs(a[k]) > 1e-3),
        "focal_shift_mm": max(abs(a["focal_shift_mm"] - b["focal_shift_mm"])
                              for a, b in zip(fa, fb)),
        "focal_shift_range_mm": (max(r["focal_shift_mm"] for r in fa)
                                 - min(r["focal_shift_mm"] for r in fa)),
        "focal_shift_max_slope_mm_per_nm": max(
            abs(b["focal_shift_mm"] - a["focal_shift_mm"])
            / (b["wavelength_nm"] - a["wavelength_nm"]) for a, b in zip(fa, fa[1:])),
        "rms_relative": max(abs(b["rms_radius_mm"] / a["rms_radius_mm"] - 1)
                            for a, b in zip(sa, sb)),
        "geo_relative": max(abs(b["geo_radius_mm"] / a["geo_radius_mm"] - 1)
                            for a, b in zip(sa, sb)),
        "centroid_over_rms": max(
            math.hypot(a["centroid_x_mm"] - b["centroid_x_mm"],
                       a["centroid_y_mm"] - b["centroid_y_mm"]) / a["rms_radius_mm"]
            for a, b in zip(sa, sb)),
        "vignetted_rays": max(round(abs(a["vignetted_fraction"] - b["vignetted_fraction"])
                                    * a["rays"]) for a, b in zip(sa, sb)),
        "borderline_rays": max(a["borderline_rays"] for a in sa),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("prescription")
    ap.add_argument("--out", help="write paraxial.csv, focal_shift.csv, spots.csv here")
    ap.add_argument("--fields", default="0,14,20")
    ap.add_argument("--rays", type=int, default=DEFAULT_RAYS)
    ap.add_argument("--f32", action="store_true",
                    help="also print how much float32 indices move every number")
    args = ap.parse_args(argv)
    p = load_prescription(args.prescription)
    fields = tuple(float(x) for x in args.fields.split(","))
    par = paraxial_table(p)
    fs = focal_shift(p)
    sp = spots(p, fields, rays=args.rays)
    print(f"{p.name} ({p.path.name}), {len(p.surfaces)} surfaces, stop = surface "
          f"{p.stop.number} (semi-aperture {p.stop.semi_aperture} mm), reference "
          f"{p.reference_nm} nm; Optiland float_by_stop_size")
    print(f"{'λ nm':>9} {'EFL':>11} {'BFL':>11} {'f/#':>8} {'EP z':>10} {'EPD':>10} "
          f"{'XP z':>10} {'XPD':>10}")
    for r in par:
        print(f"{r['wavelength_nm']:9.4f} {r['efl_mm']:11.6f} {r['bfl_mm']:11.6f} "
              f"{r['f_number']:8.4f} {r['entrance_pupil_z_mm']:10.5f} "
              f"{r['entrance_pupil_diameter_mm']:10.6f} {r['exit_pupil_z_mm']:10.5f} "
              f"{r['exit_pupil_diameter_mm']:10.6f}")
    shifts = [r["focal_shift_mm"] for r in fs]
    i_min = int(np.argmin(shifts))
    print(f"focal shift 400-700 nm (mm, BFL(λ) − BFL({p.reference_nm})): "
          f"400 {shifts[0]:+.6f}, 700 {shifts[-1]:+.6f}, minimum {shifts[i_min]:+.6f} at "
          f"{fs[i_min]['wavelength_nm']:.0f} nm")
    print(f"{'field':>6} {'λ nm':>9} {'rays':>5} {'RMS µm':>9} {'geo µm':>9} "
          f"{'cx mm':>10} {'cy mm':>11} {'vign.':>6}")
    for r in sp:
        print(f"{r['field_deg']:6.1f} {r['wavelength_nm']:9.4f} {r['rays']:5d} "
              f"{1e3 * r['rms_radius_mm']:9.3f} {1e3 * r['geo_radius_mm']:9.3f} "
              f"{r['centroid_x_mm']:10.6f} {r['centroid_y_mm']:11.6f} "
              f"{r['vignetted_fraction']:6.3f}")
    if args.f32:
        for k, v in float32_effect(p, fields, args.rays).items():
            print(f"float32 indices: {k} {v:.3g}")
    if args.out:
        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / "paraxial.csv", PARAXIAL_COLUMNS, par)
        write_csv(out / "focal_shift.csv", FOCAL_SHIFT_COLUMNS, fs)
        write_csv(out / "spots.csv", SPOT_COLUMNS, sp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
