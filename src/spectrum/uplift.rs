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

/// Reflectance spectrum for a linear sRGB reflectance (components expected in [0, 1];
/// the scene loader checks that).
pub fn rgb_to_reflectance(rgb: [f32; 3]) -> DenseSpectrum {
    let t = smits_terms(rgb);
    DenseSpectrum::from_fn(|l| t.iter().map(|(s, w)| w * s.eval(l)).sum::<f32>().max(0.0))
}

/// Emission spectrum for a linear sRGB emitter colour (components ≥ 0): the Smits
/// uplift times D65 scaled to luminance Y = 1, so (1, 1, 1) is the sRGB white point
/// with Y = 1, and the colour scales linearly with the components.
pub fn rgb_to_illuminant(rgb: [f32; 3]) -> DenseSpectrum {
    rgb_to_reflectance(rgb).mul(d65_unit())
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
