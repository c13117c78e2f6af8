//! The polarisation state of a delta light (`polarization = { axis, linear, circular }`
//! on a point, spot or directional light), for polarised transport: a laser-like source
//! for experiments. Unpolarised renders never read it.
//!
//! The state is given per ray in the Collett frame of `optics::mueller` (x̂, ŷ = k̂ × x̂)
//! with x̂ the scene vector `axis` projected perpendicular to the ray's direction of
//! travel k̂ (the field of a source whose electric vector points along `axis`, as far as
//! a transverse wave can): S = S0 (1, linear, 0, circular), so `linear` = 1 is light
//! linearly polarised along the projected axis, −1 across it, and `circular` = ±1
//! right- or left-circular (S3 > 0 right-circular, Collett's sign). The degree of
//! polarisation is √(linear² + circular²) ≤ 1; the rest is unpolarised.
use crate::spectrum::stokes::any_perpendicular;
use glam::{Vec3, Vec4};

/// A delta light's polarisation (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPolarization {
    /// The reference axis (unit), projected perpendicular to each ray.
    pub axis: Vec3,
    /// S1 / S0 in the frame of the projected axis.
    pub linear: f32,
    /// S3 / S0.
    pub circular: f32,
}

impl LightPolarization {
    /// The normalised Stokes vector of light travelling along `k` (unit) and its frame x̂.
    #[inline]
    pub fn stokes(&self, k: Vec3) -> (Vec4, Vec3) {
        let p = self.axis - k * self.axis.dot(k);
        let x = if p.length_squared() > 1e-12 {
            p.normalize()
        } else {
            any_perpendicular(k)
        };
        (Vec4::new(1.0, self.linear, 0.0, self.circular), x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_the_axis_projected_across_the_ray() {
        let p = LightPolarization {
            axis: Vec3::new(0.0, 1.0, 1.0).normalize(),
            linear: 1.0,
            circular: 0.0,
        };
        let (s, x) = p.stokes(Vec3::Z);
        assert_eq!(s, Vec4::new(1.0, 1.0, 0.0, 0.0));
        assert!((x - Vec3::Y).length() < 1e-6, "{x}");
        // Along the axis itself no direction is preferred; the frame is still ⊥ k.
        let (_, x) = p.stokes(p.axis);
        assert!(x.dot(p.axis).abs() < 1e-6);
    }
}
