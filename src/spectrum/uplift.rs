//! RGB to spectrum uplift after Jakob & Hanika (2019), "A Low-Dimensional Function Space
//! for Efficient Spectral Upsampling", Computer Graphics Forum 38(2).
//!
//! A linear sRGB reflectance becomes s(λ) = S(c0 t² + c1 t + c2) with the paper's
//! sigmoid S(x) = ½ + x / (2 √(1 + x²)) and t = (λ − 595 nm) / 235 nm; the coefficients
//! come from heron's own fitted table (spectra/rgb2spec_srgb.bin, interpolated
//! trilinearly as in the paper) and a Gauss–Newton polish against heron's film, so that
//! the reflectance lit by D65 (Y = 1) comes back through the film (CIE 1931 2°, IEC
//! 61966-2-1 matrix) as the same linear sRGB. See [`super::rgb2spec`].
//!
//! Because S maps into (0, 1), a reflectance in [0, 1]³ is within [0, 1] at every
//! wavelength with no clamping. Greys are exactly constant (c = (0, 0, x); black is 0
//! and white is 1 at every wavelength). The round trip is exact to the fit (ΔE*ab 1e-8)
//! except for the grey part of a colour: heron's D65 and the four-digit sRGB matrix
//! disagree on white by up to 1.7e-4 (spectra/README.md), and the constant spectrum is
//! taken as the grey, so a colour comes back within min(r, g, b) · 1.7e-4.
//!
//! (heron used Smits (1999) before; spectra/smits1999.csv is no longer used.)
use super::cie::d65_unit;
use super::rgb2spec::srgb_table;
use super::DenseSpectrum;

/// Reflectance spectrum for a linear sRGB reflectance (components expected in [0, 1];
/// the scene loader checks that, and out-of-range or NaN components are clamped to
/// [0, 1] here). Within [0, 1] at every wavelength by construction.
pub fn rgb_to_reflectance(rgb: [f32; 3]) -> DenseSpectrum {
    srgb_table().coefficients(rgb).to_dense()
}

/// Emission spectrum for a linear sRGB emitter colour (components ≥ 0; negative or NaN
/// ones count as 0), as pbrt-v4's RGBIlluminantSpectrum: with m = max(r, g, b), the
/// reflectance-style spectrum of rgb / m, times m, times D65 scaled to luminance Y = 1.
/// So (1, 1, 1) is exactly D65 at Y = 1 (sRGB white to 2e-4), emitters brighter than 1
/// work, and the colour scales linearly with the components.
pub fn rgb_to_illuminant(rgb: [f32; 3]) -> DenseSpectrum {
    let rgb = rgb.map(|v| if v.is_nan() { 0.0 } else { v.max(0.0) });
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m <= 0.0 {
        return DenseSpectrum::constant(0.0);
    }
    let s = srgb_table().coefficients(rgb.map(|v| v / m)).to_dense();
    s.mul(d65_unit()).scaled(m)
}

/// An unbounded spectrum (a conductor's n or k given in RGB) as pbrt-v4's
/// `RGBUnboundedSpectrum` (Pharr, Jakob & Humphreys, PBR 4th ed., §4.6.6): with
/// m = max(r, g, b), the reflectance-style spectrum of rgb / (2m), times 2m. The factor
/// 2 keeps the fitted sigmoid away from its saturation at 1, where it cannot follow a
/// colour's shape; the result reproduces the RGB curve's values roughly, not through a
/// film (n and k are not colours seen by an observer). Negative or NaN components
/// count as 0.
pub fn rgb_to_unbounded(rgb: [f32; 3]) -> DenseSpectrum {
    let rgb = rgb.map(|v| if v.is_nan() { 0.0 } else { v.max(0.0) });
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m <= 0.0 {
        return DenseSpectrum::constant(0.0);
    }
    let scale = 2.0 * m;
    srgb_table()
        .coefficients(rgb.map(|v| v / scale))
        .to_dense()
        .scaled(scale)
}

/// Named spectra a scene may use: "E" (equal energy, 1 at every wavelength), and the
/// CIE illuminants "D65" and "A", each scaled to Y = 1.
pub const NAMED_SPECTRA: &[&str] = &["E", "D65", "A"];

