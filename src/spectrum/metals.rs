//! Complex refractive indices n(λ) + i k(λ) of metals: the catalogue compiled from
//! `spectra/metals/` (gold, silver and copper from Johnson & Christy 1972, aluminium from
//! Rakić et al. 1998's Lorentz–Drude model; spectra/README.md names the sources and
//! `scripts/gen_metals.py` made the files) and user tables with rows
//! `wavelength_nm,n,k`. Values go onto heron's 1 nm grid as every spectral CSV does
//! ([`DenseSpectrum::from_table`]: Sprague for uniform rows, a not-a-knot cubic spline
//! for irregular ones, as colour-science), and the interpolated table must keep n > 0
//! and k ≥ 0.
use super::csv::{interpolate_column, parse_columns};
use super::DenseSpectrum;
use crate::{HeronError, Result};
use std::path::Path;
use std::sync::OnceLock;

/// A spectral complex refractive index n(λ) + i k(λ), relative to the outside (n = 1).
/// Its Fresnel reflectance is `bsdf::conductor`'s.
#[derive(Clone, Debug, PartialEq)]
pub struct ComplexIor {
    pub n: DenseSpectrum,
    pub k: DenseSpectrum,
}

/// The catalogue's names, in the order error messages list them.
pub const METAL_NAMES: &[&str] = &["Ag", "Al", "Au", "Cu"];

const FILES: [(&str, &str); 4] = [
    ("Ag", include_str!("../../spectra/metals/Ag.csv")),
    ("Al", include_str!("../../spectra/metals/Al.csv")),
    ("Au", include_str!("../../spectra/metals/Au.csv")),
    ("Cu", include_str!("../../spectra/metals/Cu.csv")),
];

/// Parses a `wavelength_nm,n,k` table; n > 0 and k ≥ 0 in every row, and the rows must
/// cover 360–830 nm (a metal's index is not extrapolated).
pub fn parse_nk(text: &str, path: &Path) -> Result<ComplexIor> {
    let rows = parse_columns(text, path, &["wavelength_nm", "n", "k"])?;
    let file = path.display();
    for r in &rows {
        if !(r[1] > 0.0) || !(r[2] >= 0.0) {
            return Err(HeronError::Invalid(format!(
                "{file}: expected n > 0 and k >= 0, got n = {} and k = {} at {} nm",
                r[1], r[2], r[0]
            )));
        }
    }
    let (first, last) = (rows[0][0], rows[rows.len() - 1][0]);
    if first > crate::spectrum::LAMBDA_MIN || last < crate::spectrum::LAMBDA_MAX {
        return Err(HeronError::Invalid(format!(
            "{file}: expected rows covering 360–830 nm, got {first}–{last} nm"
        )));
    }
    let n: Vec<(f32, f32)> = rows.iter().map(|r| (r[0], r[1])).collect();
    let k: Vec<(f32, f32)> = rows.iter().map(|r| (r[0], r[2])).collect();
    let ior = ComplexIor {
        n: interpolate_column(path, "n", &n)?,
        k: interpolate_column(path, "k", &k)?,
    };
    // A spline can overshoot between rows; the interpolated table must stay physical.
    for (i, (&nv, &kv)) in ior.n.values().iter().zip(ior.k.values()).enumerate() {
        if !(nv > 0.0) || !(kv >= 0.0) {
            return Err(HeronError::Invalid(format!(
                "{file}: the interpolated index has n = {nv} and k = {kv} at {} nm; expected n > 0 and k >= 0 (add rows where the data changes quickly)",
                crate::spectrum::LAMBDA_MIN + i as f32
            )));
        }
    }
    Ok(ior)
}

/// Reads a user's `wavelength_nm,n,k` table.
pub fn read_nk(path: &Path) -> Result<ComplexIor> {
    let text = std::fs::read_to_string(path).map_err(|e| HeronError::Io {
        path: path.to_path_buf(),
        message: format!("cannot read the n, k table: {e}"),
    })?;
    parse_nk(&text, path)
}

/// The catalogue entry `name` (Ag, Al, Au, Cu).
pub fn named(name: &str) -> Option<ComplexIor> {
    static CATALOGUE: OnceLock<Vec<(&'static str, ComplexIor)>> = OnceLock::new();
    let cat = CATALOGUE.get_or_init(|| {
        FILES
            .iter()
            .map(|(n, text)| {
                let path = format!("spectra/metals/{n}.csv");
                (
                    *n,
                    parse_nk(text, Path::new(&path)).expect("the compiled-in metal tables parse"),
                )
            })
            .collect()
    });
    cat.iter().find(|(n, _)| *n == name).map(|(_, c)| c.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_metals_have_their_colours() {
        // Normal-incidence reflectance from the tables: gold and copper rise toward the
        // red, silver and aluminium are high and flat.
        let r = |m: &ComplexIor, l: f32| {
            let (n, k) = (m.n.eval(l), m.k.eval(l));
            ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
        };
        let au = named("Au").unwrap();
        let cu = named("Cu").unwrap();
        let ag = named("Ag").unwrap();
        let al = named("Al").unwrap();
        assert!(r(&au, 450.0) < 0.45 && r(&au, 650.0) > 0.9);
        assert!(r(&cu, 450.0) < 0.6 && r(&cu, 650.0) > 0.9);
        assert!(r(&ag, 450.0) > 0.95 && r(&ag, 650.0) > 0.95);
        assert!((r(&al, 550.0) - 0.915).abs() < 0.01);
        assert!(named("Pt").is_none());
    }

    #[test]
    fn tables_must_cover_the_visible_range_and_be_physical() {
        let p = Path::new("m.csv");
        let e = |t: &str| parse_nk(t, p).unwrap_err().to_string();
        assert!(e("400,1,2\n900,1,2\n").contains("covering 360–830 nm, got 400–900 nm"));
        assert!(e("300,1,2\n900,-1,2\n").contains("n > 0 and k >= 0"));
        assert!(e("300,1\n900,1\n").contains("three comma-separated numbers `wavelength_nm,n,k`"));
        assert!(parse_nk("wavelength_nm,n,k\n300,1,2\n900,1.5,3\n", p).is_ok());
    }
}
