//! `heron sky lee`: Lee diagrams, the colour of the rainbow against drop radius and angle
//! (R. L. Lee Jr., "Mie theory, Airy theory, and the natural rainbow", Applied Optics
//! 37(9), 1506–1519, 1998: colour maps of the bow against drop radius from Mie theory).
//!
//! For each drop radius a (log-spaced) and wavelength λ the Lorenz–Mie profile of
//! [`MieSky`] (every radius by Mie: the largest, 1 mm, costs about a second per wavelength,
//! which is affordable; no switch to Airy) gives the sky's relative radiance
//! p(θ, λ) = dσ/dΩ / (π a²), averaged over the solar disk (radius 0.2666° by default),
//! at the angles θ from the antisolar point asked for. The sun is CIE D65 (a daylight
//! spectrum; [`cie::d65_relative`]) and the observer the CIE 1931 2° one, as heron's film:
//!
//!   X = Σ_λ p(θ, λ) S(λ) x̄(λ) / Σ_λ S(λ) ȳ(λ)
//!
//! over λ = 380, 380 + Δλ, …, ≤ 780 nm, so Y is the luminance relative to a white sheet
//! that returns the sun's light with p = 1 sr⁻¹. Colours: linear sRGB (IEC 61966-2-1) of
//! XYZ / Y_max, where Y_max is the largest Y of that radius (each radius's brightest
//! angle has Y = 1; bows of small drops are much dimmer, and Lee's diagrams show hue and
//! saturation, not that), brought into the sRGB gamut by the display transform asked for
//! (`spectrum::display`: by default keeping their hue, or clipped per channel) and
//! encoded with the sRGB transfer function.
use super::MieSky;
use crate::spectrum::display::DisplayTransform;
use crate::spectrum::{cie, color};
use crate::{HeronError, Result};
use rayon::prelude::*;
use std::fmt::Write;

/// What `heron sky lee` was asked for (radii in mm, angles in degrees, λ step in nm).
#[derive(Clone, Debug)]
pub struct LeeRequest {
    pub radius_from_mm: f64,
    pub radius_to_mm: f64,
    pub radii: usize,
    pub from_deg: f64,
    pub to_deg: f64,
    pub step_deg: f64,
    pub lambda_step_nm: f64,
    pub sun_radius_deg: f64,
    /// How the R, G, B columns are encoded.
    pub display: DisplayTransform,
}

/// First and last wavelength of the colour sums, nm.
pub const LEE_LAMBDA_FROM: f64 = 380.0;
pub const LEE_LAMBDA_TO: f64 = 780.0;
/// Most (radius, angle) rows.
pub const LEE_MAX_ROWS: usize = 1_000_000;

fn bad(msg: String) -> HeronError {
    HeronError::Invalid(msg)
}

impl LeeRequest {
    fn validate(&self) -> Result<()> {
        let max = super::spec::MIE_MAX_RADIUS_MM;
        for (flag, v) in [
            ("--radius-from", self.radius_from_mm),
            ("--radius-to", self.radius_to_mm),
        ] {
            if !(v.is_finite() && v >= 1e-3 && v <= max) {
                return Err(bad(format!(
                    "{flag}: expected a drop radius in [0.001, {max}] mm, got {v}"
                )));
            }
        }
        if self.radius_from_mm > self.radius_to_mm {
            return Err(bad(format!(
                "--radius-from {} is larger than --radius-to {}",
                self.radius_from_mm, self.radius_to_mm
            )));
        }
        if !(1..=10_000).contains(&self.radii) {
            return Err(bad(format!(
                "--radii: expected a count in 1..=10000, got {}",
                self.radii
            )));
        }
        if self.radii == 1 && self.radius_from_mm != self.radius_to_mm {
            return Err(bad(
                "--radii 1: needs --radius-from equal to --radius-to".into()
            ));
        }
        if !(self.lambda_step_nm.is_finite()
            && self.lambda_step_nm >= 1.0
            && self.lambda_step_nm <= 50.0)
        {
            return Err(bad(format!(
                "--lambda-step: expected a step in [1, 50] nm, got {}",
                self.lambda_step_nm
            )));
        }
        super::spec::check_sun_radius(self.sun_radius_deg, "--sun-radius").map_err(bad)
    }

    /// The radii (mm): log-spaced from `radius_from_mm` to `radius_to_mm`.
    pub fn radii_mm(&self) -> Vec<f64> {
        if self.radii == 1 {
            return vec![self.radius_from_mm];
        }
        let (a, b) = (self.radius_from_mm.ln(), self.radius_to_mm.ln());
        (0..self.radii)
            .map(|i| {
                let r = (a + (b - a) * i as f64 / (self.radii - 1) as f64).exp();
                // Round to 9 significant digits so the CSV's radius is the one computed.
                let p = 10f64.powi(8 - r.log10().floor() as i32);
                (r * p).round() / p
            })
            .collect()
    }

