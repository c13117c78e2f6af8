"""heron scenes as Mitsuba 3 scene dictionaries, for the side-by-side tests and the
benchmark (tests/python/test_mitsuba.py, scripts/bench_mitsuba.py).

Geometry, camera and render settings are read from the heron TOML file; every spectrum
(reflectances and emissions after heron's RGB uplift, metals' n and k) comes from
`heron spectra SCENE` on heron's 1 nm grid and is given to Mitsuba as a `regular`
spectrum, so that the comparison does not also compare the two renderers' RGB uplifts.

What maps onto what:

| heron | Mitsuba 3 |
| --- | --- |
| camera (eye, look_at, up, d) | `perspective`, fov_axis y, fov = 2 atan(1/(2d)) |
| box pixel filter | `hdrfilm` with a `box` rfilter (radius 0.5: the pixel) |
| `quad` | `rectangle` with to_world columns edge1/2, edge2/2, normal |
| `plane`, `triangle` | `ply` of heron's own triangles (a plane is heron's 2000 × 2000 quad), face normals |
| `sphere` | `sphere` |
| `lambertian` (two-sided) | `twosided` `diffuse` |
| `conductor` (smooth, rough) | `conductor`, `roughconductor` (ggx, visible normals) |
| `dielectric` with a constant index | `dielectric` / `roughdielectric` |
| `emission` on a shape (one-sided) | `area` emitter |
| `background` | `constant` emitter |
| `point` light | `point` emitter with heron's intensity spectrum |
| `max_depth` (scattering events) | `path` max_depth = heron's + 1 (Mitsuba counts vertices) |
| ideal `polarizer` on a `quad` | `polarizer`: theta from heron's axis (below), transmittance t_x |

Anything else (OBJ meshes, dispersive glass, directional, spot and sun lights, a
polariser on a sphere or a mesh, a partial polariser, retarders…) raises ValueError: the
comparison covers what both renderers model the same way.

The polariser's axis. heron's transmission axis is the scene vector `axis` projected onto
the sheet and turned by `angle` about the outward normal n = edge1 × edge2,
counter-clockwise seen from the side n points to. Mitsuba's `polarizer` absorbs along
(sin θ, cos θ, 0) of the rectangle's shading frame (s = edge1 normalised, t = n × s,
Mitsuba's mesh frame from its texture coordinates), so it transmits along
(cos θ, −sin θ, 0): θ = −atan2(a·t, a·s) for heron's in-plane axis a (θ = −angle when
`axis` is along edge1). Both models are the ideal diattenuator at normal incidence; for an
oblique ray heron projects the transmission axis perpendicular to the ray while Mitsuba
(Korger et al. 2013) projects the absorption axis and transmits across it, which differ at
second order in the angle of incidence (test_mitsuba_polarized.py measures it).
"""
from __future__ import annotations

import json
import math
import pathlib
import subprocess
import tomllib

LAMBDA_MIN, LAMBDA_MAX = 360.0, 830.0


def regular(values) -> dict:
    return {
        "type": "regular",
        "wavelength_min": LAMBDA_MIN,
        "wavelength_max": LAMBDA_MAX,
        "values": ",".join(f"{v:.9g}" for v in values),
    }


def heron_spectra(heron_bin: pathlib.Path, scene: pathlib.Path) -> dict:
    out = subprocess.run([str(heron_bin), "spectra", str(scene)], capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout)


def _constant(values, what: str) -> float:
    if max(values) - min(values) > 1e-6 * max(1.0, abs(max(values))):
        raise ValueError(f"{what}: Mitsuba's dielectric has no dispersion")
    return float(values[0])


