//! CIE 1931 2° colour-matching functions at 1 nm over 360–830 nm, embedded from
//! spectra/cie1931_2deg.csv (generated from colour-science; see spectra/README.md).
//!
//! Film convention: XYZ = Σ L(λ) x̄(λ) Δλ / Σ ȳ(λ) Δλ, so a constant spectrum L = 1 has
//! Y = 1.
use super::{DenseSpectrum, DENSE_LEN, LAMBDA_MIN};
use std::sync::OnceLock;

const CIE1931_CSV: &str = include_str!("../../spectra/cie1931_2deg.csv");
const D65_CSV: &str = include_str!("../../spectra/cie_d65.csv");

/// The observer's three matching functions as dense tables, and Σ ȳ Δλ.
pub struct Observer {
    pub x: DenseSpectrum,
    pub y: DenseSpectrum,
    pub z: DenseSpectrum,
    pub y_integral: f32,
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

/// The CIE 1931 2° standard observer.
pub fn cie1931() -> &'static Observer {
    static OBS: OnceLock<Observer> = OnceLock::new();
    OBS.get_or_init(|| {
        let rows = parse_table(CIE1931_CSV, 3);
        let y = dense_column(&rows, 1);
        let y_integral = y.values().iter().map(|&v| v as f64).sum::<f64>() as f32;
        Observer {
            x: dense_column(&rows, 0),
            y,
            z: dense_column(&rows, 2),
            y_integral,
        }
    })
}

/// CIE standard illuminant D65 as tabulated (relative power, 100 at 560 nm).
pub fn d65_relative() -> &'static DenseSpectrum {
    static D65: OnceLock<DenseSpectrum> = OnceLock::new();
    D65.get_or_init(|| dense_column(&parse_table(D65_CSV, 1), 0))
}

/// CIE XYZ of a dense spectrum under the film convention (Riemann sum at 1 nm).
pub fn spectrum_to_xyz(s: &DenseSpectrum) -> [f32; 3] {
    let o = cie1931();
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
