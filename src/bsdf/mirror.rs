//! Perfect specular reflector: ωr = 2(ωi·n)n − ωi (seed, "Reflected rays").
use crate::spectrum::DenseSpectrum;

#[derive(Clone, Debug)]
pub struct Mirror {
    /// Specular reflectance ρs(λ) in [0, 1]; 1 for the lecture's ideal mirror.
    pub rho_s: DenseSpectrum,
}
