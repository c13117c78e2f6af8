//! Interpolation of tabulated spectra onto heron's 1 nm grid, as colour-science does it.
//!
//! CIE 167:2005 ("Recommended practice for tabulating spectral data for use in colour
//! computations") recommends the Sprague (1880) interpolating polynomial for uniformly
//! spaced data; colour-science (`SpectralDistribution.align`, the interpolation
//! `sd_to_XYZ` applies to data off its colour matching functions' grid) uses
//! `SpragueInterpolator` for uniform data with at least six samples and
//! `CubicSplineInterpolator` (scipy's `interp1d(kind="cubic")`, a not-a-knot cubic
//! spline) otherwise, and holds the end values constant beyond the data. heron follows
//! the same rules ([`Interpolation::Cie167`], the default), so that `heron color` and
//! every spectral CSV a scene reads agree with colour-science to float precision:
//!
//! - uniform spacing, n ≥ 6: Sprague, with the two extra points at each end from the
//!   boundary coefficients of Westland, Ripamonti & Cheung, *Computational Colour
//!   Science using MATLAB* (2nd ed., 2012), §5 (the coefficients /209 below);
//! - otherwise n ≥ 4: the not-a-knot cubic spline (de Boor, *A Practical Guide to
//!   Splines*, ch. IV);
//! - n = 2 or 3: linear (colour-science has no interpolant for so few points).
//!
//! # Illuminants: linear ([`Interpolation::Linear`])
//!
//! Those rules are colour-science's for a distribution made with its default
//! interpolator. `align` keeps any *other* interpolator a distribution was made with,
//! and colour-science makes every entry of `SDS_ILLUMINANTS` (A, B, C, the D series,
//! FL, HP, LED, ID50/ID65, ISO 7589) with `interpolator=LinearInterpolator`
//! (`colour/colorimetry/datasets/illuminants/sds.py`: "CIE 15:2004 recommends using
//! linear interpolation for the CIE Standard Illuminant D Series. For consistency, all
//! illuminants use a linear interpolator."). So `colour.sd_to_XYZ(SDS_ILLUMINANTS[…],
//! cmfs, method="Integration")` joins the 5 nm rows with straight lines where heron, given
//! the same rows as a CSV, drew Sprague's quintic through them: that alone is why
//! `heron color` differed from it by 1.6e-4 relative for A, 1.0e-4 for D50 and 1.2e-3
//! for FL2 (whose mercury lines make the two curves differ most) while 10 nm
//! reflectances (Sprague on both sides) and 1 nm data (no interpolation) agreed to
//! 1.5e-7. Neither the rows beyond 360–830 nm nor the end handling contributes: with
//! colour-science made to use Sprague for the same illuminants, heron's default agrees
//! to 7e-8. Nothing in the rows says which interpolator their source meant, so it is a
//! choice (`heron color --interpolation linear`, `heron.color(…, interpolation=
//! "linear")`): straight lines between the rows, the end values held constant beyond
//! them, as colour-science's `LinearInterpolator` (numpy's `interp`) and its default
//! constant `Extrapolator`.
//!
//! Values are computed in f64 and stored as heron's f32 tables.

use std::fmt;
use std::str::FromStr;

/// How tabulated rows are interpolated onto the 1 nm grid (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interpolation {
    /// CIE 167:2005 as colour-science applies it to a distribution with its default
    /// interpolator: Sprague for uniform rows (n ≥ 6), a not-a-knot cubic spline
    /// otherwise (n ≥ 4), linear for two or three rows.
    #[default]
    Cie167,
    /// Straight lines between the rows: colour-science's `LinearInterpolator`, which
    /// every illuminant of its `SDS_ILLUMINANTS` carries (CIE 15:2004's recommendation
    /// for the D series, applied by colour-science to all of them).
    Linear,
}

impl Interpolation {
    /// Every choice, in the order the messages list them.
    pub const NAMES: [&'static str; 2] = ["cie167", "linear"];

    /// "cie167" or "linear", as on the command line and in `heron color`'s JSON.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Cie167 => "cie167",
            Interpolation::Linear => "linear",
        }
    }
}

impl FromStr for Interpolation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "cie167" => Ok(Interpolation::Cie167),
            "linear" => Ok(Interpolation::Linear),
            _ => Err(format!(
                "expected cie167 (Sprague or cubic spline, CIE 167:2005) or linear (colour-science's choice for its illuminants), got {s:?}"
            )),
        }
    }
}

