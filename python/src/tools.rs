//! `heron.trace`, `heron.sky_profile`, `heron.color` and `heron.ior`: the cores of
//! `heron trace`, `heron sky profile`, `heron color` and the scene files' `ior` values.
use crate::convert::{json_to_py, numbers, to_toml, vec3};
use crate::{err, guard, lib_err};
use heron_core::colorimetry::{colour_of, Illuminant, StandardObserver};
use heron_core::spectrum::interp::Interpolation;
use heron_core::spectrum::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::Path;

/// Follows one ray at one wavelength through a scene, event by event, as `heron trace`
/// does (the renderer's own intersection, materials and ray offsets); returns the
/// events as a list of dicts with the keys of the CLI's JSON: kind ("reflect",
/// "refract", "total-internal-reflection", "absorb", "escape"), position, normal,
/// material, n_i, n_t, incoming, outgoing, fresnel_r, distance (None where absent),
/// and with `stokes` also stokes and stokes_x.
///
/// scene: a heron.Scene or a path to a scene file. origin, direction: three numbers
/// (direction normalised here). wavelength: nm, 360–830. path: `heron trace --path`, a
/// string of R and T letters: at the k-th event at a surface that both reflects and
/// transmits (a smooth dielectric), R reflects and T transmits; past the string's end,
/// and by default, rays transmit; total internal reflection forces R. "TRT" is the
/// primary rainbow ray of a drop. The trace stops at absorption, escape, or after the
/// scene's max_depth continuations (the last event then still has an outgoing
/// direction). stokes: `heron trace --stokes`, the light's Stokes vector (S0, S1, S2,
/// S3) to start from, e.g. (1, 0, 0, 0); each event then reports the Stokes vector after
/// it (power) and its frame's x̂ (stokes_x).
#[pyfunction]
#[pyo3(signature = (scene, origin, direction, wavelength, path=None, stokes=None))]
pub fn trace<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    origin: &Bound<'py, PyAny>,
    direction: &Bound<'py, PyAny>,
    wavelength: f64,
    path: Option<&str>,
    stokes: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    guard(|| {
        // The CLI's flags, by the names of this function's arguments.
        const RENAMES: &[(&str, &str)] = &[
            ("--origin", "origin"),
            ("--dir", "direction"),
            ("--lambda", "wavelength"),
            ("--path", "path"),
            ("--stokes", "stokes"),
        ];
        let choices =
            heron_core::trace::parse_path(path.unwrap_or("")).map_err(|e| lib_err(e, RENAMES))?;
        let origin = vec3(origin, "origin")?;
        let direction = vec3(direction, "direction")?;
        let stokes = match stokes {
            None => None,
            Some(s) => {
                let v = numbers(s, "stokes")?;
                Some(<[f64; 4]>::try_from(v.as_slice()).map_err(|_| {
                    err(format!(
                        "stokes: expected four numbers (S0, S1, S2, S3), got {}",
                        v.len()
                    ))
                })?)
            }
        };
        let scene = crate::scene::scene_arg(py, scene)?;
        let report = py
            .detach(|| {
                let renderer = heron_core::render::Renderer::new(&scene)?;
                heron_core::trace::trace(
                    &scene,
                    renderer.accel(),
                    origin,
                    direction,
                    wavelength as f32,
                    &choices,
                    stokes,
                )
            })
            .map_err(|e| lib_err(e, RENAMES))?;
        let json = serde_json::to_value(&report.events)
            .map_err(|e| err(format!("cannot convert the trace: {e}")))?;
        json_to_py(py, &json)?
            .cast_into::<PyList>()
            .map_err(|_| err("internal error in heron: the trace's events are not a list"))
    })
}

