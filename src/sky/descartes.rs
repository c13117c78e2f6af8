//! Descartes' rainbow: geometric optics of a spherical water drop.
//!
//! A ray with impact parameter b (in units of the drop radius, 0 ≤ b ≤ 1) meets the drop
//! at incidence i = asin b, refracts to r = asin(b/n), is reflected k times inside and
//! leaves. Its total deviation (Descartes 1637; van de Hulst, *Light Scattering by Small
//! Particles*, 1957, §12.2 and §13.2) is
//!
//!   D_k(b) = 2(i − r) + k(π − 2r),
//!
//! the scattering angle is D folded into [0, π] and the angle from the antisolar point is
//! θ = π − (scattering angle). D_k has its minimum at cos² i = (n² − 1)/(k² + 2k); rays pile
//! up there (the caustic): the primary bow (k = 1, θ ≈ 42°) and the secondary (k = 2,
//! θ ≈ 51°). k = 0 (external reflection) has D = π − 2i and reaches every θ = 2i.
//!
//! Intensity (ray optics; van de Hulst §12.2): a drop of radius a scatters into solid angle
//! dΩ the power falling on the annulus 2π a² b db, so per geometric cross-section π a²,
//!
//!   p(θ) = (1/π) Σ_branches b |db/dθ| F(b) / sin θ,
//!
//! summed over the impact parameters that reach θ (two for k ≥ 1 on the bright side of the
//! bow, none on the dark side), with the Fresnel factor F = T(i) R(r)^k T(r) (entry,
//! k internal reflections, exit; `crate::bsdf::fresnel::fresnel_dielectric_sp`), taken for s
//! and p light separately and averaged for unpolarised light. Absorption in water is
//! neglected (its imaginary index is < 3.4·10⁻⁸ below 700 nm and < 1.9·10⁻⁷ up to 830 nm,
//! Hale & Querry 1973, `spectra/water_k_hale_querry1973.csv`: a 1 mm drop absorbs under
//! 1 % on the bows' paths).
//!
//! p(θ) is infinite at the caustic (|db/dθ| → ∞ like 1/√(θ₀ − θ)); the sun's disk makes it
//! finite. The disk-averaged profile ∫ K(θ − θ') p(θ') dθ' is computed as an integral over
//! b, ∫ (1/π) b F(b) / sin θ(b) · K(θ − θ(b)) db, which has no singularity: on each branch
//! where θ(b) is monotonic, the b interval with |θ(b) − θ| < α is found by bisection and
//! integrated with a cosine-mapped midpoint rule (which absorbs the kernel's square-root
//! ends). Alexander's dark band between the bows comes out by itself: no k = 1 ray leaves
//! beyond θ₁ and no k = 2 ray inside θ₂.
use super::{disk_kernel, Polarisation};
use crate::bsdf::fresnel::fresnel_dielectric_sp;
use crate::spectrum::ior::Ior;
use glam::Vec3;
use std::f64::consts::PI;

/// Total deviation D_k(b) in radians of a ray with impact parameter `b` ∈ [0, 1] after
/// `k` ≥ 1 internal reflections in a sphere of relative index `n`; for k = 0 the
/// externally reflected ray, D = π − 2i (not the directly transmitted one).
#[inline]
pub fn deviation(b: f64, n: f64, k: u32) -> f64 {
    let i = b.clamp(0.0, 1.0).asin();
    if k == 0 {
        // External reflection.
        return PI - 2.0 * i;
    }
    let r = (b.clamp(0.0, 1.0) / n).asin();
    2.0 * (i - r) + k as f64 * (PI - 2.0 * r)
}

/// Angle from the antisolar point (radians, [0, π]) of a ray with deviation `d`:
/// π minus the scattering angle, the scattering angle being d folded into [0, π].
#[inline]
pub fn theta_of_deviation(d: f64) -> f64 {
    let d = d.rem_euclid(2.0 * PI);
    let scatter = if d > PI { 2.0 * PI - d } else { d };
    PI - scatter
}

/// θ(b) for order k: [`theta_of_deviation`] of [`deviation`].
#[inline]
pub fn theta_of_b(b: f64, n: f64, k: u32) -> f64 {
    theta_of_deviation(deviation(b, n, k))
}