impl fmt::Display for Interpolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Sprague's extra points beyond the ends: rows give y(x₀ − 2h), y(x₀ − h) from the
/// first six samples and y(xₙ₋₁ + h), y(xₙ₋₁ + 2h) from the last six, each /209.
const SPRAGUE_ENDS: [[f64; 6]; 4] = [
    [884.0, -1960.0, 3033.0, -2648.0, 1080.0, -180.0],
    [508.0, -540.0, 488.0, -367.0, 144.0, -24.0],
    [-24.0, 144.0, -367.0, 488.0, -540.0, 508.0],
    [-180.0, 1080.0, -2648.0, 3033.0, -1960.0, 884.0],
];

/// Sprague's quintic on [x_k, x_k+1] in powers of t = (x − x_k)/h (exact for quartics): coefficients of t¹…t⁵,
/// each a combination (/24) of y_k−2 … y_k+3 (CIE 167:2005, Westland et al. 2012).
const SPRAGUE_POLY: [[f64; 6]; 5] = [
    [2.0, -16.0, 0.0, 16.0, -2.0, 0.0],
    [-1.0, 16.0, -30.0, 16.0, -1.0, 0.0],
    [-9.0, 39.0, -70.0, 66.0, -33.0, 7.0],
    [13.0, -64.0, 126.0, -124.0, 61.0, -12.0],
    [-5.0, 25.0, -50.0, 50.0, -25.0, 5.0],
];

/// Whether the wavelengths are uniformly spaced (to 1e-6 of the spacing, the f32
/// precision of a CSV's wavelengths).
fn is_uniform(x: &[f64]) -> bool {
    let h = x[1] - x[0];
    x.windows(2)
        .all(|w| ((w[1] - w[0]) - h).abs() <= 1e-6 * h.abs())
}

/// An interpolant through (x, y) samples, x strictly increasing, evaluated inside
/// [x₀, xₙ₋₁]; the caller holds the ends constant outside.
enum Interpolant {
    Linear,
    /// Sample values padded with Sprague's two extra points at each end.
    Sprague {
        yp: Vec<f64>,
        h: f64,
    },
    /// Second derivatives at the samples.
    Spline {
        m: Vec<f64>,
    },
}

/// Interpolates `samples` (wavelength nm, value; wavelengths strictly increasing, at
/// least one sample) at each `at` by the CIE 167 rules ([`Interpolation::Cie167`]),
/// holding the first and last values constant outside.
pub fn interpolate(samples: &[(f32, f32)], at: impl Iterator<Item = f32>) -> Vec<f32> {
    interpolate_with(samples, at, Interpolation::Cie167)
}

/// Interpolates `samples` (wavelength nm, value; wavelengths strictly increasing, at
/// least one sample) at each `at` by `how`, holding the first and last values constant
/// outside.
pub fn interpolate_with(
    samples: &[(f32, f32)],
    at: impl Iterator<Item = f32>,
    how: Interpolation,
) -> Vec<f32> {
    assert!(!samples.is_empty());
    let x: Vec<f64> = samples.iter().map(|s| s.0 as f64).collect();
    let y: Vec<f64> = samples.iter().map(|s| s.1 as f64).collect();
    let n = x.len();
    let kind = if how == Interpolation::Linear {
        Interpolant::Linear
    } else if n >= 6 && is_uniform(&x) {
        sprague(&x, &y)
    } else if n >= 4 {
        Interpolant::Spline {
            m: not_a_knot_second_derivatives(&x, &y),
        }
    } else {
        Interpolant::Linear
    };
    at.map(|l| {
        let l = l as f64;
        if n == 1 || l <= x[0] {
            return y[0] as f32;
        }
        if l >= x[n - 1] {
            return y[n - 1] as f32;
        }
        // The interval [x_k, x_k+1] holding l (x_k < l < x_k+1 or l = x_k+1).
        let k = x.partition_point(|&w| w < l) - 1;
        let v = match &kind {
            Interpolant::Linear => {
                let t = (l - x[k]) / (x[k + 1] - x[k]);
                y[k] + t * (y[k + 1] - y[k])
            }
            Interpolant::Sprague { yp, h } => {
                let t = (l - x[k]) / h;
                // yp[k + 2] is y_k; the quintic reads y_k−2 … y_k+3.
                let r = &yp[k..k + 6];
                let mut v = 0.0;
                let mut tp = 1.0;
                for row in &SPRAGUE_POLY {
                    tp *= t;
                    let a: f64 = row.iter().zip(r).map(|(w, y)| w * y).sum::<f64>() / 24.0;
                    v += a * tp;
                }
                r[2] + v
            }
            Interpolant::Spline { m } => {
                let h = x[k + 1] - x[k];
                let (a, b) = (x[k + 1] - l, l - x[k]);
                m[k] * a * a * a / (6.0 * h)
                    + m[k + 1] * b * b * b / (6.0 * h)
                    + (y[k] / h - m[k] * h / 6.0) * a
                    + (y[k + 1] / h - m[k + 1] * h / 6.0) * b
            }
        };
        v as f32
    })
    .collect()
}

