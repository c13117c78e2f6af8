//! Perfectly diffuse reflector, f_d = ρd/π (seed, "Interaction of eye rays").
use crate::spectrum::DenseSpectrum;

#[derive(Clone, Debug)]
pub struct Lambertian {
    /// Diffuse reflectance ρd(λ) in [0, 1].
    pub rho_d: DenseSpectrum,
}
