//! A rain shaft: rain falling from a cloud base, in a vertical cylinder or a cone widening
//! downward, with a soft edge and thinning below the base as drops evaporate (virga).
//!
//! With h = x·up and r the distance from the axis (the line through `center` along up):
//! ρ = radial(r, h) · vertical(h), where
//! - radial is 1 inside R(h) − w/2, 0 beyond R(h) + w/2 and a smoothstep between
//!   (R(h) = radius + (h_base − h) tan(spread), w the edge width);
//! - vertical is 0 above the cloud base h_base (the base of `center`) and
//!   exp(−(h_base − h)/falloff) below it (1 throughout when no falloff is given).
use glam::Vec3;

/// A rain shaft.
#[derive(Clone, Debug, PartialEq)]
pub struct RainShaft {
    /// A point on the axis at the cloud base.
    pub center: Vec3,
    /// Unit vector of increasing height.
    pub up: Vec3,
    /// The shaft's radius at the cloud base.
    pub radius: f32,
    /// The soft edge's width (≥ 0).
    pub edge: f32,
    /// tan of the cone's half-angle (0: a cylinder).
    pub spread: f32,
    /// The e-folding depth below the cloud base (∞: no thinning).
    pub falloff: f32,
}

/// 0 below a, 1 above b, the cubic smoothstep between.
#[inline]
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    if x <= a {
        0.0
    } else if x >= b {
        1.0
    } else {
        let t = (x - a) / (b - a);
        t * t * (3.0 - 2.0 * t)
    }
}

impl RainShaft {
    /// Depth below the base and distance from the axis of `p`.
    #[inline]
    fn coords(&self, p: Vec3) -> (f32, f32) {
        let v = p - self.center;
        let h = v.dot(self.up);
        (-h, (v - self.up * h).length())
    }

    #[inline]
    fn profile(&self, below: f32, r: f32) -> f32 {
        if below < 0.0 {
            return 0.0;
        }
        let big_r = self.radius + below * self.spread;
        let radial = 1.0 - smoothstep(big_r - 0.5 * self.edge, big_r + 0.5 * self.edge, r);
        let vertical = if self.falloff.is_finite() {
            (-below / self.falloff).exp()
        } else {
            1.0
        };
        radial * vertical
    }

    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        let (below, r) = self.coords(p);
        self.profile(below, r)
    }

    /// An upper bound of the value in the box [lo, hi]: the radial factor at the box's
    /// least distance from the axis (bounded below through its bounding sphere) with the
    /// widest radius the box's heights reach, times the vertical factor at its highest
    /// point under the base; each factor is monotone, so their product bounds ρ.
    pub fn max_in(&self, lo: Vec3, hi: Vec3) -> f32 {
        let (c, half) = (0.5 * (lo + hi), 0.5 * (hi - lo).length());
        let (below_c, r_c) = self.coords(c);
        let half_h = 0.5 * (hi - lo).abs().dot(self.up.abs());
        let (shallowest, deepest) = (below_c - half_h, below_c + half_h);
        if deepest < 0.0 {
            return 0.0;
        }
        let r_min = (r_c - half).max(0.0);
        let big_r = self.radius + deepest.max(0.0) * self.spread;
        let radial = 1.0 - smoothstep(big_r - 0.5 * self.edge, big_r + 0.5 * self.edge, r_min);
        let vertical = if self.falloff.is_finite() {
            (-shallowest.max(0.0) / self.falloff).exp()
        } else {
            1.0
        };
        radial * vertical * (1.0 + 1e-6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_in_bounds_the_shaft_in_every_box() {
        let s = RainShaft {
            center: Vec3::new(1.0, 10.0, -2.0),
            up: Vec3::Y,
            radius: 2.0,
            edge: 1.0,
            spread: 0.2,
            falloff: 6.0,
        };
        let mut rng = crate::math::rng::Rng::new(7, 1);
        for _ in 0..200 {
            let c = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 16.0
                - Vec3::new(7.0, 2.0, 10.0);
            let e = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0;
            let (lo, hi) = (c, c + e);
            let m = s.max_in(lo, hi);
            for _ in 0..50 {
                let t = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                let v = s.eval(lo + e * t);
                assert!(v <= m, "{v} > {m} in [{lo}, {hi}]");
            }
        }
    }
}
