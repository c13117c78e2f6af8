//! RGB to spectrum uplift after Smits (1999), "An RGB-to-Spectrum Conversion for
//! Reflectances", Journal of Graphics Tools 4(4). The seven basis spectra (white, cyan,
//! magenta, yellow, red, green, blue) are in spectra/smits1999.csv at Smits' ten sample
//! wavelengths over 380–720 nm; heron interpolates them linearly and holds the end
//! values beyond.
//!
//! Smits' construction is a non-negative combination of basis spectra bounded by 1 whose
//! weights sum to max(r, g, b), so a reflectance in [0, 1]³ stays within [0, 1] at every
//! wavelength, and white is (to the table's four digits) the constant 1.
use super::cie::{d65_unit, parse_table};
use super::DenseSpectrum;
use std::sync::OnceLock;

const SMITS_CSV: &str = include_str!("../../spectra/smits1999.csv");

struct SmitsBasis {
    white: DenseSpectrum,
    cyan: DenseSpectrum,
    magenta: DenseSpectrum,
    yellow: DenseSpectrum,
    red: DenseSpectrum,
    green: DenseSpectrum,
    blue: DenseSpectrum,
}

fn basis() -> &'static SmitsBasis {
    static B: OnceLock<SmitsBasis> = OnceLock::new();
    B.get_or_init(|| {
        let rows = parse_table(SMITS_CSV, 7);
        let col = |c: usize| {
            let s: Vec<(f32, f32)> = rows.iter().map(|(w, v)| (*w, v[c])).collect();
            DenseSpectrum::from_samples(&s)
        };
        SmitsBasis {
            white: col(0),
            cyan: col(1),
            magenta: col(2),
            yellow: col(3),
            red: col(4),
            green: col(5),
            blue: col(6),
        }
    })
}

/// Smits' weights: (spectrum, weight) pairs for the white and the two chromatic bases.
fn smits_terms(rgb: [f32; 3]) -> [(&'static DenseSpectrum, f32); 3] {
    let b = basis();
    let [r, g, bl] = rgb;
    if r <= g && r <= bl {
        if g <= bl {
            [(&b.white, r), (&b.cyan, g - r), (&b.blue, bl - g)]
        } else {
            [(&b.white, r), (&b.cyan, bl - r), (&b.green, g - bl)]
        }
    } else if g <= r && g <= bl {
        if r <= bl {
            [(&b.white, g), (&b.magenta, r - g), (&b.blue, bl - r)]
        } else {
            [(&b.white, g), (&b.magenta, bl - g), (&b.red, r - bl)]
        }
    } else if r <= g {
        [(&b.white, bl), (&b.yellow, r - bl), (&b.green, g - r)]
    } else {
        [(&b.white, bl), (&b.yellow, g - bl), (&b.red, r - g)]
    }
}

fn smits(rgb: [f32; 3]) -> DenseSpectrum {
    let t = smits_terms(rgb);
    DenseSpectrum::from_fn(|l| t.iter().map(|(s, w)| w * s.eval(l)).sum::<f32>().max(0.0))
}

/// Reflectance spectrum for a linear sRGB reflectance (components expected in [0, 1];
/// the scene loader checks that). Smits' red and cyan bases exceed 1 slightly (up to
/// 1.015), so the result is clamped to [0, 1]: a surface must not reflect more than it
/// receives at any wavelength.
pub fn rgb_to_reflectance(rgb: [f32; 3]) -> DenseSpectrum {
    let s = smits(rgb);
    DenseSpectrum::from_fn(|l| s.eval(l).min(1.0))
}

/// Emission spectrum for a linear sRGB emitter colour (components ≥ 0): the Smits
/// uplift times D65 scaled to luminance Y = 1, so (1, 1, 1) is the sRGB white point
/// with Y = 1, and the colour scales linearly with the components.
pub fn rgb_to_illuminant(rgb: [f32; 3]) -> DenseSpectrum {
    smits(rgb).mul(d65_unit())
}

/// Named spectra a scene may use: "E" (equal energy, 1 at every wavelength) and "D65"
/// (scaled to Y = 1).
pub const NAMED_SPECTRA: &[&str] = &["E", "D65"];

pub fn named(name: &str) -> Option<DenseSpectrum> {
    match name {
        "E" => Some(DenseSpectrum::constant(1.0)),
        "D65" => Some(d65_unit().clone()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::cie::spectrum_to_xyz;
    use crate::spectrum::color::xyz_to_linear_srgb;

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
    }

    #[test]
    fn white_light_is_srgb_white_with_unit_luminance() {
        let c = xyz_to_linear_srgb(spectrum_to_xyz(&rgb_to_illuminant([1.0, 1.0, 1.0])));
        for v in c {
            assert!((v - 1.0).abs() < 2e-3, "{c:?}");
        }
        let d = spectrum_to_xyz(&named("D65").unwrap());
        assert!((d[1] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn illuminant_colours_come_back_close_to_their_rgb() {
        // Smits' basis was fitted for a different RGB space, so it is no exact inverse
        // of sRGB: the green primary comes back with 0.09 blue. Greys and the course's
        // background within 0.03, primaries within 0.1.
        for rgb in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.5, 0.5],
            [0.1, 0.3, 0.6],
        ] {
            let c = xyz_to_linear_srgb(spectrum_to_xyz(&rgb_to_illuminant(rgb)));
            let grey_or_soft = rgb.iter().all(|&v| v > 0.05);
            let tol = if grey_or_soft { 0.03 } else { 0.1 };
            for i in 0..3 {
                assert!((c[i] - rgb[i]).abs() < tol, "{rgb:?} -> {c:?}");
            }
        }
    }
}