/// Radiance of a sky model against the angle θ from the antisolar point, as `heron sky
/// profile` computes it; returns a float32 array of len(theta) rows and len(wavelengths)
/// columns.
///
/// model: constant, aristotle, descartes, airy or mie. wavelengths: nm (360–830).
/// theta: degrees from the antisolar point (0–180). Options as the CLI's flags:
/// sun_radius (degrees, default 0.2666), droplet_radius (mm; airy and mie), k ("1", "2",
/// "both"; descartes also "0" and "all"; descartes and airy), polarisation
/// ("unpolarised", "s", "p"; descartes, airy and mie), background (constant: default 1,
/// aristotle: default 0), drops (airy and mie: a drop-size distribution as the scene
/// files' `[sky] drops` table, e.g. {"distribution": "lognormal", "median_mm": 0.5,
/// "sigma": 0.1}; monodisperse takes droplet_radius), debye (mie: only the Debye term
/// p, 0–20). Units: dσ/dΩ/(πa²) per sr for descartes, airy and mie (averaged over the
/// distribution: ⟨dσ/dΩ⟩/⟨πa²⟩); the texture's radiance for aristotle.
#[pyfunction]
#[pyo3(signature = (model, wavelengths, theta, *, sun_radius=0.2666, droplet_radius=None, k=None, polarisation=None, background=None, drops=None, debye=None))]
pub fn sky_profile<'py>(
    py: Python<'py>,
    model: &str,
    wavelengths: &Bound<'py, PyAny>,
    theta: &Bound<'py, PyAny>,
    sun_radius: f64,
    droplet_radius: Option<f64>,
    k: Option<&Bound<'py, PyAny>>,
    polarisation: Option<&str>,
    background: Option<f64>,
    drops: Option<&Bound<'py, PyAny>>,
    debye: Option<u32>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    guard(|| {
        use heron_core::sky::profile;
        const RENAMES: &[(&str, &str)] = &[
            ("--model", "model"),
            ("--sun-radius", "sun_radius"),
            ("--droplet-radius", "droplet_radius"),
            ("--lambda", "wavelengths"),
            ("--k", "k"),
            ("--polarisation", "polarisation"),
            ("--background", "background"),
            ("--distribution", "drops['distribution']"),
            ("--median-mm", "drops['median_mm']"),
            ("--sigma", "drops['sigma']"),
            ("--mode-mm", "drops['mode_mm']"),
            ("--mu", "drops['mu']"),
            ("--rain-rate-mm-h", "drops['rain_rate_mm_h']"),
            ("--nodes", "drops['nodes']"),
            ("--debye", "debye"),
        ];
        // The distribution as the scene files' table, through the same serde schema.
        let drops = match drops {
            None => None,
            Some(d) => Some(
                to_toml(d, "drops")?
                    .try_into::<heron_core::drops::DropsFile>()
                    .map_err(|e| err(format!("drops: {}", e.message())))?,
            ),
        };
        // `k` as the CLI's text: 1 and "1" alike.
        let k = match k {
            None => None,
            Some(v) => Some(match v.extract::<i64>() {
                Ok(i) => i.to_string(),
                Err(_) => v.str()?.to_string(),
            }),
        };
        // The wavelengths go through the CLI's own parser: each f32 written in its
        // shortest form reads back as the same number.
        let lambdas_text = numbers(wavelengths, "wavelengths")?
            .iter()
            .map(|&l| (l as f32).to_string())
            .collect::<Vec<_>>()
            .join(",");
        let lambdas = profile::parse_lambdas(&lambdas_text).map_err(|e| lib_err(e, RENAMES))?;
        let thetas = numbers(theta, "theta")?;
        if let Some(t) = thetas.iter().find(|t| !(0.0..=180.0).contains(*t)) {
            return Err(err(format!(
                "theta: expected angles in 0–180° from the antisolar point, got {t}"
            )));
        }
        if thetas.len() > profile::MAX_ROWS {
            return Err(err(format!(
                "theta: {} angles, more than {}",
                thetas.len(),
                profile::MAX_ROWS
            )));
        }
        let req = profile::ProfileRequest {
            model: model.to_string(),
            sun_radius_deg: sun_radius,
            droplet_radius_mm: droplet_radius,
            lambdas: lambdas_text,
            from_deg: 0.0,
            to_deg: 0.0,
            step_deg: 1.0,
            k,
            polarisation: polarisation.map(str::to_string),
            background,
            drops,
            debye,
        };
        let sky = profile::build_sky(&req).map_err(|e| lib_err(e, RENAMES))?;
        let (rows, cols) = (thetas.len(), lambdas.len());
        let table = py.detach(|| profile::profile_table(&sky, &lambdas, &thetas));
        table.into_pyarray(py).reshape([rows, cols])
    })
}

