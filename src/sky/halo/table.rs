//! The halo sky's table: the light a layer of crystals scatters toward every direction
//! of the sky, per wavelength, for one sun elevation, by Monte Carlo ray tracing
//! ([`crate::optics::ice`]) plus diffraction.
//!
//! Coordinates about the sun: θ is the angle of the view direction from the sun, ψ its
//! position angle about the sun, 0° toward the zenith (the upper tangent arc, the
//! circumzenithal arc), 90° level with the sun for a sun on the horizon (the sun dogs),
//! 180° toward the nadir. Every population is random in azimuth, so the pattern is
//! symmetric about the sun's vertical: ψ is folded into [0°, 180°].
//!
//! Cells of 0.25° in θ and 1° in ψ (the sun's disk is 0.53° across), rows every 20.4 nm
//! over 360–830 nm (24 rows; the 22° halo's edge moves 0.06° in 20 nm at 550 nm, 0.13°
//! at 400 nm, less than the disk's half-width). Every row traces
//! the same crystals and the same random numbers with its own n(λ) (common random
//! numbers), so the rows differ by dispersion alone, not by noise, and interpolating
//! between them moves an edge smoothly. A cell's value is the count of rays that left
//! toward it divided by the number of rays and by its solid angle (both halves of the
//! fold): the geometric-optics phase per unit geometric cross-section, which integrates
//! to 1 over the sphere. Diffraction, computed in closed form per population
//! ([`crate::optics::ice::scatter::diffraction_encircled`]), adds another 1 within a few
//! degrees of the sun; it is not averaged over the sun's disk (its core is narrower
//! than the cells near the sun anyway).
//!
//! Values are the sky radiance per unit solar irradiance of an optically thin layer of
//! unit geometric cross-section per unit area along the line of sight, the unit of the
//! rainbow skies (`crate::sky`).
use crate::math::rng::Rng;
use crate::optics::ice::scatter::diffraction_encircled;
use crate::optics::ice::Crystals;
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// θ cell, degrees.
pub const THETA_STEP: f64 = 0.25;
/// ψ cell, degrees.
pub const PSI_STEP: f64 = 1.0;
pub const N_THETA: usize = 720;
pub const N_PSI: usize = 180;
/// Wavelength rows over 360–830 nm.
pub const ROWS: usize = 24;

/// Orientations drawn to estimate each population's diffracting area.
const DIFFRACTION_SAMPLES: usize = 4096;

/// The table of one halo sky (see the module documentation).
#[derive(Clone, Debug)]
pub struct HaloTable {
    /// The sun's elevation, radians.
    pub sun_elevation: f64,
    /// values[(row * N_PSI + psi) * N_THETA + theta], sr⁻¹.
    values: Vec<f32>,
    /// The share of rays still inside a crystal after the tracer's limit (lost light).
    pub lost: f64,
}

/// The sun direction in the table's frame (+z the zenith, the sun at azimuth 0).
pub fn canonical_sun(elevation: f64) -> DVec3 {
    DVec3::new(elevation.cos(), 0.0, elevation.sin())
}

/// The frame about the sun: e1 toward the zenith across the sun, e2 = sun × e1. For a
/// sun at the zenith or nadir (no vertical plane) any perpendicular.
fn sun_frame(sun: DVec3, zenith: DVec3) -> (DVec3, DVec3) {
    let e1 = zenith - sun * zenith.dot(sun);
    let e1 = if e1.length_squared() > 1e-18 {
        e1.normalize()
    } else {
        sun.any_orthonormal_vector()
    };
    (e1, sun.cross(e1))
}

/// (θ, ψ) in degrees of the unit view direction `v` about the unit `sun`, with the unit
/// `zenith` defining ψ = 0; ψ folded into [0°, 180°].
pub fn sun_coordinates(v: DVec3, sun: DVec3, zenith: DVec3) -> (f64, f64) {
    let theta = v.cross(sun).length().atan2(v.dot(sun)).to_degrees();
    let (e1, e2) = sun_frame(sun, zenith);
    let psi = v.dot(e2).abs().atan2(v.dot(e1)).to_degrees();
    (theta, psi)
}

/// The unit direction at (θ, ψ) degrees about `sun`; ψ's sign picks the side.
pub fn from_sun_coordinates(theta_deg: f64, psi_deg: f64, sun: DVec3, zenith: DVec3) -> DVec3 {
    let (e1, e2) = sun_frame(sun, zenith);
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = psi_deg.to_radians().sin_cos();
    (sun * ct + (e1 * cp + e2 * sp) * st).normalize()
}

/// The wavelength of row `r`, nm.
pub fn row_lambda(r: usize) -> f32 {
    LAMBDA_MIN + (LAMBDA_MAX - LAMBDA_MIN) * r as f32 / (ROWS - 1) as f32
}

