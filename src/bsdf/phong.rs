//! The modified Phong model of the seed ("Glossy materials"; Lewis 1994, Lafortune and
//! Willems 1994): f = ρd/π + ρs (s+2)/(2π) (ωo·ωr)^s.
use super::Dielectric;
use crate::spectrum::DenseSpectrum;

#[derive(Clone, Debug)]
pub struct Glossy {
    pub rho_d: DenseSpectrum,
    /// Specular reflectance ρs; ρd + ρs ≤ 1.
    pub rho_s: f32,
    /// Phong exponent s (shininess).
    pub shininess: f32,
    /// The seed's glossy-over-refractive combination: highlights from the lights, and the
    /// path continues through this dielectric.
    pub base: Option<Dielectric>,
}
