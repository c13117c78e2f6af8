//! Airy's theory of the rainbow (Airy 1838, "On the intensity of light in the
//! neighbourhood of a caustic", Trans. Camb. Phil. Soc. 6, 379–402; in the form of
//! van de Hulst, *Light Scattering by Small Particles*, 1957, §13.24, and Nussenzveig,
//! "The theory of the rainbow", Sci. Am. 236(4), 1977).
//!
//! Near the minimum deviation D₀ of order k (at impact parameter b₀), the deviation is
//! D(b) ≈ D₀ + (h/2)(b − b₀)², h = d²D/db² ([`descartes::deviation_curvature`]). The phase
//! of the partial wave leaving in direction D obeys dφ/db = x (D − D(b)) (x = 2πa/λ, the
//! size parameter), so φ = x [Δ u − h u³/6] with u = b − b₀, Δ = D − D₀, and the amplitude
//! is the Airy integral
//!
//!   ∫ exp(iφ) du = 2π (2/(x h))^{1/3} Ai(−z),   z = Δ (2 x² / h)^{1/3}.
//!
//! Its square, scaled so that far on the bright side (z ≫ 1, where Ai²(−z) averages to
//! 1/(2π√z)) it matches the two geometric branches Σ|db/dD| = √(2/(hΔ)), replaces Σ|db/dθ|
//! in the ray-optics profile of [`descartes`]:
//!
//!   p(θ) = (1/π) b₀ F(b₀) / sin θ · 2π 2^{2/3} x^{1/3} h^{−2/3} Ai²(−z),
//!
//! with the Fresnel factor F = T R^k T of the minimum-deviation ray (s, p or their mean).
//! Same normalisation as `descartes` (dσ/dΩ / π a²). Bright side: Δ > 0, i.e. θ < θ₁ inside
//! the primary (k = 1, θ = π − D) and θ > θ₂ outside the secondary (k = 2, θ = D − π). The
//! main maximum (z = −a′₁ = 1.01879) lies on the bright side, (h/(2x²))^{1/3}·1.01879 from
//! the Descartes angle, and the supernumerary maxima follow at z = 3.2482, 4.8201, …, so
//! their angular spacing scales as x^{−2/3} ∝ a^{−2/3}. The theory holds within a few
//! degrees of each bow and for x ≳ 1000 (it ignores the external reflection and the
//! other orders; compare `mie`). The profile is averaged over the solar disk by
//! Gauss–Chebyshev quadrature ([`super::disk_quadrature`]).
use super::{descartes, disk_quadrature, Polarisation};
use crate::drops::{DropNode, DropSizeDistribution};
use crate::spectrum::ior::Ior;
use glam::Vec3;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, RwLock};

/// −a′₁, the first zero of Ai′ negated: Ai²(−z) is largest at z = 1.018792971647471.
pub const AIRY_FIRST_MAX_Z: f64 = 1.018_792_971_647_471;
/// −a′₂: the first supernumerary maximum, z = 3.248197582179837.
pub const AIRY_SECOND_MAX_Z: f64 = 3.248_197_582_179_837;

