"""The Python module `heron` (python/, PyO3) against the heron CLI.

- Renders: `Scene.render(...)` returns the numbers of the EXR `heron render` writes with
  the same scene, spp, seed, lanes, integrator, sampler, wavelengths, depth and offsets,
  bit for bit (R, G, B; X, Y, Z with --xyz; S0.* with --spectral-bins), at another
  thread count (the image does not depend on it), for a scene file (`load_scene`) and
  for the same scene as a dict (`Scene.from_dict`), under all four integrators; the
  statistics equal the CLI's summary line.
- Errors: a `heron.HeronError` (a ValueError) whose message is the CLI's line without
  `error: `; where the CLI names a flag the message names the argument.
- `trace` equals `heron trace`'s JSON, and the primary rainbow ray (TRT) of a water drop
  leaves at Descartes' deviation D = 180° + 2i − 4r for its impact parameter.
- `sky_profile` equals `heron sky profile`'s CSV (printed to 7 significant digits),
  with drop-size distributions and Debye terms too.
- `color` equals `heron color`'s JSON.
- `ior`: water and N-BK7 at known wavelengths; models as dicts.
- Ctrl-C: a SIGINT during a long render raises KeyboardInterrupt within a row of a
  tile; the interpreter goes on and renders again.
- The example examples/python/descartes_sweep.py runs and its Airy peaks move towards
  Descartes' as the drops grow.

The module must be installed in the interpreter running pytest (scripts/setup-python.sh
builds and installs it into .venv); the CLI is HERON_BIN (default target/release/heron).
"""
from __future__ import annotations

import json
import math
import os
import pathlib
import re
import subprocess
import sys
import tomllib

import heron  # built and installed by scripts/setup-python.sh; never skipped
import numpy as np
import pytest

from heronrun import REPO, SCENES, require_heron_bin
from test_render_exr import read_exr


# A small dispersive caustic scene (scenes/caustic-dispersion.toml at 32×24): a flint
# sphere on a floor under a D65 sun; every integrator has work to do in it.
SMALL_SCENE = """
background = 0.03
[camera]
eye = [0.36, 0.26, 0.12]
look_at = [0.0, 0.03, 0.035]
up = [0.0, 1.0, 0.0]
d = 1.4
resolution = [32, 24]
[render]
integrator = "bdpt"
spp = 4
max_depth = 10
[materials.floor]
type = "lambertian"
rho_d = 0.75
[materials.flint]
type = "dielectric"
ior = "N-SF11"
[[shapes]]
type = "quad"
origin = [-0.6, 0.0, 0.6]
edge1 = [1.2, 0.0, 0.0]
edge2 = [0.0, 0.0, -1.2]
material = "floor"
[[shapes]]
type = "sphere"
center = [0.0, 0.08140, 0.0]
radius = 0.08
material = "flint"
[[lights]]
type = "sun"
direction = [0.00000, -0.89493, 0.44620]
irradiance = { spectrum = "D65", scale = 1.0 }
"""


def run_cli(*args, cwd=None, check=True) -> subprocess.CompletedProcess:
    p = subprocess.run(
        [str(require_heron_bin()), *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )
    if check:
        assert p.returncode == 0, f"heron {' '.join(map(str, args))} failed:\n{p.stderr}"
    return p


def cli_error(*args, cwd=None) -> str:
    """The CLI's one-line error message, without `error: `."""
    p = run_cli(*args, cwd=cwd, check=False)
    assert p.returncode == 1, f"expected status 1 from heron {args}, got {p.returncode}: {p.stderr}"
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    return lines[0].removeprefix("error: ")


def clap_reason(msg: str) -> str:
    """The reason of a clap message `invalid value 'X' for '--flag <F>': REASON`."""
    m = re.match(r"invalid value '.*' for '--[a-z-]+ <[A-Z_]+>': (.*)$", msg)
    assert m, msg
    return m.group(1)


def py_error(f, *args, **kwargs) -> str:
    with pytest.raises(heron.HeronError) as e:
        f(*args, **kwargs)
    assert isinstance(e.value, ValueError)
    return str(e.value)


def bits(a) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float32)
    return a.view(np.uint32)


# --------------------------------------------------------------------------- module


