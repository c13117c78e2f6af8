//! Planck's law: the spectral radiance of a black body, for emitters given by their
//! temperature (Mitsuba 3 `blackbody`, pbrt-v4 `BlackbodySpectrum`).
//!
//! B(λ, T) = 2hc² / (λ⁵ (exp(hc / (λ k T)) − 1)), here in W m⁻² sr⁻¹ nm⁻¹ with the
//! CODATA 2014 constants Mitsuba 3.9 uses (`src/spectra/blackbody.cpp`), so that an
//! imported Mitsuba blackbody keeps its absolute values. A scene's
//! `{ blackbody = T }` is this spectrum scaled to luminance Y = 1, as heron's named
//! illuminants are ([`blackbody_unit`]); [`blackbody_luminance`] is the factor between
//! the two.
use super::cie::spectrum_to_xyz;
use super::DenseSpectrum;

const C: f64 = 2.997_924_58e8;
const H: f64 = 6.626_070_04e-34;
const K: f64 = 1.380_648_52e-23;

/// The lowest and highest temperatures a scene may give, K: below 100 K the visible
/// radiance underflows f64's exponent in places (exp(hc/λkT) > 1e308 at 360 nm), and
/// 1e6 K is far beyond any star's colour (its shape no longer changes in the visible).
pub const KELVIN_RANGE: (f64, f64) = (100.0, 1.0e6);

/// B(λ, T) in W m⁻² sr⁻¹ nm⁻¹ (λ in nm, T in K).
pub fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    let l = lambda_nm * 1e-9;
    let x = H * C / (l * K * kelvin);
    // Per metre of wavelength, then per nanometre.
    1e-9 * 2.0 * H * C * C / (l.powi(5) * x.exp_m1())
}

/// B(·, T) on heron's 1 nm grid, absolute (W m⁻² sr⁻¹ nm⁻¹).
pub fn blackbody(kelvin: f64) -> DenseSpectrum {
    DenseSpectrum::from_fn(|l| planck(l as f64, kelvin) as f32)
}

/// The film's luminance Y of [`blackbody`] (heron's convention: Σ L ȳ / Σ ȳ).
pub fn blackbody_luminance(kelvin: f64) -> f64 {
    let s = blackbody(kelvin);
    spectrum_to_xyz(&s)[1] as f64
}

/// B(·, T) scaled to luminance Y = 1.
pub fn blackbody_unit(kelvin: f64) -> DenseSpectrum {
    let s = blackbody(kelvin);
    let y = spectrum_to_xyz(&s)[1];
    s.scaled(1.0 / y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::cie::spectrum_to_xyz;

    #[test]
    fn wien_peak_and_stefan_boltzmann() {
        // Wien's displacement law: the peak at b / T, b = 2.897772e-3 m K.
        let t = 5800.0;
        let peak = (300..3000)
            .map(|i| i as f64)
            .max_by(|a, b| planck(*a, t).total_cmp(&planck(*b, t)))
            .unwrap();
        assert!((peak - 2.897772e6 / t).abs() <= 1.0, "{peak}");
        // ∫ B dλ over all wavelengths is σT⁴/π (σ = 5.670367e-8 W m⁻² K⁻⁴).
        let mut integral = 0.0;
        let mut l = 50.0;
        while l < 1.0e5 {
            integral += planck(l + 0.5, t);
            l += 1.0;
        }
        let expect = 5.670367e-8 * t.powi(4) / std::f64::consts::PI;
        assert!(
            (integral / expect - 1.0).abs() < 2e-3,
            "{integral} vs {expect}"
        );
    }

    #[test]
    fn unit_blackbody_has_unit_luminance_and_its_chromaticity() {
        // CIE 1931 chromaticity of the Planckian locus at 6504 K ≈ (0.3135, 0.3237)
        // (Wyszecki & Stiles, Table 1(3.3.4)), and Illuminant A's 2856 K (0.4476, 0.4074).
        for (t, x0, y0) in [(6504.0, 0.3135, 0.3237), (2856.0, 0.4476, 0.4074)] {
            let xyz = spectrum_to_xyz(&blackbody_unit(t));
            let s = xyz[0] + xyz[1] + xyz[2];
            assert!((xyz[1] - 1.0).abs() < 1e-5);
            assert!(
                (xyz[0] / s - x0).abs() < 1e-3 && (xyz[1] / s - y0).abs() < 1e-3,
                "{t}: {xyz:?}"
            );
        }
        assert!(
            (blackbody_luminance(5000.0) - spectrum_to_xyz(&blackbody(5000.0))[1] as f64).abs()
                < 1e-3
        );
    }
}
