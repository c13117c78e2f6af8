"""Render with the heron CLI and check the EXR (and PNG preview) against colour-science.

CLI contract: `heron render SCENE.toml -o OUT.exr [--spp N] [--seed S] [--threads N]`
writes OUT.exr (float32 R, G, B: linear sRGB, D65; standard `chromaticities` attribute)
and an sRGB-encoded preview OUT.png. The binary is HERON_BIN, default
<repo>/target/release/heron; without it every render test FAILS (never skips).

Statistics. heron samples random wavelengths per camera sample, so each pixel is a noisy
estimate; over a region of uniform radiance the pixels are independent estimates of the
same value. A check compares the image mean with colour-science's prediction within
N_SIGMA standard errors (SE = pixel standard deviation / √pixels) plus a small absolute
floor for what the statistics do not cover (float32, table interpolation). To give the
check power, it also requires SE ≤ POWER_FACTOR · σ_u/√(pixels · spp), where σ_u is the
per-sample standard deviation of the crudest spectral estimator (one uniformly drawn
wavelength per sample, heronref.uniform_sampling_sigma); any sensible sampler is below
it, and a renderer that ignores --spp is far above it.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

import heronref
from heronrun import require_heron_bin

N_SIGMA = 3.0
POWER_FACTOR = 2.0
SPP_BACKGROUND = 4096  # 64×48 px → 12.6 M samples: SE bound ≈ 2 × 3.5/3546 ≈ 2e-3
SPP_QUAD = 2048  # 64×64 px → 8.4 M samples: SE bound ≈ 2 × 3.3/2896 ≈ 2.3e-3
SEED = 1
# linear sRGB of D65 at film Y = 1 (heron's RGB white emitter), colour-science 0.4.7
RGB_WHITE_D65 = np.array([1.0000057, 1.0000753, 0.9998329])


# ---------------------------------------------------------------------------- helpers


def read_exr(path):
    """(header dict, {name: float32 HxW array}, {name: OpenEXR pixel type})."""
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        header = dict(f.header())
        channels = f.channels()
        pixels = {name: np.array(c.pixels) for name, c in channels.items()}
        types = {name: c.type() for name, c in channels.items()}
    return header, pixels, types


def read_rgb(path) -> np.ndarray:
    """H×W×3 float64 array of the EXR's R, G, B channels (after checking they are float32)."""
    import OpenEXR

    _, pixels, types = read_exr(path)
    missing = [c for c in "RGB" if c not in pixels]
    assert not missing, f"{path}: channels {missing} missing; has {sorted(pixels)}"
    for c in "RGB":
        assert types[c] == OpenEXR.FLOAT, f"{path}: channel {c} is {types[c]}, expected FLOAT (float32)"
        assert pixels[c].dtype == np.float32
    rgb = np.stack([pixels[c] for c in "RGB"], axis=-1).astype(np.float64)
    bad = ~np.isfinite(rgb)
    assert not bad.any(), f"{path}: {bad.sum()} non-finite values"
    return rgb


def check_mean(what, rgb, expected, expected_sd, spp, floor):
    """Image mean vs expected within N_SIGMA·SE + floor, and SE small enough to matter."""
    px = rgb.reshape(-1, 3)
    n = len(px)
    mean = px.mean(axis=0)
    se = px.std(axis=0, ddof=1) / math.sqrt(n)
    bound = POWER_FACTOR * heronref.uniform_sampling_sigma(expected_sd) / math.sqrt(n * spp)
    tol = N_SIGMA * se + floor
    table = "\n".join(
        f"  {c}: expected {e:.6f}  got {m:.6f}  diff {m - e:+.6f}  "
        f"allowed ±{t:.6f} (= {N_SIGMA:g}·SE {se_:.2e} + {floor:g})  SE bound {b:.2e}"
        for c, e, m, t, se_, b in zip("RGB", expected, mean, tol, se, bound))
    assert (se <= bound).all(), (
        f"{what}: the standard error is too large for the check to mean anything "
        f"(spp {spp}, {n} pixels; is heron honouring --spp?)\n{table}")
    assert (np.abs(mean - expected) <= tol).all(), (
        f"{what}: image mean disagrees with colour-science\n{table}")