def test_module_is_documented_and_typed():
    assert issubclass(heron.HeronError, ValueError)
    public = ["load_scene", "trace", "sky_profile", "halo_profile", "color", "ior", "lens", "Scene",
              "RenderResult"]
    for name in public:
        doc = getattr(heron, name).__doc__
        assert doc and len(doc) > 40, f"heron.{name} has no docstring"
    for name in ["from_dict", "render"]:
        assert len(getattr(heron.Scene, name).__doc__) > 40
    for name in ["rgb", "xyz", "spectral", "wavelengths", "spp", "rays", "kernel"]:
        assert getattr(heron.RenderResult, name).__doc__, name
    pkg = pathlib.Path(heron.__file__).parent
    assert (pkg / "py.typed").is_file()
    stub = (pkg / "__init__.pyi").read_text()
    for name in public:
        assert re.search(rf"^(def|class) {name}\b", stub, re.M), f"{name} missing in the stub"


# --------------------------------------------------------------------------- renders

# (name, source, python kwargs, CLI flags). Python uses one thread, the CLI two.
RENDERS = [
    (
        "file-whitted",
        "spectral_exr",
        dict(spp=4, seed=3, lanes=4, spectral_bins=10),
        ["--spp", "4", "--seed", "3", "--lanes", "4", "--spectral-bins", "10"],
    ),
    (
        "dict-path",
        "small",
        dict(spp=3, seed=5, lanes=8, integrator="path", sampler="independent",
             wavelengths="uniform", max_depth=5, offset="robust", spectral_bins=5),
        ["--spp", "3", "--seed", "5", "--lanes", "8", "--integrator", "path",
         "--sampler", "independent", "--wavelengths", "uniform", "--max-depth", "5",
         "--offset", "robust", "--spectral-bins", "5"],
    ),
    ("dict-bdpt", "small", dict(lanes=1), ["--lanes", "1"]),
    (
        "dict-lighttrace",
        "small",
        dict(spp=2, integrator="lighttrace", offset="epsilon"),
        ["--spp", "2", "--integrator", "lighttrace", "--offset", "epsilon"],
    ),
    (
        "dict-sppm",
        "small",
        dict(spp=3, lanes=4, integrator="sppm", sppm_photons=500, sppm_alpha=0.5,
             spectral_bins=4),
        ["--spp", "3", "--lanes", "4", "--integrator", "sppm", "--sppm-photons", "500",
         "--sppm-alpha", "0.5", "--spectral-bins", "4"],
    ),
]


@pytest.mark.parametrize("name,source,kwargs,flags", RENDERS, ids=[r[0] for r in RENDERS])
def test_render_equals_cli_exr(tmp_path, name, source, kwargs, flags):
    if source == "spectral_exr":
        scene_file = SCENES / "spectral_exr.toml"
        scene = heron.load_scene(scene_file)
    else:
        scene_file = tmp_path / "small.toml"
        scene_file.write_text(SMALL_SCENE)
        scene = heron.Scene.from_dict(tomllib.loads(SMALL_SCENE))
    exr = tmp_path / "out.exr"
    p = run_cli("render", scene_file, "-o", exr, "--xyz", "--no-png", "--quiet",
                "--threads", "2", *flags)
    r = scene.render(threads=1, **kwargs)
    _, px, _ = read_exr(exr)
    h, w = scene.height, scene.width
    assert r.rgb.shape == (h, w, 3) and r.rgb.dtype == np.float32
    assert r.xyz.shape == (h, w, 3) and r.xyz.dtype == np.float32
    assert np.isfinite(r.rgb).all() and r.rgb.max() > 0
    for k, c in enumerate("RGB"):
        np.testing.assert_array_equal(bits(r.rgb[..., k]), bits(px[c]), err_msg=c)
    for k, c in enumerate("XYZ"):
        np.testing.assert_array_equal(bits(r.xyz[..., k]), bits(px[c]), err_msg=c)
    bins = kwargs.get("spectral_bins", 0)
    if bins:
        assert r.spectral.shape == (h, w, bins)
        spectral = sorted((c for c in px if c.startswith("S0.")),
                          key=lambda c: float(c[3:-2].replace(",", ".")))
        assert len(spectral) == bins
        centres = [float(c[3:-2].replace(",", ".")) for c in spectral]
        np.testing.assert_allclose(r.wavelengths, centres, rtol=0, atol=1e-6)
        for k, c in enumerate(spectral):
            np.testing.assert_array_equal(bits(r.spectral[..., k]), bits(px[c]), err_msg=c)
    else:
        assert r.spectral is None and r.wavelengths is None
    # The CLI's summary line: "...: WxH at S spp, L lanes, SAMPLER, INTEGRATOR (kernel K)
    # in T s: R rays (C camera/continued, S shadow), M Mrays/s, N non-finite samples".
    m = re.search(
        r": (\d+)x(\d+) at (\d+) spp, (\d) lanes, (\w+), (\w+) \(kernel ([^)]*)\) in [\d.]+ s: "
        r"(\d+) rays \((\d+) camera/continued, (\d+) shadow\), [\d.]+ Mrays/s, (\d+) non-finite",
        p.stderr,
    )
    assert m, p.stderr
    assert (r.width, r.height, r.spp, r.lanes, r.sampler, r.integrator, r.kernel) == (
        int(m[1]), int(m[2]), int(m[3]), int(m[4]), m[5], m[6], m[7])
    assert (r.rays, r.camera_rays, r.shadow_rays, r.nonfinite_samples) == (
        int(m[8]), int(m[9]), int(m[10]), int(m[11]))
    assert r.rays == r.camera_rays + r.shadow_rays and r.wall_seconds > 0


