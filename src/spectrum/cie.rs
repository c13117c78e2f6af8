//! CIE colorimetric data at 1 nm over 360–830 nm, embedded from spectra/ (generated
//! from colour-science 0.4.7 by scripts/gen_spectra.py; spectra/README.md names each
//! source):
//!
//! - the CIE 1931 2° standard observer ([`cie1931`], spectra/cie1931_2deg.csv), the one
//!   the renderer's film uses;
//! - the CIE 1964 10° standard observer ([`cie1964`], spectra/cie1964_10deg.csv);
//! - CIE standard illuminant D65 ([`d65_relative`], [`d65_unit`], spectra/cie_d65.csv);
//! - CIE illuminant D50 ([`d50_relative`], spectra/cie_d50.csv; `heron color` only);
//! - CIE standard illuminant A ([`illuminant_a_relative`], [`illuminant_a_unit`],
//!   spectra/cie_a.csv);
//! - CIE illuminant E, the constant 1 ([`illuminant_e`]; no table).
//!
//! Film convention: XYZ = Σ L(λ) x̄(λ) Δλ / Σ ȳ(λ) Δλ, so a constant spectrum L = 1 has
//! Y = 1.
use super::{DenseSpectrum, DENSE_LEN, LAMBDA_MIN};
use std::sync::OnceLock;

const CIE1931_CSV: &str = include_str!("../../spectra/cie1931_2deg.csv");
const CIE1964_CSV: &str = include_str!("../../spectra/cie1964_10deg.csv");
const D65_CSV: &str = include_str!("../../spectra/cie_d65.csv");
const D50_CSV: &str = include_str!("../../spectra/cie_d50.csv");
const A_CSV: &str = include_str!("../../spectra/cie_a.csv");

/// The observer's three matching functions as dense tables, and Σ ȳ Δλ.
pub struct Observer {
    pub x: DenseSpectrum,
    pub y: DenseSpectrum,
    pub z: DenseSpectrum,
    pub y_integral: f32,
    /// (x̄, ȳ, z̄, 0) per 1 nm row, interleaved so that the film's weights of one lane are
    /// one 16-byte load and one lerp instead of three table walks.
    xyz: Box<[glam::Vec4; DENSE_LEN]>,
}

impl Observer {
    /// (x̄, ȳ, z̄, 0) at a [`DenseSpectrum::position`].
    #[inline]
    pub fn xyz_at(&self, i: usize, t: f32) -> glam::Vec4 {
        let a = self.xyz[i];
        a + t * (self.xyz[i + 1] - a)
    }
}

/// Parses an embedded table with a header line and columns `wavelength_nm, v1, v2, …`.
/// The tables are part of the build, so a malformed one is a bug, caught by the tests.
pub(crate) fn parse_table(csv: &str, columns: usize) -> Vec<(f32, Vec<f32>)> {
    csv.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<f32> = l
                .split(',')
                .map(|v| v.trim().parse::<f64>().expect("embedded table") as f32)
                .collect();
            assert_eq!(f.len(), columns + 1, "embedded table row: {l}");
            (f[0], f[1..].to_vec())
        })
        .collect()
}

fn dense_column(rows: &[(f32, Vec<f32>)], c: usize) -> DenseSpectrum {
    assert_eq!(rows.len(), DENSE_LEN);
    assert_eq!(rows[0].0, LAMBDA_MIN);
    let s: Vec<(f32, f32)> = rows.iter().map(|(w, v)| (*w, v[c])).collect();
    DenseSpectrum::from_samples(&s)
}

fn observer_from_table(csv: &str) -> Observer {
    let rows = parse_table(csv, 3);
    let y = dense_column(&rows, 1);
    let y_integral = y.values().iter().map(|&v| v as f64).sum::<f64>() as f32;
    let (x, z) = (dense_column(&rows, 0), dense_column(&rows, 2));
    let mut xyz = Box::new([glam::Vec4::ZERO; DENSE_LEN]);
    for (i, v) in xyz.iter_mut().enumerate() {
        *v = glam::Vec4::new(x.values()[i], y.values()[i], z.values()[i], 0.0);
    }
    Observer {
        x,
        y,
        z,
        y_integral,
        xyz,
    }
}

