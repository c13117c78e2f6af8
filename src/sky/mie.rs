//! The Lorenz–Mie sky: water drops' scattering per wavelength, tabulated over angle.
//!
//! The series is [`crate::optics::mie`] (Bohren & Huffman's BHMIE) with a real relative
//! index m: water's imaginary index is < 3.4·10⁻⁸ below 700 nm and < 1.9·10⁻⁷ up to
//! 830 nm (Hale & Querry 1973), so absorption is neglected in the skies (the media of
//! `crate::medium` include it). With only Debye term p ([`MieSky::debye`]) the
//! coefficients are [`crate::optics::debye::coefficients`] instead.
//!
//! The sky profile is p = dσ/dΩ / (π a²) = |S₁|²/(π x²) for s light, |S₂|²/(π x²) for p light,
//! (|S₁|² + |S₂|²)/(2π x²) unpolarised (same normalisation as `descartes` and `airy`), at
//! scattering angle π − θ.
//!
//! Table per (radius, wavelength), computed on first use and cached in the model:
//! θ from 0 to 180°, with step min(0.01°, 0.5/x rad) (0.01° for a drop-size distribution,
//! see [`MieSky`]) inside the bow window (default
//! 30°–62°, the bows, the dark band and the first supernumeraries) and 0.05° outside.
//! Large drops have fine ripple (period ~ a few /x rad), so inside the window the step
//! resolves it; outside, the ripple is undersampled and the disk average there is only
//! indicative. The table is then averaged over the sun's disk with the chord kernel
//! (trapezoid weights over the table nodes; a Gauss–Chebyshev average of the linearly
//! interpolated table when the disk spans fewer than 16 nodes) and looked up by linear
//! interpolation. Wavelengths are either computed exactly as asked (`lambda_step_nm` = 0,
//! what `heron sky profile` uses) or on a grid every `lambda_step_nm` and interpolated
//! linearly between the two nearest (for rendering).
use super::{disk_kernel, disk_quadrature, Polarisation};
use crate::drops::{DropNode, DropSizeDistribution};
use crate::optics::{self, mie::amplitudes};
use crate::spectrum::ior::Ior;
use glam::Vec3;
use num_complex::Complex64;
use rayon::prelude::*;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, RwLock};

/// The largest Debye term p accepted by the CLI and the scene (p = 0 … 20).
pub const MAX_DEBYE_TERM: u32 = 20;

/// Profile value dσ/dΩ / (π a²) from S₁, S₂ for the polarisation.
#[inline]
pub fn phase_value(s1: Complex64, s2: Complex64, x: f64, pol: Polarisation) -> f64 {
    pol.mix(s1.norm_sqr(), s2.norm_sqr()) / (PI * x * x)
}

/// One wavelength's table over θ (radians from the antisolar point).
pub struct MieTable {
    pub lambda_nm: f32,
    pub size_parameter: f64,
    pub theta: Vec<f64>,
    /// Point-sun profile at `theta`.
    pub point: Vec<f64>,
    /// Disk-averaged profile at `theta`.
    pub disk: Vec<f64>,
}

pub(crate) fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let i = xs.partition_point(|&v| v <= x);
    if i == 0 {
        return ys[0];
    }
    if i >= xs.len() {
        return ys[xs.len() - 1];
    }
    let t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
    ys[i - 1] + t * (ys[i] - ys[i - 1])
}

impl MieTable {
    /// Disk-averaged profile at θ (linear interpolation in the table).
    pub fn eval(&self, theta: f64) -> f64 {
        interp(&self.theta, &self.disk, theta)
    }
}

