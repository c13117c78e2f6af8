#!/usr/bin/env python3
"""Paraxial numbers and real-ray footprints of heron lens prescriptions (issue 22).

An independent check of the lens files in this directory, in the Python standard
library only (3.11+ for tomllib), so that heron's Rust numbers have something to be
held against. It reads the prescription TOML (lenses/*.toml) and pbrt-v4 `.dat` files
(with heron's optional fifth column, a glass name), takes glasses from
spectra/ior_catalogue.toml, and prints, at F, d and C (486.1327, 587.5618, 656.2725 nm)
and an object at infinity:

  EFL   = -y1/u_k of a paraxial ray entering parallel to the axis
  BFL   = distance from the last vertex to the paraxial focus
  EPD   = entrance-pupil diameter (the stop imaged into object space)
  f/#   = EFL / EPD
  pupil positions: entrance from the FIRST vertex, exit from the LAST vertex (+ toward
  the image), as in /work/notes/lens-spec.md.

With --fields it also traces real rays (a square grid of --grid points across the
d-line paraxial entrance pupil, the points inside the disc; paraxial ray aiming; not
clipped), as `heron lens` defines its spots.csv, and prints per field and wavelength
the RMS and geometric spot radius about the centroid on the d-line paraxial image
plane and the share of rays a rim or the stop would clip, then per surface the
largest ray height against the semi-aperture (what the semi-apertures were sized with).

    python3 lenses/paraxial.py lenses/cooke-triplet.toml --fields 0,14,20
"""
import argparse
import math
import pathlib
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent
LINES = {"F": 486.1327, "d": 587.5618, "C": 656.2725}


def catalogue():
    return tomllib.loads((ROOT / "spectra" / "ior_catalogue.toml").read_text())


def sellmeier(b, c):
    def n(lam_nm):
        l2 = (lam_nm * 1e-3) ** 2
        return math.sqrt(1 + sum(bi * l2 / (l2 - ci) for bi, ci in zip(b, c)))

    return n


def medium(m, cat):
    """n(λ nm) for a prescription medium, as lens-spec.md defines them."""
    if m is None or m == "air":
        return lambda lam: 1.0
    if isinstance(m, (int, float)):
        return lambda lam: float(m)
    if isinstance(m, str):
        if m not in cat:
            raise SystemExit(f"unknown glass {m!r}")
        s = cat[m]["sellmeier"]
        return sellmeier(s["b"], s["c"])
    if "sellmeier" in m:
        return sellmeier(m["sellmeier"]["b"], m["sellmeier"]["c"])
    if "cauchy" in m:
        k = list(m["cauchy"]) + [0.0]
        return lambda lam: k[0] + k[1] / (lam * 1e-3) ** 2 + k[2] / (lam * 1e-3) ** 4
    if "n_d" in m:
        # two-term Cauchy through n_d with n_F - n_C = (n_d - 1)/V_d
        nd, vd = m["n_d"], m["v_d"]
        B = (nd - 1) / vd / ((LINES["F"] * 1e-3) ** -2 - (LINES["C"] * 1e-3) ** -2)
        A = nd - B / (LINES["d"] * 1e-3) ** 2
        return lambda lam: A + B / (lam * 1e-3) ** 2
    raise SystemExit(f"cannot read medium {m!r}")


def load(path):
    """[(radius, thickness, n_after(λ), semi_aperture, is_stop, label)], name."""
    path = pathlib.Path(path)
    cat = catalogue()
    surfs = []
    if path.suffix == ".toml":
        d = tomllib.loads(path.read_text())
        for s in d["surface"]:
            surfs.append(
                (
                    float(s["radius"]),
                    float(s["thickness"]),
                    medium(s.get("medium"), cat),
                    float(s["semi_aperture"]),
                    bool(s.get("stop", False)),
                    str(s.get("medium", "air")),
                )
            )
        return surfs, d["name"]
    for line in path.read_text().splitlines():
        line = line.split("#")[0].split()
        if not line:
            continue
        r, t, ior, diam = map(float, line[:4])
        glass = line[4] if len(line) > 4 else None
        if glass:
            n, label = medium(glass, cat), glass
        elif ior in (0.0, 1.0):
            n, label = medium("air", cat), "air"
        else:
            n, label = medium(ior, cat), str(ior)
        surfs.append((r, t, n, diam / 2, ior == 0, label))
    return surfs, path.name


