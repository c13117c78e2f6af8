//! Fresnel equations for a smooth dielectric interface (Hecht, "Optics", 5th ed.,
//! §4.6.2, eqs. 4.34 and 4.40): reflectance for s- and p-polarised light and their mean
//! for unpolarised light. Transmittance is 1 − R (energy conservation at the interface).

/// Reflectances (R_s, R_p) for light arriving with cos θi = `cos_i` (≥ 0, measured on the
/// incident side) from a medium of index n_i onto one of index n_t, given
/// `eta = n_i / n_t` (the seed's ior1_over_ior2). Total internal reflection gives (1, 1).
#[inline]
pub fn fresnel_dielectric_sp(cos_i: f32, eta: f32) -> (f32, f32) {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    // Divide numerator and denominator by n_t: n_i/n_t = eta.
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (eta * cos_t - cos_i) / (eta * cos_t + cos_i);
    (rs * rs, rp * rp)
}

/// Unpolarised reflectance R = (R_s + R_p) / 2.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (s, p) = fresnel_dielectric_sp(cos_i, eta);
    0.5 * (s + p)
}

/// Fresnel reflectance of a dielectric interface for light leaving along a direction
/// whose cosine with the (outward) normal is `cos` (either sign), where
/// `eta` = n_inside/n_outside: the pbrt-v4 `FrDielectric` convention, for microfacet
/// normals.
#[inline]
pub fn fresnel_dielectric_signed(cos: f32, eta: f32) -> f32 {
    if cos < 0.0 {
        fresnel_dielectric(-cos, eta)
    } else {
        fresnel_dielectric(cos, 1.0 / eta)
    }
}

/// Unpolarised reflectance of a conductor with complex index η = n + i k (relative to
/// the outside medium) for light at cos θi = `cos_i` (Born & Wolf, "Principles of
/// Optics", 7th ed., §14.2; the form of pbrt-v4 `FrComplex`): Snell's law with complex
/// η gives a complex cos θt, and R = (|r_s|² + |r_p|²)/2 with the Fresnel amplitude
/// ratios r_s = (cos θi − η cos θt)/(cos θi + η cos θt) and
/// r_p = (η cos θi − cos θt)/(η cos θi + cos θt).
#[inline]
pub fn fresnel_conductor(cos_i: f32, n: f32, k: f32) -> f32 {
    use num_complex::Complex32;
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = Complex32::new(n, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = Complex32::new(sin2_i, 0.0) / (eta * eta);
    let cos_t = (Complex32::new(1.0, 0.0) - sin2_t).sqrt();
    let ci = Complex32::new(cos_i, 0.0);
    let r_p = (eta * ci - cos_t) / (eta * ci + cos_t);
    let r_s = (ci - eta * cos_t) / (ci + eta * cos_t);
    0.5 * (r_p.norm_sqr() + r_s.norm_sqr())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_matches_the_closed_form() {
        // R0 = ((n_i - n_t) / (n_i + n_t))^2 = 0.04 for glass in air.
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
    }

    #[test]
    fn brewster_angle_has_no_p_reflection() {
        let n = 1.5f32;
        let theta_b = n.atan();
        let (_, rp) = fresnel_dielectric_sp(theta_b.cos(), 1.0 / n);
        assert!(rp < 1e-10, "R_p at Brewster = {rp}");
    }

    #[test]
    fn grazing_incidence_reflects_everything() {
        assert!((fresnel_dielectric(0.0, 1.0 / 1.5) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn total_internal_reflection_past_the_critical_angle() {
        let n = 1.5f32;
        let crit = (1.0 / n).asin();
        assert_eq!(fresnel_dielectric((crit + 1e-3).cos(), n), 1.0);
        assert!(fresnel_dielectric((crit - 1e-2).cos(), n) < 1.0);
    }

    /// Transmittance from the amplitude transmission coefficients (Hecht eqs. 4.41,
    /// 4.43): T = (n_t cos θt)/(n_i cos θi) t². Computed independently of R, so
    /// R + T = 1 is a real check of energy conservation.
    fn transmittance_sp(cos_i: f64, ni: f64, nt: f64) -> (f64, f64) {
        let sin_t = ni / nt * (1.0 - cos_i * cos_i).sqrt();
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let ts = 2.0 * ni * cos_i / (ni * cos_i + nt * cos_t);
        let tp = 2.0 * ni * cos_i / (nt * cos_i + ni * cos_t);
        let k = (nt * cos_t) / (ni * cos_i);
        (k * ts * ts, k * tp * tp)
    }

    #[test]
    fn conductor_reduces_to_the_dielectric_and_to_its_normal_incidence_form() {
        // k = 0: a dielectric of index n (light from n = 1).
        for &n in &[1.2f32, 1.5, 2.4] {
            for k in 0..=100 {
                let c = k as f32 / 100.0;
                let a = fresnel_conductor(c, n, 0.0);
                let b = fresnel_dielectric(c, 1.0 / n);
                assert!((a - b).abs() < 2e-5, "n = {n}, cos = {c}: {a} vs {b}");
            }
        }
        // Normal incidence: ((n − 1)² + k²)/((n + 1)² + k²); gold at 550 nm ≈ 0.79.
        for &(n, k) in &[(0.424f32, 2.472f32), (0.06, 3.6), (0.97, 6.46), (2.0, 0.5)] {
            let r0 = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            assert!((fresnel_conductor(1.0, n, k) - r0).abs() < 1e-5);
            // Grazing incidence reflects everything, and R stays in [0, 1].
            assert!((fresnel_conductor(0.0, n, k) - 1.0).abs() < 1e-5);
            for j in 0..=100 {
                let r = fresnel_conductor(j as f32 / 100.0, n, k);
                assert!((0.0..=1.0 + 1e-6).contains(&r));
            }
        }
    }

    #[test]
    fn reflectance_plus_transmittance_is_one() {
        for &(ni, nt) in &[(1.0f64, 1.5f64), (1.5, 1.0), (1.0, 2.42), (1.333, 1.0)] {
            for k in 1..1000 {
                let cos_i = k as f64 / 1000.0;
                let (rs, rp) = fresnel_dielectric_sp(cos_i as f32, (ni / nt) as f32);
                let sin_t = ni / nt * (1.0 - cos_i * cos_i).sqrt();
                if sin_t >= 1.0 {
                    assert_eq!((rs, rp), (1.0, 1.0));
                    continue;
                }
                let (ts, tp) = transmittance_sp(cos_i, ni, nt);
                assert!((rs as f64 + ts - 1.0).abs() < 1e-5, "s: {rs} + {ts}");
                assert!((rp as f64 + tp - 1.0).abs() < 1e-5, "p: {rp} + {tp}");
            }
        }
    }
}