/// Lorenz–Mie sky of water drops of one radius or of a drop-size distribution.
///
/// With a distribution ([`MieSky::with_distribution`]) each wavelength's point profile is
/// Σ wᵢ aᵢ² pᵢ(θ) / Σ wᵢ aᵢ² over the quadrature nodes ([`crate::drops`]; wᵢ the number
/// fractions), i.e. ⟨dσ/dΩ⟩ / ⟨π a²⟩, which for one radius is that radius's profile; the
/// θ grid is the largest radius's (the finest), and the sum is disk-averaged once (the
/// average is linear). The cost is one Mie series per node and wavelength.
pub struct MieSky {
    pub ior: Ior,
    /// Drop radius in nm: the monodisperse radius, or the distribution's
    /// cross-section-weighted mean radius (what [`MieSky::size_parameter`] reports).
    pub droplet_radius_nm: f64,
    /// The radii (mm) averaged, with their cross-section weights (Σ = 1).
    pub drops: Vec<DropNode>,
    /// Only this term of the Debye series ([`crate::optics::debye`]), or the full Mie
    /// solution.
    pub debye: Option<u32>,
    /// Sun angular radius α, radians (> 0).
    pub sun_radius: f64,
    pub polarisation: Polarisation,
    /// θ window (radians) tabulated finely.
    pub window: (f64, f64),
    /// Tabulate only the window (outside it the table holds its edge values): for
    /// `heron sky lee`, which asks for angles well inside it.
    pub window_only: bool,
    /// 0: compute each wavelength asked for; > 0: a grid every this many nm, interpolated.
    pub lambda_step_nm: f32,
    cache: RwLock<HashMap<u32, Arc<MieTable>>>,
}

impl std::fmt::Debug for MieSky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MieSky")
            .field("droplet_radius_nm", &self.droplet_radius_nm)
            .field("drops", &self.drops.len())
            .field("debye", &self.debye)
            .field("sun_radius", &self.sun_radius)
            .field("polarisation", &self.polarisation)
            .field("lambda_step_nm", &self.lambda_step_nm)
            .finish()
    }
}

impl MieSky {
    /// Water drops of radius `radius_mm`, unpolarised, exact wavelengths, window 30°–62°.
    pub fn water(radius_mm: f64, sun_radius: f64) -> Self {
        MieSky {
            ior: crate::spectrum::ior::named("water").expect("water in the catalogue"),
            droplet_radius_nm: radius_mm * 1e6,
            drops: vec![DropNode {
                radius_mm,
                weight: 1.0,
            }],
            debye: None,
            sun_radius,
            polarisation: Polarisation::Unpolarised,
            window: (30f64.to_radians(), 62f64.to_radians()),
            window_only: false,
            lambda_step_nm: 0.0,
            cache: RwLock::new(HashMap::new()),
        }
    }

    /// The same sky for drops distributed as `dsd`, integrated with `nodes` quadrature
    /// nodes (see [`crate::drops`]).
    pub fn with_distribution(mut self, dsd: &DropSizeDistribution, nodes: usize) -> Self {
        self.drops = dsd.cross_section_nodes(nodes);
        self.droplet_radius_nm = crate::drops::mean_radius_nm(&self.drops);
        self
    }

    /// Size parameter x = 2πa/λ of [`MieSky::droplet_radius_nm`].
    pub fn size_parameter(&self, lambda_nm: f32) -> f64 {
        2.0 * PI * self.droplet_radius_nm / lambda_nm as f64
    }

    /// The θ nodes for size parameter x (one radius) or, for a distribution (`dsd`),
    /// 0.01° in the window whatever x: the sum over nodes is evaluated exactly at each θ,
    /// and the ripple finer than that, whose phase ∝ x differs from node to node, is
    /// averaged out by the distribution and the sun's disk (a residue of order the
    /// one-radius ripple over √nodes remains).
    fn grid(&self, x: f64, dsd: bool) -> Vec<f64> {
        let fine = if dsd {
            0.01f64.to_radians()
        } else {
            (0.01f64.to_radians()).min(0.5 / x)
        };
        let coarse = 0.05f64.to_radians().max(fine);
        let (w0, w1) = self.window;
        let mut g = Vec::new();
        let push_range = |a: f64, b: f64, step: f64, g: &mut Vec<f64>| {
            let n = ((b - a) / step).ceil().max(1.0) as usize;
            for i in 0..n {
                g.push(a + (b - a) * i as f64 / n as f64);
            }
        };
        if self.window_only {
            push_range(w0, w1, fine, &mut g);
            g.push(w1);
            return g;
        }
        push_range(0.0, w0, coarse, &mut g);
        push_range(w0, w1, fine, &mut g);
        push_range(w1, PI, coarse, &mut g);
        g.push(PI);
        g
    }

