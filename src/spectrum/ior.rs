//! Refractive-index models n(λ). Units: the API takes λ in nm; the dispersion formulas
//! use λ in µm, as their catalogues do.
//!
//! - Sellmeier: n²(λ) = 1 + Σ_i B_i λ² / (λ² − C_i), with λ in µm and C_i in µm² (the form
//!   of the Schott catalogue, Malitson 1965, Daimon & Masumura 2007).
//! - Cauchy: n(λ) = A + B/λ² + C/λ⁴, with λ in µm.
//! - Tabulated: linear interpolation of (λ nm, n) samples.
//!
//! The named catalogue lives in spectra/ior_catalogue.toml, compiled into the binary
//! with the tables its `table =` entries name (ice: Warren & Brandt 2008).
use super::DenseSpectrum;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// Up to four Sellmeier terms (the water fit has four); unused terms have B = 0.
pub const SELLMEIER_TERMS: usize = 4;

#[derive(Clone, Debug, PartialEq)]
pub enum Ior {
    /// The same index at every wavelength (no dispersion).
    Constant(f32),
    Sellmeier {
        b: [f32; SELLMEIER_TERMS],
        c: [f32; SELLMEIER_TERMS],
    },
    Cauchy {
        a: f32,
        b: f32,
        c: f32,
    },
    Table(DenseSpectrum),
}

impl Ior {
    /// n at `lambda_nm`.
    #[inline]
    pub fn eval(&self, lambda_nm: f32) -> f32 {
        match self {
            Ior::Constant(n) => *n,
            Ior::Sellmeier { b, c } => {
                let l2 = (lambda_nm * 1e-3) * (lambda_nm * 1e-3);
                let mut n2 = 1.0;
                for i in 0..SELLMEIER_TERMS {
                    n2 += b[i] * l2 / (l2 - c[i]);
                }
                n2.sqrt()
            }
            Ior::Cauchy { a, b, c } => {
                let l2 = (lambda_nm * 1e-3) * (lambda_nm * 1e-3);
                a + b / l2 + c / (l2 * l2)
            }
            Ior::Table(t) => t.eval(lambda_nm),
        }
    }

    /// True when n depends on wavelength, so that refraction separates the lanes.
    pub fn is_dispersive(&self) -> bool {
        match self {
            Ior::Constant(_) => false,
            Ior::Sellmeier { b, .. } => b.iter().any(|&x| x != 0.0),
            Ior::Cauchy { b, c, .. } => *b != 0.0 || *c != 0.0,
            Ior::Table(t) => !t.is_constant(),
        }
    }

    /// Builds a Sellmeier model from 1 to 4 (B, C) pairs.
    pub fn sellmeier(b: &[f32], c: &[f32]) -> Result<Ior, String> {
        if b.len() != c.len() || b.is_empty() || b.len() > SELLMEIER_TERMS {
            return Err(format!(
                "expected 1 to {SELLMEIER_TERMS} B and as many C coefficients, got {} and {}",
                b.len(),
                c.len()
            ));
        }
        let mut bb = [0.0; SELLMEIER_TERMS];
        let mut cc = [0.0; SELLMEIER_TERMS];
        bb[..b.len()].copy_from_slice(b);
        cc[..c.len()].copy_from_slice(c);
        Ok(Ior::Sellmeier { b: bb, c: cc })
    }

    /// A glass known by its index n_d (587.56 nm, the helium d line) and Abbe number
    /// V_d = (n_d − 1)/(n_F − n_C): the two-term Cauchy model n = A + B/λ² through n_d
    /// whose n_F − n_C (486.13 and 656.27 nm) is (n_d − 1)/V_d. It reproduces both
    /// numbers exactly; between the lines it follows a real glass to about 1e-4, and it
    /// has no UV or IR poles. The form design programs use for "model glasses" (e.g.
    /// Zemax's model glass, Optiland's `AbbeMaterial`).
    pub fn abbe(n_d: f32, v_d: f32) -> Ior {
        let (ld, lf, lc) = (0.5875618f64, 0.4861327f64, 0.6562725f64);
        let b = (n_d as f64 - 1.0) / v_d as f64 / (1.0 / (lf * lf) - 1.0 / (lc * lc));
        let a = n_d as f64 - b / (ld * ld);
        Ior::Cauchy {
            a: a as f32,
            b: b as f32,
            c: 0.0,
        }
    }