def _bsdf(m: dict, name: str) -> dict:
    t = m["type"]
    if t == "lambertian":
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": regular(m["rho_d"])}}
    if t == "conductor":
        d = {"eta": regular(m["n"]), "k": regular(m["k"])}
        if m["alpha"] == 0.0:
            return {"type": "conductor", **d}
        return {"type": "roughconductor", "distribution": "ggx", "alpha": m["alpha"],
                "sample_visible": True, **d}
    if t == "dielectric":
        d = {"int_ior": _constant(m["ior"], name), "ext_ior": _constant(m["outside_ior"], name)}
        if not m["fresnel"]:
            raise ValueError(f"{name}: Mitsuba has no Fresnel-free dielectric")
        if m["alpha"] == 0.0:
            return {"type": "dielectric", **d}
        return {"type": "roughdielectric", "distribution": "ggx", "alpha": m["alpha"],
                "sample_visible": True, **d}
    raise ValueError(f"{name}: no Mitsuba counterpart for heron's {t}")


def _polarizer(m: dict, name: str, shape: dict, i: int) -> dict:
    """Mitsuba's `polarizer` for heron's polariser material `m` on quad `shape`."""
    if shape["type"] != "quad":
        raise ValueError(f"shapes[{i}]: the polarizer {name} on a {shape['type']} is not "
                         "converted (only quads)")
    if m["t_y"] != 0.0:
        raise ValueError(f"{name}: Mitsuba's polarizer is ideal (no extinction_ratio)")
    e1, e2 = (list(map(float, shape[k])) for k in ("edge1", "edge2"))
    n = _unit(_cross(e1, e2))
    s = _unit([e1[j] - _dot(e1, n) * n[j] for j in range(3)])
    t = _cross(n, s)
    axis = list(map(float, m["axis"]))
    a = [axis[j] - _dot(axis, n) * n[j] for j in range(3)]
    if _dot(a, a) < 1e-12:
        raise ValueError(f"{name}: axis along the normal of shapes[{i}] is not converted")
    a = _unit(a)
    # turned by `angle` (radians in `heron spectra`) about n, counter-clockwise seen from n
    c, sn = math.cos(m["angle"]), math.sin(m["angle"])
    na = _cross(n, a)
    a = [c * a[j] + sn * na[j] for j in range(3)]
    theta = -math.degrees(math.atan2(_dot(a, t), _dot(a, s)))
    return {"type": "polarizer", "theta": theta, "transmittance": float(m["t_x"])}


def _dot(a, b) -> float:
    return sum(x * y for x, y in zip(a, b))


def _cross(a, b) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _unit(a) -> list:
    ln = math.sqrt(_dot(a, a))
    return [x / ln for x in a]


def _look_at(mi, eye, target, up):
    return mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up)