/// The Airy function Ai(x) (Abramowitz & Stegun 10.4), to about 1e-12 relative where it
/// is not near a zero:
/// - −7 ≤ x ≤ 1: Maclaurin series Ai = c₁ f(x) − c₂ g(x) (A&S 10.4.2–3);
/// - x > 1: Ai(x) = (1/π) √(x/3) K_{1/3}(ζ), ζ = (2/3) x^{3/2} (A&S 10.4.14), with
///   K_ν(ζ) = ∫₀^∞ e^{−ζ cosh t} cosh(νt) dt by the trapezoidal rule (exponentially accurate);
/// - x < −7: the asymptotic expansion A&S 10.4.60 (with 10.4.58 for u_k), truncated at its
///   smallest term.
pub fn airy_ai(x: f64) -> f64 {
    const C1: f64 = 0.355_028_053_887_817_2;
    const C2: f64 = 0.258_819_403_792_806_8;
    if (-7.0..=1.0).contains(&x) {
        let x3 = x * x * x;
        let (mut f, mut g) = (1.0, x);
        let (mut tf, mut tg) = (1.0, x);
        for k in 1..200 {
            let k3 = 3.0 * k as f64;
            tf *= x3 / (k3 * (k3 - 1.0));
            tg *= x3 / ((k3 + 1.0) * k3);
            f += tf;
            g += tg;
            if tf.abs() < 1e-18 * f.abs().max(1e-300) && tg.abs() < 1e-18 * g.abs().max(1e-300) {
                break;
            }
        }
        C1 * f - C2 * g
    } else if x > 1.0 {
        let zeta = 2.0 / 3.0 * x.powf(1.5);
        let h: f64 = 0.1;
        let mut s = 0.5; // t = 0 term, e^{−ζ(cosh 0 − 1)} cosh 0 = 1, halved
        let mut t: f64 = h;
        loop {
            let e = (-zeta * (t.cosh() - 1.0)).exp();
            s += e * (t / 3.0).cosh();
            if e < 1e-20 {
                break;
            }
            t += h;
        }
        let k = h * s * (-zeta).exp();
        (x / 3.0).sqrt() * k / PI
    } else {
        let z = -x;
        let zeta = 2.0 / 3.0 * z.powf(1.5);
        // u_k, A&S 10.4.58: u_0 = 1, u_k = (6k−5)(6k−3)(6k−1) / ((2k−1) 216 k) u_{k−1}.
        let (mut p, mut q) = (0.0, 0.0);
        let mut u = 1.0;
        let mut zpow = 1.0;
        let mut last = f64::INFINITY;
        for k in 0..60 {
            if k > 0 {
                let kf = k as f64;
                u *= (6.0 * kf - 5.0) * (6.0 * kf - 3.0) * (6.0 * kf - 1.0)
                    / ((2.0 * kf - 1.0) * 216.0 * kf);
                zpow *= zeta;
            }
            let term = u / zpow;
            if term > last || term < 1e-17 {
                break;
            }
            last = term;
            let sign = if (k / 2) % 2 == 0 { 1.0 } else { -1.0 };
            if k % 2 == 0 {
                p += sign * term;
            } else {
                q += sign * term;
            }
        }
        let ph = zeta + PI / 4.0;
        (ph.sin() * p - ph.cos() * q) / (PI.sqrt() * z.powf(0.25))
    }
}

/// The bright-side offset (radians) of the main Airy maximum from the Descartes angle for
/// order k, index n and size parameter x: 1.01879 (h / (2x²))^{1/3}. For k = 1 the maximum
/// is at θ₁ minus this, for k = 2 at θ₂ plus this.
pub fn main_peak_offset(n: f64, k: u32, x: f64) -> f64 {
    let h = descartes::deviation_curvature(descartes::min_deviation_b(n, k), n, k);
    AIRY_FIRST_MAX_Z * (h / (2.0 * x * x)).cbrt()
}

/// What the Airy profile of order k needs of the index n (root solves, done once per
/// (n, k)): minimum-deviation impact parameter b₀, Descartes angle θ₀, curvature h, and the
/// Fresnel factor for the polarisation.
#[derive(Clone, Copy, Debug)]
pub struct OrderParams {
    pub k: u32,
    pub b0: f64,
    pub theta0: f64,
    pub h: f64,
    pub fresnel: f64,
}

impl OrderParams {
    pub fn new(n: f64, k: u32, pol: Polarisation) -> Self {
        let b0 = descartes::min_deviation_b(n, k);
        let (fs, fp) = descartes::fresnel_factors(b0, n, k);
        OrderParams {
            k,
            b0,
            theta0: descartes::theta_of_b(b0, n, k),
            h: descartes::deviation_curvature(b0, n, k),
            fresnel: pol.mix(fs, fp),
        }
    }

    /// The point-sun profile at θ for size parameter x.
    pub fn eval(&self, theta: f64, x: f64) -> f64 {
        let delta = if self.k % 2 == 1 {
            self.theta0 - theta
        } else {
            theta - self.theta0
        };
        let z = delta * (2.0 * x * x / self.h).cbrt();
        let ai = airy_ai(-z);
        2.0 * 2f64.cbrt().powi(2)
            * self.b0
            * self.fresnel
            * x.cbrt()
            * self.h.powf(-2.0 / 3.0)
            * ai
            * ai
            / theta.sin().max(1e-12)
    }
}

/// Point-sun Airy profile of one order k (see the module documentation), normalised as
/// dσ/dΩ / (π a²).
pub fn order_point_profile(theta: f64, n: f64, k: u32, x: f64, pol: Polarisation) -> f64 {
    OrderParams::new(n, k, pol).eval(theta, x)
}

/// A distribution's profile at one wavelength, tabulated over θ (see [`AirySky`]).
#[derive(Debug)]
struct DsdTable {
    theta: Vec<f64>,
    disk: Vec<f64>,
}

