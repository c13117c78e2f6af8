//! Isotropic point light of radiant intensity I(λ) [W sr⁻¹ nm⁻¹]: the irradiance it
//! gives a surface at distance r is I cos θ / r² (seed, shadow rays to a light at p).
//! A delta light: it can be reached only by sampling it, never by a ray hitting it.
use super::{LightLeSample, LightLiSample};
use crate::math::warp::{uniform_sphere, UNIFORM_SPHERE_PDF};
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: DenseSpectrum,
}

impl PointLight {
    /// Incident radiance "L_i" of the delta light: I/r² toward the light (pdf 1).
    #[inline]
    pub fn sample_li<const N: usize>(
        &self,
        p: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<LightLiSample<N>> {
        let to = self.position - p;
        let d2 = to.length_squared();
        let d = d2.sqrt();
        if !(d > 0.0) {
            return None;
        }
        Some(LightLiSample {
            l: wl.eval(&self.intensity) * (1.0 / d2),
            wi: to / d,
            pdf: 1.0,
            dist: d,
            delta: true,
            n: Vec3::ZERO,
            p: self.position,
            p_err: Vec3::ZERO,
        })
    }

    /// Emission is isotropic: a direction uniform on the sphere.
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> LightLeSample<N> {
        LightLeSample {
            origin: self.position,
            origin_err: Vec3::ZERO,
            dir: uniform_sphere(u),
            l: wl.eval(&self.intensity),
            pdf_pos: 1.0,
            pdf_dir: UNIFORM_SPHERE_PDF,
            normal: None,
            uv: Vec2::ZERO,
        }
    }

    /// Radiant flux Φ = 4π I (per nm, averaged over 360–830 nm).
    pub fn phi(&self) -> f32 {
        4.0 * std::f32::consts::PI * self.intensity.mean()
    }
}