def test_dict_scene_paths_start_at_the_current_directory(tmp_path, monkeypatch):
    """A mesh named relatively in a dict is read from the current directory."""
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    d = tomllib.loads(SMALL_SCENE)
    d["shapes"].append({"type": "mesh", "file": "tri.obj", "material": "floor"})
    monkeypatch.chdir(tmp_path)
    assert heron.Scene.from_dict(d).width == 32
    monkeypatch.chdir(REPO)
    msg = py_error(heron.Scene.from_dict, d)
    assert msg.startswith("tri.obj: shapes[2].file: cannot read the mesh file"), msg


# --------------------------------------------------------------------------- errors


def test_scene_errors_are_the_loaders(tmp_path, monkeypatch):
    missing = tmp_path / "missing.toml"
    assert py_error(heron.load_scene, missing) == cli_error("render", missing, "-o", tmp_path / "o.exr")
    monkeypatch.chdir(tmp_path)
    cases = {
        "unknown key": SMALL_SCENE.replace("d = 1.4", "d = 1.4\nfocal = 3"),
        "wrong type": SMALL_SCENE.replace("spp = 4", 'spp = "four"'),
        "bad integrator": SMALL_SCENE.replace('"bdpt"', '"photon"'),
        "bad ior": SMALL_SCENE.replace('"N-SF11"', '"BK7"'),
        "negative radius": SMALL_SCENE.replace("radius = 0.08", "radius = -0.08"),
        "missing mesh": SMALL_SCENE + '[[shapes]]\ntype = "mesh"\nfile = "nowhere.obj"\nmaterial = "floor"\n',
    }
    for what, text in cases.items():
        f = tmp_path / "bad.toml"
        f.write_text(text)
        want = cli_error("render", "bad.toml", "-o", "o.exr", cwd=tmp_path)
        assert want.startswith("bad.toml: " if what != "missing mesh" else "nowhere.obj: "), want
        assert py_error(heron.load_scene, "bad.toml") == want, what
        got = py_error(heron.Scene.from_dict, tomllib.loads(text))
        assert got == re.sub(r"^bad\.toml", "<dict>", want), what
    assert py_error(heron.Scene.from_dict, {"camera": None}).startswith(
        "camera: expected a bool, int, float, str, list or dict (a TOML value), got None")


def test_render_argument_errors(tmp_path):
    scene = heron.Scene.from_dict(tomllib.loads(SMALL_SCENE))
    f = tmp_path / "s.toml"
    f.write_text(SMALL_SCENE)

    def cli(*flags):
        return cli_error("render", f, "-o", tmp_path / "o.exr", *flags)

    assert py_error(scene.render, lanes=3) == "lanes: " + clap_reason(cli("--lanes", "3"))
    assert py_error(scene.render, spp=0) == cli("--spp", "0").replace("--spp", "spp")
    assert py_error(scene.render, wavelengths="red") == 'wavelengths: expected uniform or visible, got "red"'
    assert py_error(scene.render, integrator="photon") == (
        'integrator: expected one of whitted, path, lighttrace, bdpt, sppm, got "photon"')
    assert py_error(scene.render, integrator="sppm", sppm_alpha=1.0) == (
        cli("--integrator", "sppm", "--sppm-alpha", "1").replace("--sppm-alpha", "sppm_alpha"))
    assert py_error(scene.render, integrator="sppm", sppm_radius=-2.0).startswith(
        "sppm_radius: expected 0 (automatic")
    assert py_error(scene.render, integrator="sppm", sppm_photons=-1).startswith(
        "sppm_photons: expected 0 (one per pixel)")
    assert py_error(scene.render, sampler="halton") == 'sampler: expected sobol or independent, got "halton"'
    assert py_error(scene.render, offset="big") == 'offset: expected auto, epsilon or robust, got "big"'
    assert py_error(scene.render, spectral_bins=471).startswith("spectral_bins: expected 0 (none) or 1 to 470")
    assert py_error(scene.render, max_depth=0) == "max_depth: expected at least 1, got 0"
    assert py_error(scene.render, packets="sideways") == (
        'packets: expected auto, paths, camera or off, got "sideways"')
    assert py_error(scene.render, threads=-1).startswith("threads: expected 0")
    # The scene file's own messages for the same values.
    g = tmp_path / "t.toml"
    g.write_text(SMALL_SCENE.replace('"bdpt"', '"photon"'))
    assert cli_error("render", g, "-o", tmp_path / "o.exr").endswith(
        'render.integrator: expected one of whitted, path, lighttrace, bdpt, sppm, got "photon"')


