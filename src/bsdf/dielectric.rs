//! Smooth dielectric interface: refraction after the seed ("Refraction and total internal
//! reflection"), with a Fresnel-weighted choice between reflection and refraction.
use crate::spectrum::ior::Ior;
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct Dielectric {
    /// Index of refraction of the inside relative to the outside (air/vacuum = 1), a
    /// function of wavelength.
    pub ior: Ior,
    /// Weight reflection and refraction by the Fresnel equations (default). When false,
    /// the lecture's pure refraction: always refract, reflect only on total internal
    /// reflection.
    pub fresnel: bool,
}

/// Refracted direction after the seed's formula
/// ωt = η((ωi·n)n − ωi) − n √(1 − η²(1 − (ωi·n)²)), with η = n_i/n_t (the lecture's
/// ior1_over_ior2), ωi the unit direction toward the incident side and n the unit normal
/// on that side (ωi·n ≥ 0). Returns None on total internal reflection, when
/// cos²θt < 0.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wi.dot(n);
    let cos2_t = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if cos2_t < 0.0 {
        return None;
    }
    Some(eta * (cos_i * n - wi) - n * cos2_t.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rng;

    fn random_unit_toward(n: Vec3, rng: &mut Rng) -> Vec3 {
        loop {
            let v = Vec3::new(
                2.0 * rng.uniform() - 1.0,
                2.0 * rng.uniform() - 1.0,
                2.0 * rng.uniform() - 1.0,
            );
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                let v = v / l;
                return if v.dot(n) >= 0.0 { v } else { -v };
            }
        }
    }

    #[test]
    fn snell_holds_at_random_angles_both_ways() {
        let mut rng = Rng::new(42, 1);
        for &(ni, nt) in &[(1.0f32, 1.5f32), (1.5, 1.0), (1.0, 2.42), (1.333, 1.0)] {
            let mut refracted = 0;
            for _ in 0..10_000 {
                let n = random_unit_toward(Vec3::Y, &mut rng);
                let wi = random_unit_toward(n, &mut rng);
                let Some(wt) = refract(wi, n, ni / nt) else {
                    continue;
                };
                refracted += 1;
                assert!((wt.length() - 1.0).abs() < 1e-5);
                // Transmitted ray leaves on the other side, in the plane of incidence.
                assert!(wt.dot(n) <= 0.0);
                assert!(wi.cross(n).dot(wt).abs() < 1e-5);
                let sin_i = wi.cross(n).length();
                let sin_t = wt.cross(n).length();
                assert!(
                    (ni * sin_i - nt * sin_t).abs() < 1e-5,
                    "n_i sin θi = {} vs n_t sin θt = {}",
                    ni * sin_i,
                    nt * sin_t
                );
            }
            assert!(refracted > 1000);
        }
    }

    #[test]
    fn total_internal_reflection_exactly_past_the_critical_angle() {
        let (ni, nt) = (1.5f64, 1.0f64);
        let crit = (nt / ni).asin();
        for &d in &[1e-4f64, 1e-3, 1e-2, 0.3] {
            let below = crit - d;
            let above = crit + d;
            let wi_below = Vec3::new(below.sin() as f32, below.cos() as f32, 0.0);
            let wi_above = Vec3::new(above.sin() as f32, above.cos() as f32, 0.0);
            assert!(
                refract(wi_below, Vec3::Y, (ni / nt) as f32).is_some(),
                "{d}"
            );
            assert!(
                refract(wi_above, Vec3::Y, (ni / nt) as f32).is_none(),
                "{d}"
            );
        }
    }

    #[test]
    fn reflection_law_angle_in_equals_angle_out() {
        use crate::bsdf::mirror::reflect;
        let mut rng = Rng::new(3, 9);
        for _ in 0..10_000 {
            let n = random_unit_toward(Vec3::Z, &mut rng);
            let wi = random_unit_toward(n, &mut rng);
            let wr = reflect(wi, n);
            assert!((wr.dot(n) - wi.dot(n)).abs() < 1e-5);
            assert!((wr.length() - 1.0).abs() < 1e-5);
            assert!(wi.cross(n).dot(wr).abs() < 1e-5, "plane of incidence");
            assert!((wr + wi).cross(n).length() < 1e-5, "symmetric about n");
        }
    }
}
