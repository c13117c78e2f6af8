//! Directional light: a source infinitely far away, so its shadow rays have no distance
//! cutoff (seed, "Shadow rays"). `radiance` is the lecture's L_i, the incident radiance
//! times the light's solid angle (irradiance at normal incidence). A delta light.
use super::{LightLeSample, LightLiSample, SceneBounds};
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct DirectionalLight {
    /// Unit vector in the direction the light travels (from the light into the scene).
    pub direction: Vec3,
    pub radiance: DenseSpectrum,
}

impl DirectionalLight {
    #[inline]
    pub fn sample_li<const N: usize>(&self, wl: &SampledWavelengths<N>) -> LightLiSample<N> {
        LightLiSample {
            l: wl.eval(&self.radiance),
            wi: -self.direction,
            pdf: 1.0,
            dist: f32::INFINITY,
            delta: true,
            n: Vec3::ZERO,
            p: Vec3::ZERO,
            p_err: Vec3::ZERO,
        }
    }

    /// A ray along the light's direction through a point uniform on the disk that
    /// covers the scene's bounding sphere (pbrt-v4 `DistantLight::SampleLe`).
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u: Vec2,
        wl: &SampledWavelengths<N>,
        bounds: &SceneBounds,
    ) -> LightLeSample<N> {
        let (origin, pdf_pos) = bounds.disk_point(-self.direction, u);
        LightLeSample {
            origin,
            origin_err: Vec3::ZERO,
            dir: self.direction,
            l: wl.eval(&self.radiance),
            pdf_pos,
            pdf_dir: 1.0,
            normal: Some(self.direction),
            uv: Vec2::ZERO,
        }
    }

    /// Φ = π R² E over the scene's bounding disk.
    pub fn phi(&self, bounds: &SceneBounds) -> f32 {
        bounds.disk_area() * self.radiance.mean()
    }
}
