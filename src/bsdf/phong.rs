//! The modified Phong model of the seed ("Glossy materials"; Lewis 1994, Lafortune and
//! Willems 1994):
//!
//! f(ωi, ωo) = ρd/π + ρs (s+2)/(2π) (ωo·ωr)^s,  ωr = 2(ωi·n)n − ωi,
//!
//! which, as a BRDF on its own, loses energy but never creates it when ρd + ρs ≤ 1.
//! The course's glossy-over-refractive combination (`base`) adds the dielectric's
//! continuation at full weight on top (integrator::whitted), so with ρd > 0 that
//! combination can reflect more than it receives; the course's scenes use ρd = 0.
use super::Dielectric;
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct Glossy {
    pub rho_d: DenseSpectrum,
    /// Specular reflectance ρs; ρd + ρs ≤ 1.
    pub rho_s: f32,
    /// Phong exponent s (shininess).
    pub shininess: f32,
    /// The seed's glossy-over-refractive combination: highlights from the lights, and the
    /// path continues through this dielectric.
    pub base: Option<Dielectric>,
}

/// The specular lobe ρs (s+2)/(2π) max(0, ωo·ωr)^s for unit ωi, ωo (away from the
/// surface) and unit normal n on their side.
#[inline]
pub fn phong_specular(rho_s: f32, s: f32, wi: Vec3, wo: Vec3, n: Vec3) -> f32 {
    let wr = super::mirror::reflect(wi, n);
    let c = wo.dot(wr);
    if c <= 0.0 {
        return 0.0;
    }
    rho_s * (s + 2.0) / (2.0 * PI) * c.powf(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directional albedo ∫ f_s(ωi, ωo) cos θi dωi over the hemisphere, by a midpoint
    /// rule in (θ, φ) fine enough to resolve a lobe of exponent `s`.
    fn specular_albedo(s: f32, theta_o: f32) -> f64 {
        let wo = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
        let n = Vec3::Z;
        let nt = 2000;
        let np = 1000;
        let (dt, dp) = (
            std::f64::consts::FRAC_PI_2 / nt as f64,
            2.0 * std::f64::consts::PI / np as f64,
        );
        let mut sum = 0.0;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * dt;
            for j in 0..np {
                let p = (j as f64 + 0.5) * dp;
                let wi = Vec3::new(
                    (t.sin() * p.cos()) as f32,
                    (t.sin() * p.sin()) as f32,
                    t.cos() as f32,
                );
                let f = phong_specular(1.0, s, wi, wo, n) as f64;
                sum += f * t.cos() * t.sin() * dt * dp;
            }
        }
        sum
    }

    #[test]
    fn modified_phong_albedo_never_exceeds_one() {
        for &s in &[1.0f32, 2.0, 10.0, 42.0, 100.0, 1000.0] {
            let mut at_normal = 0.0;
            for &deg in &[0.0f32, 30.0, 60.0, 85.0] {
                let a = specular_albedo(s, deg.to_radians());
                assert!(a <= 1.0 + 2e-3, "s = {s}, θo = {deg}°: albedo {a}");
                if deg == 0.0 {
                    at_normal = a;
                }
            }
            // At normal incidence the normalisation (s+2)/(2π) makes the lobe exactly
            // energy conserving: ∫ (s+2)/(2π) cos^s θ cos θ dω = 1.
            assert!((at_normal - 1.0).abs() < 5e-3, "s = {s}: {at_normal}");
        }
    }

    #[test]
    fn lobe_peaks_in_the_mirror_direction() {
        let n = Vec3::Z;
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let wr = super::super::mirror::reflect(wi, n);
        let peak = phong_specular(1.0, 42.0, wi, wr, n);
        assert!((peak - 44.0 / (2.0 * PI)).abs() < 1e-4);
        let off = phong_specular(1.0, 42.0, wi, (wr + 0.1 * Vec3::X).normalize(), n);
        assert!(off < peak);
    }
}
