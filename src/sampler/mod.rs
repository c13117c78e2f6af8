//! Samplers: where an integrator's random numbers come from.
//!
//! An integrator asks for numbers through one interface (pbrt-v4 `base/sampler.h`):
//! [`Sampler::start_pixel_sample`] for a (pixel, sample index), then
//! [`Sampler::get_pixel_2d`] for the position on the film, and [`Sampler::get_1d`] /
//! [`Sampler::get_2d`] for each decision, in an order the integrator fixes (its
//! documentation lists its dimensions). A sampler that places points by dimension (a
//! low-discrepancy sequence) can then replace the independent one without changing the
//! integrators, and every sampler's numbers depend only on (seed, pixel, sample index),
//! never on the thread or the tile order.
//!
//! `Sampler` is a closed enum dispatched by `match`, chosen once per render.
pub mod independent;
pub mod sobol;

pub use independent::IndependentSampler;
pub use sobol::SobolSampler;

use crate::settings::SamplerKind;
use glam::Vec2;

// The Sobol' sampler carries its per-pixel cache inline (about 0.5 kB). Samplers are made
// once per tile and passed by reference, so the size costs nothing per sample, while a
// box would add an indirection to every decision.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Sampler {
    Independent(IndependentSampler),
    Sobol(SobolSampler),
}

impl Sampler {
    /// The independent sampler for a render with `seed` on a film `width` pixels wide.
    pub fn independent(seed: u64, width: u32) -> Sampler {
        Sampler::Independent(IndependentSampler::new(seed, width))
    }

    /// The sampler `kind` for a render with `seed` on a `width` × `height` film at `spp`
    /// samples per pixel.
    pub fn new(kind: SamplerKind, seed: u64, width: u32, height: u32, spp: u32) -> Sampler {
        match kind {
            SamplerKind::Independent => Sampler::independent(seed, width),
            SamplerKind::Sobol => Sampler::Sobol(SobolSampler::new(seed, width, height, spp)),
        }
    }

    /// Starts the numbers of sample `index` of pixel (x, y).
    #[inline]
    pub fn start_pixel_sample(&mut self, x: u32, y: u32, index: u32) {
        match self {
            Sampler::Independent(s) => s.start_pixel_sample(x, y, index),
            Sampler::Sobol(s) => s.start_pixel_sample(x, y, index),
        }
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        match self {
            Sampler::Independent(s) => s.get_1d(),
            Sampler::Sobol(s) => s.get_1d(),
        }
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        match self {
            Sampler::Independent(s) => s.get_2d(),
            Sampler::Sobol(s) => s.get_2d(),
        }
    }

    /// A key of the current pixel sample and decision, drawing no number: it seeds the
    /// streams of estimators that need as many numbers as the scene makes them (the
    /// null-collision trackers, `medium::tracking`), so that those depend on which
    /// sample and decision they serve and not on the last bits of a ray, which the
    /// packet and one-ray engines may compute differently.
    #[inline]
    pub fn stream_key(&self) -> u64 {
        match self {
            Sampler::Independent(s) => s.stream_key(),
            Sampler::Sobol(s) => s.stream_key(),
        }
    }

    /// The position within the pixel, [0, 1)².
    #[inline]
    pub fn get_pixel_2d(&mut self) -> Vec2 {
        match self {
            Sampler::Independent(s) => s.get_2d(),
            Sampler::Sobol(s) => s.get_2d(),
        }
    }
}
