//! Choosing one light per shading point (pbrt-v4 `PowerLightSampler`,
//! `UniformLightSampler`): in proportion to each light's emitted power Φ (averaged over
//! 360–830 nm, lights at infinity over the scene's bounding disk), or uniformly. A light
//! with Φ = 0 emits nothing at any wavelength, so the power sampler never picks it.
//!
//! The power of a light at infinity (the environment, the sun, a directional light) is
//! what crosses the scene's bounding disk, πR²·∫L dω, and grows with the scene's extent,
//! not with what the camera sees: a ground `plane` (2000 units across) made the course's
//! background 850,000 times its point light, so the point light was picked once in
//! 850,000 choices and came back as single samples of 10⁵ (the mean right, the image a
//! scatter of fireflies). When a scene has lights of both kinds, the lights at infinity
//! therefore share half the choices and the finite lights the other half, each group
//! split by power within: pbrt-v4's `BVHLightSampler` also sets the infinite lights'
//! probability by their count, apart from their power (`lightsamplers.h`, `pInfinite`).
//! Every light with Φ > 0 keeps a positive probability and `sample` and `pmf` read one
//! distribution, so the estimators stay unbiased; only the variance changes.
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
            LightSamplerKind::Power => {
                LightSampler::Power(Distribution1D::new(&split_by_kind(&phi, lights)))
            }
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

/// The weights of the power sampler: `phi` as it is, or, when lights at infinity and
/// finite lights both emit, half to each group in proportion to power within it.
fn split_by_kind(phi: &[f32], lights: &[Light]) -> Vec<f32> {
    let group = |infinite: bool| -> f32 {
        phi.iter()
            .zip(lights)
            .filter(|(_, l)| l.is_infinite() == infinite)
            .map(|(p, _)| p)
            .sum()
    };
    let (far, near) = (group(true), group(false));
    if !(far > 0.0 && near > 0.0) {
        return phi.to_vec();
    }
    phi.iter()
        .zip(lights)
        .map(|(&p, l)| 0.5 * p / if l.is_infinite() { far } else { near })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{EnvironmentLight, PointLight};
    use crate::spectrum::DenseSpectrum;
    use glam::Vec3;

    fn point(i: f32) -> Light {
        Light::Point(PointLight {
            position: Vec3::Y,
            intensity: DenseSpectrum::constant(i),
        })
    }

    /// The course's scene: a point light of intensity π under a background of mean 1/3
    /// over a scene 1414 units in radius (its ground plane). By power the point light
    /// would be picked with probability 1.2·10⁻⁶; as a group it keeps half, and two
    /// finite lights keep their power ratio within that half.
    #[test]
    fn finite_lights_keep_half_the_choices_beside_a_wide_environment() {
        let bounds = SceneBounds {
            center: Vec3::ZERO,
            radius: 1414.0,
        };
        let env = Light::Environment(EnvironmentLight::new(
            DenseSpectrum::constant(1.0 / 3.0),
            None,
            None,
        ));
        let by_power = |lights: &[Light]| {
            let phi: Vec<f32> = lights.iter().map(|l| l.phi(&bounds)).collect();
            phi[0] / phi.iter().sum::<f32>()
        };
        let lights = [point(std::f32::consts::PI), env.clone()];
        assert!(by_power(&lights) < 2e-6, "{}", by_power(&lights));
        let s = LightSampler::new(LightSamplerKind::Power, &lights, &bounds);
        assert!((s.pmf(0) - 0.5).abs() < 1e-6 && (s.pmf(1) - 0.5).abs() < 1e-6);
        let lights = [point(3.0), point(1.0), env];
        let s = LightSampler::new(LightSamplerKind::Power, &lights, &bounds);
        assert!((s.pmf(0) - 0.375).abs() < 1e-6, "{}", s.pmf(0));
        assert!((s.pmf(1) - 0.125).abs() < 1e-6, "{}", s.pmf(1));
        // sample and pmf agree.
        let n = 100_000;
        let mut count = [0usize; 3];
        for k in 0..n {
            let (i, p) = s.sample((k as f32 + 0.5) / n as f32).unwrap();
            assert_eq!(p, s.pmf(i));
            count[i] += 1;
        }
        assert_eq!(count, [37_500, 12_500, 50_000]);
        // Lights of one kind only: by power, as before.
        let lights = [point(3.0), point(1.0)];
        let s = LightSampler::new(LightSamplerKind::Power, &lights, &bounds);
        assert!((s.pmf(0) - 0.75).abs() < 1e-6);
    }
}
