//! `heron color`: the CIE XYZ, xy and linear sRGB of a spectral distribution read from a
//! CSV file, computed with the renderer's own tables and code ([`crate::spectrum::cie`],
//! [`DenseSpectrum`], [`crate::spectrum::color`]) so that anyone can hold heron's
//! colorimetry against colour-science (tests/python/test_color_cmd.py does).
//!
//! The file is read by [`SpectrumCsv`] (its format is documented there) and put on the
//! 1 nm grid by CIE 167:2005's rules as colour-science applies them (Sprague for uniform
//! rows, a cubic spline otherwise), or with `--interpolation linear` by straight lines
//! between the rows, which is how colour-science interpolates every illuminant of its
//! `SDS_ILLUMINANTS` ([`Interpolation`]; `crate::spectrum::interp` says why this, and
//! nothing else, made `heron color` differ from `colour.sd_to_XYZ` by up to 1.2e-3 for
//! the CIE illuminants' own data). The built-in illuminants (D65, D50, A) are
//! colour-science's tables aligned that way, linearly.
//!
//! # Colorimetry
//!
//! All sums run over the 471 rows λ = 360, 361, …, 830 nm (Δλ = 1 nm cancels), with the
//! chosen observer's x̄, ȳ, z̄ (CIE 1931 2° or CIE 1964 10°):
//!
//! - with an illuminant I (D65, D50, A or E), the distribution is a reflectance (or
//!   transmittance) R and XYZ = Σ R·I·x̄ / Σ I·ȳ, so the perfect reflector R = 1 has
//!   Y = 1 and the XYZ of the illuminant's white point (CIE 15 with k = 1/Σ I·ȳ);
//! - with `none`, the distribution is an emitted spectrum (radiance) S and
//!   XYZ = Σ S·x̄ / Σ ȳ, heron's film convention: the constant 1 has Y = 1.
//!
//! (E is the constant 1, so a reflectance under E and the same numbers as an emitter give
//! identical XYZ.) xy = (X, Y) / (X + Y + Z), or `null` when X + Y + Z = 0. Linear sRGB is
//! the IEC 61966-2-1 matrix applied to XYZ as it is: XYZ is taken as D65-relative and no
//! chromatic adaptation is made, so under illuminant A (or E) the result is the
//! un-adapted colour (A's white comes out orange, not (1, 1, 1)); the 10° observer's XYZ
//! goes through the same matrix, although sRGB is defined for the 2° observer.
use crate::spectrum::cie::{self, Observer};
use crate::spectrum::color::xyz_to_linear_srgb;
use crate::spectrum::csv::SpectrumCsv;
use crate::spectrum::interp::Interpolation;
use crate::spectrum::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use crate::Result;
use serde::Serialize;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// A CIE standard observer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StandardObserver {
    /// CIE 1931 2° (the renderer's film uses it).
    Cie1931,
    /// CIE 1964 10°.
    Cie1964,
}

impl StandardObserver {
    /// The observer's matching functions.
    pub fn tables(self) -> &'static Observer {
        match self {
            StandardObserver::Cie1931 => cie::cie1931(),
            StandardObserver::Cie1964 => cie::cie1964(),
        }
    }

    /// "1931" or "1964", as on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            StandardObserver::Cie1931 => "1931",
            StandardObserver::Cie1964 => "1964",
        }
    }
}

impl FromStr for StandardObserver {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.trim() {
            "1931" => Ok(StandardObserver::Cie1931),
            "1964" => Ok(StandardObserver::Cie1964),
            _ => Err(format!(
                "expected 1931 (CIE 1931 2°) or 1964 (CIE 1964 10°), got {s:?}"
            )),
        }
    }
}

impl fmt::Display for StandardObserver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the distribution is seen under: a CIE illuminant (the distribution is then a
/// reflectance) or none (the distribution is emitted).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Illuminant {
    /// CIE standard illuminant D65 ([`cie::d65_relative`]).
    D65,
    /// CIE illuminant D50 ([`cie::d50_relative`]).
    D50,
    /// CIE standard illuminant A ([`cie::illuminant_a_relative`]).
    A,
    /// CIE illuminant E, equal energy ([`cie::illuminant_e`]).
    E,
    /// No illuminant: the distribution is an emitted spectrum.
    None,
}