def _rectangle(mi, origin, e1, e2):
    o, a, b = (list(map(float, v)) for v in (origin, e1, e2))
    n = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    ln = math.sqrt(sum(x * x for x in n))
    n = [x / ln for x in n]
    c = [o[i] + 0.5 * a[i] + 0.5 * b[i] for i in range(3)]
    m = [[0.5 * a[i], 0.5 * b[i], n[i], c[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]
    return mi.ScalarTransform4f(m)


def _write_ply(path: pathlib.Path, mesh: dict) -> None:
    """A binary PLY of heron's triangles (positions as heron loaded them)."""
    import struct

    pos, idx = mesh["positions"], mesh["indices"]
    head = ("ply\nformat binary_little_endian 1.0\n"
            f"element vertex {len(pos)}\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {len(idx)}\nproperty list uchar int vertex_indices\nend_header\n")
    body = b"".join(struct.pack("<3f", *p) for p in pos)
    body += b"".join(struct.pack("<B3i", 3, *t) for t in idx)
    path.write_bytes(head.encode() + body)


def mitsuba_dict(mi, scene_path: pathlib.Path, spectra: dict, *, width=None, height=None,
                 spp: int = 16, max_depth=None, integrator=None, mesh_dir=None,
                 sampler: str = "independent") -> dict:
    """The Mitsuba scene dictionary of heron scene `scene_path` (variant already set).

    `integrator` replaces the default `path` integrator's dictionary; `mesh_dir` is where
    PLY files of planes and triangles are written (needed only when there are some);
    `sampler` names Mitsuba's sampler plugin (independent, stratified, multijitter,
    orthogonal, ldsampler)."""
    doc = tomllib.loads(scene_path.read_text())
    cam = doc["camera"]
    w, h = cam["resolution"]
    w, h = width or w, height or h
    d = float(cam.get("d", 1.0))
    render = doc.get("render", {})
    depth = max_depth if max_depth is not None else int(render.get("max_depth", 10))
    lights = doc.get("lights", [])
    if any(lt.get("type") != "point" for lt in lights):
        raise ValueError("directional, spot and sun lights are not converted")
    scene = {
        "type": "scene",
        "integrator": integrator or {"type": "path", "max_depth": depth + 1},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": math.degrees(2.0 * math.atan(1.0 / (2.0 * d))),
            "to_world": _look_at(mi, cam["eye"], cam["look_at"], cam.get("up", [0.0, 1.0, 0.0])),
            "sampler": {"type": sampler, "sample_count": spp},
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"},
                     "pixel_format": "xyz", "component_format": "float32"},
        },
    }
    for name, m in spectra["materials"].items():
        if name.startswith("("):
            scene["bsdf-black"] = {"type": "diffuse", "reflectance": 0.0}
            continue
        if m["type"] == "polarizer":
            continue  # one per shape: its theta depends on the shape's frame
        scene[f"bsdf-{name}"] = _bsdf(m, name)
    for i, (s, sp) in enumerate(zip(doc.get("shapes", []), spectra["shapes"])):
        t = s["type"]
        if t == "quad":
            shape = {"type": "rectangle", "to_world": _rectangle(mi, s["origin"], s["edge1"], s["edge2"])}
        elif t == "sphere":
            shape = {"type": "sphere", "center": list(map(float, s["center"])),
                     "radius": float(s["radius"])}
        elif t in ("plane", "triangle") and sp.get("mesh"):
            if mesh_dir is None:
                raise ValueError(f"shapes[{i}]: {t} needs mesh_dir for its PLY file")
            ply = pathlib.Path(mesh_dir) / f"shape-{i}.ply"
            _write_ply(ply, sp["mesh"])
            shape = {"type": "ply", "filename": str(ply), "face_normals": True}
        else:
            raise ValueError(f"shapes[{i}]: {t} is not converted")
        mat = sp["material"]
        if spectra["materials"].get(mat, {}).get("type") == "polarizer":
            shape["bsdf"] = _polarizer(spectra["materials"][mat], mat, s, i)
        else:
            shape["bsdf"] = {"type": "ref",
                             "id": "bsdf-black" if mat.startswith("(") else f"bsdf-{mat}"}
        if sp["emission"] is not None:
            if sp["two_sided"]:
                raise ValueError(f"shapes[{i}]: Mitsuba's area emitter is one-sided")
            shape["emitter"] = {"type": "area", "radiance": regular(sp["emission"])}
        scene[f"shape-{i}"] = shape
    for i, pl in enumerate(spectra.get("point_lights", [])):
        scene[f"point-{i}"] = {"type": "point", "position": list(map(float, pl["position"])),
                               "intensity": regular(pl["intensity"])}
    if max(spectra["background"]) > 0.0:
        scene["environment"] = {"type": "constant", "radiance": regular(spectra["background"])}
    return scene


def xyz_normalisation(mi, colour) -> float:
    """Factor that turns Mitsuba's XYZ into heron's: Mitsuba divides by a fixed
    ∫ȳ = 1/MI_CIE_Y_NORMALIZATION (106.7502594), heron by the sum of its 1 nm CIE 1931
    table over 360–830 nm (106.857, colour-science's), so Mitsuba's values are 0.1%
    higher for the same spectrum."""
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(
        colour.SpectralShape(360, 830, 1))
    y_integral = float(cmfs.values[:, 1].sum())
    return 1.0 / (float(mi.MI_CIE_Y_NORMALIZATION) * y_integral)
