//! Spectral representation: sampled wavelengths carried along a path, dense 1 nm tables
//! for everything a scene defines, the CIE observer, and RGB uplift.
//!
//! Units: wavelengths are in nanometres in this API.
pub mod blackbody;
pub mod cie;
pub mod color;
pub mod csv;
pub mod dense;
pub mod display;
pub mod interp;
pub mod ior;
pub mod metals;
pub mod rgb2spec;
pub mod sampled;
pub mod stokes;
pub mod uplift;

pub use dense::DenseSpectrum;
pub use sampled::{SampledSpectrum, SampledWavelengths};

/// Shortest wavelength heron transports, nm (pbrt-v4 and Mitsuba 3 use the same range).
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength heron transports, nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Number of 1 nm samples in a [`DenseSpectrum`] (360..=830).
pub const DENSE_LEN: usize = 471;
