//! `heron halo profile`: the halo sky's radiance against the angle from the sun along
//! great circles through the sun, per wavelength, as CSV (and a chart). The great circle
//! at position angle ψ leaves the sun toward ψ: 0° straight up toward the zenith (the
//! upper tangent arc, the circumzenithal arc), 90° sideways (the sun dogs, for a low
//! sun), 180° straight down. The numbers are the whole table, the forward cone about the
//! sun included ([`super::FORWARD_CUT_DEG`] applies to renders only).
use super::spec::{CrystalFile, HaloKey, HaloSpec};
use super::table::HaloTable;
use crate::sky::profile::{angles_from, parse_lambdas};
use crate::sky::spec::check_sun_radius;
use crate::{HeronError, Result};
use std::fmt::Write;

/// What `heron halo profile` was asked for.
#[derive(Clone, Debug, Default)]
pub struct HaloProfileRequest {
    pub sun_elevation_deg: f64,
    pub sun_radius_deg: f64,
    /// `--crystals` flags, one population each.
    pub crystals: Vec<String>,
    /// Wavelengths, nm, comma-separated.
    pub lambdas: String,
    /// Position angles of the great circles, degrees, comma-separated.
    pub psi: String,
    pub from_deg: f64,
    pub to_deg: f64,
    pub step_deg: f64,
    pub rays: Option<u64>,
    pub seed: Option<u64>,
}

/// The profile's numbers.
#[derive(Clone, Debug)]
pub struct HaloProfile {
    pub lambdas: Vec<f32>,
    pub psis_deg: Vec<f64>,
    pub thetas_deg: Vec<f64>,
    /// thetas × psis × lambdas, row-major.
    pub table: Vec<f32>,
    /// The share of rays lost in crystals (trapped by total internal reflection).
    pub lost: f64,
}

fn bad(msg: String) -> HeronError {
    HeronError::Invalid(msg)
}

/// The flag of a key.
pub fn flag(key: HaloKey) -> String {
    match key {
        HaloKey::Crystals => "--crystals".into(),
        HaloKey::Crystal(i, k) => format!("--crystals (population {}) {k}", i + 1),
        HaloKey::SunElevation => "--sun-elevation".into(),
        HaloKey::Rays => "--rays".into(),
    }
}

fn parse_psis(s: &str) -> Result<Vec<f64>> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            t.parse::<f64>()
                .ok()
                .filter(|p| (-180.0..=180.0).contains(p))
                .ok_or_else(|| {
                    bad(format!(
                        "--psi: expected position angles in −180…180°, got {t:?}"
                    ))
                })
        })
        .collect()
}

/// The spec of a request (its flags checked).
pub fn halo_spec(req: &HaloProfileRequest) -> Result<HaloSpec> {
    check_sun_radius(req.sun_radius_deg, "--sun-radius").map_err(bad)?;
    let crystals = req
        .crystals
        .iter()
        .map(|c| CrystalFile::parse_flag(c, "--crystals"))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(bad)?;
    Ok(HaloSpec {
        sun_elevation_deg: req.sun_elevation_deg,
        sun_radius_rad: req.sun_radius_deg.to_radians(),
        crystals,
        rays: req.rays,
        seed: req.seed,
    })
}

/// Evaluates a request: every flag is checked before the table is traced.
pub fn profile(req: &HaloProfileRequest) -> Result<HaloProfile> {
    let lambdas = parse_lambdas(&req.lambdas)?;
    let psis_deg = parse_psis(&req.psi)?;
    let thetas_deg = angles_from("the sun", req.from_deg, req.to_deg, req.step_deg)?;
    let sky = halo_spec(req)?.build(&flag).map_err(bad)?;
    let table = sky.table();
    Ok(HaloProfile {
        table: sample(table, &thetas_deg, &psis_deg, &lambdas),
        lambdas,
        psis_deg,
        thetas_deg,
        lost: table.lost,
    })
}

/// The table at every (θ, ψ, λ), row-major.
pub fn sample(table: &HaloTable, thetas: &[f64], psis: &[f64], lambdas: &[f32]) -> Vec<f32> {
    let mut out = Vec::with_capacity(thetas.len() * psis.len() * lambdas.len());
    for &t in thetas {
        for &p in psis {
            for &l in lambdas {
                out.push(table.eval(t, p.abs(), l));
            }
        }
    }
    out
}

impl HaloProfile {
    /// `theta_deg,psi<ψ>_<λ>nm,…`, one row per angle from the sun.
    pub fn csv(&self) -> String {
        let mut out = String::from("theta_deg");
        for p in &self.psis_deg {
            for l in &self.lambdas {
                write!(out, ",psi{p}_{l}nm").unwrap();
            }
        }
        out.push('\n');
        let w = (self.psis_deg.len() * self.lambdas.len()).max(1);
        for (&t, row) in self.thetas_deg.iter().zip(self.table.chunks(w)) {
            write!(out, "{t}").unwrap();
            for v in row {
                write!(out, ",{v:.6e}").unwrap();
            }
            out.push('\n');
        }
        out
    }
}
