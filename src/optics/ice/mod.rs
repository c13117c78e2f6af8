//! Ice crystals: the hexagonal prisms of halos, traced by geometric optics.
//!
//! - [`crystal`]: the prism (plates and columns by the aspect ratio c/a), its projected
//!   area and entry points.
//! - [`orientation`]: how a population floats (random, plates, columns, Parry, Lowitz).
//! - [`trace`]: one ray through one crystal, Fresnel by Fresnel, optionally with its
//!   Stokes vector.
//! - [`scatter`]: a ray of sunlight scattered by a crystal drawn from a mixture of
//!   populations, each crystal drawn with probability proportional to the area it
//!   presents to the light (so every ray carries the same power), and the diffraction by
//!   the crystals' projected areas (a circular aperture of the same area, the stated
//!   approximation of halo simulators that include it: Takano & Liou 1989, J. Atmos. Sci.
//!   46, 3, §2; Macke, Mueller & Raschke 1996, J. Atmos. Sci. 53, 2813).
//!
//! The refractive index comes from the caller (`crate::sky::halo` reads ice's n(λ)
//! from the catalogue: Warren & Brandt 2008), so this module stays free of heron's
//! spectral types, as the rest of [`crate::optics`].
pub mod crystal;
pub mod orientation;
pub mod scatter;
pub mod trace;

pub use crystal::HexPrism;
pub use orientation::Orientation;
pub use scatter::{Crystals, Population, Scattered};
pub use trace::{trace, Exit};
