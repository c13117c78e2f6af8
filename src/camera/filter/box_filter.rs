//! The box filter: h(x) = 1 on [−r, r] (pbrt-v4 `BoxFilter`, Mitsuba 3
//! `src/rfilters/box.cpp`). Sampled exactly (uniformly), so every weight is 1; with
//! r = 0.5 the camera sample is uniform over its own pixel, heron's original jitter.

/// A box of radius `radius` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxFilter {
    pub radius: f32,
}

impl BoxFilter {
    #[inline]
    pub fn eval(&self, x: f32) -> f32 {
        if x.abs() <= self.radius {
            1.0
        } else {
            0.0
        }
    }

    /// ∫ h over [−r, r].
    pub fn integral(&self) -> f64 {
        2.0 * self.radius as f64
    }

    /// The offset for `u` in [0, 1): uniform on [−r, r), density 1/(2r).
    #[inline]
    pub fn sample(&self, u: f32) -> f32 {
        (2.0 * u - 1.0) * self.radius
    }

    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        self.eval(x) / (2.0 * self.radius)
    }
}
