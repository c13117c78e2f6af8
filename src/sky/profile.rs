//! `heron sky profile`: radiance against the angle from the antisolar point as CSV, one
//! column per wavelength; its flags (the Python module's `heron.sky_profile` passes its
//! keyword arguments as the same flags) mapped to a [`SkySpec`], which holds the rules and
//! the limits. And `heron sky mie-phase` (hidden), the raw Mie amplitudes for the
//! miepython comparison in tests/python/test_mie.py.
use super::{Sky, SkyKey, SkySpec};
use crate::spectrum::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use crate::{HeronError, Result};
use std::fmt::Write;

/// What `heron sky profile` was asked for (angles in degrees, radius in mm).
#[derive(Clone, Debug)]
pub struct ProfileRequest {
    pub model: String,
    pub sun_radius_deg: f64,
    pub droplet_radius_mm: Option<f64>,
    pub lambdas: String,
    pub from_deg: f64,
    pub to_deg: f64,
    pub step_deg: f64,
    pub k: Option<String>,
    pub polarisation: Option<String>,
    /// Background radiance for `constant` (default 1) and `aristotle` (default 0).
    pub background: Option<f64>,
    /// A drop-size distribution (airy, mie) from the flags `--distribution`,
    /// `--median-mm`, …: the scene table's keys ([`crate::drops::DropsFile`]); the
    /// monodisperse radius is `--droplet-radius`.
    pub drops: Option<crate::drops::DropsFile>,
    /// Only Debye term p (mie).
    pub debye: Option<u32>,
}

/// The CLI flag of a drop-size distribution key: `median_mm` → `--median-mm`.
pub fn drops_flag(key: &str) -> String {
    format!("--{}", key.replace('_', "-"))
}

fn bad(msg: String) -> HeronError {
    HeronError::Invalid(msg)
}

/// Parses `--lambda NM[,NM…]`: each in 360–830 nm.
pub fn parse_lambdas(s: &str) -> Result<Vec<f32>> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| {
            let t = t.trim();
            let l: f32 = t
                .parse()
                .ok()
                .filter(|x: &f32| x.is_finite())
                .ok_or_else(|| bad(format!("--lambda: expected numbers in nm, got {t:?}")))?;
            if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&l) {
                return Err(bad(format!(
                    "--lambda: expected wavelengths in 360–830 nm, got {t}"
                )));
            }
            Ok(l)
        })
        .collect::<Result<_>>()?;
    Ok(v)
}

/// The flag that names `key` of a [`SkySpec`] on the command line (the Python module
/// renames the flags to its arguments).
pub fn flag(key: SkyKey) -> String {
    match key {
        SkyKey::Model => "--model".into(),
        SkyKey::SunRadius => "--sun-radius".into(),
        // A monodisperse distribution takes its radius from --droplet-radius.
        SkyKey::DropletRadius | SkyKey::Drop("radius_mm") => "--droplet-radius".into(),
        SkyKey::Orders => "--k".into(),
        SkyKey::Polarisation => "--polarisation".into(),
        SkyKey::Drops => "--distribution".into(),
        SkyKey::Drop(k) => drops_flag(k),
        SkyKey::MonodisperseDrops => "--distribution monodisperse --droplet-radius …".into(),
        SkyKey::Debye => "--debye".into(),
        SkyKey::Background => "--background".into(),
    }
}

/// `--k`: 1, 2, both, 0 (the external reflection) or all (0, 1 and 2) as a list of
/// orders; which orders a model takes is [`SkySpec`]'s rule.
fn parse_orders(k: &str) -> Result<Vec<u32>> {
    match k {
        "1" => Ok(vec![1]),
        "2" => Ok(vec![2]),
        "both" => Ok(vec![1, 2]),
        "0" => Ok(vec![0]),
        "all" => Ok(vec![0, 1, 2]),
        other => Err(bad(format!(
            "--k: expected 1, 2 or both (descartes also 0 or all), got {other:?}"
        ))),
    }
}

/// Largest number of rows.
pub const MAX_ROWS: usize = 2_000_000;

/// The sky of a request as a [`SkySpec`]: each flag to its key, a monodisperse
/// `--distribution` with the radius of `--droplet-radius`.
pub fn sky_spec(req: &ProfileRequest) -> Result<SkySpec> {
    let mut droplet_radius_mm = req.droplet_radius_mm;
    let mut drops = req.drops.clone();
    if let Some(f) = &mut drops {
        if f.distribution == "monodisperse" {
            f.radius_mm = droplet_radius_mm.take();
        }
    }
    Ok(SkySpec {
        model: req.model.clone(),
        sun_radius_deg: req.sun_radius_deg,
        sun_radius_rad: req.sun_radius_deg.to_radians(),
        droplet_radius_mm,
        drops,
        orders: req.k.as_deref().map(parse_orders).transpose()?,
        polarisation: req.polarisation.clone(),
        debye: req.debye,
        background: req.background.map(|b| DenseSpectrum::constant(b as f32)),
    })
}

/// Builds the model of a request (validating every value by [`SkySpec::build`], errors
/// named by flag).
pub fn build_sky(req: &ProfileRequest) -> Result<Sky> {
    sky_spec(req)?.build(&flag).map_err(bad)
}

