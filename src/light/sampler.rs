//! Choosing one light per shading point (pbrt-v4 `PowerLightSampler`,
//! `UniformLightSampler`): in proportion to each light's emitted power Φ (averaged over
//! 360–830 nm, lights at infinity over the scene's bounding disk), or uniformly. A light
//! with Φ = 0 emits nothing at any wavelength, so the power sampler never picks it.
use super::{Light, SceneBounds};
use crate::math::Distribution1D;
use crate::settings::LightSamplerKind;

#[derive(Clone, Debug)]
pub enum LightSampler {
    /// No light emits: nothing to sample.
    Empty,
    Uniform {
        count: usize,
    },
    Power(Distribution1D),
}

impl LightSampler {
    pub fn new(kind: LightSamplerKind, lights: &[Light], bounds: &SceneBounds) -> LightSampler {
        let phi: Vec<f32> = lights
            .iter()
            .map(|l| {
                let p = l.phi(bounds);
                if p.is_finite() {
                    p.max(0.0)
                } else {
                    0.0
                }
            })
            .collect();
        if phi.iter().all(|&p| p == 0.0) {
            return LightSampler::Empty;
        }
        match kind {
            LightSamplerKind::Uniform => LightSampler::Uniform {
                count: lights.len(),
            },
            LightSamplerKind::Power => LightSampler::Power(Distribution1D::new(&phi)),
        }
    }

    /// A light index and the probability of having chosen it.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        match self {
            LightSampler::Empty => None,
            LightSampler::Uniform { count } => {
                let i = ((u * *count as f32) as usize).min(count - 1);
                Some((i, 1.0 / *count as f32))
            }
            LightSampler::Power(d) => {
                let (i, p, _) = d.sample_discrete(u);
                Some((i, p))
            }
        }
    }

    /// The probability that `sample` returns light `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        match self {
            LightSampler::Empty => 0.0,
            LightSampler::Uniform { count } => 1.0 / *count as f32,
            LightSampler::Power(d) => d.pmf(i),
        }
    }
}
