"""Writes scenes/textures/tiles.png: the 8-bit sRGB texture of
scenes/mitsuba/textures.xml (64 × 32): soft-edged tiles in six colours with a letter-like
mark in one corner, so that a texture turned, mirrored or shifted by a texel shows.

The tiles' edges are blurred over a few texels, as scripts/gen_envmap.py explains for
envmaps: both renderers interpolate the texels' spectra, but 8-bit steps between
saturated colours make the comparison depend on texel-exact alignment, which the test
checks separately (tests/texture.rs).

    .venv/bin/python scripts/gen_textures.py
"""
from __future__ import annotations

import pathlib

import numpy as np
from PIL import Image

W, H = 64, 32
OUT = pathlib.Path(__file__).resolve().parent.parent / "scenes" / "textures" / "tiles.png"
COLOURS = np.array([[0.75, 0.25, 0.15], [0.2, 0.6, 0.25], [0.15, 0.3, 0.7],
                    [0.7, 0.65, 0.2], [0.55, 0.2, 0.6], [0.6, 0.6, 0.6]])


def srgb_encode(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def tiles() -> np.ndarray:
    j, i = np.mgrid[0:H, 0:W].astype(float)
    u, v = (i + 0.5) / W, (j + 0.5) / H
    # 4 × 2 tiles, colour index by tile, blended smoothly across tile borders.
    tu, tv = u * 4, v * 2
    k = (np.floor(tu) + 4 * np.floor(tv)).astype(int) % len(COLOURS)
    img = COLOURS[k]
    fu, fv = tu - np.floor(tu), tv - np.floor(tv)
    edge = np.clip(np.minimum(np.minimum(fu, 1 - fu) * 6, np.minimum(fv, 1 - fv) * 3), 0, 1)
    img = 0.35 + (img - 0.35) * edge[..., None]
    # A dark "L" in the top-left tile: which way is up, and which way is left.
    mark = ((i >= 3) & (i < 5) & (j >= 3) & (j < 12)) | ((i >= 3) & (i < 10) & (j >= 10) & (j < 12))
    img[mark] = 0.05
    return img


def main() -> None:
    img = (np.round(srgb_encode(tiles()) * 255)).astype(np.uint8)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(img, "RGB").save(OUT)
    print(f"wrote {OUT} ({W} x {H})")


if __name__ == "__main__":
    main()