pub fn named(name: &str) -> Option<DenseSpectrum> {
    match name {
        "E" => Some(DenseSpectrum::constant(1.0)),
        "D65" => Some(d65_unit().clone()),
        "A" => Some(super::cie::illuminant_a_unit().clone()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::cie::spectrum_to_xyz;
    use crate::spectrum::color::xyz_to_linear_srgb;

    fn film_rgb(s: &DenseSpectrum) -> [f32; 3] {
        xyz_to_linear_srgb(spectrum_to_xyz(s))
    }

    #[test]
    fn an_unbounded_uplift_keeps_greys_scales_linearly_and_follows_the_channels() {
        // A grey index g is exactly constant: rgb / 2g is the grey 0.5.
        let g = rgb_to_unbounded([2.5; 3]);
        assert!((g.min_value() - 2.5).abs() < 1e-5 && (g.max_value() - 2.5).abs() < 1e-5);
        // Scaling the channels scales the spectrum.
        let a = rgb_to_unbounded([0.143, 0.374, 1.442]);
        let b = rgb_to_unbounded([0.286, 0.748, 2.884]);
        for l in [400.0, 500.0, 600.0, 700.0] {
            assert!((2.0 * a.eval(l) - b.eval(l)).abs() < 1e-5 * b.eval(l).max(1.0));
        }
        // Gold's n: low in the red, high in the blue, near the channels' values.
        assert!(
            a.eval(620.0) < 0.3 && a.eval(450.0) > 1.0,
            "{} {}",
            a.eval(620.0),
            a.eval(450.0)
        );
        assert_eq!(rgb_to_unbounded([0.0, -1.0, f32::NAN]).max_value(), 0.0);
    }

    #[test]
    fn reflectances_stay_within_zero_and_one() {
        for r in 0..=10 {
            for g in 0..=10 {
                for b in 0..=10 {
                    let rgb = [r as f32 / 10.0, g as f32 / 10.0, b as f32 / 10.0];
                    let s = rgb_to_reflectance(rgb);
                    assert!(s.min_value() >= 0.0 && s.max_value() <= 1.0, "{rgb:?}");
                }
            }
        }
        // Out-of-range input is clamped, not extrapolated.
        let s = rgb_to_reflectance([1.5, -0.2, f32::NAN]);
        assert!(s.min_value() >= 0.0 && s.max_value() <= 1.0);
        assert_eq!(s, rgb_to_reflectance([1.0, 0.0, 0.0]));
    }

    #[test]
    fn greys_are_constant_black_is_zero_white_is_one() {
        assert_eq!(rgb_to_reflectance([0.0; 3]), DenseSpectrum::constant(0.0));
        assert_eq!(rgb_to_reflectance([1.0; 3]), DenseSpectrum::constant(1.0));
        for g in [0.001f32, 0.18, 0.5, 0.8, 0.999] {
            let s = rgb_to_reflectance([g; 3]);
            assert!(s.is_constant() && (s.values()[0] - g).abs() < 1e-6, "{g}");
        }
        assert_eq!(rgb_to_illuminant([0.0; 3]), DenseSpectrum::constant(0.0));
    }

    #[test]
    fn white_light_is_d65_at_unit_luminance_and_srgb_white() {
        let w = rgb_to_illuminant([1.0, 1.0, 1.0]);
        assert_eq!(&w, d65_unit());
        for v in film_rgb(&w) {
            assert!((v - 1.0).abs() < 2e-4, "{v}");
        }
        let d = spectrum_to_xyz(&named("D65").unwrap());
        assert!((d[1] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn illuminant_colours_come_back_as_their_rgb() {
        // Jakob–Hanika plus the polish is an inverse of the film to the grey part's
        // 1.7e-4 (Smits' basis missed the green primary by 0.09).
        for rgb in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.5, 0.5],
            [0.1, 0.3, 0.6],
            [4.0, 2.0, 0.5],
            [0.0, 30.0, 10.0],
        ] {
            let m = rgb.iter().fold(0.0f32, |a, &b| a.max(b));
            let c = film_rgb(&rgb_to_illuminant(rgb));
            for i in 0..3 {
                assert!((c[i] - rgb[i]).abs() <= 2e-4 * m, "{rgb:?} -> {c:?}");
            }
        }
    }

    #[test]
    fn illuminants_scale_linearly() {
        let a = rgb_to_illuminant([0.2, 0.4, 0.1]);
        let b = rgb_to_illuminant([2.0, 4.0, 1.0]);
        for (x, y) in a.values().iter().zip(b.values()) {
            assert!((10.0 * x - y).abs() <= 1e-5 * y.max(1e-3), "{x} {y}");
        }
    }

    #[test]
    fn named_illuminants_have_unit_luminance_and_their_white_points() {
        use crate::spectrum::cie::spectrum_to_xyz;
        for (name, xy) in [
            ("D65", (0.3127, 0.3290)),
            ("A", (0.4476, 0.4074)),
            ("E", (0.3333, 0.3333)),
        ] {
            let xyz = spectrum_to_xyz(&named(name).unwrap());
            let sum = xyz[0] + xyz[1] + xyz[2];
            assert!((xyz[1] - 1.0).abs() < 1e-5, "{name}: Y = {}", xyz[1]);
            assert!(
                (xyz[0] / sum - xy.0).abs() < 2e-4 && (xyz[1] / sum - xy.1).abs() < 2e-4,
                "{name}"
            );
        }
        assert!(named("F2").is_none());
    }
}
