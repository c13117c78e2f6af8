//! Scattering by a single particle, the physics that the skies and the media share.
//!
//! - [`mie`]: Lorenz–Mie theory for a homogeneous sphere (Bohren & Huffman 1983's BHMIE,
//!   with Wiscombe 1980's number of terms and a deeper start of the downward recurrence):
//!   the coefficients a_n, b_n, the number of terms, the logarithmic derivative D_n,
//!   Q_ext and Q_sca, and the amplitudes S₁, S₂. One implementation, generic over the
//!   relative index ([`mie::RelativeIndex`]): real for the rainbow skies (`crate::sky`,
//!   which neglect water's absorption), complex for the media (`crate::medium`, which
//!   include it).
//! - [`debye`]: the Debye series of the Mie coefficients (Hovenac & Lock 1992), which
//!   splits each partial wave into the waves leaving the sphere after p internal passes
//!   (the `mie` sky's `debye` term).
//!
//! - [`ice`]: hexagonal ice crystals by geometric optics (the halo sky and the ice
//!   media): the prism, the orientations of its populations, Fresnel ray tracing inside
//!   it with Mueller matrices, and diffraction by its projected area.
//! - [`mueller`]: Stokes vectors and Mueller matrices (Collett 2005's convention): the
//!   Fresnel reflection and transmission of dielectrics and conductors with their
//!   retardance, polarisers, retarders, rotations (the closed forms the materials'
//!   Mueller matrices for polarised transport are computed from, `crate::bsdf::polarization`).
//!
//! Layer 2 ("physics", `../shared/DESIGN.md`): this module imports nothing of heron's
//! but `math`'s random numbers (the ice crystals' Monte Carlo; otherwise `num-complex`,
//! `glam` and `libm`); `sky` and `medium` import it, never the reverse.
//!
//! What is here and what is not: [`mie::MieSphere`] (a sphere's coefficients and
//! efficiencies) is pure optics, so it is here. The drop population a medium is made of
//! (`crate::medium::PopulationNode`, radii with number densities) and its bulk
//! coefficients (Frisvad, Christensen & Jensen 2007) are the medium's; the sky's
//! normalisation of S₁, S₂ into a profile (`crate::sky::mie::phase_value`, with
//! `crate::sky::Polarisation`) and the largest Debye term the CLI and scenes accept
//! (`crate::sky::mie::MAX_DEBYE_TERM`) are the sky's.
pub mod debye;
pub mod ice;
pub mod mie;
pub mod mueller;

pub use mie::{amplitudes, MieCoefficients, MieSphere, RelativeIndex};