impl Illuminant {
    /// "D65", "D50", "A", "E" or "none", as in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Illuminant::D65 => "D65",
            Illuminant::D50 => "D50",
            Illuminant::A => "A",
            Illuminant::E => "E",
            Illuminant::None => "none",
        }
    }

    /// The illuminant's spectral power (any scale: it cancels), or `None` for `none`.
    pub fn spectrum(self) -> Option<DenseSpectrum> {
        match self {
            Illuminant::D65 => Some(cie::d65_relative().clone()),
            Illuminant::D50 => Some(cie::d50_relative().clone()),
            Illuminant::A => Some(cie::illuminant_a_relative().clone()),
            Illuminant::E => Some(cie::illuminant_e()),
            Illuminant::None => None,
        }
    }
}

impl FromStr for Illuminant {
    type Err = String;
    /// Case-insensitive: `D65`, `D50`, `A`, `E` or `none`.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "d65" => Ok(Illuminant::D65),
            "d50" => Ok(Illuminant::D50),
            "a" => Ok(Illuminant::A),
            "e" => Ok(Illuminant::E),
            "none" => Ok(Illuminant::None),
            _ => Err(format!("expected D65, D50, A, E or none, got {s:?}")),
        }
    }
}

impl fmt::Display for Illuminant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The colour of a distribution; see the module documentation for the formulas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Colour {
    pub xyz: [f32; 3],
    /// (x, y); `None` when X + Y + Z = 0.
    pub xy: Option<[f32; 2]>,
    pub linear_srgb: [f32; 3],
}

/// XYZ, xy and linear sRGB of `s` seen by `observer` under `illuminant`:
/// XYZ = Σ s·I·x̄ / Σ I·ȳ with an illuminant I (s is a reflectance), XYZ = Σ s·x̄ / Σ ȳ
/// with [`Illuminant::None`] (s is emitted). Sums at 1 nm over 360–830 nm in f64 by
/// [`cie::spectrum_to_xyz_with`]; linear sRGB by
/// [`crate::spectrum::color::xyz_to_linear_srgb`] without chromatic adaptation.
pub fn colour_of(s: &DenseSpectrum, observer: StandardObserver, illuminant: Illuminant) -> Colour {
    let obs = observer.tables();
    let xyz = match illuminant.spectrum() {
        None => cie::spectrum_to_xyz_with(obs, s),
        Some(i) => {
            // Σ s·I·x̄ / Σ ȳ divided by Σ I·ȳ / Σ ȳ: the film sums, whose Σ ȳ cancels.
            let num = cie::spectrum_to_xyz_with(obs, &s.mul(&i));
            let k = cie::spectrum_to_xyz_with(obs, &i)[1] as f64;
            num.map(|v| (v as f64 / k) as f32)
        }
    };
    let sum = xyz[0] as f64 + xyz[1] as f64 + xyz[2] as f64;
    let xy = (sum != 0.0).then(|| [(xyz[0] as f64 / sum) as f32, (xyz[1] as f64 / sum) as f32]);
    Colour {
        xyz,
        xy,
        linear_srgb: xyz_to_linear_srgb(xyz),
    }
}

/// What `heron color` prints, as JSON (keys in this order).
#[derive(Clone, Debug, Serialize)]
pub struct ColorReport {
    /// The file as given on the command line.
    pub file: String,
    /// "1931" or "1964".
    pub observer: &'static str,
    /// "D65", "D50", "A", "E" or "none".
    pub illuminant: &'static str,
    /// "cie167" or "linear": how the rows were put on the 1 nm grid.
    pub interpolation: &'static str,
    #[serde(rename = "XYZ")]
    pub xyz: [f32; 3],
    /// `null` when X + Y + Z = 0.
    pub xy: Option<[f32; 2]>,
    pub linear_srgb: [f32; 3],
    /// Remarks for stderr (not part of the JSON), e.g. that the data does not cover
    /// 360–830 nm and its end values were held.
    #[serde(skip)]
    pub notes: Vec<String>,
}

