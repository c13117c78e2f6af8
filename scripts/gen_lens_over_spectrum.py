"""Writes scenes/lens-over-spectrum.toml and scenes/meshes/magnifier.obj: Newton's
prism and screen (scenes/newton-prism.toml's room, prism, slit and sun), and a
biconvex N-BK7 magnifying lens between the screen and a camera that looks at the
spectrum through it from above the beam.

The lens: diameter 120 mm, both faces of radius 310 mm (a thin-lens focal length of
300 mm at n = 1.5168), 2 mm thick at the rim; its axis on the camera's line of sight to
the screen's centre, its centre 200 mm before the screen, so the screen is inside its
focal length and seen magnified about three times (f / (f − 0.2 m)). The faces are
triangulated in RINGS rings of SECTORS sectors (flat triangles: heron has no shading
normals), the rim in SECTORS quads; every normal points out of the glass.

    python3 scripts/gen_lens_over_spectrum.py
"""
import math
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RINGS, SECTORS = 48, 144
A, R, EDGE = 0.06, 0.31, 0.002

def sub(a, b): return [x - y for x, y in zip(a, b)]
def add(a, b): return [x + y for x, y in zip(a, b)]
def mul(a, k): return [x * k for x in a]
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def norm(a): return mul(a, 1 / math.sqrt(dot(a, a)))
def cross(a, b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]

# From scenes/newton-prism.toml: the beam after the prism and the screen.
beam = [math.cos(math.radians(33.17)), -math.sin(math.radians(33.17)), 0.0]
screen_origin = [1.442715, -1.445269, -0.120000]
screen_e1, screen_e2 = [0.0, 0.0, 0.24], [0.492570, 0.753300, 0.0]
centre = add(screen_origin, add(mul(screen_e1, 0.5), mul(screen_e2, 0.5)))
# The camera: 0.5 m back along the beam and 0.28 m up, looking at the screen's centre.
eye = add(sub(centre, mul(beam, 0.5)), [0.0, 0.0, 0.28])
axis = norm(sub(centre, eye))                     # from the camera toward the screen
lens_centre = add(centre, mul(axis, -0.2 / dot(axis, beam)))  # 0.2 m before the screen, along the beam

sag = R - math.sqrt(R * R - A * A)
half = EDGE / 2 + sag                              # centre half-thickness
u = norm(cross(axis, [0.0, 0.0, 1.0]))
v = cross(u, axis)

verts, faces = [], []
def vert(p):
    verts.append(p)
    return len(verts)

def face_side(s):
    """s = +1: the face toward the screen (+axis), -1: toward the camera."""
    apex = vert(add(lens_centre, mul(axis, s * half)))
    rings = []
    for i in range(1, RINGS + 1):
        rho = A * math.sqrt(i / RINGS)             # equal-area rings
        z = half - (R - math.sqrt(R * R - rho * rho))
        ring = []
        for k in range(SECTORS):
            phi = 2 * math.pi * k / SECTORS
            p = add(lens_centre, add(mul(axis, s * z),
                    add(mul(u, rho * math.cos(phi)), mul(v, rho * math.sin(phi)))))
            ring.append(vert(p))
        rings.append(ring)
    # (u, v, axis) is left-handed (u × v = −axis), so the rings run clockwise seen from +axis.
    tri = (lambda a, b, c: faces.append((a, c, b))) if s > 0 else (lambda a, b, c: faces.append((a, b, c)))
    for k in range(SECTORS):
        tri(apex, rings[0][k], rings[0][(k + 1) % SECTORS])
    for i in range(RINGS - 1):
        for k in range(SECTORS):
            a, b = rings[i][k], rings[i][(k + 1) % SECTORS]
            c, d = rings[i + 1][k], rings[i + 1][(k + 1) % SECTORS]
            tri(a, c, d)
            tri(a, d, b)
    return rings[-1]

front, back = face_side(1), face_side(-1)
for k in range(SECTORS):
    a, b = front[k], front[(k + 1) % SECTORS]
    c, d = back[k], back[(k + 1) % SECTORS]
    faces.append((a, d, c))
    faces.append((a, b, d))

# Check the winding: every normal points away from the lens's centre.
for f in faces:
    p = [verts[i - 1] for i in f]
    n = cross(sub(p[1], p[0]), sub(p[2], p[0]))
    mid = mul(add(p[0], add(p[1], p[2])), 1 / 3)
    assert dot(n, sub(mid, lens_centre)) > 0, f

lines = ["# A biconvex magnifier for scenes/lens-over-spectrum.toml (scripts/gen_lens_over_spectrum.py",
         f"# writes it): diameter {2 * A * 1000:g} mm, faces of radius {R * 1000:g} mm, {EDGE * 1000:g} mm rim, in world coordinates."]
lines += [f"v {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}" for p in verts]
lines += [f"f {a} {b} {c}" for a, b, c in faces]
(ROOT / "scenes/meshes/magnifier.obj").write_text("\n".join(lines) + "\n")

prism = (ROOT / "scenes/newton-prism.toml").read_text()
body = prism[prism.index("[materials.screen]"):]
fmt = lambda p: "[" + ", ".join(f"{x:.6f}" for x in p) + "]"
(ROOT / "scenes/lens-over-spectrum.toml").write_text(f"""# Newton's spectrum seen through a magnifying lens: scenes/newton-prism.toml's dark room,
# slit, N-SF11 prism and screen, and a biconvex N-BK7 magnifier (f ≈ 300 mm, 120 mm
# across, scenes/meshes/magnifier.obj) 200 mm before the screen, through which the camera
# looks at the spectrum from above the beam. Every path of the magnified spectrum is
# specular–diffuse–specular (eye, lens, screen, prism, slit, sun): no camera path, light
# path or connection reaches it, and photon mapping does. The lens's own dispersion
# moves each colour's magnified image a little, as the prism's moves it on the screen;
# tests/sppm.rs holds both to heron trace's rays.
#
# Written by scripts/gen_lens_over_spectrum.py.
#
#   heron render scenes/lens-over-spectrum.toml -o lens-over-spectrum.exr

[camera]
eye = {fmt(eye)}
look_at = {fmt(centre)}
up = [0.0, 0.0, 1.0]
d = 1.6
resolution = [512, 384]

[render]
integrator = "sppm"
spp = 64
max_depth = 10

[materials.lens]
type = "dielectric"
ior = "N-BK7"

[[shapes]]
type = "mesh"
file = "meshes/magnifier.obj"
material = "lens"

""" + body)
print("eye", eye, "lens centre", lens_centre, "axis", axis)