def test_render_packets_choose_the_engine_and_agree():
    """`packets` is `heron render --packets`: every choice renders the same image up to the
    last bits of Embree's hits (tests/packets.rs holds that over every scene), and what ran
    is recorded as the CLI records it."""
    scene = heron.Scene.from_dict(tomllib.loads(SMALL_SCENE))
    images = {}
    for integrator in ("whitted", "path", "bdpt"):
        for packets in ("auto", "paths", "camera", "off"):
            r = scene.render(spp=2, integrator=integrator, packets=packets, threads=2)
            images[integrator, packets] = r.rgb
        ref = images[integrator, "camera"]
        for packets in ("auto", "paths", "off"):
            close = np.isclose(images[integrator, packets], ref, rtol=1e-4, atol=1e-6)
            assert close.mean() > 0.99, (integrator, packets, close.mean())
    # auto: packets of paths under whitted, one path at a time under path.
    assert np.array_equal(images["whitted", "auto"], images["whitted", "paths"])
    assert np.array_equal(images["path", "auto"], images["path", "camera"])


FOG_SCENE = """
background = 0.05
[camera]
eye = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
d = 2.0
resolution = [24, 24]
[render]
integrator = "path"
max_depth = 4
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
medium = { type = "henyey-greenstein", sigma_a = 0.05, sigma_s = 0.6, g = 0.7 }
[[lights]]
type = "sun"
direction = [0.0, -0.4, -0.9]
irradiance = 2.0
"""


def test_render_medium_estimators_are_arguments_and_agree(tmp_path):
    """`medium_nee` and `sun_guide` are `heron render --medium-nee` and `--sun-guide`:
    each choice takes effect (the images differ in their bits), all agree in the mean
    (unbiased estimators of one image; tests/media_estimators.rs holds them to region
    z-tests), and bad values are the CLI's errors under the arguments' names."""
    scene = heron.Scene.from_dict(tomllib.loads(FOG_SCENE))
    means = {}
    images = {}
    for nee in ("forced", "collision"):
        for guide in (0.0, 0.25):
            r = scene.render(spp=64, seed=3, sampler="independent", threads=2,
                             medium_nee=nee, sun_guide=guide)
            images[nee, guide] = r.rgb
            means[nee, guide] = float(r.rgb.mean())
    default = scene.render(spp=64, seed=3, sampler="independent", threads=2)
    assert np.array_equal(bits(default.rgb), bits(images["forced", 0.25]))
    keys = list(images)
    for i, a in enumerate(keys):
        for b in keys[i + 1:]:
            assert not np.array_equal(bits(images[a]), bits(images[b])), (a, b)
    m = np.mean(list(means.values()))
    for k, v in means.items():
        # 576 pixels x 64 spp: each image mean's standard error is below 1% here.
        assert abs(v / m - 1.0) < 0.03, (k, v, m)
    assert py_error(scene.render, sun_guide=1.0) == (
        "sun_guide: expected a fraction in [0, 1) (0: phase sampling alone), got 1")
    assert py_error(scene.render, medium_nee="often") == (
        'medium_nee: expected forced or collision, got "often"')
    f = tmp_path / "fog.toml"
    f.write_text(FOG_SCENE)
    assert cli_error("render", f, "--sun-guide", "1", "-o", tmp_path / "o.exr") == (
        "--sun-guide: expected a fraction in [0, 1) (0: phase sampling alone), got 1")


# --------------------------------------------------------------------------- trace

DROP = REPO / "scenes" / "droplet.toml"


def cli_trace(origin, direction, lam, path=""):
    args = ["trace", DROP, "--origin", ",".join(map(str, origin)), "--dir",
            ",".join(map(str, direction)), "--lambda", str(lam)]
    if path:
        args += ["--path", path]
    return json.loads(run_cli(*args).stdout)