/// The halo sky's radiance per unit solar irradiance (sr⁻¹) along great circles through
/// the sun, as `heron halo profile` computes it; returns a float32 array of
/// len(theta) × len(psi) × len(wavelengths).
///
/// sun_elevation: degrees above the horizon. crystals: a list of populations as the
/// scene files' `[sky] crystals` tables, e.g. [{"orientation": "plates", "aspect": 0.2,
/// "tilt_deg": 0.5}]. theta: degrees from the sun (0–180). psi: position angles of the
/// great circles (degrees: 0 up toward the zenith, 90 sideways; default [0, 90, 180]).
/// sun_radius (degrees, default 0.2666), rays (per wavelength row of the table, default
/// 2^20) and seed (default 0) as the CLI's flags.
#[pyfunction]
#[pyo3(signature = (sun_elevation, crystals, wavelengths, theta, *, psi=None, sun_radius=0.2666, rays=None, seed=None))]
pub fn halo_profile<'py>(
    py: Python<'py>,
    sun_elevation: f64,
    crystals: &Bound<'py, PyAny>,
    wavelengths: &Bound<'py, PyAny>,
    theta: &Bound<'py, PyAny>,
    psi: Option<&Bound<'py, PyAny>>,
    sun_radius: f64,
    rays: Option<u64>,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        use heron_core::sky::halo::{profile, CrystalFile, HaloKey, HaloSpec};
        const RENAMES: &[(&str, &str)] =
            &[("--lambda", "wavelengths"), ("--sun-radius", "sun_radius")];
        let list = crystals
            .cast::<PyList>()
            .map_err(|_| err("crystals: expected a list of dicts, one per population"))?;
        let crystals = list
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let at = format!("crystals[{i}]");
                to_toml(&c, &at)?
                    .try_into::<CrystalFile>()
                    .map_err(|e| err(format!("{at}: {}", e.message())))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let lambdas_text = numbers(wavelengths, "wavelengths")?
            .iter()
            .map(|&l| (l as f32).to_string())
            .collect::<Vec<_>>()
            .join(",");
        let lambdas = heron_core::sky::profile::parse_lambdas(&lambdas_text)
            .map_err(|e| lib_err(e, RENAMES))?;
        let thetas = numbers(theta, "theta")?;
        if let Some(t) = thetas.iter().find(|t| !(0.0..=180.0).contains(*t)) {
            return Err(err(format!(
                "theta: expected angles in 0–180° from the sun, got {t}"
            )));
        }
        let psis = match psi {
            None => vec![0.0, 90.0, 180.0],
            Some(p) => numbers(p, "psi")?,
        };
        if let Some(p) = psis.iter().find(|p| !(-180.0..=180.0).contains(*p)) {
            return Err(err(format!(
                "psi: expected position angles in −180…180°, got {p}"
            )));
        }
        heron_core::sky::spec::check_sun_radius(sun_radius, "sun_radius").map_err(err)?;
        let spec = HaloSpec {
            sun_elevation_deg: sun_elevation,
            sun_radius_rad: sun_radius.to_radians(),
            crystals,
            rays,
            seed,
        };
        let sky = spec
            .build(&|k| match k {
                HaloKey::Crystals => "crystals".into(),
                HaloKey::Crystal(i, key) => format!("crystals[{i}].{key}"),
                HaloKey::SunElevation => "sun_elevation".into(),
                HaloKey::Rays => "rays".into(),
            })
            .map_err(err)?;
        let shape = [thetas.len(), psis.len(), lambdas.len()];
        let table = py.detach(|| profile::sample(sky.table(), &thetas, &psis, &lambdas));
        Ok(table.into_pyarray(py).reshape(shape)?.into_any())
    })
}

/// The colour of a spectral distribution, as `heron color` computes it for a CSV file:
/// returns a dict with "XYZ" (3 floats), "xy" (2 floats, None when X + Y + Z = 0),
/// "linear_srgb" (3 floats, IEC 61966-2-1 without chromatic adaptation), "observer" and
/// "illuminant".
///
/// wavelengths (nm, strictly increasing) and values: at least two samples, interpolated
/// onto heron's 1 nm grid over 360–830 nm as colour-science does (held constant beyond
/// the ends): interpolation "cie167" (Sprague or cubic spline) or "linear" (as
/// colour-science interpolates its SDS_ILLUMINANTS). illuminant: "D65", "D50", "A" or
/// "E" (values are a reflectance, white has Y = 1) or "none" (values are emitted, the
/// constant 1 has Y = 1). observer: "1931" (2°) or "1964" (10°).
#[pyfunction]
#[pyo3(
    signature = (wavelengths, values, illuminant="D65", observer=None, interpolation="cie167"),
    text_signature = "(wavelengths, values, illuminant='D65', observer='1931', interpolation='cie167')"
)]
pub fn color<'py>(
    py: Python<'py>,
    wavelengths: &Bound<'py, PyAny>,
    values: &Bound<'py, PyAny>,
    illuminant: &str,
    observer: Option<&Bound<'py, PyAny>>,
    interpolation: &str,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let illuminant: Illuminant = illuminant
            .parse()
            .map_err(|e| err(format!("illuminant: {e}")))?;
        let interpolation: Interpolation = interpolation
            .parse()
            .map_err(|e| err(format!("interpolation: {e}")))?;
        // 1931 and "1931" alike.
        let observer_text = match observer {
            None => "1931".to_string(),
            Some(o) => match o.extract::<i64>() {
                Ok(i) => i.to_string(),
                Err(_) => o.str()?.to_string(),
            },
        };
        let observer: StandardObserver = observer_text
            .parse()
            .map_err(|e| err(format!("observer: {e}")))?;
        let samples = spectral_samples(
            &numbers(wavelengths, "wavelengths")?,
            &numbers(values, "values")?,
        )?;
        // The same interpolation and check as a CSV file's (SpectrumCsv::parse).
        heron_core::spectrum::csv::interpolate_column(Path::new("values"), "value", &samples)
            .map_err(|e| lib_err(e, &[]))?;
        let dense = DenseSpectrum::from_table_with(&samples, interpolation);
        let c = colour_of(&dense, observer, illuminant);
        let d = PyDict::new(py);
        d.set_item("XYZ", c.xyz.to_vec())?;
        d.set_item("xy", c.xy.map(|v| v.to_vec()))?;
        d.set_item("linear_srgb", c.linear_srgb.to_vec())?;
        d.set_item("observer", observer.name())?;
        d.set_item("illuminant", illuminant.name())?;
        d.set_item("interpolation", interpolation.name())?;
        Ok(d)
    })
}

