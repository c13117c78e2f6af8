//! The Mitchell–Netravali filter (Mitchell & Netravali 1988, "Reconstruction filters in
//! computer graphics", eq. 8): a piecewise cubic on [−2, 2] with parameters B and C,
//! scaled to the radius r (pbrt-v4 `MitchellFilter`: h(x) = k(2x/r); Mitsuba 3
//! `src/rfilters/mitchell.cpp` fixes r = 2). Its lobes past |x| = r/2 are negative for
//! C > 0, so it is sampled from a table of |h| ([`super::table::Table1D`]) and a
//! sample's weight h/(p ∫h) carries the sign: about ±∫|h|/∫h.

/// Mitchell–Netravali with `b`, `c` and radius `radius` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MitchellFilter {
    pub radius: f32,
    pub b: f32,
    pub c: f32,
}

impl MitchellFilter {
    /// h(x) in f64 (the table and the integral are built from it).
    #[inline]
    pub fn eval(&self, x: f64) -> f64 {
        let (b, c) = (self.b as f64, self.c as f64);
        let x = (2.0 * x / self.radius as f64).abs();
        let k = if x <= 1.0 {
            (12.0 - 9.0 * b - 6.0 * c) * x.powi(3)
                + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                + (6.0 - 2.0 * b)
        } else if x <= 2.0 {
            (-b - 6.0 * c) * x.powi(3)
                + (6.0 * b + 30.0 * c) * x * x
                + (-12.0 * b - 48.0 * c) * x
                + (8.0 * b + 24.0 * c)
        } else {
            0.0
        };
        k / 6.0
    }
}