@pytest.mark.parametrize("b,path", [(0.86, "TRT"), (0.5, "TRRT"), (0.3, None), (0.95, "R")])
def test_trace_equals_cli(b, path):
    origin, direction, lam = [0.0, b, -3.0], [0.0, 0.0, 1.0], 589.0
    events = heron.trace(DROP, origin, direction, lam, path=path)
    want = cli_trace(origin, direction, lam, path or "")["events"]
    assert [e["kind"] for e in events] == [e["kind"] for e in want]
    for got, exp in zip(events, want):
        assert got.keys() == exp.keys()
        for k, v in exp.items():
            if isinstance(v, (list, float)):
                np.testing.assert_array_equal(np.float32(got[k]), np.float32(v), err_msg=k)
            else:
                assert got[k] == v, k
    # The same with a loaded Scene.
    assert heron.trace(heron.load_scene(DROP), origin, direction, lam, path=path) == events


def test_trace_primary_rainbow_ray_has_descartes_deviation():
    """TRT through a unit water drop at impact parameter b: refraction at incidence i,
    one internal reflection, refraction out; total deviation D = 180° + 2i − 4r with
    sin i = n sin r (Descartes; e.g. Nussenzveig 1977). The angle between the incoming
    and outgoing directions is D (D < 180° for k = 1)."""
    lam = 589.0
    n = float(heron.ior("water", [lam])[0])
    for b in [0.5, 0.86, 0.95]:
        ev = heron.trace(DROP, [0.0, b, -3.0], [0.0, 0.0, 1.0], lam, path="TRT")
        assert [e["kind"] for e in ev] == ["refract", "reflect", "refract", "escape"]
        assert ev[0]["n_i"] == 1.0 and abs(ev[0]["n_t"] - n) < 1e-6
        i = math.asin(b)
        r = math.asin(b / n)
        deviation = math.degrees(math.pi + 2 * i - 4 * r)
        out = np.array(ev[-1]["outgoing"], dtype=float)
        angle = math.degrees(math.acos(np.clip(out @ np.array([0.0, 0.0, 1.0]), -1, 1)))
        # f32 geometry: directions good to ~1e-6 rad, 3 surface events.
        assert abs(angle - deviation) < 1e-3, (b, angle, deviation)


def test_trace_errors():
    assert py_error(heron.trace, DROP, [0, 0, -3], [0, 0, 1], 589.0, path="TX") == (
        'path: expected only the letters R (reflect) and T (transmit), got \'X\' in "TX"')
    want = run_cli("trace", DROP, "--origin", "0,0,-3", "--dir", "0,0,1", "--lambda", "900",
                   check=False).stderr.strip().removeprefix("error: ")
    assert py_error(heron.trace, DROP, [0, 0, -3], [0, 0, 1], 900.0) == want.replace("--lambda", "wavelength")
    assert py_error(heron.trace, DROP, [0, 0, -3], [0, 0, 0], 589.0) == (
        "origin and direction: expected finite vectors, direction not zero")
    assert py_error(heron.trace, DROP, [0, 0], [0, 0, 1], 589.0) == (
        "origin: expected X,Y,Z (three numbers), got 2 numbers")


# --------------------------------------------------------------------------- sky


def cli_profile(model, lambdas, lo, hi, step, *flags):
    out = run_cli("sky", "profile", "--model", model, "--lambda", ",".join(map(str, lambdas)),
                  "--from", lo, "--to", hi, "--step", step, *flags).stdout
    rows = [line.split(",") for line in out.strip().splitlines()]
    assert rows[0] == ["theta_deg"] + [f"{l:g}nm" for l in lambdas]
    table = np.array([[float(x) for x in r] for r in rows[1:]])
    return table[:, 0], table[:, 1:]


PROFILES = [
    ("descartes", {}, []),
    ("descartes", dict(k="all", polarisation="s", sun_radius=0.5),
     ["--k", "all", "--polarisation", "s", "--sun-radius", "0.5"]),
    ("airy", dict(droplet_radius=0.3, k=2), ["--droplet-radius", "0.3", "--k", "2"]),
    ("mie", dict(droplet_radius=0.02, polarisation="p"), ["--droplet-radius", "0.02", "--polarisation", "p"]),
    ("aristotle", dict(background=0.25), ["--background", "0.25"]),
    # Drop-size distributions (issue 12) and a Debye term, as the scene files' table.
    ("airy", dict(drops=dict(distribution="lognormal", median_mm=0.3, sigma=0.1, nodes=12)),
     ["--distribution", "lognormal", "--median-mm", "0.3", "--sigma", "0.1", "--nodes", "12"]),
    ("mie", dict(droplet_radius=0.02, debye=2), ["--droplet-radius", "0.02", "--debye", "2"]),
]