/// (λ, value) rows checked as `heron color` checks a CSV's (finite in f32, wavelengths
/// strictly increasing, at least two), with messages naming the element.
fn spectral_samples(lambdas: &[f64], values: &[f64]) -> PyResult<Vec<(f32, f32)>> {
    if lambdas.len() != values.len() {
        return Err(err(format!(
            "values: expected as many values as wavelengths ({}), got {}",
            lambdas.len(),
            values.len()
        )));
    }
    if lambdas.len() < 2 {
        return Err(err(format!(
            "wavelengths, values: expected at least 2 samples, found {}",
            lambdas.len()
        )));
    }
    let finite = |name: &str, i: usize, v: f64| -> PyResult<f32> {
        let v32 = v as f32;
        if v.is_finite() && v32.is_finite() {
            Ok(v32)
        } else {
            Err(err(format!(
                "{name}[{i}]: expected a finite number (within ±3.4e38), got {v}"
            )))
        }
    };
    let mut out: Vec<(f32, f32)> = Vec::with_capacity(lambdas.len());
    for (i, (&l, &v)) in lambdas.iter().zip(values).enumerate() {
        let l = finite("wavelengths", i, l)?;
        let v = finite("values", i, v)?;
        if let Some(&(prev, _)) = out.last() {
            if l <= prev {
                return Err(err(format!(
                    "wavelengths[{i}]: expected wavelengths in strictly increasing order, got {l} nm after {prev} nm"
                )));
            }
        }
        out.push((l, v));
    }
    Ok(out)
}

/// The refractive index n(λ) of a model, as a scene file's `ior` value defines it;
/// returns a float32 array, one n per wavelength.
///
/// model: a catalogue name ("water", "N-BK7", "fused-silica", "N-SF11", "F2",
/// "diamond", Schott lens glasses such as "N-SK16" or "N-LASF9";
/// spectra/ior_catalogue.toml), a positive number (no dispersion), or a dict:
/// {"sellmeier": {"b": [...], "c": [...]}} (λ in µm, C in µm²), {"cauchy": [A, B]} or
/// [A, B, C] (λ in µm), {"table": "file.csv"} (rows wavelength_nm,n; relative to the
/// current directory). Checked as the scene loader checks it (n ≥ 1 and finite over
/// 360–830 nm). wavelengths: nm, 360–830.
#[pyfunction]
pub fn ior<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    wavelengths: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    guard(|| {
        let value = to_toml(model, "ior")?;
        let ior =
            heron_core::scene::load::ior_from_value("ior", value, Path::new("")).map_err(err)?;
        let lambdas = numbers(wavelengths, "wavelengths")?;
        let mut n = Vec::with_capacity(lambdas.len());
        for (i, &l) in lambdas.iter().enumerate() {
            if !(l >= LAMBDA_MIN as f64 && l <= LAMBDA_MAX as f64) {
                return Err(err(format!(
                    "wavelengths[{i}]: expected a wavelength in 360–830 nm, got {l}"
                )));
            }
            n.push(ior.eval(l as f32));
        }
        Ok(n.into_pyarray(py))
    })
}