def paraxial(surfs, lam):
    """Paraxial EFL, BFL, entrance/exit pupil at lam (object at infinity)."""
    curv = [0.0 if s[0] == 0 else 1 / s[0] for s in surfs]
    n_after = [s[2](lam) for s in surfs]
    n_before = [1.0] + n_after[:-1]
    k = len(surfs)

    def trace(y, u, first, last):
        """(y, u) at surface `first` (u before refraction there) to after `last`:
        returns the heights at each surface and the final (y, u) after refraction at
        `last`."""
        heights = []
        nu = n_before[first] * u
        for i in range(first, last + 1):
            if i > first:
                y = y + surfs[i - 1][1] * nu / n_after[i - 1]
            heights.append(y)
            nu = nu - y * curv[i] * (n_after[i] - n_before[i])
        return heights, y, nu / n_after[last]

    _, yk, uk = trace(1.0, 0.0, 0, k - 1)
    efl = -1.0 / uk
    bfl = -yk / uk
    stop = next(i for i, s in enumerate(surfs) if s[4])
    a = surfs[stop][3]
    # entrance pupil: heights at the stop of unit rays in object space
    A = trace(1.0, 0.0, 0, stop)[0][-1]
    B = trace(0.0, 1.0, 0, stop)[0][-1]
    ep_z, epd = B / A, 2 * a / abs(A)
    # exit pupil: the stop imaged by the surfaces from the stop on
    _, y0, u0 = trace(0.0, 1.0, stop, k - 1)
    _, y1, u1 = trace(1.0, 0.0, stop, k - 1)
    if stop == k - 1 and curv[stop] == 0:
        xp_z, xpd = 0.0, 2 * a
    else:
        xp_z = -y0 / u0
        xpd = 2 * a * abs(y1 + u1 * xp_z)
    return dict(efl=efl, bfl=bfl, epd=epd, fno=efl / epd, ep_z=ep_z, xp_z=xp_z, xpd=xpd)


