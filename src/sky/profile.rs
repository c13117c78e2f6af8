//! `heron sky profile`: radiance against the angle from the antisolar point as CSV, one
//! column per wavelength; and `heron sky mie-phase` (hidden), the raw Mie amplitudes for
//! the miepython comparison in tests/python/test_mie.py.
use super::{AirySky, AristotleSky, ConstantSky, DescartesSky, MieSky, Polarisation, Sky};
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

/// `--k`: 1, 2 or both; descartes also takes 0 (external reflection) and all (0, 1, 2).
fn parse_orders(k: Option<&str>, model: &str) -> Result<Vec<u32>> {
    match (k.unwrap_or("both"), model) {
        ("1", _) => Ok(vec![1]),
        ("2", _) => Ok(vec![2]),
        ("both", _) => Ok(vec![1, 2]),
        ("0", "descartes") => Ok(vec![0]),
        ("all", "descartes") => Ok(vec![0, 1, 2]),
        (other, _) => Err(bad(format!(
            "--k: expected 1, 2 or both (descartes also 0 or all), got {other:?}"
        ))),
    }
}

fn parse_polarisation(p: Option<&str>) -> Result<Polarisation> {
    match p.unwrap_or("unpolarised") {
        "unpolarised" | "unpolarized" => Ok(Polarisation::Unpolarised),
        "s" => Ok(Polarisation::S),
        "p" => Ok(Polarisation::P),
        other => Err(bad(format!(
            "--polarisation: expected unpolarised, s or p, got {other:?}"
        ))),
    }
}

/// Largest drop radius accepted for `mie` (x ≈ 35 000 at 360 nm: seconds per wavelength).
pub const MIE_MAX_RADIUS_MM: f64 = 2.0;
/// Largest number of rows.
pub const MAX_ROWS: usize = 2_000_000;

