//! Stokes radiance and Mueller matrices per wavelength lane, what polarised transport
//! (`[render] polarization`, `integrator::polarized`) carries instead of a
//! [`SampledSpectrum`].
//!
//! The convention is `optics::mueller`'s (Collett 2005, as Mitsuba 3): a Stokes vector
//! (S0, S1, S2, S3) is given in a frame (x̂, ŷ = k̂ × x̂) perpendicular to the direction
//! of travel k̂; S1 > 0 is linear polarisation along x̂, S2 > 0 along (x̂ + ŷ)/√2, S3 > 0
//! right-circular. The matrices here are glam's `Mat4` in f32 (column-major inside, built
//! from rows by [`mueller_from_rows`]), so the per-event products are SIMD; the closed
//! forms are computed in f64 by `optics::mueller` and converted once per event.
use super::SampledSpectrum;
use glam::{Mat4, Vec3, Vec4};

/// A Stokes vector per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StokesSpectrum<const N: usize>(pub [Vec4; N]);

impl<const N: usize> StokesSpectrum<N> {
    #[inline]
    pub fn zero() -> Self {
        StokesSpectrum([Vec4::ZERO; N])
    }

    /// Component `k` (0 to 3) of every lane.
    #[inline]
    pub fn component(&self, k: usize) -> SampledSpectrum<N> {
        SampledSpectrum(std::array::from_fn(|i| self.0[i][k]))
    }

    #[inline]
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

impl<const N: usize> std::ops::AddAssign for StokesSpectrum<N> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

/// A Mueller matrix from its rows.
#[inline]
pub fn mueller_from_rows(r: [[f32; 4]; 4]) -> Mat4 {
    Mat4::from_cols_array_2d(&r).transpose()
}

/// The Mueller matrix that re-expresses a Stokes vector given in the frame x̂ = `from`
/// in the frame x̂ = `to`, both perpendicular to the direction of travel `k` (unit
/// vectors): Collett's rotator R(θ) with θ the angle from `from` to `to`, right-handed
/// about `k` (Mitsuba 3's `rotate_stokes_basis`). Computed from the vectors without a
/// trigonometric call: cos 2θ and sin 2θ from cos θ and sin θ.
#[inline]
pub fn rotate_basis(k: Vec3, from: Vec3, to: Vec3) -> Mat4 {
    let c = from.dot(to);
    let s = k.dot(from.cross(to));
    let n = c * c + s * s;
    if !(n > 0.0) {
        return Mat4::IDENTITY;
    }
    let (c2, s2) = ((c * c - s * s) / n, 2.0 * c * s / n);
    mueller_from_rows([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, c2, s2, 0.0],
        [0.0, -s2, c2, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
}

/// A unit vector perpendicular to the unit `k`, for a frame where any will do (light
/// without a preferred axis, a degenerate plane of incidence).
#[inline]
pub fn any_perpendicular(k: Vec3) -> Vec3 {
    let a = if k.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    (a - k * a.dot(k)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotating_the_frame_turns_linear_light_the_other_way() {
        // Light linear along x, seen in a frame turned by 30° about z: at −30°.
        let t = 30f32.to_radians();
        let to = Vec3::new(t.cos(), t.sin(), 0.0);
        let s = rotate_basis(Vec3::Z, Vec3::X, to) * Vec4::new(1.0, 1.0, 0.0, 0.0);
        let want = Vec4::new(1.0, (2.0 * -t).cos(), (2.0 * -t).sin(), 0.0);
        assert!((s - want).abs().max_element() < 1e-6, "{s} vs {want}");
        // A turn by 90° swaps x and y polarisation; by 180° changes nothing.
        let s = rotate_basis(Vec3::Z, Vec3::X, Vec3::Y) * Vec4::new(1.0, 1.0, 0.0, 0.0);
        assert!((s - Vec4::new(1.0, -1.0, 0.0, 0.0)).abs().max_element() < 1e-6);
        let s = rotate_basis(Vec3::Z, Vec3::X, -Vec3::X) * Vec4::new(1.0, 0.3, 0.4, 0.5);
        assert!((s - Vec4::new(1.0, 0.3, 0.4, 0.5)).abs().max_element() < 1e-6);
    }

    #[test]
    fn rows_are_rows() {
        let m = mueller_from_rows([
            [1.0, 2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        assert_eq!(
            m * Vec4::new(0.0, 1.0, 0.0, 0.0),
            Vec4::new(2.0, 1.0, 0.0, 0.0)
        );
    }
}
