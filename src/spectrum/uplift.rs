//! RGB to spectrum uplift (filled in by the core work).
use super::DenseSpectrum;

/// Reflectance spectrum for a linear sRGB reflectance; values stay in [0, 1] when the
/// input is in [0, 1]; (1, 1, 1) gives the constant 1.
pub fn rgb_to_reflectance(rgb: [f32; 3]) -> DenseSpectrum {
    let _ = rgb;
    unimplemented!()
}

/// Emission spectrum for a linear sRGB emitter colour: the reflectance uplift times the
/// D65 illuminant scaled to luminance Y = 1, so (1, 1, 1) is sRGB white with Y = 1.
pub fn rgb_to_illuminant(rgb: [f32; 3]) -> DenseSpectrum {
    let _ = rgb;
    unimplemented!()
}

/// Named spectra a scene may use: "E" (equal energy, 1 everywhere) and "D65" (scaled
/// to Y = 1).
pub const NAMED_SPECTRA: &[&str] = &["E", "D65"];

pub fn named(name: &str) -> Option<DenseSpectrum> {
    let _ = name;
    unimplemented!()
}
