"""Writes scenes/maps/studio-sky.exr: the latitude-longitude environment map of
scenes/mitsuba/envmap.xml and scenes/envmap.toml (128 × 64, linear sRGB, float32).

A sky that is easy to read and hard to fake: a blue zenith fading to a pale horizon, a
brown ground, a small warm sun of peak radiance 20 (so importance sampling matters: it
is 1% of the texels and a third of the light), and a green panel on one side only (so a
map turned the wrong way, or mirrored, shows). Every edge is soft, over a few texels:
where neighbouring texels differ a lot in both colour and brightness, Mitsuba's spectral
envmap (which interpolates the texels' sigmoids and their scales separately) and heron's
(which interpolates the texels' spectra, linear in the radiance as the RGB image is)
part by up to 10% (measured on a hard horizon), which is a choice of each renderer and
not what the comparison is for. The map is +y up in Mitsuba's layout
(src/light/envmap.rs): column u looks along (sin 2πu, ·, −cos 2πu).

    .venv/bin/python scripts/gen_envmap.py
"""
from __future__ import annotations

import pathlib

import numpy as np
import OpenEXR

W, H = 128, 64
OUT = pathlib.Path(__file__).resolve().parent.parent / "scenes" / "maps" / "studio-sky.exr"


def sky() -> np.ndarray:
    j = np.arange(H)[:, None]
    i = np.arange(W)[None, :]
    theta = np.pi * j / (H - 1)            # rows: the poles are the first and last
    phi = 2 * np.pi * (i + 0.5) / W        # columns: texel centres
    d = np.stack(np.broadcast_arrays(np.sin(phi) * np.sin(theta), np.cos(theta),
                                     -np.cos(phi) * np.sin(theta)), -1)
    y = d[..., 1:2]
    up = np.clip(y, 0, 1)
    zenith, horizon = np.array([0.25, 0.45, 0.9]), np.array([0.9, 0.9, 0.85])
    ground = np.array([0.35, 0.27, 0.2])
    sky_part = horizon + (zenith - horizon) * up ** 0.6
    # The horizon blends into the ground over ±12°.
    t = np.clip((y + 0.2) / 0.4, 0, 1)
    t = t * t * (3 - 2 * t)
    img = ground + (sky_part - ground) * t
    # A warm sun 35° up toward +x and +z: a Gaussian of 5° on the sky.
    s = np.array([np.cos(np.radians(35)) * np.sin(np.radians(60)), np.sin(np.radians(35)),
                  np.cos(np.radians(35)) * np.cos(np.radians(60))])
    ang = np.degrees(np.arccos(np.clip(d @ s, -1, 1)))[..., None]
    img = img + np.array([20.0, 17.0, 12.0]) * np.exp(-0.5 * (ang / 5.0) ** 2)
    # A green panel low toward −x, with soft edges.
    w = np.clip((-d[..., 0] - 0.75) / 0.15, 0, 1) * np.clip((0.3 - np.abs(y[..., 0] - 0.1)) / 0.15, 0, 1)
    img = img + w[..., None] * (np.array([0.1, 1.2, 0.2]) - img) * 0.9
    return img.astype(np.float32)


def main() -> None:
    img = sky()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    channels = {c: np.ascontiguousarray(img[..., k]) for k, c in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(str(OUT))
    print(f"wrote {OUT} ({W} x {H}); mean {img.mean((0, 1))}")


if __name__ == "__main__":
    main()
