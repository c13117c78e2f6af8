//! The Trowbridge–Reitz (GGX) microfacet distribution, isotropic, with roughness α
//! (Trowbridge & Reitz 1975; Walter, Marschner, Li & Torrance 2007, "Microfacet Models
//! for Refraction through Rough Surfaces", EGSR, eqs. 33–34), the height-correlated
//! Smith masking-shadowing function (Heitz 2014, "Understanding the Masking-Shadowing
//! Function in Microfacet-Based BRDFs", JCGT 3(2), eq. 99) and sampling of the visible
//! normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)).
//!
//! α is the GGX parameter itself (Mitsuba 3's `alpha`; pbrt-v4 maps its `roughness`
//! through √ first). All directions are in the local frame, z = the macro-normal.
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Below this α the lobe is narrower than f32 resolves; such materials are loaded as
/// their smooth (delta) counterparts, as pbrt-v4's `EffectivelySmooth` does.
pub const MIN_ALPHA: f32 = 1e-3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    pub alpha: f32,
}

impl TrowbridgeReitz {
    /// D(m) = 1 / (π α² ((m_x² + m_y²)/α² + m_z²)²) for a unit microfacet normal m with
    /// m_z > 0 (Walter et al. eq. 33 rewritten without tan θ, which overflows at the
    /// horizon); ∫ D(m) cos θm dm = 1.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let e = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
        1.0 / (PI * a2 * e * e)
    }

    /// Smith's Λ(ω) = (√(1 + α² tan²θ) − 1)/2 (Heitz 2014, eq. 86).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        if z2 == 0.0 {
            return f32::INFINITY;
        }
        let t = self.alpha * self.alpha * (w.x * w.x + w.y * w.y) / z2;
        0.5 * ((1.0 + t).sqrt() - 1.0)
    }

    /// Masking G1(ω) = 1/(1 + Λ(ω)).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing G2(ωo, ωi) = 1/(1 + Λ(ωo) + Λ(ωi)).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of the visible normals seen from ω: D_ω(m) = G1(ω) max(0, ω·m) D(m)/cos θ
    /// (Heitz 2018, eq. 1); ∫ D_ω(m) dm = 1. For ω below the surface, the normals
    /// visible from −ω (the same set `sample_wm` draws from).
    #[inline]
    pub fn d_visible(&self, w: Vec3, m: Vec3) -> f32 {
        let w = if w.z < 0.0 { -w } else { w };
        if w.z == 0.0 {
            return 0.0;
        }
        self.g1(w) / w.z * self.d(m) * w.dot(m).max(0.0)
    }

    /// A microfacet normal drawn from D_ω (Heitz 2018, listing 1: stretch the view
    /// direction to the α = 1 configuration, sample the projected hemisphere there as a
    /// disk with its lower half squeezed, and unstretch). ω may be on either side; the
    /// result has m_z > 0.
    #[inline]
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        let a = self.alpha;
        let mut vh = Vec3::new(a * w.x, a * w.y, w.z).normalize();
        if vh.z < 0.0 {
            vh = -vh;
        }
        let lensq = vh.x * vh.x + vh.y * vh.y;
        let t1 = if lensq > 1e-14 {
            Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let p1 = r * phi.cos();
        let mut p2 = r * phi.sin();
        let s = 0.5 * (1.0 + vh.z);
        p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let pz = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let nh = p1 * t1 + p2 * t2 + pz * vh;
        Vec3::new(a * nh.x, a * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::warp::uniform_sphere;
    use crate::math::Rng;

    /// ∫ D(m) cos θm dm = 1 and ∫ D_ω(m) dm = 1 over the hemisphere, by a midpoint rule in
    /// (cos θ, φ) fine enough for α ≥ 0.05.
    #[test]
    fn distribution_and_visible_normals_are_normalised() {
        for &alpha in &[0.05f32, 0.2, 0.5, 1.0] {
            let d = TrowbridgeReitz { alpha };
            let wo = Vec3::new(0.6, 0.2, 0.3).normalize();
            let (nt, np) = (4000, 64);
            let (mut a, mut b) = (0.0f64, 0.0f64);
            for i in 0..nt {
                // θ sampled densely near the pole, where a small α puts its mass.
                let x = (i as f64 + 0.5) / nt as f64;
                let theta = x * x * std::f64::consts::FRAC_PI_2;
                let dtheta = 2.0 * x / nt as f64 * std::f64::consts::FRAC_PI_2;
                for j in 0..np {
                    let phi = (j as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                    let m = Vec3::new(
                        (theta.sin() * phi.cos()) as f32,
                        (theta.sin() * phi.sin()) as f32,
                        theta.cos() as f32,
                    );
                    let dw = theta.sin() * dtheta * 2.0 * std::f64::consts::PI / np as f64;
                    a += d.d(m) as f64 * m.z as f64 * dw;
                    b += d.d_visible(wo, m) as f64 * dw;
                }
            }
            assert!((a - 1.0).abs() < 2e-3, "α = {alpha}: ∫D cos = {a}");
            assert!((b - 1.0).abs() < 2e-3, "α = {alpha}: ∫D_ω = {b}");
        }
    }

    #[test]
    fn sampled_normals_face_up_and_are_unit() {
        let mut rng = Rng::new(4, 4);
        for &alpha in &[1e-3f32, 0.1, 1.0] {
            let d = TrowbridgeReitz { alpha };
            for _ in 0..10_000 {
                let w = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
                let m = d.sample_wm(w, Vec2::new(rng.uniform(), rng.uniform()));
                assert!(m.is_finite() && (m.length() - 1.0).abs() < 1e-5 && m.z > 0.0);
            }
        }
    }
}