def real_rays(surfs, lam, theta_deg, ep_z, epd, grid):
    """Real rays of one field and wavelength through the d-line entrance pupil (a
    grid x grid square grid across its diameter, the points inside the disc): per ray,
    the (x, y, z) on each surface and then (x, y, z, dx, dy, dz) leaving the last one,
    or None for a ray that misses a sphere or is totally reflected."""
    th = math.radians(theta_deg)
    d0 = (0.0, math.sin(th), math.cos(th))
    vz, z = [], 0.0
    for s in surfs:
        vz.append(z)
        z += s[1]
    n_after = [s[2](lam) for s in surfs]
    n_before = [1.0] + n_after[:-1]
    rays = []
    pts = [-1 + 2 * i / (grid - 1) for i in range(grid)]
    for u in pts:
        for v in pts:
            if u * u + v * v > 1:
                continue
            px, py = u * epd / 2, v * epd / 2
            back = ep_z + 200.0
            p = [px - back * d0[0], py - back * d0[1], ep_z - back * d0[2]]
            d = list(d0)
            hits = []
            for k, s in enumerate(surfs):
                c = 0.0 if s[0] == 0 else 1 / s[0]
                q = [p[0], p[1], p[2] - vz[k]]
                b = c * (q[0] * d[0] + q[1] * d[1] + q[2] * d[2]) - d[2]
                cc = c * (q[0] ** 2 + q[1] ** 2 + q[2] ** 2) - 2 * q[2]
                disc = b * b - c * cc
                if disc < 0:
                    hits = None
                    break
                t = -cc / (b - math.sqrt(disc))
                q = [q[m] + t * d[m] for m in range(3)]
                p = [q[0], q[1], q[2] + vz[k]]
                hits.append(tuple(p))
                nrm = [c * q[0], c * q[1], c * q[2] - 1]
                ln = math.sqrt(sum(v * v for v in nrm))
                nrm = [v / ln for v in nrm]
                cosi = -sum(nrm[m] * d[m] for m in range(3))
                if cosi < 0:
                    nrm, cosi = [-v for v in nrm], -cosi
                eta = n_before[k] / n_after[k]
                kk = 1 - eta * eta * (1 - cosi * cosi)
                if kk < 0:
                    hits = None
                    break
                d = [eta * d[m] + (eta * cosi - math.sqrt(kk)) * nrm[m] for m in range(3)]
            if hits is not None:
                hits.append(tuple(p) + tuple(d))
            rays.append(hits)
    return rays


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("prescription")
    ap.add_argument("--fields", default="", help="field angles in degrees, e.g. 0,14,20")
    ap.add_argument("--grid", type=int, default=32, help="rays across the pupil")
    args = ap.parse_args()
    surfs, name = load(args.prescription)
    print(f"{name}: {len(surfs)} surfaces, total track {sum(s[1] for s in surfs[:-1]):.4f} mm")
    print("line  lambda_nm      EFL       BFL      EPD     f/#    EP_z   XP_z    XPD")
    par = {}
    for line, lam in LINES.items():
        p = par[line] = paraxial(surfs, lam)
        print(
            f"{line:4s} {lam:9.4f} {p['efl']:9.4f} {p['bfl']:9.4f} {p['epd']:8.4f}"
            f" {p['fno']:6.3f} {p['ep_z']:7.3f} {p['xp_z']:7.3f} {p['xpd']:6.3f}"
        )
    print(
        f"longitudinal colour BFL(F) - BFL(C) = {par['F']['bfl'] - par['C']['bfl']:+.4f} mm;"
        f" image plane of the last thickness: {surfs[-1][1]:.4f} mm"
        f" (d-line paraxial focus at {par['d']['bfl']:.4f})"
    )
    if not args.fields:
        return
    ep = par["d"]
    fields = [float(f) for f in args.fields.split(",")]
    maxh = [0.0] * len(surfs)
    print(
        "field  line  rays  rms_radius_mm  geo_radius_mm  centroid_y_mm  vignetted"
        "  (surfaces that clip: rays)"
    )
    # image plane: the d-line paraxial focus (not the last thickness), as heron lens does
    z_img = sum(s[1] for s in surfs[:-1]) + ep["bfl"]
    for f in fields:
        for line, lam in LINES.items():
            rays = real_rays(surfs, lam, f, ep["ep_z"], ep["epd"], args.grid)
            lost, clip, spot = 0, {}, []
            for r in rays:
                if r is None:
                    lost += 1
                    continue
                bad = False
                for k, (x, y, _) in enumerate(r[:-1]):
                    h = math.hypot(x, y)
                    maxh[k] = max(maxh[k], h)
                    if h > surfs[k][3] + 1e-9:
                        clip[k + 1] = clip.get(k + 1, 0) + 1
                        bad = True
                lost += bad
                spot.append(r[-1])
            pts = []
            for x, y, z, dx, dy, dz in spot:
                t = (z_img - z) / dz
                pts.append((x + t * dx, y + t * dy))
            cx = sum(p[0] for p in pts) / len(pts)
            cy = sum(p[1] for p in pts) / len(pts)
            d2 = [(p[0] - cx) ** 2 + (p[1] - cy) ** 2 for p in pts]
            rms, geo = math.sqrt(sum(d2) / len(d2)), math.sqrt(max(d2))
            print(
                f"{f:5.1f}  {line:4s} {len(rays):5d}  {rms:13.6f}  {geo:13.6f}  {cy:13.6f}"
                f"  {lost / len(rays):9.4f}  {clip}"
            )
    print("surface  radius  thickness  medium  semi_aperture  max_ray_height  edge_thickness")
    for k, s in enumerate(surfs):
        edge = ""
        if k + 1 < len(surfs):
            # axial distance to the next surface at the smaller of the two semi-apertures
            h = min(s[3], surfs[k + 1][3])

            def sag(r, h):
                if r == 0:
                    return 0.0
                return r - math.copysign(math.sqrt(max(r * r - h * h, 0.0)), r)

            edge = f"{s[1] - sag(s[0], h) + sag(surfs[k + 1][0], h):8.3f} (at h={h:.2f})"
        print(
            f"{k + 1:4d}{'*' if s[4] else ' '} {s[0]:10.4f} {s[1]:9.4f}  {s[5]:>8s}"
            f" {s[3]:9.3f} {maxh[k]:12.3f}   {edge}"
        )


if __name__ == "__main__":
    main()
