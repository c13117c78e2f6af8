//! Independent uniform random numbers: one PCG32 stream per (seed, pixel, sample index)
//! ([`crate::math::Rng::for_sample`]), read in the order the integrator asks. Every
//! number is independent of every other, so the estimate converges as 1/√N.
use crate::math::Rng;
use glam::Vec2;

#[derive(Clone, Debug)]
pub struct IndependentSampler {
    seed: u64,
    width: u32,
    rng: Rng,
}

impl IndependentSampler {
    pub fn new(seed: u64, width: u32) -> Self {
        IndependentSampler {
            seed,
            width,
            rng: Rng::new(seed, 0),
        }
    }

    /// The stream of pixel (x, y), sample `index`; the pixel is numbered row by row, as
    /// heron has done since its first image, so the Whitted renders keep their bytes.
    #[inline]
    pub fn start_pixel_sample(&mut self, x: u32, y: u32, index: u32) {
        let pixel = y as u64 * self.width as u64 + x as u64;
        self.rng = Rng::for_sample(self.seed, pixel, index as u64);
    }

    /// The stream's state, drawing no number: it identifies (seed, pixel, sample, the
    /// numbers drawn so far).
    #[inline]
    pub fn stream_key(&self) -> u64 {
        self.rng.key()
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        self.rng.uniform()
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.rng.uniform();
        Vec2::new(x, self.rng.uniform())
    }
}