# ----------------------------------------------- the references themselves (no binary)


def test_reference_equal_energy():
    # Film XYZ of E is (1, 1, 1) up to the CMF table's integrals (Σx̄/Σȳ, Σz̄/Σȳ).
    xyz = heronref.film_xyz(heronref.spectrum_e())
    np.testing.assert_allclose(xyz, [1.0000800, 1.0, 1.0003307], atol=5e-8)
    np.testing.assert_allclose(xyz, [1, 1, 1], atol=5e-4)
    rgb = heronref.expected_srgb(heronref.spectrum_e())
    np.testing.assert_allclose(rgb, [1.2048945, 0.9483362, 0.9090540], atol=5e-7)
    # ... which is what the IEC matrix gives for XYZ (1, 1, 1), to 4e-4.
    m = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])
    np.testing.assert_allclose(rgb, m @ [1, 1, 1], atol=4e-4)


def test_reference_rgb_white_emitter_is_d65():
    # Jakob & Hanika: RGB (1, 1, 1) as an emitter is exactly D65 at Y = 1, which maps to
    # white only to 2e-4 (xy 0.31273, 0.32902 vs the sRGB white 0.3127, 0.3290).
    rgb = heronref.expected_srgb(heronref.grey_emitter(1.0))
    np.testing.assert_allclose(rgb, RGB_WHITE_D65, atol=5e-7)
    assert np.abs(rgb - 1).max() < 2e-4
    assert np.abs(rgb - 1).max() > 1e-4  # not exactly white: the reference matters
    np.testing.assert_array_equal(heronref.grey_emitter(0.5).values,
                                  0.5 * heronref.d65_unit().values)


# ------------------------------------------------------------------------- the binary


def test_heron_binary_exists():
    require_heron_bin()


# -------------------------------------------------------------- (i) equal energy E


def test_equal_energy_background_matches_colour_science(render):
    r = render("background_e.toml", spp=SPP_BACKGROUND, seed=SEED)
    sd = heronref.spectrum_e()
    check_mean("background { spectrum = \"E\" }", read_rgb(r.exr),
               heronref.expected_srgb(sd), sd, SPP_BACKGROUND, floor=5e-4)


# ------------------------------------------------------------- (ii) RGB white [1,1,1]


def test_rgb_white_background_is_d65(render):
    r = render("background_white.toml", spp=SPP_BACKGROUND, seed=SEED)
    sd = heronref.grey_emitter(1.0)
    expected = heronref.expected_srgb(sd)
    check_mean("background [1, 1, 1]", read_rgb(r.exr), expected, sd, SPP_BACKGROUND, floor=5e-4)


# ------------------------------------ (iii) Lambertian quad under a directional light


@pytest.mark.parametrize("scene, cos_theta", [("quad_head_on.toml", 1.0), ("quad_oblique.toml", 0.5)])
def test_lambertian_quad_under_directional_light(render, scene, cos_theta):
    # Lr = ρd/π · L · cos θ with ρd = E = 1 and L = uplift of RGB π·(1, 1, 1) = π·D65(Y=1).
    r = render(scene, spp=SPP_QUAD, seed=SEED)
    sd = heronref.spectrum_e() * heronref.grey_emitter(math.pi) * (cos_theta / math.pi)
    expected = heronref.expected_srgb(sd)
    np.testing.assert_allclose(expected, cos_theta * RGB_WHITE_D65, atol=5e-7)
    rgb = read_rgb(r.exr)
    assert rgb.shape == (64, 64, 3)
    check_mean(f"{scene} (cos θ = {cos_theta})", rgb, expected, sd, SPP_QUAD, floor=5e-4)