fn sprague(x: &[f64], y: &[f64]) -> Interpolant {
    let n = y.len();
    let ends: Vec<f64> = SPRAGUE_ENDS
        .iter()
        .enumerate()
        .map(|(row, c)| {
            let src = if row < 2 { &y[..6] } else { &y[n - 6..] };
            c.iter().zip(src).map(|(c, y)| c * y).sum::<f64>() / 209.0
        })
        .collect();
    let mut yp = Vec::with_capacity(n + 4);
    yp.extend_from_slice(&ends[..2]);
    yp.extend_from_slice(y);
    yp.extend_from_slice(&ends[2..]);
    Interpolant::Sprague { yp, h: x[1] - x[0] }
}

/// Second derivatives M of the not-a-knot cubic spline through (x, y), n ≥ 4: the
/// interior equations h_i−1 M_i−1 + 2(h_i−1 + h_i) M_i + h_i M_i+1 = 6 (Δ_i − Δ_i−1), with
/// M₀ and Mₙ₋₁ eliminated by the not-a-knot conditions (the third derivative continuous
/// at x₁ and xₙ₋₂), solved as a tridiagonal system (Thomas algorithm).
fn not_a_knot_second_derivatives(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    // Unknowns M_1 … M_n−2: sub-, main and super-diagonal and right-hand side.
    let m = n - 2;
    let (mut a, mut b, mut c, mut r) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    for j in 0..m {
        let i = j + 1;
        a[j] = h[i - 1];
        b[j] = 2.0 * (h[i - 1] + h[i]);
        c[j] = h[i];
        r[j] = 6.0 * (d[i] - d[i - 1]);
    }
    // M_0 = (1 + h0/h1) M_1 − (h0/h1) M_2.
    let (h0, h1) = (h[0], h[1]);
    b[0] += h0 * (1.0 + h0 / h1);
    c[0] -= h0 * h0 / h1;
    // M_n−1 = (1 + hₙ₋₂/hₙ₋₃) M_n−2 − (hₙ₋₂/hₙ₋₃) M_n−3.
    let (hl, hp) = (h[n - 2], h[n - 3]);
    b[m - 1] += hl * (1.0 + hl / hp);
    a[m - 1] -= hl * hl / hp;
    // Thomas algorithm (with n = 4 the two modified rows form the whole 2 × 2 system).
    for j in 1..m {
        let w = a[j] / b[j - 1];
        b[j] -= w * c[j - 1];
        r[j] -= w * r[j - 1];
    }
    let mut mid = vec![0.0; m];
    mid[m - 1] = r[m - 1] / b[m - 1];
    for j in (0..m - 1).rev() {
        mid[j] = (r[j] - c[j] * mid[j + 1]) / b[j];
    }
    let mut out = Vec::with_capacity(n);
    out.push((1.0 + h0 / h1) * mid[0] - (h0 / h1) * mid[1.min(m - 1)]);
    out.extend_from_slice(&mid);
    out.push((1.0 + hl / hp) * mid[m - 1] - (hl / hp) * mid[m.saturating_sub(2)]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(samples: &[(f32, f32)], at: &[f32]) -> Vec<f32> {
        interpolate(samples, at.iter().copied())
    }

    #[test]
    fn sprague_is_exact_for_quartics_inside_and_lines_everywhere() {
        // Sprague's quintic reproduces polynomials up to degree 4 where it reads only
        // real samples (two intervals in from each end); the extra end points (/209) are
        // exact for straight lines, so a line is reproduced everywhere.
        let quartic = |l: f64| {
            let t = (l - 500.0) / 100.0;
            0.3 + 0.2 * t - 0.1 * t * t + 0.05 * t.powi(3) + 0.02 * t.powi(4)
        };
        let line = |l: f64| 0.1 + 0.002 * (l - 400.0);
        for (p, inside) in [
            (&quartic as &dyn Fn(f64) -> f64, 420..=580),
            (&line, 400..=600),
        ] {
            let s: Vec<(f32, f32)> = (0..=20)
                .map(|i| {
                    let l = 400.0 + 10.0 * i as f32;
                    (l, p(l as f64) as f32)
                })
                .collect();
            let at: Vec<f32> = inside.map(|l| l as f32).collect();
            for (l, v) in at.iter().zip(eval(&s, &at)) {
                let want = p(*l as f64);
                assert!((v as f64 - want).abs() < 2e-6, "{l}: {v} vs {want}");
            }
            // Through the samples themselves.
            for &(l, v) in &s {
                assert!((eval(&s, &[l])[0] - v).abs() <= 1e-6, "{l}");
            }
        }
    }

    #[test]
    fn not_a_knot_spline_is_exact_for_cubics_on_irregular_data() {
        let p = |l: f64| {
            let t = (l - 500.0) / 100.0;
            0.4 - 0.3 * t + 0.2 * t * t + 0.1 * t.powi(3)
        };
        for xs in [
            vec![400.0, 430.0, 470.0, 520.0, 580.0, 600.0, 640.0],
            vec![400.0, 450.0, 510.0, 600.0],
        ] {
            let s: Vec<(f32, f32)> = xs.iter().map(|&l: &f32| (l, p(l as f64) as f32)).collect();
            let at: Vec<f32> = (400..=600).map(|l| l as f32).collect();
            for (l, v) in at.iter().zip(eval(&s, &at)) {
                let want = p(*l as f64);
                assert!(
                    (v as f64 - want).abs() < 2e-6,
                    "{xs:?} at {l}: {v} vs {want}"
                );
            }
        }
    }

    #[test]
    fn few_samples_are_linear_and_ends_are_held() {
        let s = [(500.0, 1.0), (510.0, 3.0), (530.0, 2.0)];
        assert_eq!(
            eval(&s, &[400.0, 505.0, 520.0, 900.0]),
            vec![1.0, 2.0, 2.5, 2.0]
        );
        assert_eq!(eval(&[(550.0, 0.7)], &[360.0, 830.0]), vec![0.7, 0.7]);
        // Sprague and the spline hold the ends too.
        let u: Vec<(f32, f32)> = (0..8)
            .map(|i| (400.0 + 10.0 * i as f32, i as f32))
            .collect();
        assert_eq!(
            eval(&u, &[360.0, 400.0, 470.0, 830.0]),
            vec![0.0, 0.0, 7.0, 7.0]
        );
    }

    #[test]
    fn linear_joins_rows_with_straight_lines_where_sprague_curves() {
        // A line spike in uniform 5 nm rows (like FL2's mercury lines): linear gives the
        // chords, Sprague overshoots between rows; both hold the ends.
        let s: Vec<(f32, f32)> = (0..12)
            .map(|i| (380.0 + 5.0 * i as f32, if i == 6 { 10.0 } else { 1.0 }))
            .collect();
        let at: Vec<f32> = (360..=450).map(|l| l as f32).collect();
        let lin = interpolate_with(&s, at.iter().copied(), Interpolation::Linear);
        let cie = interpolate_with(&s, at.iter().copied(), Interpolation::Cie167);
        assert_eq!(cie, interpolate(&s, at.iter().copied()));
        for (l, v) in at.iter().zip(&lin) {
            let want = if (405.0..=415.0).contains(l) {
                10.0 - 9.0 * (l - 410.0).abs() / 5.0
            } else {
                1.0
            };
            assert!((v - want).abs() < 1e-6, "{l}: {v} vs {want}");
        }
        // Sprague passes through the rows but rings beside the spike.
        assert_eq!(cie[(400 - 360) as usize], 1.0);
        assert!((cie[(402 - 360) as usize] - 1.0).abs() > 0.1);
        assert!((cie[(412 - 360) as usize] - lin[(412 - 360) as usize]).abs() > 0.1);
    }

    #[test]
    fn interpolation_names_parse_back() {
        for n in Interpolation::NAMES {
            assert_eq!(n.parse::<Interpolation>().unwrap().name(), n);
        }
        assert_eq!(Interpolation::default(), Interpolation::Cie167);
        let e = "sprague".parse::<Interpolation>().unwrap_err();
        assert!(e.contains("expected cie167") && e.contains("linear") && e.contains("\"sprague\""));
    }
}