/// A direction uniform within the disk of angular radius `alpha` about the unit `s`.
fn in_disk(s: DVec3, alpha: f64, u: &mut impl FnMut() -> f64) -> DVec3 {
    if alpha <= 0.0 {
        return s;
    }
    // Uniform in solid angle over the cone: cos θ uniform in [cos α, 1].
    let c = 1.0 - u() * (1.0 - alpha.cos());
    let sn = (1.0 - c * c).max(0.0).sqrt();
    let phi = 2.0 * PI * u();
    let (a, b) = s.any_orthonormal_pair();
    (s * c + (a * phi.cos() + b * phi.sin()) * sn).normalize()
}

/// The two cells along one axis a value at `x` shares between, and the second one's
/// weight: the tent about cell centres (the inverse of the bilinear reading); beyond
/// the first or last centre the edge cell takes it all (for ψ, the mirror image across
/// 0° or 180° falls in the same cell).
#[inline]
fn tent(x: f64, step: f64, n: usize) -> (usize, usize, f64) {
    let t = x / step - 0.5;
    if t <= 0.0 {
        return (0, 0, 0.0);
    }
    let i = t as usize;
    if i >= n - 1 {
        return (n - 1, n - 1, 0.0);
    }
    (i, i + 1, t - i as f64)
}

/// Adds one ray leaving toward (θ, ψ) degrees to the cells, bilinearly: the kernel
/// density estimate whose bilinear reading is unbiased at the cell centres for a smooth
/// pattern, with about half the variance of counting in the nearest cell.
fn splat(counts: &mut [f64], theta: f64, psi: f64) {
    let (j0, j1, wj) = tent(theta, THETA_STEP, N_THETA);
    let (k0, k1, wk) = tent(psi, PSI_STEP, N_PSI);
    counts[k0 * N_THETA + j0] += (1.0 - wk) * (1.0 - wj);
    counts[k0 * N_THETA + j1] += (1.0 - wk) * wj;
    counts[k1 * N_THETA + j0] += wk * (1.0 - wj);
    counts[k1 * N_THETA + j1] += wk * wj;
}

/// The solid angle of a cell of θ ring `j` spanning one ψ step, on one side of the fold.
fn cell_solid_angle(j: usize) -> f64 {
    let (t0, t1) = (
        (j as f64 * THETA_STEP).to_radians(),
        ((j + 1) as f64 * THETA_STEP).to_radians(),
    );
    (t0.cos() - t1.cos()) * PSI_STEP.to_radians()
}

impl HaloTable {
    /// Traces `rays` rays per wavelength row through `crystals` (index `n_of(λ)`) for a
    /// sun at `sun_elevation` (radians) of angular radius `sun_radius` (radians), with
    /// the random numbers of `seed`; rows in parallel, each deterministic.
    pub fn build(
        crystals: &Crystals,
        n_of: &(dyn Fn(f32) -> f64 + Sync),
        sun_elevation: f64,
        sun_radius: f64,
        rays: usize,
        seed: u64,
    ) -> HaloTable {
        let sun = canonical_sun(sun_elevation);
        let zenith = DVec3::Z;
        let areas: Vec<f64> = (0..crystals.populations.len())
            .map(|i| crystals.diffraction_area_um2(i, -sun, DIFFRACTION_SAMPLES))
            .collect();
        let rows: Vec<(Vec<f32>, usize)> = (0..ROWS)
            .into_par_iter()
            .map(|r| {
                let lambda = row_lambda(r);
                let n = n_of(lambda);
                let mut counts = vec![0.0f64; N_PSI * N_THETA];
                let mut lost = 0usize;
                for i in 0..rays {
                    // One stream per ray, the same in every row: the rays of two rows
                    // part only where n(λ) parts them.
                    let mut rng = Rng::keyed(seed, i as u64);
                    let mut u = || rng.uniform_f64();
                    let incident = -in_disk(sun, sun_radius, &mut u);
                    let Some(s) = crystals.scatter(incident, n, false, &mut u) else {
                        lost += 1;
                        continue;
                    };
                    let (theta, psi) = sun_coordinates(-s.dir, sun, zenith);
                    splat(&mut counts, theta, psi);
                }
                let mut values = vec![0.0f32; N_PSI * N_THETA];
                for j in 0..N_THETA {
                    let omega = cell_solid_angle(j);
                    // Diffraction: the share of each population in this ring, spread
                    // evenly over the ring's 2 × N_PSI cells.
                    let (t0, t1) = (
                        (j as f64 * THETA_STEP).to_radians(),
                        ((j + 1) as f64 * THETA_STEP).to_radians(),
                    );
                    let diff: f64 = areas
                        .iter()
                        .enumerate()
                        .map(|(i, &a)| {
                            crystals.share(i)
                                * (diffraction_encircled(t1, a, lambda as f64)
                                    - diffraction_encircled(t0, a, lambda as f64))
                        })
                        .sum::<f64>()
                        / (2.0 * N_PSI as f64 * omega);
                    for k in 0..N_PSI {
                        let c = counts[k * N_THETA + j];
                        values[k * N_THETA + j] = (c / (rays as f64 * 2.0 * omega) + diff) as f32;
                    }
                }
                (values, lost)
            })
            .collect();
        let lost = rows.iter().map(|r| r.1).sum::<usize>() as f64 / (rays * ROWS) as f64;
        HaloTable {
            sun_elevation,
            values: rows.into_iter().flat_map(|r| r.0).collect(),
            lost,
        }
    }