/// `heron color FILE`: reads the CSV, builds the 1 nm table (interpolated as
/// `interpolation` says) and computes its colour.
pub fn color_file(
    path: &Path,
    observer: StandardObserver,
    illuminant: Illuminant,
    interpolation: Interpolation,
) -> Result<ColorReport> {
    let csv = SpectrumCsv::read(path)?;
    let c = colour_of(&csv.to_dense_with(interpolation), observer, illuminant);
    let (lo, hi) = csv.range();
    let mut notes = Vec::new();
    if lo > LAMBDA_MIN || hi < LAMBDA_MAX {
        notes.push(format!(
            "{}: the data covers {lo}–{hi} nm; its end values are held constant over the rest of {LAMBDA_MIN}–{LAMBDA_MAX} nm",
            path.display()
        ));
    }
    Ok(ColorReport {
        file: path.display().to_string(),
        observer: observer.name(),
        illuminant: illuminant.name(),
        interpolation: interpolation.name(),
        xyz: c.xyz,
        xy: c.xy,
        linear_srgb: c.linear_srgb,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<SpectrumCsv> {
        SpectrumCsv::parse(t, Path::new("t.csv"))
    }

    #[test]
    fn header_comments_and_blank_lines() {
        let s = parse("\u{feff}# a comment\n\nwavelength_nm,value\r\n400, 0.5\n  # x\n500,1e0\n")
            .unwrap();
        assert_eq!(s.samples, vec![(400.0, 0.5), (500.0, 1.0)]);
    }

    #[test]
    fn errors_name_file_line_and_expectation() {
        let e = |t: &str| parse(t).unwrap_err().to_string();
        assert!(e("400,1\n500,x\n").contains("t.csv: line 2: value: expected a number"));
        assert!(e("h\n400,1\n500,1,2\n").contains("line 3: expected two comma-separated"));
        assert!(e("400,1\n400,2\n")
            .contains("line 2: expected wavelengths in strictly increasing order"));
        assert!(e("400,1\n500,inf\n").contains("line 2: value: expected a finite number"));
        assert!(e("400,1\n500,1e39\n").contains("finite number"));
        assert!(e("400,1\nnan,1\n").contains("line 2: wavelength (nm): expected a finite"));
        assert!(e("# only\n400,1\n").contains("t.csv: expected at least 2 rows"));
        assert!(e("").contains("found 0"));
        // A second non-numeric line is not a header.
        assert!(e("a,b\nc,d\n").contains("line 2: wavelength (nm): expected a number"));
        // Found by fuzzing: finite rows whose not-a-knot spline overflows f32 between
        // 530 nm and 1e38 nm.
        assert!(e("500,1\n511,3\n530,2\n1e38,2\n")
            .contains("t.csv: value: the rows interpolated onto the 1 nm grid give inf at 531 nm"));
    }

    #[test]
    fn reflector_and_emitter_conventions() {
        let one = DenseSpectrum::constant(1.0);
        let d65 = colour_of(&one, StandardObserver::Cie1931, Illuminant::D65);
        let want = cie::spectrum_to_xyz(cie::d65_unit());
        for (got, want) in d65.xyz.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "{:?}", d65.xyz);
        }
        for obs in [StandardObserver::Cie1931, StandardObserver::Cie1964] {
            let e = colour_of(&one, obs, Illuminant::E);
            let none = colour_of(&one, obs, Illuminant::None);
            assert_eq!(e.xyz, none.xyz);
            assert!((none.xyz[1] - 1.0).abs() < 1e-6);
            let a = colour_of(&one, obs, Illuminant::A);
            assert!((a.xyz[1] - 1.0).abs() < 1e-6);
        }
        let zero = colour_of(
            &DenseSpectrum::constant(0.0),
            StandardObserver::Cie1931,
            Illuminant::None,
        );
        assert_eq!(zero.xy, None);
    }

    #[test]
    fn names_parse_back() {
        for i in [
            Illuminant::D65,
            Illuminant::D50,
            Illuminant::A,
            Illuminant::E,
            Illuminant::None,
        ] {
            assert_eq!(i.name().parse::<Illuminant>().unwrap(), i);
        }
        assert_eq!("d65".parse::<Illuminant>().unwrap(), Illuminant::D65);
        assert!("F2".parse::<Illuminant>().is_err());
        for o in [StandardObserver::Cie1931, StandardObserver::Cie1964] {
            assert_eq!(o.name().parse::<StandardObserver>().unwrap(), o);
        }
    }
}
