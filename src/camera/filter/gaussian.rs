//! The Gaussian filter: h(x) = max(0, g(x) − g(r)) with g(x) = exp(−x²/2σ²), the
//! Gaussian less its value at the radius so that it falls to zero there (pbrt-v4
//! `GaussianFilter`, Mitsuba 3 `src/rfilters/gaussian.cpp`, whose radius is 4σ).
//! h is not a truncated Gaussian, so it is sampled from a table of |h|
//! ([`super::table::Table1D`], pbrt-v4's `FilterSampler`); the weights h/(p ∫h) are
//! then 1 up to the table's resolution.

/// A Gaussian of standard deviation `stddev` cut at `radius` (both in pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianFilter {
    pub radius: f32,
    pub stddev: f32,
}

impl GaussianFilter {
    /// h(x) in f64 (the table and the integral are built from it).
    #[inline]
    pub fn eval(&self, x: f64) -> f64 {
        let s2 = 2.0 * (self.stddev as f64).powi(2);
        let r = self.radius as f64;
        if x.abs() > r {
            return 0.0;
        }
        ((-x * x / s2).exp() - (-r * r / s2).exp()).max(0.0)
    }
}