    /// Computes the table for one wavelength (not cached; see [`MieSky::table`]).
    pub fn compute_table(&self, lambda_nm: f32) -> MieTable {
        let m = self.ior.eval(lambda_nm) as f64;
        let to_x = |radius_mm: f64| 2.0 * PI * radius_mm * 1e6 / lambda_nm as f64;
        let x_max = self
            .drops
            .iter()
            .map(|d| to_x(d.radius_mm))
            .fold(0.0, f64::max);
        let theta = self.grid(x_max, self.drops.len() > 1);
        let pol = self.polarisation;
        let mut point = vec![0.0; theta.len()];
        for d in &self.drops {
            let x = to_x(d.radius_mm);
            let c = match self.debye {
                None => optics::mie::coefficients(m, x),
                Some(p) => optics::debye::coefficients(m, x, p),
            };
            let one: Vec<f64> = theta
                .par_iter()
                .with_min_len(64)
                .map(|&t| {
                    let (s1, s2) = amplitudes(&c, (PI - t).cos());
                    phase_value(s1, s2, x, pol)
                })
                .collect();
            for (acc, v) in point.iter_mut().zip(one) {
                *acc += d.weight * v;
            }
        }
        let x = self.size_parameter(lambda_nm);
        let alpha = self.sun_radius;
        let disk: Vec<f64> = (0..theta.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|i| disk_average(&theta, &point, i, alpha))
            .collect();
        MieTable {
            lambda_nm,
            size_parameter: x,
            theta,
            point,
            disk,
        }
    }

    /// The (cached) table for `lambda_nm` exactly.
    pub fn table(&self, lambda_nm: f32) -> Arc<MieTable> {
        let key = lambda_nm.to_bits();
        if let Some(t) = self.cache.read().expect("mie cache").get(&key) {
            return t.clone();
        }
        let t = Arc::new(self.compute_table(lambda_nm));
        self.cache
            .write()
            .expect("mie cache")
            .entry(key)
            .or_insert(t)
            .clone()
    }

    /// Computes the tables the given wavelengths need, in parallel over wavelengths.
    pub fn prepare(&self, lambdas: &[f32]) {
        let mut need: Vec<f32> = lambdas.iter().flat_map(|&l| self.nodes(l)).collect();
        need.sort_by(f32::total_cmp);
        need.dedup();
        need.iter().for_each(|&l| {
            self.table(l);
        });
    }

    /// Node wavelengths used for `lambda_nm`.
    fn nodes(&self, lambda_nm: f32) -> Vec<f32> {
        if self.lambda_step_nm <= 0.0 {
            return vec![lambda_nm];
        }
        let s = self.lambda_step_nm;
        let lo = (lambda_nm / s).floor() * s;
        if lo == lambda_nm {
            vec![lo]
        } else {
            vec![lo, lo + s]
        }
    }

    pub fn profile(&self, theta_rad: f64, lambda_nm: f32) -> f32 {
        let nodes = self.nodes(lambda_nm);
        if nodes.len() == 1 {
            return self.table(nodes[0]).eval(theta_rad) as f32;
        }
        let t = ((lambda_nm - nodes[0]) / (nodes[1] - nodes[0])) as f64;
        let a = self.table(nodes[0]).eval(theta_rad);
        let b = self.table(nodes[1]).eval(theta_rad);
        (a + t * (b - a)) as f32
    }

    pub fn radiance(&self, view_dir: Vec3, lambda_nm: f32, sun_dir: Vec3) -> f32 {
        self.profile(super::antisolar_angle(view_dir, sun_dir), lambda_nm)
    }
}

/// Disk average of the tabulated `point` profile at node i.
pub(crate) fn disk_average(theta: &[f64], point: &[f64], i: usize, alpha: f64) -> f64 {
    let t0 = theta[i];
    let lo = theta.partition_point(|&t| t < t0 - alpha);
    let hi = theta.partition_point(|&t| t <= t0 + alpha);
    if hi - lo >= 16 {
        let (mut s, mut w) = (0.0, 0.0);
        for j in lo..hi {
            let left = if j > 0 { theta[j - 1] } else { theta[j] };
            let right = if j + 1 < theta.len() {
                theta[j + 1]
            } else {
                theta[j]
            };
            let k = disk_kernel(t0 - theta[j], alpha) * 0.5 * (right - left);
            s += k * point[j];
            w += k;
        }
        s / w
    } else {
        disk_quadrature(32)
            .iter()
            .map(|&(t, w)| w * interp(theta, point, t0 - alpha * t))
            .sum()
    }
}