    /// Checks that n is finite and at least 1 over 360–830 nm (a pole of a Sellmeier
    /// term inside the range, or a fit used far outside its range, would break this).
    pub fn validate(&self) -> Result<(), String> {
        for l in 360..=830 {
            let n = self.eval(l as f32);
            if !n.is_finite() || n < 1.0 {
                return Err(format!(
                    "expected a refractive index ≥ 1 over 360–830 nm, got n({l} nm) = {n}"
                ));
            }
        }
        Ok(())
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CatalogueEntry {
    #[allow(dead_code)]
    source: String,
    #[serde(default)]
    sellmeier: Option<SellmeierCoefficients>,
    /// A table of spectra/ with columns `wavelength_nm, n, …` ([`TABLES`]).
    #[serde(default)]
    table: Option<String>,
    n_d: f32,
    #[serde(default)]
    v_d: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SellmeierCoefficients {
    b: Vec<f32>,
    c: Vec<f32>,
}

/// One catalogue material: its model, and the catalogue's n_d (587.56 nm) and Abbe
/// number V_d (where the source gives one) to check it.
#[derive(Clone, Debug)]
pub struct CatalogueMaterial {
    pub name: String,
    pub ior: Ior,
    pub n_d: f32,
    pub v_d: Option<f32>,
}

const CATALOGUE: &str = include_str!("../../spectra/ior_catalogue.toml");

/// The tables of spectra/ the catalogue's `table =` entries may name, compiled in.
const TABLES: [(&str, &str); 1] = [(
    "ice_warren_brandt2008.csv",
    include_str!("../../spectra/ice_warren_brandt2008.csv"),
)];

/// n(λ) from a compiled-in table's `n` column, linear between its rows.
fn table_ior(name: &str) -> Ior {
    let (_, text) = TABLES
        .iter()
        .find(|(n, _)| *n == name)
        .expect("the catalogue names a compiled-in table");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = header
        .iter()
        .position(|h| h.trim() == "n")
        .expect("a column n");
    let rows: Vec<(f32, f32)> = lines
        .filter_map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            Some((
                cells[0].trim().parse().ok()?,
                cells.get(col)?.trim().parse().ok()?,
            ))
        })
        .collect();
    Ior::Table(DenseSpectrum::from_table_with(
        &rows,
        super::interp::Interpolation::Linear,
    ))
}

/// The named refractive-index models of spectra/ior_catalogue.toml, by name.
pub fn catalogue() -> &'static BTreeMap<String, CatalogueMaterial> {
    static CAT: OnceLock<BTreeMap<String, CatalogueMaterial>> = OnceLock::new();
    CAT.get_or_init(|| {
        let raw: BTreeMap<String, CatalogueEntry> =
            toml::from_str(CATALOGUE).expect("spectra/ior_catalogue.toml is valid");
        raw.into_iter()
            .map(|(name, e)| {
                let ior = match (&e.sellmeier, &e.table) {
                    (Some(s), None) => Ior::sellmeier(&s.b, &s.c).expect("catalogue coefficients"),
                    (None, Some(t)) => table_ior(t),
                    _ => panic!("catalogue entry {name}: expected sellmeier or table"),
                };
                (
                    name.clone(),
                    CatalogueMaterial {
                        name,
                        ior,
                        n_d: e.n_d,
                        v_d: e.v_d,
                    },
                )
            })
            .collect()
    })
}

/// The model named `name` in the catalogue.
pub fn named(name: &str) -> Option<Ior> {
    catalogue().get(name).map(|m| m.ior.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_reproduces_its_n_d() {
        assert!(catalogue().len() >= 6);
        for m in catalogue().values() {
            let n = m.ior.eval(587.56);
            let tol = if m.name == "water" { 5e-4 } else { 1e-4 };
            assert!((n - m.n_d).abs() < tol, "{}: n_d {n} vs {}", m.name, m.n_d);
            assert!(m.ior.is_dispersive());
            m.ior.validate().unwrap();
        }
    }

    #[test]
    fn abbe_model_reproduces_n_d_and_v_d() {
        for (n_d, v_d) in [(1.5168f32, 64.17f32), (1.7847, 25.76), (1.0, 50.0)] {
            let m = Ior::abbe(n_d, v_d);
            let (d, f, c) = (m.eval(587.5618), m.eval(486.1327), m.eval(656.2725));
            assert!((d - n_d).abs() < 2e-6, "{d} vs {n_d}");
            if n_d > 1.0 {
                let v = (d - 1.0) / (f - c);
                assert!((v - v_d).abs() < 2e-3 * v_d, "{v} vs {v_d}");
            }
        }
    }

    #[test]
    fn normal_dispersion_index_falls_with_wavelength() {
        for m in catalogue().values() {
            let (f, c) = (m.ior.eval(486.13), m.ior.eval(656.27));
            assert!(f > c, "{}: n_F {f} <= n_C {c}", m.name);
        }
        // Abbe numbers (n_d − 1)/(n_F − n_C) as the data sheets give them (N-BK7: 64.17),
        // to their last digit: 0.01 apart from rounding.
        let mut checked = 0;
        for m in catalogue().values() {
            let Some(v_d) = m.v_d else { continue };
            let n = |l: f32| m.ior.eval(l) as f64;
            let v = (n(587.56) - 1.0) / (n(486.13) - n(656.27));
            assert!(
                (v - v_d as f64).abs() < 0.015,
                "{}: V_d {v} vs {v_d}",
                m.name
            );
            checked += 1;
        }
        assert!(checked >= 11, "{checked} Abbe numbers");
        assert_eq!(catalogue()["N-BK7"].v_d, Some(64.17));
    }

    #[test]
    fn cauchy_and_constant() {
        let c = Ior::Cauchy {
            a: 1.5,
            b: 0.004,
            c: 0.0,
        };
        assert!((c.eval(500.0) - (1.5 + 0.004 / 0.25)).abs() < 1e-6);
        assert!(c.is_dispersive());
        assert!(!Ior::Constant(1.5).is_dispersive());
        assert!(Ior::Cauchy {
            a: 0.5,
            b: 0.0,
            c: 0.0
        }
        .validate()
        .is_err());
        assert!(
            Ior::sellmeier(&[1.0], &[0.2]).unwrap().validate().is_err(),
            "pole at 447 nm"
        );
    }
}
