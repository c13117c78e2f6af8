"""Data for papers/descartes-rainbow from `heron trace`, i.e. from the renderer's own
refraction, reflection and water n(λ):

  water_n.csv          n(λ) of heron's water, read from the first refraction event
  deviation_curve.csv  deviation D(b) against impact parameter b for k = 1, 2 at a few
                       wavelengths (traced, and Descartes' formula with the same n)
  (rainbow angles by minimum search: returned to make_figures.py)

A ray along +z from (0, b, -5) hits scenes/droplet.toml's drop (radius 1, at the
origin) at impact parameter b; --path TRT keeps the primary (k = 1) ray, TRRT the
secondary (k = 2). The escaping direction d gives the deviation (the rotation from +z,
taken with the primary bow's sense) D = (-atan2(d_y, d_z)) mod 360°, and the angle
from the antisolar point θ = |180° - D|.
"""
from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.optimize import minimize_scalar

from heronfig import Heron

SCENE = "scenes/droplet.toml"
PATHS = {1: "TRT", 2: "TRRT"}
# heron trace runs as separate processes; two at a time (each result depends only on its
# inputs, and results are gathered in order, so the output does not depend on this).
WORKERS = 2


def pmap(fn, items):
    with ThreadPoolExecutor(max_workers=WORKERS) as pool:
        return list(pool.map(fn, items))


def water_n(heron: Heron, lam_nm: float) -> float:
    """heron's n(λ) for water: n_t of the first (air → water) refraction."""
    rep = heron.trace(SCENE, (0.0, 0.0, -5.0), (0.0, 0.0, 1.0), lam_nm)
    ev = rep["events"][0]
    assert ev["kind"] == "refract" and ev["n_i"] == 1.0, ev
    return float(ev["n_t"])


def traced_deviation(heron: Heron, b: float, lam_nm: float, k: int) -> float:
    """Deviation in degrees of the k-th order ray at impact parameter b, traced."""
    rep = heron.trace(SCENE, (0.0, b, -5.0), (0.0, 0.0, 1.0), lam_nm, PATHS[k])
    kinds = [e["kind"] for e in rep["events"]]
    want = ["refract"] + ["reflect"] * k + ["refract", "escape"]
    if kinds != want:
        raise SystemExit(f"trace at b={b}, λ={lam_nm}, k={k}: events {kinds}, expected {want}")
    d = rep["events"][-1]["outgoing"]
    return math.degrees(-math.atan2(d[1], d[2])) % 360.0


def formula_deviation(b: float, n: float, k: int) -> float:
    """Descartes: D_k(b) = k·180° + 2i − 2(k+1)r, sin i = b, sin r = b/n."""
    i = math.asin(b)
    r = math.asin(b / n)
    return math.degrees(k * math.pi + 2 * i - 2 * (k + 1) * r)


def formula_rainbow_angle(n: float, k: int) -> float:
    """Angle of the k-th bow from the antisolar point at minimum deviation,
    cos² i = (n² − 1)/(k² + 2k)."""
    ci = math.sqrt((n * n - 1.0) / (k * k + 2 * k))
    b = math.sqrt(1.0 - ci * ci)
    return abs(180.0 - formula_deviation(b, n, k))


def theta_from_deviation(d_deg: float) -> float:
    return abs(180.0 - d_deg)


def traced_minimum(heron: Heron, lam_nm: float, k: int, n: float) -> tuple[float, float]:
    """(b, D) at the minimum deviation found by a bounded Brent search over traced rays,
    bracketed around the formula's b_min."""
    ci = math.sqrt((n * n - 1.0) / (k * k + 2 * k))
    b0 = math.sqrt(1.0 - ci * ci)
    lo, hi = b0 - 0.06, min(b0 + 0.04, 0.9999)
    res = minimize_scalar(lambda b: traced_deviation(heron, b, lam_nm, k), bounds=(lo, hi),
                          method="bounded", options={"xatol": 2e-5})
    return float(res.x), float(res.fun)


def deviation_curves(heron: Heron, lambdas, nb: int):
    """Rows (k, λ, b, n, D_traced, D_formula, θ_traced) on b = (j + ½)/nb."""
    ns = dict(zip(lambdas, pmap(lambda lam: water_n(heron, lam), lambdas)))
    jobs = [(k, lam, (j + 0.5) / nb) for k in (1, 2) for lam in lambdas for j in range(nb)]
    traced = pmap(lambda job: traced_deviation(heron, job[2], job[1], job[0]), jobs)
    rows = []
    for (k, lam, b), d_t in zip(jobs, traced):
        n = ns[lam]
        rows.append((k, lam, b, n, d_t, formula_deviation(b, n, k), theta_from_deviation(d_t)))
    return rows


def rainbow_angles(heron: Heron, lambdas, search_every: int):
    """Rows (λ, n, θ1_formula, θ2_formula, θ1_trace, θ2_trace); the traced minimum
    search runs at every `search_every`-th wavelength (NaN elsewhere)."""
    ns = pmap(lambda lam: water_n(heron, lam), lambdas)
    jobs = [(idx, lam, k, n) for idx, (lam, n) in enumerate(zip(lambdas, ns))
            for k in (1, 2) if idx % search_every == 0]
    found = pmap(lambda job: traced_minimum(heron, job[1], job[2], job[3])[1], jobs)
    theta_min = {(job[0], job[2]): theta_from_deviation(d) for job, d in zip(jobs, found)}
    nan = float("nan")
    rows = [(lam, n, formula_rainbow_angle(n, 1), formula_rainbow_angle(n, 2),
             theta_min.get((idx, 1), nan), theta_min.get((idx, 2), nan))
            for idx, (lam, n) in enumerate(zip(lambdas, ns))]
    return np.array(rows, dtype=float)
