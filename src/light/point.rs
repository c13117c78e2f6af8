//! Isotropic point light of radiant intensity I(λ) [W sr⁻¹ nm⁻¹]: the irradiance it
//! gives a surface at distance r is I cos θ / r² (seed, shadow rays to a light at p).
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: DenseSpectrum,
}