    /// Row and weight for λ.
    #[inline]
    fn row(lambda: f32) -> (usize, f32) {
        let x = ((lambda - LAMBDA_MIN) / (LAMBDA_MAX - LAMBDA_MIN) * (ROWS - 1) as f32)
            .clamp(0.0, (ROWS - 1) as f32);
        let r = (x as usize).min(ROWS - 2);
        (r, x - r as f32)
    }

    /// Index and weight between cell centres along one axis.
    #[inline]
    fn axis(x: f64, step: f64, n: usize) -> (usize, f32) {
        let t = (x / step - 0.5).clamp(0.0, (n - 1) as f64);
        let i = (t as usize).min(n - 2);
        (i, (t - i as f64) as f32)
    }

    /// The value at θ, ψ (degrees; ψ folded) and λ: bilinear between cell centres,
    /// linear between rows.
    #[inline]
    pub fn eval(&self, theta_deg: f64, psi_deg: f64, lambda: f32) -> f32 {
        let (j, wj) = Self::axis(theta_deg, THETA_STEP, N_THETA);
        let (k, wk) = Self::axis(psi_deg.abs(), PSI_STEP, N_PSI);
        let (r, wr) = Self::row(lambda);
        let at = |r: usize| {
            let base = r * N_PSI * N_THETA;
            let v = |k: usize, j: usize| self.values[base + k * N_THETA + j];
            let a = v(k, j) + wj * (v(k, j + 1) - v(k, j));
            let b = v(k + 1, j) + wj * (v(k + 1, j + 1) - v(k + 1, j));
            a + wk * (b - a)
        };
        let (a, b) = (at(r), at(r + 1));
        a + wr * (b - a)
    }

    /// The mean over the rows of cell (ψ cell `k`, θ cell `j`), for importance sampling.
    pub fn cell_mean(&self, k: usize, j: usize) -> f32 {
        (0..ROWS)
            .map(|r| self.values[(r * N_PSI + k) * N_THETA + j])
            .sum::<f32>()
            / ROWS as f32
    }

    /// ∫ value dΩ over the sphere at row `r` (1 + 1 for geometric optics and diffraction,
    /// less the lost rays): a check of the normalisation.
    pub fn integral(&self, r: usize) -> f64 {
        let mut s = 0.0;
        for j in 0..N_THETA {
            let omega = cell_solid_angle(j);
            for k in 0..N_PSI {
                s += self.values[(r * N_PSI + k) * N_THETA + j] as f64 * 2.0 * omega;
            }
        }
        s
    }
}

/// The sky's view of a table: the scene's sun and zenith, and the cone about the sun
/// left to the sun light (see [`super::FORWARD_CUT_DEG`]).
#[derive(Clone, Debug)]
pub struct Placed {
    pub sun: DVec3,
    pub zenith: DVec3,
}

impl Placed {
    pub fn new(sun: Vec3, zenith: Vec3) -> Placed {
        Placed {
            sun: sun.as_dvec3().normalize(),
            zenith: zenith.as_dvec3().normalize(),
        }
    }

    /// (θ, ψ) of the view direction `v` (degrees).
    #[inline]
    pub fn coordinates(&self, v: Vec3) -> (f64, f64) {
        sun_coordinates(v.as_dvec3().normalize(), self.sun, self.zenith)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_round_trip() {
        let sun = canonical_sun(20f64.to_radians());
        for &(t, p) in &[
            (22.0, 0.0),
            (22.0, 90.0),
            (46.0, 135.0),
            (120.0, 179.0),
            (5.0, 45.0),
        ] {
            let v = from_sun_coordinates(t, p, sun, DVec3::Z);
            let (t2, p2) = sun_coordinates(v, sun, DVec3::Z);
            assert!(
                (t - t2).abs() < 1e-9 && (p - p2).abs() < 1e-9,
                "{t},{p}: {t2},{p2}"
            );
        }
        // ψ = 0 is toward the zenith: higher than the sun.
        let up = from_sun_coordinates(10.0, 0.0, sun, DVec3::Z);
        assert!(up.z > sun.z);
        let total: f64 = (0..N_THETA).map(cell_solid_angle).sum::<f64>() * 2.0 * N_PSI as f64;
        assert!((total - 4.0 * PI).abs() < 1e-9);
    }
}