/// The CIE 1931 2° standard observer (the renderer's film uses this one).
pub fn cie1931() -> &'static Observer {
    static OBS: OnceLock<Observer> = OnceLock::new();
    OBS.get_or_init(|| observer_from_table(CIE1931_CSV))
}

/// The CIE 1964 10° standard observer (x̄₁₀, ȳ₁₀, z̄₁₀), same layout as [`cie1931`].
/// Σ ȳ₁₀ Δλ = 116.6618771; equal energy has XYZ = (0.9998855, 1, 1.0001037) under the
/// film convention with this observer.
pub fn cie1964() -> &'static Observer {
    static OBS: OnceLock<Observer> = OnceLock::new();
    OBS.get_or_init(|| observer_from_table(CIE1964_CSV))
}

/// CIE standard illuminant D65 as tabulated (relative power, 100 at 560 nm).
pub fn d65_relative() -> &'static DenseSpectrum {
    static D65: OnceLock<DenseSpectrum> = OnceLock::new();
    D65.get_or_init(|| dense_column(&parse_table(D65_CSV, 1), 0))
}

/// CIE illuminant D50 as tabulated at 5 nm (relative power, 100 at 560 nm), linearly
/// interpolated to 1 nm and held at its 780 nm value (78.274) over 781–830 nm:
/// colour-science's `SDS_ILLUMINANTS["D50"]` aligned to 360–830 nm, as D65 is.
pub fn d50_relative() -> &'static DenseSpectrum {
    static D50: OnceLock<DenseSpectrum> = OnceLock::new();
    D50.get_or_init(|| dense_column(&parse_table(D50_CSV, 1), 0))
}

/// CIE standard illuminant A as tabulated by CIE 15:2004 at 5 nm (relative power, 100 at
/// 560 nm), linearly interpolated to 1 nm and held at its 780 nm value (241.675) over
/// 781–830 nm: colour-science's `SDS_ILLUMINANTS["A"]` aligned to 360–830 nm (see
/// spectra/README.md for how far that is from the Planckian formula).
pub fn illuminant_a_relative() -> &'static DenseSpectrum {
    static A: OnceLock<DenseSpectrum> = OnceLock::new();
    A.get_or_init(|| dense_column(&parse_table(A_CSV, 1), 0))
}

/// Illuminant A scaled so that its luminance under the film convention with the CIE
/// 1931 2° observer is Y = 1 (like [`d65_unit`]).
pub fn illuminant_a_unit() -> &'static DenseSpectrum {
    static AU: OnceLock<DenseSpectrum> = OnceLock::new();
    AU.get_or_init(|| {
        let a = illuminant_a_relative();
        a.scaled(1.0 / spectrum_to_xyz(a)[1])
    })
}

/// CIE illuminant E (equal energy): 1 at every wavelength, which is also Y = 1 under the
/// film convention with either observer.
pub fn illuminant_e() -> DenseSpectrum {
    DenseSpectrum::constant(1.0)
}

/// CIE XYZ of a dense spectrum under the film convention (Riemann sum at 1 nm) with the
/// CIE 1931 2° observer, the one the renderer's film uses.
pub fn spectrum_to_xyz(s: &DenseSpectrum) -> [f32; 3] {
    spectrum_to_xyz_with(cie1931(), s)
}

/// CIE XYZ of a dense spectrum under the film convention with observer `o`:
/// XYZ = Σ s(λ) x̄(λ) Δλ / Σ ȳ(λ) Δλ over the 471 rows at 1 nm (sums in f64), so the
/// constant 1 has Y = 1 for every observer.
pub fn spectrum_to_xyz_with(o: &Observer, s: &DenseSpectrum) -> [f32; 3] {
    let mut xyz = [0.0f64; 3];
    for i in 0..DENSE_LEN {
        let v = s.values()[i] as f64;
        xyz[0] += v * o.x.values()[i] as f64;
        xyz[1] += v * o.y.values()[i] as f64;
        xyz[2] += v * o.z.values()[i] as f64;
    }
    let k = o.y_integral as f64;
    [
        (xyz[0] / k) as f32,
        (xyz[1] / k) as f32,
        (xyz[2] / k) as f32,
    ]
}

