//! The tent (triangle) filter: h(x) = max(0, 1 − |x|/r) (pbrt-v4 `TriangleFilter`,
//! Mitsuba 3 `src/rfilters/tent.cpp`). Sampled exactly by inverting its CDF, so every
//! weight is 1.

/// A tent of radius `radius` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TentFilter {
    pub radius: f32,
}

impl TentFilter {
    #[inline]
    pub fn eval(&self, x: f32) -> f32 {
        (1.0 - x.abs() / self.radius).max(0.0)
    }

    /// ∫ h over [−r, r] = r.
    pub fn integral(&self) -> f64 {
        self.radius as f64
    }

    /// The offset for `u` in [0, 1), with density h(x)/r: each half is a linear ramp
    /// whose CDF, (1 − |x|/r)²/2 from the outside in, inverts to a square root.
    #[inline]
    pub fn sample(&self, u: f32) -> f32 {
        if u < 0.5 {
            -self.radius * (1.0 - (2.0 * u).sqrt())
        } else {
            self.radius * (1.0 - (2.0 - 2.0 * u).sqrt())
        }
    }

    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        self.eval(x) / self.radius
    }
}