/// Builds the model of a request (validating every value).
pub fn build_sky(req: &ProfileRequest) -> Result<Sky> {
    let alpha = req.sun_radius_deg.to_radians();
    super::check_sun_radius(alpha)?;
    let model = req.model.as_str();
    let uses_orders = matches!(model, "descartes" | "airy");
    let uses_pol = matches!(model, "descartes" | "airy" | "mie");
    if req.k.is_some() && !uses_orders && is_model(model) {
        return Err(bad(format!(
            "--k applies to descartes and airy, not {model}"
        )));
    }
    if req.polarisation.is_some() && !uses_pol && is_model(model) {
        return Err(bad(format!(
            "--polarisation applies to descartes, airy and mie, not {model}"
        )));
    }
    if (req.drops.is_some() || req.debye.is_some())
        && is_model(model)
        && !matches!(model, "airy" | "mie")
    {
        let flag = if req.drops.is_some() {
            "--distribution"
        } else {
            "--debye"
        };
        return Err(bad(format!("{flag} applies to airy and mie, not {model}")));
    }
    if req.debye.is_some() && model == "airy" {
        return Err(bad("--debye applies to mie, not airy".into()));
    }
    if let Some(p) = req.debye {
        if p > super::mie::MAX_DEBYE_TERM {
            return Err(bad(format!(
                "--debye: expected a term p in 0..={}, got {p}",
                super::mie::MAX_DEBYE_TERM
            )));
        }
    }
    let orders = parse_orders(req.k.as_deref(), model)?;
    let pol = parse_polarisation(req.polarisation.as_deref())?;
    // A distribution other than monodisperse replaces --droplet-radius.
    let dsd = |max_mm: f64| -> Result<Option<(crate::drops::DropSizeDistribution, usize)>> {
        let Some(f) = &req.drops else { return Ok(None) };
        let mut f = f.clone();
        if f.distribution == "monodisperse" {
            f.radius_mm = req.droplet_radius_mm;
        } else if req.droplet_radius_mm.is_some() {
            return Err(bad(format!(
                "--droplet-radius: gives one radius; the {} distribution takes its own flags",
                f.distribution
            )));
        }
        let (d, n) = f
            .parse_named(&|k| {
                if k == "radius_mm" {
                    "--droplet-radius".into()
                } else {
                    drops_flag(k)
                }
            })
            .map_err(bad)?;
        let n = if model == "mie" && f.nodes.is_none() {
            crate::drops::MIE_DEFAULT_NODES
        } else {
            n
        };
        let largest = d.max_radius_mm();
        if largest > max_mm {
            return Err(bad(format!(
                "--distribution: the {model} model takes radii up to {max_mm} mm; this distribution reaches {largest:.3} mm"
            )));
        }
        Ok(Some((d, n)))
    };
    let radius = |max_mm: f64| -> Result<f64> {
        let r = req.droplet_radius_mm.ok_or_else(|| {
            bad(format!(
                "--droplet-radius: the {model} model needs a drop radius in mm"
            ))
        })?;
        if !(r.is_finite() && r > 0.0 && r <= max_mm) {
            return Err(bad(format!(
                "--droplet-radius: expected a radius in (0, {max_mm}] mm for {model}, got {r}"
            )));
        }
        // Airy and Mie need x = 2πa/λ well above 1 for the bows to exist at all.
        Ok(r)
    };
    let background = |default: f64| -> Result<DenseSpectrum> {
        let b = req.background.unwrap_or(default);
        if !(b.is_finite() && b >= 0.0) {
            return Err(bad(format!(
                "--background: expected a radiance ≥ 0, got {b}"
            )));
        }
        Ok(DenseSpectrum::constant(b as f32))
    };
    Ok(match model {
        "constant" => Sky::Constant(ConstantSky::new(background(1.0)?)),
        "aristotle" => Sky::Aristotle(AristotleSky::new(alpha, background(0.0)?)),
        "descartes" => {
            let mut s = DescartesSky::water(alpha);
            s.orders = orders;
            s.polarisation = pol;
            Sky::Descartes(s)
        }
        "airy" => {
            let mut s = match dsd(10.0)? {
                Some((d, n)) => AirySky::water(1.0, alpha).with_distribution(&d, n),
                None => AirySky::water(radius(10.0)?, alpha),
            };
            s.orders = orders;
            s.polarisation = pol;
            Sky::Airy(s)
        }
        "mie" => {
            let mut s = match dsd(MIE_MAX_RADIUS_MM)? {
                Some((d, n)) => MieSky::water(1.0, alpha).with_distribution(&d, n),
                None => MieSky::water(radius(MIE_MAX_RADIUS_MM)?, alpha),
            };
            s.polarisation = pol;
            s.debye = req.debye;
            Sky::Mie(s)
        }
        other => {
            return Err(bad(format!(
                "--model: unknown model {other:?}; expected constant, aristotle, descartes, airy or mie"
            )))
        }
    })
}

fn is_model(m: &str) -> bool {
    matches!(m, "constant" | "aristotle" | "descartes" | "airy" | "mie")
}

/// The θ values (degrees) of a request.
pub fn angles(from: f64, to: f64, step: f64) -> Result<Vec<f64>> {
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
            "--from, --to: expected angles in 0–180° from the antisolar point, got {from} and {to}"
        )));
    }
    if from > to {
        return Err(bad(format!("--from {from} is larger than --to {to}")));
    }
    let n = ((to - from) / step * (1.0 + 1e-12) + 1e-9).floor() as usize + 1;
    if n > MAX_ROWS {
        return Err(bad(format!(
            "--step {step}: {n} rows, more than {MAX_ROWS}; use a larger step"
        )));
    }
    Ok((0..n)
        .map(|i| {
            let t = from + step * i as f64;
            (t * 1e9).round() / 1e9
        })
        .collect())
}

/// The CSV text of a request: `theta_deg,<λ1>nm,…`, one row per angle.
pub fn profile_csv(req: &ProfileRequest) -> Result<String> {
    let lambdas = parse_lambdas(&req.lambdas)?;
    let thetas = angles(req.from_deg, req.to_deg, req.step_deg)?;
    let sky = build_sky(req)?;
    let table = profile_table(&sky, &lambdas, &thetas);
    let mut out = String::from("theta_deg");
    for l in &lambdas {
        write!(out, ",{l}nm").unwrap();
    }
    out.push('\n');
    for (&t, row) in thetas.iter().zip(table.chunks(lambdas.len().max(1))) {
        write!(out, "{t}").unwrap();
        for v in row {
            write!(out, ",{v:.6e}").unwrap();
        }
        out.push('\n');
    }
    Ok(out)
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
