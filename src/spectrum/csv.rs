//! Spectral tables in CSV: the format of every spectral distribution a scene, `heron
//! color` or the Python module reads (`wavelength_nm,value`), of tabulated refractive
//! indices, and of metals' `wavelength_nm,n,k`.
//!
//! # Format
//!
//! A text file of rows `wavelength_nm,value` (two comma-separated numbers; spaces around
//! them are ignored). Blank lines and lines whose first non-blank character is `#` are
//! skipped. The first remaining line is a header, and skipped, when its first field is
//! not a number. At least two rows; wavelengths finite and strictly increasing (as f32);
//! values finite (as f32); and the table interpolated onto the 1 nm grid (below) finite
//! too. Any other line is an error naming the file, the line number and what was
//! expected.
//!
//! The rows are turned into heron's 1 nm table over 360–830 nm by
//! [`DenseSpectrum::from_table`], as every spectral CSV of a scene is, the way
//! colour-science aligns a distribution (CIE 167:2005): the Sprague (1880) interpolating
//! polynomial for uniformly spaced rows (at least six), a not-a-knot cubic spline for
//! irregular ones (at least four), linear for two or three rows, evaluated at each whole
//! nanometre, the end values held constant beyond the first and last row. (Data finer
//! than 1 nm is therefore point-sampled at whole nanometres, not averaged.) `heron color`
//! can interpolate linearly instead ([`SpectrumCsv::to_dense_with`],
//! [`Interpolation::Linear`]), as colour-science does for its illuminants.
use super::interp::Interpolation;
use super::{DenseSpectrum, LAMBDA_MIN};
use crate::{HeronError, Result};
use std::path::Path;

/// Rows (wavelength nm, value) of a spectral distribution CSV (see the module
/// documentation for the format), checked.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumCsv {
    pub samples: Vec<(f32, f32)>,
}

impl SpectrumCsv {
    /// Reads and checks `path`.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| HeronError::Io {
            path: path.to_path_buf(),
            message: format!("cannot read the spectral distribution: {e}"),
        })?;
        Self::parse(&text, path)
    }

    /// Parses `text`; `path` only names the file in error messages.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let rows = parse_columns(text, path, &["wavelength_nm", "value"])?;
        let samples: Vec<(f32, f32)> = rows.iter().map(|r| (r[0], r[1])).collect();
        interpolate_column(path, "value", &samples)?;
        Ok(SpectrumCsv { samples })
    }

    /// The distribution on heron's 1 nm grid over 360–830 nm
    /// ([`DenseSpectrum::from_table`]: as colour-science interpolates, held constant
    /// beyond the ends).
    pub fn to_dense(&self) -> DenseSpectrum {
        DenseSpectrum::from_table(&self.samples)
    }

    /// The distribution on heron's 1 nm grid, interpolated as `how` says
    /// ([`DenseSpectrum::from_table_with`]), held constant beyond the ends.
    pub fn to_dense_with(&self, how: Interpolation) -> DenseSpectrum {
        DenseSpectrum::from_table_with(&self.samples, how)
    }

    /// First and last wavelength, nm.
    pub fn range(&self) -> (f32, f32) {
        (self.samples[0].0, self.samples[self.samples.len() - 1].0)
    }
}

/// Rows of a CSV whose first column is a wavelength in nm (strictly increasing) and
/// whose other columns are numbers, named by `columns` (e.g. `["wavelength_nm", "n", "k"]`)
/// in error messages; `#` comments, blank lines and one header line are skipped. At
/// least two rows. Every error names the file and the line.
pub fn parse_columns(text: &str, path: &Path, columns: &[&str]) -> Result<Vec<Vec<f32>>> {
    let file = path.display();
    let err = |line: usize, msg: String| HeronError::Invalid(format!("{file}: line {line}: {msg}"));
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let count_word = match columns.len() {
        2 => "two",
        3 => "three",
        _ => "the",
    };
    let layout = columns.join(",");
    let mut rows: Vec<Vec<f32>> = Vec::new();
    let mut prev_line = 0;
    let mut seen_content = false;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let first = !seen_content;
        seen_content = true;
        if first && fields[0].parse::<f64>().is_err() {
            continue; // header line
        }
        if fields.len() != columns.len() {
            return Err(err(
                n,
                format!(
                    "expected {count_word} comma-separated numbers `{layout}`, found {} field{} in {}",
                    fields.len(),
                    if fields.len() == 1 { "" } else { "s" },
                    quote(line)
                ),
            ));
        }
        let mut row = Vec::with_capacity(columns.len());
        for (k, f) in fields.iter().enumerate() {
            let what = if k == 0 {
                "wavelength (nm)"
            } else {
                columns[k]
            };
            row.push(number(f).map_err(|m| err(n, format!("{what}: {m}")))?);
        }
        if let Some(prev) = rows.last() {
            if row[0] <= prev[0] {
                return Err(err(
                    n,
                    format!(
                        "expected wavelengths in strictly increasing order, got {} nm after {} nm (line {prev_line})",
                        fields[0], prev[0]
                    ),
                ));
            }
        }
        rows.push(row);
        prev_line = n;
    }
    if rows.len() < 2 {
        return Err(HeronError::Invalid(format!(
            "{file}: expected at least 2 rows `{layout}`, found {}",
            rows.len()
        )));
    }
    Ok(rows)
}

/// The column `(wavelength, value)` rows of `path` on heron's 1 nm grid
/// ([`DenseSpectrum::from_table`]), which must be finite: rows whose wavelengths or values
/// are near the end of f32's range can make Sprague's or the spline's overshoot between
/// them overflow (e.g. a row at 1e38 nm after rows 20 nm apart).
pub fn interpolate_column(
    path: &Path,
    column: &str,
    samples: &[(f32, f32)],
) -> Result<DenseSpectrum> {
    let dense = DenseSpectrum::from_table(samples);
    if let Some((i, v)) = dense
        .values()
        .iter()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
    {
        return Err(HeronError::Invalid(format!(
            "{}: {column}: the rows interpolated onto the 1 nm grid give {v} at {} nm; expected wavelengths and values small enough that the interpolation stays finite in f32",
            path.display(),
            LAMBDA_MIN + i as f32
        )));
    }
    Ok(dense)
}

fn quote(s: &str) -> String {
    const MAX: usize = 60;
    if s.chars().count() <= MAX {
        format!("{s:?}")
    } else {
        let head: String = s.chars().take(MAX).collect();
        format!("{head:?}…")
    }
}

/// A finite number that is also finite as f32 (the tables are f32).
fn number(s: &str) -> std::result::Result<f32, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("expected a number, got {}", quote(s)))?;
    let v32 = v as f32;
    if !v.is_finite() || !v32.is_finite() {
        return Err(format!(
            "expected a finite number (within ±3.4e38), got {}",
            quote(s)
        ));
    }
    Ok(v32)
}
