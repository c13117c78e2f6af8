"""Writes scenes/meshes/pool-tiles.obj: the floor tiles of scenes/pool.toml, 16 x 16
square tiles of 24 cm with 1 cm gaps (the grout, the dark floor quad beneath), over
x, z in [-2, 2] m at y = 2 mm. Each tile is two triangles wound so that the normal
(v1 - v0) x (v2 - v0) points up (+y).

    python3 scripts/gen_pool_tiles.py
"""
from pathlib import Path

N, SIZE, GAP, Y = 16, 4.0, 0.01, 0.002
pitch = SIZE / N
lines = [
    "# The floor tiles of scenes/pool.toml (scripts/gen_pool_tiles.py writes this file):",
    f"# {N} x {N} tiles of {pitch - GAP:g} m with {GAP:g} m gaps over x, z in [-2, 2] at y = {Y:g}.",
]
faces = []
for j in range(N):
    for i in range(N):
        x0 = -SIZE / 2 + i * pitch + GAP / 2
        z0 = -SIZE / 2 + j * pitch + GAP / 2
        x1, z1 = x0 + pitch - GAP, z0 + pitch - GAP
        base = len(faces) // 2 * 4 + 1
        for x, z in [(x0, z0), (x0, z1), (x1, z1), (x1, z0)]:
            lines.append(f"v {x:.4f} {Y:g} {z:.4f}")
        faces.append(f"f {base} {base + 1} {base + 2}")
        faces.append(f"f {base} {base + 2} {base + 3}")
Path(__file__).resolve().parent.parent.joinpath("scenes/meshes/pool-tiles.obj").write_text(
    "\n".join(lines + faces) + "\n")