/// Impact parameter of minimum deviation for k ≥ 1: cos² i = (n² − 1)/(k² + 2k),
/// b = sin i.
pub fn min_deviation_b(n: f64, k: u32) -> f64 {
    let kf = k as f64;
    let c2 = (n * n - 1.0) / (kf * kf + 2.0 * kf);
    (1.0 - c2).max(0.0).sqrt()
}

/// The rainbow angle of order k ≥ 1 (radians from the antisolar point): θ at minimum
/// deviation.
pub fn rainbow_angle(n: f64, k: u32) -> f64 {
    theta_of_b(min_deviation_b(n, k), n, k)
}

/// d²D/db² at b (radians per unit b²): D = 2i − 2(k+1)r with di/db = 1/cos i and
/// dr/db = 1/(n cos r), so D'' = 2 sin i / cos³ i − 2(k + 1) sin r / (n² cos³ r).
pub fn deviation_curvature(b: f64, n: f64, k: u32) -> f64 {
    let i = b.asin();
    let r = (b / n).asin();
    2.0 * i.sin() / i.cos().powi(3) - 2.0 * (k as f64 + 1.0) * r.sin() / (n * n * r.cos().powi(3))
}

/// Fresnel factor T(i) R(r)^k T(r) for s and for p light (k = 0: external reflection
/// R(i)). Uses `fresnel_dielectric_sp` with η = 1/n at entry and η = n inside.
pub fn fresnel_factors(b: f64, n: f64, k: u32) -> (f64, f64) {
    let b = b.clamp(0.0, 1.0);
    let cos_i = (1.0 - b * b).sqrt();
    let (rs_out, rp_out) = fresnel_dielectric_sp(cos_i as f32, (1.0 / n) as f32);
    if k == 0 {
        return (rs_out as f64, rp_out as f64);
    }
    let sin_r = b / n;
    let cos_r = (1.0 - sin_r * sin_r).sqrt();
    let (rs_in, rp_in) = fresnel_dielectric_sp(cos_r as f32, n as f32);
    let (rs_out, rp_out, rs_in, rp_in) = (rs_out as f64, rp_out as f64, rs_in as f64, rp_in as f64);
    let f = |r_out: f64, r_in: f64| (1.0 - r_out) * r_in.powi(k as i32) * (1.0 - r_in);
    (f(rs_out, rs_in), f(rp_out, rp_in))
}

/// Monotonic pieces of θ(b) on [0, 1] for order k: k = 0 one piece, k ≥ 1 split at the
/// minimum deviation.
fn branches(n: f64, k: u32) -> Vec<(f64, f64)> {
    if k == 0 {
        vec![(0.0, 1.0)]
    } else {
        let b0 = min_deviation_b(n, k);
        vec![(0.0, b0), (b0, 1.0)]
    }
}

