//! Spot light: a point light whose intensity falls off from I(λ) on its axis to 0 at the
//! cone's edge, with pbrt-v4's smooth falloff (`SpotLight`, §12.2.2):
//! I(θ) = I · smoothstep(cos θ_end, cos θ_start, cos θ), θ_end = `cone_angle`,
//! θ_start = `cone_angle − cone_delta`. A delta light.
use super::{LightLeSample, LightLiSample};
use crate::math::warp::{uniform_cone, uniform_cone_pdf};
use crate::math::Frame;
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit vector along the cone's axis (the direction light travels).
    pub direction: Vec3,
    pub intensity: DenseSpectrum,
    pub cos_falloff_start: f32,
    pub cos_falloff_end: f32,
}

#[inline]
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl SpotLight {
    /// The falloff for light leaving along unit `w`.
    #[inline]
    pub fn falloff(&self, w: Vec3) -> f32 {
        smoothstep(
            self.cos_falloff_end,
            self.cos_falloff_start,
            w.dot(self.direction),
        )
    }

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
        let wi = to / d;
        let k = self.falloff(-wi);
        if k == 0.0 {
            return None;
        }
        Some(LightLiSample {
            l: wl.eval(&self.intensity) * (k / d2),
            wi,
            pdf: 1.0,
            dist: d,
            delta: true,
            n: Vec3::ZERO,
            p: self.position,
            p_err: Vec3::ZERO,
        })
    }

    /// A direction uniform in the cone of half-angle θ_end.
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> Option<LightLeSample<N>> {
        let omc = 1.0 - self.cos_falloff_end;
        let dir = Frame::from_z(self.direction).to_world(uniform_cone(u, omc));
        let k = self.falloff(dir);
        if k == 0.0 {
            return None;
        }
        Some(LightLeSample {
            origin: self.position,
            origin_err: Vec3::ZERO,
            dir,
            l: wl.eval(&self.intensity) * k,
            pdf_pos: 1.0,
            pdf_dir: uniform_cone_pdf(omc),
            normal: None,
            uv: Vec2::ZERO,
        })
    }

    /// Direction density of `sample_le`: uniform over the cone of half-angle θ_end.
    #[inline]
    pub fn pdf_dir(&self, dir: Vec3) -> f32 {
        if dir.dot(self.direction) >= self.cos_falloff_end {
            uniform_cone_pdf(1.0 - self.cos_falloff_end)
        } else {
            0.0
        }
    }

    /// Φ = I · 2π ((1 − cos θ_start) + (cos θ_start − cos θ_end)/2) (pbrt-v4
    /// `SpotLight::Phi`, the smoothstep integrated over the falloff ring).
    pub fn phi(&self) -> f32 {
        self.intensity.mean()
            * 2.0
            * std::f32::consts::PI
            * ((1.0 - self.cos_falloff_start)
                + (self.cos_falloff_start - self.cos_falloff_end) / 2.0)
    }
}
