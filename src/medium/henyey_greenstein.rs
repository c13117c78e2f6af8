//! A homogeneous medium with the Henyey–Greenstein phase function (Henyey & Greenstein
//! 1941, ApJ 93, 70), for comparison with the Lorenz–Mie media:
//! p(θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}), θ the angle between the incident and
//! scattered propagation directions, g the mean cosine (g > 0 forward).
//!
//! Sampling inverts the CDF in μ = cos θ (pbrt-v4 §11.3.1, written for propagation
//! directions): μ = (1 + g² − ((1 − g²)/(1 − g + 2g u))²)/(2g), and μ = 1 − 2u for |g| < 1e-3.
//! The sampler returns v = 1 − μ, which keeps small angles precise.
use crate::spectrum::DenseSpectrum;
use std::f32::consts::PI;

#[derive(Clone, Debug)]
pub struct HgMedium {
    /// Absorption and scattering coefficients, per scene unit of length.
    pub sigma_a: DenseSpectrum,
    pub sigma_s: DenseSpectrum,
    pub sigma_t: DenseSpectrum,
    /// Mean cosine, in (−1, 1).
    pub g: f32,
}

impl HgMedium {
    pub fn new(sigma_a: DenseSpectrum, sigma_s: DenseSpectrum, g: f32) -> HgMedium {
        let sigma_t = DenseSpectrum::from_fn(|l| sigma_a.eval(l) + sigma_s.eval(l));
        HgMedium {
            sigma_a,
            sigma_s,
            sigma_t,
            g,
        }
    }
}

/// p at v = 1 − cos θ.
#[inline]
pub fn hg(g: f32, v: f32) -> f32 {
    // 1 + g² − 2gμ = (1 − g)² + 2g v, without cancellation near μ = 1.
    let denom = (1.0 - g) * (1.0 - g) + 2.0 * g * v;
    (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
}

/// v = 1 − cos θ sampled from HG with mean cosine `g`, and its pdf.
#[inline]
pub fn sample_hg(g: f32, u: f32) -> (f32, f32) {
    let v = if g.abs() < 1e-3 {
        2.0 * u
    } else {
        // 1 − μ = ((1 − g²)/(1 − g + 2gu))² − (1 − g)²) / (2g)
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
        ((s * s - (1.0 - g) * (1.0 - g)) / (2.0 * g)).clamp(0.0, 2.0)
    };
    (v, hg(g, v))
}