/// D65 scaled so that its luminance under the film convention is Y = 1.
pub fn d65_unit() -> &'static DenseSpectrum {
    static D65U: OnceLock<DenseSpectrum> = OnceLock::new();
    D65U.get_or_init(|| {
        let d = d65_relative();
        d.scaled(1.0 / spectrum_to_xyz(d)[1])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f64; 3], tol: f64) -> bool {
        a.iter()
            .zip(b)
            .all(|(&a, b)| (a as f64 - b).abs() <= tol * b.abs())
    }

    fn xy(c: [f32; 3]) -> [f64; 2] {
        let s = (c[0] + c[1] + c[2]) as f64;
        [c[0] as f64 / s, c[1] as f64 / s]
    }

    #[test]
    fn observers_have_the_documented_normalisation() {
        let e = illuminant_e();
        assert!((cie1931().y_integral as f64 - 106.856917101).abs() < 1e-4);
        assert!((cie1964().y_integral as f64 - 116.6618771).abs() < 1e-4);
        let c = spectrum_to_xyz(&e);
        assert!(close(c, [1.00008004, 1.0, 1.00033067], 1e-6), "{c:?}");
        let c = spectrum_to_xyz_with(cie1964(), &e);
        assert!(close(c, [0.9998855, 1.0, 1.00010375], 1e-6), "{c:?}");
    }

    #[test]
    fn tables_start_where_the_csvs_do() {
        let o = cie1964();
        assert_eq!(o.x.values()[0], 1.222e-7);
        assert_eq!(o.z.values()[DENSE_LEN - 1], 0.0);
        assert_eq!(illuminant_a_relative().eval(560.0), 100.0);
        assert_eq!(illuminant_a_relative().eval(830.0), 241.675);
    }

    #[test]
    fn illuminant_a_chromaticity_is_cie_s() {
        // CIE 15:2004 Table T.3: A is (0.44757, 0.40745) for 2° and (0.45117, 0.40594)
        // for 10°. The 5 nm table linearly interpolated to 1 nm lands within 2e-5 of
        // both (x 0.447561, y 0.407431; x10 0.451160, y10 0.405928).
        let a = illuminant_a_relative();
        let c2 = xy(spectrum_to_xyz(a));
        let c10 = xy(spectrum_to_xyz_with(cie1964(), a));
        for (got, want) in [(c2, [0.44757, 0.40745]), (c10, [0.45117, 0.40594])] {
            assert!(
                (got[0] - want[0]).abs() < 3e-5 && (got[1] - want[1]).abs() < 3e-5,
                "{got:?} vs {want:?}"
            );
        }
        let y = spectrum_to_xyz(illuminant_a_unit())[1];
        assert!((y - 1.0).abs() < 1e-6, "{y}");
    }

    #[test]
    fn d50_chromaticity_is_cie_s() {
        // CIE 15:2004 Table T.3: D50 is (0.34567, 0.35850) for 2° and (0.34773, 0.35952)
        // for 10°; the 5 nm table linearly interpolated to 1 nm gives (0.345684,
        // 0.358504) and (0.347748, 0.359536), as colour-science's sd_to_XYZ does.
        let d = d50_relative();
        assert_eq!(d.eval(560.0), 100.0);
        assert_eq!(d.eval(830.0), 78.274);
        let c2 = xy(spectrum_to_xyz(d));
        let c10 = xy(spectrum_to_xyz_with(cie1964(), d));
        for (got, want) in [(c2, [0.34567, 0.35850]), (c10, [0.34773, 0.35952])] {
            assert!(
                (got[0] - want[0]).abs() < 3e-5 && (got[1] - want[1]).abs() < 3e-5,
                "{got:?} vs {want:?}"
            );
        }
    }

    #[test]
    fn existing_d65_unit_is_unchanged() {
        let c = spectrum_to_xyz(d65_unit());
        assert!(close(c, [0.95047076, 1.0, 1.08882842], 1e-6), "{c:?}");
    }
}