@pytest.mark.parametrize("model,kwargs,flags", PROFILES, ids=[f"{p[0]}-{i}" for i, p in enumerate(PROFILES)])
def test_sky_profile_equals_cli(model, kwargs, flags):
    lambdas = [450.0, 532.5, 650.0]
    theta, want = cli_profile(model, lambdas, 38, 54, 0.25, *flags)
    got = heron.sky_profile(model, lambdas, theta, **kwargs)
    assert got.shape == (len(theta), len(lambdas)) and got.dtype == np.float32
    assert want.max() > 0
    # The CSV prints 7 significant digits (`{:.6e}`).
    np.testing.assert_allclose(got, want, rtol=6e-7, atol=0)


def test_halo_profile_equals_cli():
    """heron.halo_profile reads the same table as `heron halo profile` (same crystals,
    sun, rays and seed): equal to the CSV's 7 significant digits. 20 000 rays per row
    keep the two tables' tracing to about a second."""
    lambdas, psis = [450.0, 650.0], [0.0, 90.0]
    p = run_cli("halo", "profile", "--sun-elevation", "20", "--crystals", "random",
                "--crystals", "plates:aspect=0.3,tilt_deg=1", "--lambda", "450,650",
                "--psi", "0,90", "--from", "15", "--to", "30", "--step", "0.5",
                "--rays", "20000", "--seed", "3")
    rows = np.array([[float(x) for x in line.split(",")] for line in p.stdout.splitlines()[1:]])
    theta = rows[:, 0]
    got = heron.halo_profile(20.0, [dict(orientation="random"),
                                    dict(orientation="plates", aspect=0.3, tilt_deg=1)],
                             lambdas, theta, psi=psis, rays=20000, seed=3)
    assert got.shape == (len(theta), 2, 2) and got.dtype == np.float32
    np.testing.assert_allclose(got.reshape(len(theta), 4), rows[:, 1:], rtol=6e-7, atol=0)
    assert got.max() > 0.1


def test_halo_profile_errors():
    want = cli_error("halo", "profile", "--sun-elevation", "20", "--crystals", "plates:aspect=0",
                     "--lambda", "500")
    assert want.startswith("--crystals (population 1) aspect: expected c/a in [0.02, 50]")
    assert py_error(heron.halo_profile, 20.0, [dict(orientation="plates", aspect=0)], [500], [22]) \
        == want.replace("--crystals (population 1) ", "crystals[0].")
    assert py_error(heron.halo_profile, 20.0, [dict(orientation="plates", colour=1)], [500], [22]) \
        .startswith("crystals[0]: unknown field `colour`")
    assert py_error(heron.halo_profile, 20.0, "plates", [500], [22]).startswith("crystals: expected a list")
    assert py_error(heron.halo_profile, 20.0, [dict(orientation="random")], [300], [22]) \
        .startswith("wavelengths: expected wavelengths in 360–830 nm")
    assert py_error(heron.halo_profile, 20.0, [dict(orientation="random")], [500], [190]) \
        == "theta: expected angles in 0–180° from the sun, got 190"


def test_sky_profile_errors():
    want = cli_error("sky", "profile", "--model", "airy", "--lambda", "500", "--from", "40",
                     "--to", "41", "--step", "1")
    assert want == "--droplet-radius: the airy model needs a drop radius in mm"
    assert py_error(heron.sky_profile, "airy", [500], [40, 41]) == want.replace("--droplet-radius", "droplet_radius")
    want = cli_error("sky", "profile", "--model", "descartes", "--lambda", "300", "--from", "40",
                     "--to", "41", "--step", "1")
    assert py_error(heron.sky_profile, "descartes", [300], [40]) == want.replace("--lambda", "wavelengths")
    want = cli_error("sky", "profile", "--model", "mie", "--k", "1", "--droplet-radius", "0.1",
                     "--lambda", "500", "--from", "40", "--to", "41", "--step", "1")
    assert py_error(heron.sky_profile, "mie", [500], [40], k=1, droplet_radius=0.1) == want.replace("--k", "k")
    assert py_error(heron.sky_profile, "rainbow", [500], [40]).startswith('model: expected one of constant,')
    want = cli_error("sky", "profile", "--model", "airy", "--distribution", "lognormal",
                     "--median-mm", "0.3", "--lambda", "500", "--from", "40", "--to", "41", "--step", "1")
    assert "--sigma" in want
    assert py_error(heron.sky_profile, "airy", [500], [40],
                    drops=dict(distribution="lognormal", median_mm=0.3)) == want.replace("--sigma", "drops['sigma']")
    assert py_error(heron.sky_profile, "airy", [500], [40],
                    drops=dict(distribution="gauss")).startswith("drops['distribution']")
    assert py_error(heron.sky_profile, "airy", [500], [40], drops=dict(median=1)).startswith("drops: unknown field")
    assert py_error(heron.sky_profile, "descartes", [500], [190]) == (
        "theta: expected angles in 0–180° from the antisolar point, got 190")