/// Airy-theory sky of water drops of one radius or of a drop-size distribution,
/// averaged over the sun's disk.
///
/// With a distribution ([`AirySky::with_distribution`]) the profile is the average of the
/// per-radius profiles weighted by each node's share of the geometric cross-section,
/// Σ wᵢ aᵢ² pᵢ(θ) / Σ wᵢ aᵢ² with wᵢ the number fractions ([`crate::drops`]): that is
/// ⟨dσ/dΩ⟩ / ⟨π a²⟩, the same normalisation as for one radius, which it reduces to.
///
/// Cost: one radius is evaluated per call (the disk average by Gauss–Chebyshev
/// quadrature). A distribution is tabulated once per wavelength instead (the per-call sum
/// over nodes × disk nodes costs minutes for a scene's table): the node-weighted point
/// profile on θ steps of 1/16 of the largest radius's fringe scale (h/(2x²))^{1/3}, at
/// most 0.01° (at 1/8 the table's interpolation moved a narrow distribution's profile by
/// 0.9% of the peak from the directly evaluated one), within 25°–70° (both bows,
/// Alexander's band, the supernumeraries) and 0.1° outside, then averaged over the disk
/// with the chord kernel (`mie`'s trapezoid rule) and interpolated linearly.
#[derive(Debug)]
pub struct AirySky {
    pub ior: Ior,
    /// Drop radius in nm: the monodisperse radius, or the distribution's
    /// cross-section-weighted mean radius (what [`AirySky::size_parameter`] reports).
    pub droplet_radius_nm: f64,
    /// The radii (mm) the profile averages, with their cross-section weights (Σ = 1);
    /// one node for one radius.
    pub drops: Vec<DropNode>,
    /// Sun angular radius α, radians (> 0).
    pub sun_radius: f64,
    /// Orders k, each 1 or 2.
    pub orders: Vec<u32>,
    pub polarisation: Polarisation,
    /// Per-wavelength tables of a distribution (λ bits → table), filled on first use: set
    /// `orders`, `polarisation` and `sun_radius` before the first `profile` call.
    cache: RwLock<HashMap<u32, Arc<DsdTable>>>,
}

impl Clone for AirySky {
    fn clone(&self) -> Self {
        AirySky {
            ior: self.ior.clone(),
            droplet_radius_nm: self.droplet_radius_nm,
            drops: self.drops.clone(),
            sun_radius: self.sun_radius,
            orders: self.orders.clone(),
            polarisation: self.polarisation,
            cache: RwLock::new(HashMap::new()),
        }
    }
}

