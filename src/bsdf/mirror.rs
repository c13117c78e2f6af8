//! Perfect specular reflector (seed, "Reflected rays"): the law of reflection,
//! ωr = 2(ωi·n)n − ωi, with ωi pointing away from the surface.
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct Mirror {
    /// Specular reflectance ρs(λ) in [0, 1]; 1 for the lecture's ideal mirror.
    pub rho_s: DenseSpectrum,
}

/// Mirror direction of `wi` (unit, pointing away from the surface) about the unit
/// normal `n`.
#[inline]
pub fn reflect(wi: Vec3, n: Vec3) -> Vec3 {
    2.0 * wi.dot(n) * n - wi
}