# --------------------------------------------------------------------------- colour


@pytest.mark.parametrize("illuminant,observer,interpolation", [
    ("D65", "1931", "cie167"), ("A", 1964, "cie167"), ("none", "1931", "cie167"),
    ("D50", "1931", "linear"), ("none", 1964, "linear")])
def test_color_equals_cli(tmp_path, illuminant, observer, interpolation):
    lam = np.arange(380.0, 781.0, 5.0)
    values = 0.2 + 0.7 / (1 + np.exp(-(lam - 560.0) / 15.0))  # an orange-ish reflectance
    values[40] += 0.5  # a spike at 580 nm, where the two interpolations differ
    csv = tmp_path / "s.csv"
    csv.write_text("wavelength_nm,value\n" + "".join(f"{l:g},{np.float32(v)!r}\n" for l, v in zip(lam, values)))
    want = json.loads(run_cli("color", csv, "--illuminant", illuminant, "--observer", observer,
                              "--interpolation", interpolation).stdout)
    got = heron.color(lam, values.astype(np.float32), illuminant=illuminant, observer=observer,
                      interpolation=interpolation)
    assert got["illuminant"] == want["illuminant"] and got["observer"] == want["observer"]
    assert got["interpolation"] == want["interpolation"] == interpolation
    other = "linear" if interpolation == "cie167" else "cie167"
    assert heron.color(lam, values.astype(np.float32), illuminant=illuminant, observer=observer,
                       interpolation=other)["XYZ"] != got["XYZ"]
    for k in ["XYZ", "xy", "linear_srgb"]:
        np.testing.assert_array_equal(np.float32(got[k]), np.float32(want[k]), err_msg=k)


def test_color_errors(tmp_path):
    csv = tmp_path / "s.csv"
    csv.write_text("400,1\n500,1\n")
    want = cli_error("color", csv, "--illuminant", "F2")
    assert py_error(heron.color, [400, 500], [1, 1], illuminant="F2") == "illuminant: " + clap_reason(want)
    want = cli_error("color", csv, "--observer", "1976")
    assert py_error(heron.color, [400, 500], [1, 1], observer="1976") == "observer: " + clap_reason(want)
    want = cli_error("color", csv, "--interpolation", "sprague")
    assert py_error(heron.color, [400, 500], [1, 1], interpolation="sprague") == (
        "interpolation: " + clap_reason(want))
    assert py_error(heron.color, [400, 400], [1, 1]) == (
        "wavelengths[1]: expected wavelengths in strictly increasing order, got 400 nm after 400 nm")
    assert py_error(heron.color, [400], [1]) == "wavelengths, values: expected at least 2 samples, found 1"
    assert py_error(heron.color, [400, 500], [1]) == "values: expected as many values as wavelengths (2), got 1"
    assert py_error(heron.color, [400, 500], [1, float("nan")]).startswith("values[1]: expected a finite number")


# --------------------------------------------------------------------------- ior


def test_ior_known_values():
    # Water at 589.3 nm, 20 °C: the handbook's n_D = 1.3330; heron's catalogue holds the
    # four-term Sellmeier fit of Daimon & Masumura 2007 (Appl. Opt. 46(18)), which gives
    # 1.33340 there (spectra/ior_catalogue.toml), so 5e-4 of the handbook value, and
    # exactly the fit's formula evaluated here in float64 (to float32 rounding).
    n_water = heron.ior("water", 589.3)[0]
    assert abs(n_water - 1.3330) < 5e-4
    b = [5.684027565e-1, 1.726177391e-1, 2.086189578e-2, 1.130748688e-1]
    c = [5.101829712e-3, 1.821153936e-2, 2.620722293e-2, 10.69792721]
    l2 = 0.5893**2
    assert abs(n_water - math.sqrt(1 + sum(bi * l2 / (l2 - ci) for bi, ci in zip(b, c)))) < 1e-6
    # N-BK7: n_d = 1.5168 at 587.56 nm, n_F = 1.52238 at 486.13 nm, n_C = 1.51432 at
    # 656.27 nm (Schott data sheet).
    n = heron.ior("N-BK7", np.array([587.56, 486.13, 656.27]))
    assert n.dtype == np.float32 and n.shape == (3,)
    np.testing.assert_allclose(n, [1.5168, 1.52238, 1.51432], atol=5e-5)
    # Normal dispersion: n falls with λ.
    lam = np.linspace(400, 800, 41)
    assert (np.diff(heron.ior("water", lam)) < 0).all()
    # Models as scene files write them.
    assert heron.ior(1.5, [400, 700]).tolist() == [1.5, 1.5]
    np.testing.assert_allclose(heron.ior({"cauchy": [1.5, 0.0042]}, [500.0]), [1.5 + 0.0042 / 0.25], rtol=1e-6)
    bk7 = {"sellmeier": {"b": [1.03961212, 0.231792344, 1.01046945],
                         "c": [0.00600069867, 0.0200179144, 103.560653]}}
    np.testing.assert_array_equal(heron.ior(bk7, lam), heron.ior("N-BK7", lam))
    table = {"table": str(REPO / "tests" / "python" / "scenes" / "missing.csv")}
    assert "cannot read" in py_error(heron.ior, table, [500])


