//! Exponential height fog: ρ(x) = exp(−(h − h₀)/H) with h = x·up the height, so the
//! medium's coefficients are as written at the base height h₀ and fall by e every scale
//! height H above it (the barometric form of an isothermal layer; fog and haze pooling
//! in a valley, Nishita et al. 1993's exponential atmosphere).
use glam::Vec3;

/// Exponential height fog.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightFog {
    /// Unit vector of increasing height.
    pub up: Vec3,
    /// The height at which ρ = 1.
    pub base: f32,
    /// The scale height H (> 0).
    pub scale_height: f32,
}

impl HeightFog {
    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        (-(p.dot(self.up) - self.base) / self.scale_height).exp()
    }

    /// The largest value in the box [lo, hi]: at its lowest corner.
    pub fn max_in(&self, lo: Vec3, hi: Vec3) -> f32 {
        let low = (0..8)
            .map(|i| {
                let c = Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                );
                c.dot(self.up)
            })
            .fold(f32::INFINITY, f32::min);
        // One ulp of headroom for the rounding of eval's dot product.
        (-(low - self.base) / self.scale_height).exp() * (1.0 + 1e-6)
    }

    /// The optical depth ∫ ρ along o + t d, t ∈ [0, len] (d unit), in closed form: the
    /// reference the tracking tests compare with.
    pub fn integral(&self, o: Vec3, d: Vec3, len: f32) -> f64 {
        let (h0, s) = ((o.dot(self.up) - self.base) as f64, d.dot(self.up) as f64);
        let hh = self.scale_height as f64;
        if s.abs() < 1e-9 {
            return (-h0 / hh).exp() * len as f64;
        }
        hh / s * ((-h0 / hh).exp() - (-(h0 + s * len as f64) / hh).exp())
    }
}