# ------------------- (iii b) known spectra only: reflectance and light without any RGB


def test_known_spectrum_quad_under_known_spectrum_light(render):
    # ρd = 0.8 × D65(Y=1) and L = π × D65(Y=1), head-on: Lr = ρd/π · L = 0.8 × D65(Y=1)².
    # No RGB uplift is involved, so this checks the film against colour-science's
    # conversion of an arbitrary (non-flat, non-illuminant) product spectrum.
    r = render("quad_d65_squared.toml", spp=SPP_QUAD, seed=SEED)
    d65 = heronref.d65_unit()
    sd = (d65 * 0.8) * (d65 * math.pi) * (1.0 / math.pi)
    expected = heronref.expected_srgb(sd)
    # colour-science 0.4.7's numbers for it (bluish: neither factor's white).
    np.testing.assert_allclose(expected, [0.6507371, 0.8435839, 0.8885206], atol=5e-7)
    rgb = read_rgb(r.exr)
    assert rgb.shape == (64, 64, 3)
    check_mean("quad ρd = 0.8·D65 under L = π·D65", rgb, expected, sd, SPP_QUAD, floor=5e-4)


# ------------------------------------------------- (iv) EXR layout and chromaticities


def test_exr_channels_window_and_chromaticities(render):
    import OpenEXR

    r = render("background_e.toml", spp=SPP_BACKGROUND, seed=SEED)
    header, pixels, types = read_exr(r.exr)
    for c in "RGB":
        assert c in pixels, f"channel {c} missing; channels: {sorted(pixels)}"
        assert types[c] == OpenEXR.FLOAT, f"channel {c} is {types[c]}, expected FLOAT"
        assert pixels[c].shape == (48, 64), f"channel {c} is {pixels[c].shape}, expected (48, 64) for 64×48"
    lo, hi = (np.asarray(v) for v in header["dataWindow"])
    assert lo.tolist() == [0, 0] and hi.tolist() == [63, 47], header["dataWindow"]

    assert "chromaticities" in header, f"no chromaticities attribute; header keys {sorted(header)}"
    chroma = np.asarray(header["chromaticities"], dtype=np.float64)
    srgb = heronref.colour.RGB_COLOURSPACES["sRGB"]
    expected = np.concatenate([srgb.primaries.ravel(), srgb.whitepoint])  # rx ry gx gy bx by wx wy
    np.testing.assert_allclose(expected, [0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290])
    # The attribute is stored as float32.
    np.testing.assert_array_equal(chroma.astype(np.float32), expected.astype(np.float32),
                                  err_msg="chromaticities (rx ry gx gy bx by wx wy) are not sRGB/D65")


def test_exr_carries_provenance_readable_by_openexr(render, tmp_path):
    """Issue 10, part 5: heron's provenance as text attributes any OpenEXR reader sees."""
    import hashlib
    import subprocess

    import OpenEXR

    r = render("background_e.toml", spp=4, seed=9, extra=("--lanes", "4"))
    header, _, _ = read_exr(r.exr)
    got = {k: v for k, v in header.items() if k.startswith("heron.")}
    scene_sha = hashlib.sha256(r.scene.read_bytes()).hexdigest()
    assert got == {
        "heron.version": got.get("heron.version"),
        "heron.commit": got.get("heron.commit"),
        "heron.scene": "background_e.toml",
        "heron.sceneSha256": scene_sha,
        "heron.inputs": "",
        "heron.integrator": "whitted",
        "heron.sampler": "sobol",
        "heron.spp": "4",
        "heron.seed": "9",
        "heron.lanes": "4",
        "heron.wavelengths": "visible",
        "heron.maxDepth": got.get("heron.maxDepth"),
        "heron.offset": "epsilon 0.0001",
        "heron.packets": "paths",  # whitted under --packets auto: packets of paths
        "heron.spectralBins": "0",
    }, got
    assert got["heron.version"] and got["heron.maxDepth"].isdigit()
    assert re.fullmatch(r"[0-9a-f]{40}(-dirty)?|unknown", got["heron.commit"]), got["heron.commit"]
    # An EXR without them: `heron info` says so in one line and fails.
    plain = tmp_path / "plain.exr"
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                      {"Y": np.zeros((2, 3), dtype=np.float32)}) as f:
        f.write(str(plain))
    proc = subprocess.run([str(require_heron_bin()), "info", str(plain)], capture_output=True,
                          text=True)
    assert proc.returncode == 1 and "no heron provenance" in proc.stderr, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr


# ------------------------------------------------------------------ (v) PNG preview


def read_png(path):
    from PIL import Image

    with Image.open(path) as im:
        assert im.format == "PNG", f"{path} is {im.format}, not PNG"
        size = im.size
        rgb = np.asarray(im.convert("RGB"), dtype=np.float64)
    return size, rgb


def test_png_preview_exists_with_image_size(render):
    r = render("background_e.toml", spp=SPP_BACKGROUND, seed=SEED)
    assert r.png.is_file(), f"no preview {r.png} next to {r.exr}"
    size, _ = read_png(r.png)
    assert size == (64, 48), f"preview is {size[0]}×{size[1]}, expected 64×48"
    leftovers = sorted(p.name for p in r.outdir.iterdir())
    assert leftovers == ["out.exr", "out.png"], f"output folder holds {leftovers} (temporary files left?)"


def test_png_preview_is_srgb_encoded_exr(render):
    # Mid-grey scene (≈0.5 linear): sRGB encoding gives ≈188/255, a plain gamma 2.2 ≈186,
    # no encoding 128. Allow 2 codes for rounding choices and dithering.
    r = render("quad_oblique.toml", spp=SPP_QUAD, seed=SEED)
    size, png = read_png(r.png)
    assert size == (64, 64)
    lin = np.clip(read_rgb(r.exr), 0.0, 1.0)
    expected = 255.0 * heronref.colour.cctf_encoding(lin, function="sRGB")
    diff = np.abs(png - expected)
    assert diff.max() <= 2.0 and diff.mean() <= 0.75, (
        f"PNG is not the sRGB encoding of the EXR: max |diff| {diff.max():.2f} codes, "
        f"mean {diff.mean():.2f}; PNG mean {png.mean(axis=(0, 1))}, expected {expected.mean(axis=(0, 1))}")


# ------------------------------------------------------- determinism and orientation


def test_same_seed_same_image_whatever_the_thread_count(render):
    a = read_rgb(render("background_e.toml", spp=16, seed=7, threads=1).exr)
    b = read_rgb(render("background_e.toml", spp=16, seed=7, threads=2).exr)
    assert np.array_equal(a, b), (
        f"--threads 1 and --threads 2 differ in {(a != b).any(axis=-1).sum()} pixels "
        f"(same scene, seed and spp must give bit-identical output)")
    c = read_rgb(render("background_e.toml", spp=16, seed=8, threads=2).exr)
    assert not np.array_equal(a, c), "--seed 7 and --seed 8 gave identical images"


def test_image_orientation(render):
    rgb = read_rgb(render("quad_top_right.toml", spp=16, seed=SEED).exr)
    assert rgb.shape == (64, 64, 3)
    lum = rgb.mean(axis=-1)
    q = {  # interiors of the four quadrants, 3 px away from the centre lines
        "top-left": lum[:29, :29], "top-right": lum[:29, 35:],
        "bottom-left": lum[35:, :29], "bottom-right": lum[35:, 35:],
    }
    means = {k: float(v.mean()) for k, v in q.items()}
    assert means["top-right"] > 0.5, f"top-right quadrant should be lit (≈1): {means}"
    for k in ("top-left", "bottom-left", "bottom-right"):
        assert np.all(q[k] == 0.0), f"{k} quadrant should be black (background 0): {means}"