def test_ior_errors_are_the_loaders(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(SMALL_SCENE.replace('"N-SF11"', '"BK7"'))
    want = cli_error("render", f, "-o", tmp_path / "o.exr")
    at = f"{f}: materials.flint.ior"
    assert want.startswith(at), want
    assert py_error(heron.ior, "BK7", [500]) == "ior" + want.removeprefix(at)
    assert py_error(heron.ior, -1.5, [500]) == "ior: expected a positive finite number, got -1.5"
    assert py_error(heron.ior, "water", [900]) == "wavelengths[0]: expected a wavelength in 360–830 nm, got 900"


# --------------------------------------------------------------------------- Ctrl-C

CTRL_C = r"""
import os, signal, sys, threading, tomllib
import heron
# The default handler even if this process was started with SIGINT ignored.
signal.signal(signal.SIGINT, signal.default_int_handler)
d = tomllib.loads(sys.argv[1])
d["camera"]["resolution"] = [64, 64]
d["render"]["integrator"] = "path"
scene = heron.Scene.from_dict(d)
threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
try:
    # 10^6 spp of 4096 pixels would take hours; passes are 2^22 pixel samples.
    scene.render(spp=1_000_000, threads=2)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
r = scene.render(spp=1, threads=2)
print("rendered again", r.spp, r.rgb.shape, flush=True)
"""


def test_ctrl_c_stops_a_render():
    # Without the stop flag the render would run for hours; the timeout is the failure.
    p = subprocess.run([sys.executable, "-c", CTRL_C, SMALL_SCENE], capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert p.stdout.splitlines() == ["interrupted", "rendered again 1 (64, 64, 3)"], p.stdout


def test_render_releases_the_gil():
    """While one thread renders, another runs Python code. With a switch interval of
    100 s, a thread keeps the GIL until it blocks or releases it: if `render` held it,
    the main thread could not run before the rendering thread had finished and set
    `done`, and would count nothing; since `render` releases it, the main thread counts
    to 100 000 while the render is still going (a path-traced 32×24 image at 256 spp)."""
    import threading

    scene = heron.Scene.from_dict(tomllib.loads(SMALL_SCENE))
    inside = threading.Event()
    done = threading.Event()
    result = {}

    def render():
        inside.set()
        try:
            result["r"] = scene.render(spp=256, integrator="path", threads=1)
        finally:
            done.set()

    interval = sys.getswitchinterval()
    sys.setswitchinterval(100.0)
    try:
        t = threading.Thread(target=render)
        t.start()
        inside.wait()
        count, target = 0, 100_000
        while not done.is_set() and count < target:
            count += 1
        t.join()
    finally:
        sys.setswitchinterval(interval)
    assert result["r"].spp == 256
    assert count == target, f"counted only {count} while render ran"


# --------------------------------------------------------------------------- example


def test_descartes_sweep_example(tmp_path):
    out = tmp_path / "sweep.png"
    p = subprocess.run([sys.executable, str(REPO / "examples" / "python" / "descartes_sweep.py"),
                        "--out", str(out)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    peaks = {}
    for line in p.stdout.splitlines():
        if line.startswith("peak "):
            _, model, radius, lam, theta = line.split()
            peaks[(model, radius, float(lam))] = float(theta)
    assert len(peaks) == 12, p.stdout
    for lam in [450.0, 550.0, 650.0]:
        a = [peaks[("airy", r, lam)] for r in ["0.1", "0.3", "1"]]
        d = peaks[("descartes", "-", lam)]
        # Airy's maximum lies inside the geometric bow and approaches it as a grows
        # (the shift scales as a^(-2/3)).
        assert a[0] < a[1] < a[2], (lam, a)
        assert abs(a[2] - d) < abs(a[1] - d) < abs(a[0] - d), (lam, a, d)
    # Dispersion: red bows lie outside blue ones.
    assert peaks[("descartes", "-", 450.0)] < peaks[("descartes", "-", 550.0)] < peaks[("descartes", "-", 650.0)]
