//! Sampled wavelengths and spectra.
pub struct SampledSpectrum<const N: usize>(pub [f32; N]);
pub struct SampledWavelengths<const N: usize>;