    /// The wavelengths of the colour sums, nm.
    pub fn lambdas(&self) -> Vec<f32> {
        let n = ((LEE_LAMBDA_TO - LEE_LAMBDA_FROM) / self.lambda_step_nm + 1e-9).floor() as usize;
        (0..=n)
            .map(|i| (LEE_LAMBDA_FROM + self.lambda_step_nm * i as f64) as f32)
            .collect()
    }
}

/// A computed Lee diagram.
#[derive(Clone, Debug)]
pub struct LeeDiagram {
    /// Drop radii, mm.
    pub radii_mm: Vec<f64>,
    /// Angles from the antisolar point, degrees.
    pub theta_deg: Vec<f64>,
    /// X, Y, Z of every (radius, angle), radius-major: `xyz[radius][angle]`.
    pub xyz: Vec<Vec<[f64; 3]>>,
}

/// Computes the diagram of a request.
pub fn lee_xyz(req: &LeeRequest) -> Result<LeeDiagram> {
    req.validate()?;
    let thetas = super::profile::angles(req.from_deg, req.to_deg, req.step_deg)?;
    let radii = req.radii_mm();
    if radii.len() * thetas.len() > LEE_MAX_ROWS {
        return Err(bad(format!(
            "--radii × angles: {} rows, more than {LEE_MAX_ROWS}",
            radii.len() * thetas.len()
        )));
    }
    let lambdas = req.lambdas();
    let obs = cie::cie1931();
    let sun = cie::d65_relative();
    let norm: f64 = lambdas
        .iter()
        .map(|&l| sun.eval(l) as f64 * obs.y.eval(l) as f64)
        .sum();
    let weights: Vec<[f64; 3]> = lambdas
        .iter()
        .map(|&l| {
            let s = sun.eval(l) as f64 / norm;
            [
                s * obs.x.eval(l) as f64,
                s * obs.y.eval(l) as f64,
                s * obs.z.eval(l) as f64,
            ]
        })
        .collect();
    let alpha = req.sun_radius_deg.to_radians();
    // Tabulate only the angles asked for (plus the disk and a margin), finely.
    let lo = (req.from_deg - req.sun_radius_deg - 0.5)
        .max(0.0)
        .to_radians();
    let hi = (req.to_deg + req.sun_radius_deg + 0.5)
        .min(180.0)
        .to_radians();
    // One job per (radius, λ); each is computed independently and summed below in a
    // fixed order, so the output does not depend on the thread count.
    let jobs: Vec<(usize, usize)> = (0..radii.len())
        .flat_map(|r| (0..lambdas.len()).map(move |l| (r, l)))
        .collect();
    let profiles: Vec<Vec<f64>> = jobs
        .par_iter()
        .map(|&(r, l)| {
            let mut sky = MieSky::water(radii[r], alpha);
            sky.window = (lo, hi);
            sky.window_only = true;
            let t = sky.compute_table(lambdas[l]);
            thetas.iter().map(|d| t.eval(d.to_radians())).collect()
        })
        .collect();
    let mut xyz = vec![vec![[0.0f64; 3]; thetas.len()]; radii.len()];
    for (&(r, l), p) in jobs.iter().zip(&profiles) {
        for (cell, v) in xyz[r].iter_mut().zip(p) {
            for c in 0..3 {
                cell[c] += v * weights[l][c];
            }
        }
    }
    Ok(LeeDiagram {
        radii_mm: radii,
        theta_deg: thetas,
        xyz,
    })
}

/// The CSV of a request: `radius_mm,theta_deg,X,Y,Z,R,G,B` (R, G, B: encoded sRGB in
/// [0, 1] of XYZ / the radius's largest Y through the request's display transform, see the
/// module documentation).
pub fn lee_csv(req: &LeeRequest) -> Result<String> {
    let LeeDiagram {
        radii_mm: radii,
        theta_deg: thetas,
        xyz,
    } = lee_xyz(req)?;
    let mut out = String::from("radius_mm,theta_deg,X,Y,Z,R,G,B\n");
    for (r, row) in radii.iter().zip(&xyz) {
        let ymax = row.iter().map(|c| c[1]).fold(0.0, f64::max);
        for (t, c) in thetas.iter().zip(row) {
            let k = if ymax > 0.0 { 1.0 / ymax } else { 0.0 };
            let lin = color::xyz_to_linear_srgb([
                (c[0] * k) as f32,
                (c[1] * k) as f32,
                (c[2] * k) as f32,
            ]);
            let [sr, sg, sb] = req.display.encode(lin);
            writeln!(
                out,
                "{r},{t},{:.6e},{:.6e},{:.6e},{sr:.6},{sg:.6},{sb:.6}",
                c[0], c[1], c[2],
            )
            .unwrap();
        }
    }
    Ok(out)
}

/// Writes the CSV to `path` through a temporary file renamed into place (no half-written
/// file on error).
pub fn write_csv(path: &std::path::Path, csv: &str) -> Result<()> {
    crate::files::write_atomically(path, |tmp| {
        std::fs::write(tmp, csv).map_err(|e| format!("{}: {e}", path.display()))
    })
}