/// The θ values (degrees) of a request.
pub fn angles(from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
    angles_from("the antisolar point", from, to, step)
}

/// The angles `--from`, `--to`, `--step` (degrees) measured from `origin`, which the
/// messages name: `heron sky profile`'s from the antisolar point, `heron halo
/// profile`'s from the sun.
pub fn angles_from(origin: &str, from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
    if !(from.is_finite() && to.is_finite() && step.is_finite()) {
        return Err(bad("--from, --to, --step: expected finite numbers".into()));
    }
    if step <= 0.0 {
        return Err(bad(format!(
            "--step: expected a positive angle, got {step}"
        )));
    }
    if !(0.0..=180.0).contains(&from) || !(0.0..=180.0).contains(&to) {
        return Err(bad(format!(
            "--from, --to: expected angles in 0–180° from {origin}, got {from} and {to}"
        )));
    }
    if from > to {
        return Err(bad(format!("--from {from} is larger than --to {to}")));
    }
    // Counted in f64 first: a tiny step would saturate the cast and wrap the + 1.
    let rows = ((to - from) / step * (1.0 + 1e-12) + 1e-9).floor() + 1.0;
    if rows > MAX_ROWS as f64 {
        return Err(bad(format!(
            "--step {step}: {rows} rows, more than {MAX_ROWS}; use a larger step"
        )));
    }
    let n = rows as usize;
    Ok((0..n)
        .map(|i| {
            let t = from + step * i as f64;
            (t * 1e9).round() / 1e9
        })
        .collect())
}

/// The numbers of a request: radiance at each angle and wavelength.
#[derive(Clone, Debug)]
pub struct Profile {
    pub lambdas: Vec<f32>,
    pub thetas_deg: Vec<f64>,
    /// Row-major: one row of `lambdas.len()` values per angle ([`profile_table`]).
    pub table: Vec<f32>,
}

impl Profile {
    /// The CSV text: `theta_deg,<λ1>nm,…`, one row per angle.
    pub fn csv(&self) -> String {
        let mut out = String::from("theta_deg");
        for l in &self.lambdas {
            write!(out, ",{l}nm").unwrap();
        }
        out.push('\n');
        for (&t, row) in self
            .thetas_deg
            .iter()
            .zip(self.table.chunks(self.lambdas.len().max(1)))
        {
            write!(out, "{t}").unwrap();
            for v in row {
                write!(out, ",{v:.6e}").unwrap();
            }
            out.push('\n');
        }
        out
    }
}

/// Evaluates a request (every flag checked first).
pub fn profile(req: &ProfileRequest) -> Result<Profile> {
    let lambdas = parse_lambdas(&req.lambdas)?;
    let thetas_deg = angles(req.from_deg, req.to_deg, req.step_deg)?;
    let sky = build_sky(req)?;
    let table = profile_table(&sky, &lambdas, &thetas_deg);
    Ok(Profile {
        lambdas,
        thetas_deg,
        table,
    })
}

/// The CSV text of a request: `theta_deg,<λ1>nm,…`, one row per angle.
pub fn profile_csv(req: &ProfileRequest) -> Result<String> {
    Ok(profile(req)?.csv())
}

/// The radiance of `sky` at each angle of `thetas_deg` (degrees from the antisolar
/// point) and wavelength of `lambdas` (nm, checked by [`parse_lambdas`]), row-major:
/// `thetas_deg.len()` rows of `lambdas.len()` values. The numbers of `heron sky
/// profile` and of the Python module's `heron.sky_profile`.
pub fn profile_table(sky: &Sky, lambdas: &[f32], thetas_deg: &[f64]) -> Vec<f32> {
    if let Sky::Mie(m) = sky {
        m.prepare(lambdas);
    }
    let mut out = Vec::with_capacity(thetas_deg.len() * lambdas.len());
    for &t in thetas_deg {
        for &l in lambdas {
            out.push(sky.profile(t.to_radians(), l));
        }
    }
    out
}

/// `heron sky mie-phase`: S₁, S₂ of a sphere of real index `m` and size parameter `x` at
/// scattering angles from..to (degrees) as CSV `angle_deg,s1_re,s1_im,s2_re,s2_im`
/// (Bohren & Huffman's convention, no normalisation).
pub fn mie_phase_csv(m: f64, x: f64, from: f64, to: f64, step: f64) -> Result<String> {
    if !(m.is_finite() && m > 1.0 && m < 3.0) {
        return Err(bad(format!(
            "--m: expected a real index in (1, 3), got {m}"
        )));
    }
    if !(x.is_finite() && x > 0.0 && x <= 100_000.0) {
        return Err(bad(format!(
            "--x: expected a size parameter in (0, 1e5], got {x}"
        )));
    }
    let thetas = angles(from, to, step)?;
    let c = crate::optics::mie::coefficients(m, x);
    let mut out = String::from("angle_deg,s1_re,s1_im,s2_re,s2_im\n");
    for t in thetas {
        let (s1, s2) = crate::optics::mie::amplitudes(&c, t.to_radians().cos());
        writeln!(
            out,
            "{t},{:.17e},{:.17e},{:.17e},{:.17e}",
            s1.re, s1.im, s2.re, s2.im
        )
        .unwrap();
    }
    Ok(out)
}