impl AirySky {
    /// Water drops of radius `radius_mm`, primary and secondary, unpolarised.
    pub fn water(radius_mm: f64, sun_radius: f64) -> Self {
        AirySky {
            ior: crate::spectrum::ior::named("water").expect("water in the catalogue"),
            droplet_radius_nm: radius_mm * 1e6,
            drops: vec![DropNode {
                radius_mm,
                weight: 1.0,
            }],
            sun_radius,
            orders: vec![1, 2],
            polarisation: Polarisation::Unpolarised,
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

    /// Size parameter x = 2πa/λ of [`AirySky::droplet_radius_nm`].
    pub fn size_parameter(&self, lambda_nm: f32) -> f64 {
        2.0 * PI * self.droplet_radius_nm / lambda_nm as f64
    }

    /// The disk-averaged profile of one radius (nm).
    fn radius_profile(&self, theta_rad: f64, n: f64, radius_nm: f64, lambda_nm: f32) -> f64 {
        let x = 2.0 * PI * radius_nm / lambda_nm as f64;
        let alpha = self.sun_radius;
        let mut sum = 0.0;
        for &k in &self.orders {
            // Resolve the fringes: the Airy pattern's scale in θ is (h/(2x²))^{1/3}.
            let b0 = descartes::min_deviation_b(n, k);
            let h = descartes::deviation_curvature(b0, n, k);
            let scale = (h / (2.0 * x * x)).cbrt();
            let nodes = ((24.0 * alpha / scale).ceil() as usize).clamp(24, 4096);
            let q = disk_quadrature(nodes);
            sum += q
                .iter()
                .map(|&(t, w)| {
                    w * order_point_profile(theta_rad - alpha * t, n, k, x, self.polarisation)
                })
                .sum::<f64>();
        }
        sum
    }

    pub fn profile(&self, theta_rad: f64, lambda_nm: f32) -> f32 {
        let n = self.ior.eval(lambda_nm) as f64;
        if let [d] = self.drops.as_slice() {
            return (d.weight * self.radius_profile(theta_rad, n, d.radius_mm * 1e6, lambda_nm))
                as f32;
        }
        let t = self.dsd_table(lambda_nm);
        super::mie::interp(&t.theta, &t.disk, theta_rad) as f32
    }

    /// The (cached) table of a distribution at `lambda_nm`.
    fn dsd_table(&self, lambda_nm: f32) -> Arc<DsdTable> {
        let key = lambda_nm.to_bits();
        if let Some(t) = self.cache.read().expect("airy cache").get(&key) {
            return t.clone();
        }
        let t = Arc::new(self.compute_dsd_table(lambda_nm));
        self.cache
            .write()
            .expect("airy cache")
            .entry(key)
            .or_insert(t)
            .clone()
    }

    fn compute_dsd_table(&self, lambda_nm: f32) -> DsdTable {
        let n = self.ior.eval(lambda_nm) as f64;
        let params: Vec<OrderParams> = self
            .orders
            .iter()
            .map(|&k| OrderParams::new(n, k, self.polarisation))
            .collect();
        let xs: Vec<(f64, f64)> = self
            .drops
            .iter()
            .map(|d| (2.0 * PI * d.radius_mm * 1e6 / lambda_nm as f64, d.weight))
            .collect();
        let x_max = xs.iter().map(|&(x, _)| x).fold(0.0, f64::max);
        let scale = params
            .iter()
            .map(|p| (p.h / (2.0 * x_max * x_max)).cbrt())
            .fold(f64::INFINITY, f64::min);
        let fine = (scale / 16.0)
            .min(0.01f64.to_radians())
            .max(1e-3f64.to_radians());
        let coarse = 0.1f64.to_radians().max(fine);
        let (w0, w1) = (25f64.to_radians(), 70f64.to_radians());
        let mut theta = Vec::new();
        let mut push = |a: f64, b: f64, step: f64| {
            let m = ((b - a) / step).ceil().max(1.0) as usize;
            theta.extend((0..m).map(|i| a + (b - a) * i as f64 / m as f64));
        };
        push(0.0, w0, coarse);
        push(w0, w1, fine);
        push(w1, PI, coarse);
        theta.push(PI);
        let point: Vec<f64> = theta
            .iter()
            .map(|&t| {
                xs.iter()
                    .map(|&(x, w)| w * params.iter().map(|p| p.eval(t, x)).sum::<f64>())
                    .sum()
            })
            .collect();
        let disk = (0..theta.len())
            .map(|i| super::mie::disk_average(&theta, &point, i, self.sun_radius))
            .collect();
        DsdTable { theta, disk }
    }

    pub fn radiance(&self, view_dir: Vec3, lambda_nm: f32, sun_dir: Vec3) -> f32 {
        self.profile(super::antisolar_angle(view_dir, sun_dir), lambda_nm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn airy_function_reference_values() {
        // A&S Table 10.11 and 10.13; zeros a_s of Ai and a′_s of Ai′.
        assert!((airy_ai(0.0) - 0.355_028_053_887_817).abs() < 1e-14);
        for zero in [
            -2.338_107_410_459_767,
            -4.087_949_444_130_971,
            -5.520_559_828_095_551,
            -6.786_708_090_071_759,
            -7.944_133_587_120_853,
            -9.022_650_853_340_98,
        ] {
            assert!(
                airy_ai(zero).abs() < 1e-11,
                "Ai({zero}) = {}",
                airy_ai(zero)
            );
        }
        // Ai′ vanishes at −1.01879…: a maximum of Ai(−z).
        let d = (airy_ai(-AIRY_FIRST_MAX_Z + 1e-5) - airy_ai(-AIRY_FIRST_MAX_Z - 1e-5)) / 2e-5;
        assert!(d.abs() < 1e-8, "{d}");
        assert!((airy_ai(-AIRY_FIRST_MAX_Z) - 0.535_656_656_015_700).abs() < 1e-12);
        assert!((airy_ai(1.0) - 0.135_292_416_312_881_4).abs() < 1e-13);
        assert!((airy_ai(2.0) - 0.034_924_130_423_274_38).abs() < 1e-14);
        assert!((airy_ai(5.0) - 1.083_444_281_360_744e-4).abs() < 1e-16);
        // Both sides of the switch between series and asymptotics (scipy 1.17 reference
        // values).
        for (x, want) in [
            (-6.999_999_999, 0.184_280_834_479_497_8),
            (-7.0, 0.184_280_835_250_506_2),
            (-7.5, 0.321_775_716_380_647_9),
            (-10.0, 0.040_241_238_486_441_955),
            (-30.0, -0.087_968_188_456_840_05),
            (3.0, 0.006_591_139_357_460_717),
        ] {
            let got = airy_ai(x);
            assert!((got - want).abs() < 2e-12, "Ai({x}) = {got}, want {want}");
        }
    }
}