/// b in [lo, hi] with θ(b) = target on a monotonic branch (bisection to f64 precision).
fn invert(lo: f64, hi: f64, target: f64, n: f64, k: u32) -> f64 {
    let (mut a, mut b) = (lo, hi);
    let increasing = theta_of_b(hi, n, k) > theta_of_b(lo, n, k);
    for _ in 0..64 {
        let m = 0.5 * (a + b);
        if (theta_of_b(m, n, k) < target) == increasing {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Nodes of the cosine-mapped midpoint rule on [0, 1].
const NODES: usize = 64;

/// Disk-averaged profile of one order k at θ for index n, sun radius α (radians).
pub fn order_profile(theta: f64, n: f64, k: u32, alpha: f64, pol: Polarisation) -> f64 {
    let mut sum = 0.0;
    for (bl, br) in branches(n, k) {
        let (tl, tr) = (theta_of_b(bl, n, k), theta_of_b(br, n, k));
        let (tmin, tmax) = (tl.min(tr), tl.max(tr));
        let lo = (theta - alpha).max(tmin);
        let hi = (theta + alpha).min(tmax);
        if lo >= hi {
            continue;
        }
        let b1 = invert(bl, br, lo, n, k);
        let b2 = invert(bl, br, hi, n, k);
        let (b1, b2) = (b1.min(b2), b1.max(b2));
        let w = b2 - b1;
        if w <= 0.0 {
            continue;
        }
        let mut s = 0.0;
        for j in 0..NODES {
            let t = (j as f64 + 0.5) / NODES as f64;
            let b = b1 + w * 0.5 * (1.0 - (PI * t).cos());
            let db = w * 0.5 * PI * (PI * t).sin() / NODES as f64;
            let th = theta_of_b(b, n, k);
            let (fs, fp) = fresnel_factors(b, n, k);
            s += b * pol.mix(fs, fp) / th.sin().max(1e-12) * disk_kernel(theta - th, alpha) * db;
        }
        sum += s / PI;
    }
    sum
}

/// Geometric-optics sky of water drops for the chosen orders, averaged over the sun's
/// disk. Normalisation: dσ/dΩ / (π a²) (see the module `sky`), independent of the drop size.
#[derive(Clone, Debug)]
pub struct DescartesSky {
    pub ior: Ior,
    /// Sun angular radius α, radians (> 0).
    pub sun_radius: f64,
    /// Orders k to include, each in {0, 1, 2}.
    pub orders: Vec<u32>,
    pub polarisation: Polarisation,
}

impl DescartesSky {
    /// Water (Daimon & Masumura 2007), primary and secondary bows, unpolarised.
    pub fn water(sun_radius: f64) -> Self {
        DescartesSky {
            ior: crate::spectrum::ior::named("water").expect("water in the catalogue"),
            sun_radius,
            orders: vec![1, 2],
            polarisation: Polarisation::Unpolarised,
        }
    }

    pub fn profile(&self, theta_rad: f64, lambda_nm: f32) -> f32 {
        let n = self.ior.eval(lambda_nm) as f64;
        self.orders
            .iter()
            .map(|&k| order_profile(theta_rad, n, k, self.sun_radius, self.polarisation))
            .sum::<f64>() as f32
    }

    pub fn radiance(&self, view_dir: Vec3, lambda_nm: f32, sun_dir: Vec3) -> f32 {
        self.profile(super::antisolar_angle(view_dir, sun_dir), lambda_nm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descartes_angles_of_water() {
        let n = 1.3330;
        let t1 = rainbow_angle(n, 1).to_degrees();
        let t2 = rainbow_angle(n, 2).to_degrees();
        assert!((t1 - 42.08).abs() < 0.05, "{t1}");
        assert!((t2 - 50.9).abs() < 0.2, "{t2}");
        // D'' vanishes nowhere near; numerical second derivative agrees.
        for k in [1, 2] {
            let b0 = min_deviation_b(n, k);
            let h = 1e-4;
            let num = (deviation(b0 + h, n, k) - 2.0 * deviation(b0, n, k)
                + deviation(b0 - h, n, k))
                / (h * h);
            let ana = deviation_curvature(b0, n, k);
            assert!((num - ana).abs() < 1e-4 * ana, "{num} vs {ana}");
        }
    }

    #[test]
    fn geometric_orders_conserve_energy_without_fresnel_losses() {
        // Σ over θ of p(θ) 2π sin θ dθ = ∫ 2 b F(b) db for each order.
        let n = 1.335;
        let alpha = 0.3f64.to_radians();
        for k in [1u32, 2] {
            let m = 20_000;
            let h = PI / m as f64;
            let total: f64 = (0..m)
                .map(|j| {
                    let th = (j as f64 + 0.5) * h;
                    order_profile(th, n, k, alpha, Polarisation::Unpolarised)
                        * 2.0
                        * PI
                        * th.sin()
                        * h
                })
                .sum();
            let mm = 200_000;
            let want: f64 = (0..mm)
                .map(|j| {
                    let b = (j as f64 + 0.5) / mm as f64;
                    let (s, p) = fresnel_factors(b, n, k);
                    2.0 * b * 0.5 * (s + p) / mm as f64
                })
                .sum();
            assert!(
                (total - want).abs() < 2e-3 * want,
                "k={k}: {total} vs {want}"
            );
        }
    }
}
