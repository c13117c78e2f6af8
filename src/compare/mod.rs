//! `heron compare`: are two renders the same image up to noise?
//!
//! Two unbiased renders of one scene estimate the same pixel integrals, so the per-pixel
//! difference of their images has expectation zero everywhere, whatever the noise. The
//! test averages the difference over square regions and asks, region by region and
//! channel by channel, whether the mean difference is within what the noise allows: a
//! z-test per region, as Mitsuba 3's render tests run a z-test per pixel against a
//! reference and its variance image, with the Šidák-corrected significance level
//! 1 − (1 − α)^(1/m) for m tests (Mitsuba 3, `src/render/tests/test_renders.py`,
//! `z_test`; the regions are the downsampled image of its earlier test, and the block
//! averages of Jung, Hanika & Dachsbacher 2020, "Detecting Bias in Monte Carlo
//! Renderers using Welch's t-test", JCGT 9(2)). Averaging over a region makes the mean
//! close to normal (the central limit theorem over its pixels) and gives the test power
//! against a small difference spread over many pixels.
//!
//! Per region R of n pixels and channel c, D = (1/n) Σ_R (a − b) and its standard error
//! comes from one of two estimators:
//!
//! - **variance channels** (both files have `variance.R/G/B`, `heron render
//!   --variance`): Var D = (1/n²) Σ_R (Var a + Var b), the renders being independent
//!   and their pixels' estimates independent; z = D / √Var D is standard normal under
//!   the hypothesis that the images agree;
//! - **spread within the region** (either file lacks them, e.g. another renderer's
//!   image): the sample variance s² of the n differences a − b (each with mean zero, so
//!   the image's own detail cancels), SE = s/√n, and z = D/SE follows Student's t with
//!   n − 1 degrees of freedom (its p-value uses that distribution, so small regions are
//!   not over-trusted).
//!
//! Every tested (region, channel) is one test, and the whole image is one more per
//! channel; a region where both images are equal and the standard error is zero (a
//! black background in both) is not a test. A standard error is never taken below the
//! images' resolution, f32's ε times the channel's mean magnitude over the compared
//! pixels: a difference smaller than that is rounding (a black region's fixed-point
//! residue, ±10⁻¹⁹, with zero variance), not a difference. The family of m tests is held at level α
//! by Šidák's correction (each test at 1 − (1 − α)^(1/m)) or Bonferroni's (α/m); a test
//! fails when its two-sided p-value is below that. The images are the same up to noise
//! when no test fails.
//!
//! What the test assumes: pixels' errors independent (true for the independent sampler
//! and per-pixel paths; Sobol' points make pixels weakly, mostly negatively, correlated,
//! which makes the test conservative; a splatting integrator's light path splats into
//! several pixels, which correlates neighbours a little), and region means near normal
//! (heavy-tailed noise, fireflies, needs larger regions). The estimated variance of a
//! Sobol'-sampled pixel is that of independent samples, an overestimate: conservative.
//!
//! Besides the verdict: the relative RMSE √(Σ(a − b)² / Σ b²) over all pixels and
//! channels (B as the reference), the relMSE (1/3N) Σ (a − b)² / (b² + ε) with
//! ε = 10⁻² (Rousselle, Knaus & Zwicker 2011, "Adaptive Sampling and Reconstruction
//! using Greedy Error Minimization", ACM TOG 30(6) 159: the relative error with dark
//! pixels regularised), and the image's mean difference per channel with its standard
//! error (the whole-image test). The two error measures are defined once, in
//! [`errors`] and [`ErrorSums`], which `heron converge` calls too.
use crate::files::write_atomically;
use crate::film::exr::VARIANCE_CHANNELS;
use crate::film::Film;
use crate::{HeronError, Result};
use serde::Serialize;
use std::path::Path;

mod distributions;
mod input;
mod measures;

pub use distributions::{
    incomplete_beta, normal_critical, normal_two_sided, student_critical, student_two_sided,
};
pub use input::Image;
pub use measures::{
    errors, heat_colour, rel_squared_error, ErrorSums, Errors, HEAT_LEFT_OUT, REL_MSE_EPSILON,
};

/// How the significance level of the family of tests is split among them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Correction {
    /// Each of m tests at α/m (Bonferroni): valid for any dependence between tests.
    Bonferroni,
    /// Each of m tests at 1 − (1 − α)^(1/m) (Šidák 1967): exact for independent tests,
    /// and valid for two-sided normal tests under any dependence (Šidák's inequality);
    /// slightly less strict than Bonferroni. Mitsuba 3's render tests use it.
    Sidak,
}

impl Correction {
    pub const NAMES: [&'static str; 2] = ["sidak", "bonferroni"];

    pub fn parse(s: &str) -> std::result::Result<Correction, String> {
        match s {
            "sidak" => Ok(Correction::Sidak),
            "bonferroni" => Ok(Correction::Bonferroni),
            other => Err(format!("expected sidak or bonferroni, got {other:?}")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Correction::Sidak => "sidak",
            Correction::Bonferroni => "bonferroni",
        }
    }

    /// The level of each of `m` tests for a family-wise level `alpha`.
    pub fn per_test(self, alpha: f64, m: usize) -> f64 {
        let m = m.max(1) as f64;
        match self {
            Correction::Bonferroni => alpha / m,
            // 1 − (1 − α)^(1/m), without cancellation for small α.
            Correction::Sidak => -((-alpha).ln_1p() / m).exp_m1(),
        }
    }
}

/// Where the standard errors come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum VarianceSource {
    /// Both images' variance channels.
    Channels,
    /// The spread of the pixel differences within each region.
    Spread,
}

/// The options of a comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Region edge in pixels (the last region of a row or column also takes the
    /// remainder, so every pixel is in a region of at least region² pixels, or in the
    /// whole image when it is smaller).
    pub region: u32,
    /// Family-wise significance level: the probability that two renders of the same
    /// image are called different.
    pub alpha: f64,
    pub correction: Correction,
    /// Pixels to compare (row-major; None: all). A region with fewer than half its
    /// pixels in the mask is not tested.
    pub mask: Option<Vec<bool>>,
    /// An equivalence margin, relative: a mean difference within `tolerance` times the
    /// mean of the two images' magnitudes is not counted, only what lies beyond it is
    /// held to the noise (0: the plain z-test). For an estimator that is consistent but
    /// biased at any finite sample count, by a bound stated beforehand (photon
    /// mapping's radius bias), or a reference whose known small differences are not
    /// the question.
    pub tolerance: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            region: 16,
            alpha: 0.01,
            correction: Correction::Sidak,
            mask: None,
            tolerance: 0.0,
        }
    }
}

impl Options {
    /// Checks the numbers; the messages name the CLI's flags.
    pub fn check(&self) -> std::result::Result<(), String> {
        if self.region == 0 {
            return Err("--region: expected at least 1 pixel".into());
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(format!(
                "--alpha: expected a significance level between 0 and 1 (e.g. 0.01), got {}",
                self.alpha
            ));
        }
        if !(self.tolerance >= 0.0 && self.tolerance < 1.0) {
            return Err(format!(
                "--tolerance: expected a relative margin in [0, 1) (e.g. 0.02), got {}",
                self.tolerance
            ));
        }
        Ok(())
    }
}

/// One test: a region (or the whole image) and a channel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RegionTest {
    /// The region's top-left pixel and size.
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    pub channel: usize,
    /// Pixels compared (those in the mask).
    pub pixels: usize,
    pub mean_a: f64,
    pub mean_b: f64,
    /// mean_a − mean_b.
    pub difference: f64,
    pub standard_error: f64,
    /// difference / standard_error (±∞ when the images differ where both are exact).
    pub z: f64,
    /// Two-sided p-value: normal, or Student's t with `degrees_of_freedom`.
    pub p: f64,
    /// n − 1 when the standard error comes from the spread; None for variance channels.
    pub degrees_of_freedom: Option<f64>,
    /// p below the per-test level.
    pub fails: bool,
    /// Whether this is the whole image's test rather than a region's.
    pub whole_image: bool,
}

/// The outcome of [`compare`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    pub width: u32,
    pub height: u32,
    pub channels: [String; 3],
    pub region: u32,
    pub alpha: f64,
    pub correction: Correction,
    /// The relative margin ([`Options::tolerance`]).
    pub tolerance: f64,
    pub variance_from: VarianceSource,
    /// The level of each test (α split among the tests by the correction).
    pub per_test_alpha: f64,
    /// |z| beyond which a normal test fails at the per-test level (a t test needs a
    /// little more, depending on its degrees of freedom).
    pub critical_z: f64,
    /// With the spread estimator, |t| beyond which a full region's test (region² − 1
    /// degrees of freedom) fails.
    pub critical_t: Option<f64>,
    /// Every region test, in row-major region order, channel by channel.
    pub regions: Vec<RegionTest>,
    /// The whole image's test per channel: its mean difference and standard error.
    pub whole: Vec<RegionTest>,
    /// Region tests left out because both images are equal there with zero standard
    /// error.
    pub identical: usize,
    /// √(Σ (a − b)² / Σ b²) over all compared pixels and channels.
    pub rel_rmse: f64,
    /// (1/3N) Σ (a − b)² / (b² + ε), ε = [`REL_MSE_EPSILON`].
    pub rel_mse: f64,
}

impl Comparison {
    /// Whether no test failed: the images are the same up to noise.
    pub fn same(&self) -> bool {
        !self.regions.iter().chain(&self.whole).any(|t| t.fails)
    }

    /// The number of tests in the family.
    pub fn tests(&self) -> usize {
        self.regions.len() + self.whole.len()
    }

    /// The failing tests, largest |z| first.
    pub fn failing(&self) -> Vec<&RegionTest> {
        let mut f: Vec<&RegionTest> = self
            .regions
            .iter()
            .chain(&self.whole)
            .filter(|t| t.fails)
            .collect();
        f.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
        f
    }

    /// The region z-scores as a grid: (rows, columns, values row-major with the three
    /// channels innermost), NaN where a region and channel was not tested.
    pub fn z_grid(&self) -> (usize, usize, Vec<f64>) {
        let (cols, rows) = (
            tiles(self.width, self.region),
            tiles(self.height, self.region),
        );
        let mut z = vec![f64::NAN; rows.len() * cols.len() * 3];
        for t in &self.regions {
            let r = rows.iter().position(|&(y, _)| y == t.y).unwrap_or(0);
            let c = cols.iter().position(|&(x, _)| x == t.x).unwrap_or(0);
            z[(r * cols.len() + c) * 3 + t.channel] = t.z;
        }
        (rows.len(), cols.len(), z)
    }

    /// The largest |z| over the region tests (0 without any).
    pub fn max_abs_z(&self) -> f64 {
        self.regions.iter().map(|t| t.z.abs()).fold(0.0, f64::max)
    }

    /// The report `heron compare` prints, naming the images `a` and `b`; at most
    /// `max_listed` failing tests are listed.
    pub fn report(&self, a: &str, b: &str, max_listed: usize) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let ch = |c: usize| self.channels[c].as_str();
        let _ = writeln!(s, "A: {a}\nB: {b}");
        let _ = writeln!(
            s,
            "{}x{}, regions of {} px: {} region tests + 3 whole-image tests; standard errors from {}",
            self.width,
            self.height,
            self.region,
            self.regions.len(),
            match self.variance_from {
                VarianceSource::Channels => "the variance channels of both images",
                VarianceSource::Spread =>
                    "the spread of the differences within each region (Student t; an image has no variance channels)",
            }
        );
        if self.identical > 0 {
            let _ = writeln!(
                s,
                "{} region tests left out: both images equal there, with no noise",
                self.identical
            );
        }
        let cut = match self.critical_t {
            Some(t) => format!(
                "|t| > {t:.2} for a region's {} degrees of freedom",
                self.region as u64 * self.region as u64 - 1
            ),
            None => format!("|z| > {:.2}", self.critical_z),
        };
        let _ = writeln!(
            s,
            "significance {} for the family, {}: each test at {:.3e} ({cut})",
            self.alpha,
            match self.correction {
                Correction::Sidak => "Šidák",
                Correction::Bonferroni => "Bonferroni",
            },
            self.per_test_alpha,
        );
        if self.tolerance > 0.0 {
            let _ = writeln!(
                s,
                "tolerance {}: differences within {}% of the means are allowed, z counts the rest",
                self.tolerance,
                100.0 * self.tolerance
            );
        }
        let _ = write!(s, "mean difference A − B:");
        for t in &self.whole {
            let _ = write!(
                s,
                " {} {:+.4e} ± {:.2e} (z {:+.2}){}",
                ch(t.channel),
                t.difference,
                t.standard_error,
                t.z,
                if t.channel < 2 { "," } else { "" }
            );
        }
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "relative RMSE {:.4e}, relMSE {:.4e} (B as the reference)",
            self.rel_rmse, self.rel_mse
        );
        let failing = self.failing();
        if failing.is_empty() {
            let _ = writeln!(
                s,
                "failing regions: none (largest |z| {:.2})",
                self.max_abs_z()
            );
            let _ = writeln!(s, "verdict: same up to noise");
        } else {
            let _ = writeln!(s, "failing regions: {}", failing.len());
            for t in failing.iter().take(max_listed) {
                let place = if t.whole_image {
                    "whole image".to_string()
                } else {
                    format!(
                        "x {}-{}, y {}-{}",
                        t.x,
                        t.x + t.width - 1,
                        t.y,
                        t.y + t.height - 1
                    )
                };
                let rel = if t.mean_b != 0.0 {
                    format!(" ({:+.2}%)", 100.0 * t.difference / t.mean_b.abs())
                } else {
                    String::new()
                };
                let _ = writeln!(
                    s,
                    "  {place} {}: A {:.5e} B {:.5e}, difference {:+.3e}{rel}, z {:+.2}, p {:.2e}",
                    ch(t.channel),
                    t.mean_a,
                    t.mean_b,
                    t.difference,
                    t.z,
                    t.p
                );
            }
            if failing.len() > max_listed {
                let _ = writeln!(s, "  … and {} more", failing.len() - max_listed);
            }
            let _ = writeln!(s, "verdict: different");
        }
        s
    }

    /// A heat map of the region z-scores at the image's size: each pixel coloured by
    /// its region's z of largest magnitude over the channels, white at 0, red where A is
    /// brighter, blue where B is, full colour at twice the critical |z|; failing regions
    /// outlined in black; pixels outside the mask grey.
    pub fn heat_map(&self, mask: Option<&[bool]>) -> image::RgbImage {
        let (w, h) = (self.width, self.height);
        let mut z = vec![0.0f64; (w * h) as usize];
        let mut outline = vec![false; (w * h) as usize];
        for t in &self.regions {
            let (x1, y1) = (t.x + t.width - 1, t.y + t.height - 1);
            for y in t.y..=y1 {
                for x in t.x..=x1 {
                    let i = (y * w + x) as usize;
                    if t.z.abs() > z[i].abs() {
                        z[i] = t.z;
                    }
                    outline[i] |= t.fails && (x == t.x || y == t.y || x == x1 || y == y1);
                }
            }
        }
        let mut img = image::RgbImage::new(w, h);
        let scale = 2.0 * self.critical_z.max(1.0);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let px = if mask.is_some_and(|m| !m[i]) {
                    HEAT_LEFT_OUT
                } else if outline[i] {
                    [0, 0, 0]
                } else {
                    heat_colour(z[i] / scale)
                };
                img.put_pixel(x, y, image::Rgb(px));
            }
        }
        img
    }

    /// Writes [`Comparison::heat_map`] as PNG, atomically (a temporary file renamed
    /// into place).
    pub fn write_heat_map(&self, path: &Path, mask: Option<&[bool]>) -> Result<()> {
        let img = self.heat_map(mask);
        write_atomically(path, |tmp| {
            img.save_with_format(tmp, image::ImageFormat::Png)
                .map_err(|e| format!("cannot write PNG: {e}"))
        })
    }
}

/// The region tiling of one axis: starts and lengths; the last region takes the
/// remainder.
fn tiles(len: u32, region: u32) -> Vec<(u32, u32)> {
    let n = (len / region).max(1);
    (0..n)
        .map(|k| {
            let start = k * region;
            let end = if k + 1 == n { len } else { start + region };
            (start, end - start)
        })
        .collect()
}

/// Compares image `a` with image `b` (B is the reference of the relative errors). Errors
/// when they cannot be compared: different sizes, a mask of the wrong length, bad
/// options.
pub fn compare(a: &Image, b: &Image, o: &Options) -> Result<Comparison> {
    o.check().map_err(HeronError::Invalid)?;
    if (a.width, a.height) != (b.width, b.height) {
        return Err(HeronError::Invalid(format!(
            "cannot compare a {}x{} image with a {}x{} one: expected the same size",
            a.width, a.height, b.width, b.height
        )));
    }
    let (w, h) = (a.width, a.height);
    let npix = w as usize * h as usize;
    if let Some(m) = &o.mask {
        if m.len() != npix {
            return Err(HeronError::Invalid(format!(
                "mask: expected {npix} values for {w}x{h}, got {}",
                m.len()
            )));
        }
    }
    let inside = |i: usize| o.mask.as_ref().map_or(true, |m| m[i]);
    let source = match (&a.variance, &b.variance) {
        (Some(_), Some(_)) => VarianceSource::Channels,
        _ => VarianceSource::Spread,
    };
    let all: Vec<usize> = (0..npix).filter(|&i| inside(i)).collect();
    let floor: [f64; 3] = std::array::from_fn(|c| {
        let magnitude: f64 = all
            .iter()
            .map(|&i| (a.values[i][c].abs() + b.values[i][c].abs()) as f64)
            .sum();
        f32::EPSILON as f64 * magnitude / (2 * all.len().max(1)) as f64
    });
    let test = |pixels: &[usize], c: usize, x: u32, y: u32, tw: u32, th: u32| {
        region_test(
            a,
            b,
            source,
            pixels,
            (c, floor[c], o.tolerance),
            (x, y, tw, th),
        )
    };
    let mut regions = Vec::new();
    let mut identical = 0;
    let mut pixels = Vec::new();
    for &(y0, th) in &tiles(h, o.region) {
        for &(x0, tw) in &tiles(w, o.region) {
            pixels.clear();
            for y in y0..y0 + th {
                for x in x0..x0 + tw {
                    let i = (y * w + x) as usize;
                    if inside(i) {
                        pixels.push(i);
                    }
                }
            }
            if o.mask.is_some() && 2 * pixels.len() < (tw * th) as usize {
                continue;
            }
            for c in 0..3 {
                match test(&pixels, c, x0, y0, tw, th) {
                    Some(t) => regions.push(t),
                    None => identical += 1,
                }
            }
        }
    }
    let mut whole: Vec<RegionTest> = (0..3)
        .filter_map(|c| test(&all, c, 0, 0, w, h))
        .map(|t| RegionTest {
            whole_image: true,
            ..t
        })
        .collect();
    let m = regions.len() + whole.len();
    let per_test = o.correction.per_test(o.alpha, m);
    for t in regions.iter_mut().chain(whole.iter_mut()) {
        t.fails = t.p < per_test;
    }
    // Relative errors over the compared pixels, B as the reference.
    let e = errors(&a.values, &b.values, all.iter().copied());
    Ok(Comparison {
        width: w,
        height: h,
        channels: a.channels.clone(),
        region: o.region,
        alpha: o.alpha,
        correction: o.correction,
        tolerance: o.tolerance,
        variance_from: source,
        per_test_alpha: per_test,
        critical_z: normal_critical(per_test),
        critical_t: (source == VarianceSource::Spread && o.region > 1)
            .then(|| student_critical(per_test, (o.region as f64).powi(2) - 1.0)),
        regions,
        whole,
        identical,
        rel_rmse: e.rel_rmse,
        rel_mse: e.rel_mse,
    })
}

/// The test of one region and channel `c`, whose standard error is at least `floor`
/// (the images' resolution) and whose difference counts only beyond `tolerance` times
/// the two means' magnitude; None when there is nothing to test (no pixels, one pixel
/// with the spread estimator, or both images equal with zero standard error).
fn region_test(
    a: &Image,
    b: &Image,
    source: VarianceSource,
    pixels: &[usize],
    (c, floor, tolerance): (usize, f64, f64),
    (x, y, width, height): (u32, u32, u32, u32),
) -> Option<RegionTest> {
    let n = pixels.len();
    if n == 0 || (source == VarianceSource::Spread && n < 2) {
        return None;
    }
    let nf = n as f64;
    let (mut sa, mut sb) = (0.0f64, 0.0f64);
    for &i in pixels {
        sa += a.values[i][c] as f64;
        sb += b.values[i][c] as f64;
    }
    let (mean_a, mean_b) = (sa / nf, sb / nf);
    let d = mean_a - mean_b;
    let (se, dof) = match source {
        VarianceSource::Channels => {
            let (va, vb) = (a.variance.as_ref()?, b.variance.as_ref()?);
            let v: f64 = pixels
                .iter()
                .map(|&i| va[i][c] as f64 + vb[i][c] as f64)
                .sum();
            (v.sqrt() / nf, None)
        }
        VarianceSource::Spread => {
            // Two passes: the differences' mean first, then the spread about it.
            let ss: f64 = pixels
                .iter()
                .map(|&i| {
                    let e = (a.values[i][c] as f64 - b.values[i][c] as f64) - d;
                    e * e
                })
                .sum();
            ((ss / (nf - 1.0) / nf).sqrt(), Some(nf - 1.0))
        }
    };
    if se == 0.0 && d == 0.0 {
        return None;
    }
    let se = se.max(floor);
    // The margin is taken off the difference before it meets the noise: the test of
    // |D| ≤ margin + z·SE (the spread estimator's s comes from the differences about
    // their own mean, so the margin does not enter it).
    let margin = tolerance * 0.5 * (mean_a.abs() + mean_b.abs());
    let excess = d.signum() * (d.abs() - margin).max(0.0);
    let z = if excess == 0.0 {
        0.0
    } else if se == 0.0 {
        excess.signum() * f64::INFINITY
    } else {
        excess / se
    };
    let p = match dof {
        _ if !z.is_finite() => 0.0,
        None => normal_two_sided(z),
        Some(nu) => student_two_sided(z, nu),
    };
    Some(RegionTest {
        x,
        y,
        width,
        height,
        channel: c,
        pixels: n,
        mean_a,
        mean_b,
        difference: d,
        standard_error: se,
        z,
        p,
        degrees_of_freedom: dof,
        fails: false,
        whole_image: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Rng;

    #[test]
    fn distributions_match_tabulated_values() {
        // Two-sided normal tail (A&S table 26.1).
        for (z, p) in [
            (1.959963984540054, 0.05),
            (2.5758293035489, 0.01),
            (3.890591886413, 1e-4),
        ] {
            assert!((normal_two_sided(z) / p - 1.0).abs() < 1e-9, "{z}");
            assert!((normal_critical(p) - z).abs() < 1e-9, "{p}");
        }
        // Student's t two-sided critical values (A&S table 26.10): p = 0.05 at
        // ν = 1, 5, 30; p = 0.01 at ν = 10.
        for (t, nu, p) in [
            (12.706204736, 1.0, 0.05),
            (2.570581836, 5.0, 0.05),
            (2.042272456, 30.0, 0.05),
            (3.169272673, 10.0, 0.01),
        ] {
            let got = student_two_sided(t, nu);
            assert!((got / p - 1.0).abs() < 1e-7, "t {t}, ν {nu}: {got}");
            assert!((student_critical(p, nu) / t - 1.0).abs() < 1e-7, "ν {nu}");
        }
        // Large ν: the normal's tail.
        let (z, nu) = (4.5, 1e6);
        assert!((student_two_sided(z, nu) / normal_two_sided(z) - 1.0).abs() < 1e-3);
        // I_x(a, 1) = x^a.
        assert!((incomplete_beta(0.3, 2.5, 1.0) - 0.3f64.powf(2.5)).abs() < 1e-14);
    }

    #[test]
    fn error_measures_have_their_known_values() {
        // Differences (0, 1, 0) and (2, 0, −1) against references (1, 1, 0), (1, 0, 1):
        // Σd² = 6, Σr² = 4, and every nonzero difference sits on a reference of
        // magnitude 1 or 0.
        let x = [[1.0, 2.0, 0.0], [3.0, 0.0, 0.0]];
        let r = [[1.0, 1.0, 0.0], [1.0, 0.0, 1.0]];
        let e = errors(&x, &r, 0..2);
        assert!((e.rel_rmse - 1.5f64.sqrt()).abs() < 1e-12, "{e:?}");
        // (1/1.01 + 4/1.01 + 1/1.01) / 6 values.
        assert!((e.rel_mse - 1.0 / 1.01).abs() < 1e-12, "{e:?}");
        // The second pixel alone: Σd² = 5, Σr² = 2; (4 + 1)/1.01 over 3 values.
        let e = errors(&x, &r, [1]);
        assert!((e.rel_rmse - 2.5f64.sqrt()).abs() < 1e-12);
        assert!((e.rel_mse - 5.0 / 3.03).abs() < 1e-12);
        // A black reference: the relMSE counts the absolute error over ε = 0.01 (0.1² /
        // 0.01 = 1 in every channel), the relative RMSE is infinite.
        let e = errors(&[[0.1; 3]], &[[0.0; 3]], [0]);
        assert_eq!(e.rel_rmse, f64::INFINITY);
        assert!((e.rel_mse - 1.0).abs() < 1e-6, "{e:?}");
        assert_eq!(REL_MSE_EPSILON, 1e-2);
        // Nothing differs: both are zero, even over a black reference.
        let e = errors(&[[0.0; 3]], &[[0.0; 3]], [0]);
        assert_eq!((e.rel_rmse, e.rel_mse), (0.0, 0.0));
        // The relMSE does not depend on the sign of the difference, and scales as d².
        assert_eq!(rel_squared_error(-0.3, 2.0), rel_squared_error(0.3, 2.0));
        let q = rel_squared_error(0.6, 2.0) / rel_squared_error(0.3, 2.0);
        assert!((q - 4.0).abs() < 1e-12);
    }

    #[test]
    fn heat_colour_fades_from_white() {
        assert_eq!(heat_colour(0.0), [255, 255, 255]);
        assert_eq!(heat_colour(1.0), [255, 0, 0]);
        assert_eq!(heat_colour(-7.0), [0, 0, 255]);
        assert_eq!(heat_colour(0.5), [255, 128, 128]);
    }

    #[test]
    fn corrections_split_the_level() {
        let s = Correction::Sidak.per_test(0.01, 100);
        assert!((1.0 - (1.0 - s).powi(100) - 0.01).abs() < 1e-15);
        assert_eq!(Correction::Bonferroni.per_test(0.01, 100), 1e-4);
        assert!(s > 1e-4, "Šidák is less strict than Bonferroni");
    }

    fn noisy(seed: u64, w: u32, h: u32, sigma: f32, shift: f32, variance: bool) -> Image {
        let mut r = Rng::new(seed, 1);
        let values = (0..w * h)
            .map(|i| {
                let base = 1.0 + 0.5 * ((i % w) as f32 / w as f32);
                std::array::from_fn(|_| {
                    // Box–Muller.
                    let g = (-2.0 * (1.0 - r.uniform()).ln()).sqrt()
                        * (std::f32::consts::TAU * r.uniform()).cos();
                    base + shift + sigma * g
                })
            })
            .collect();
        let var = variance.then(|| vec![[sigma * sigma; 3]; (w * h) as usize]);
        Image::new("test", w, h, ["R", "G", "B"], values, var).unwrap()
    }

    #[test]
    fn noise_passes_and_a_shift_fails_with_either_estimator() {
        for var in [true, false] {
            let (a, b) = (
                noisy(1, 64, 48, 0.1, 0.0, var),
                noisy(2, 64, 48, 0.1, 0.0, var),
            );
            let c = compare(&a, &b, &Options::default()).unwrap();
            assert!(c.same(), "{}", c.report("a", "b", 5));
            assert_eq!(c.regions.len(), 4 * 3 * 3);
            let shifted = noisy(3, 64, 48, 0.1, 0.03, var);
            let c = compare(&shifted, &b, &Options::default()).unwrap();
            assert!(!c.same(), "{}", c.report("a", "b", 5));
            // 0.03 over a region of 256 pixels of σ 0.1 (difference σ √2·0.1): z ≈ 3.4
            // per region, 11 on the whole image.
            assert!(c.whole.iter().all(|t| t.fails && t.z > 8.0));
        }
    }

    /// A black region whose values are fixed-point residue (±10⁻¹⁹, what a render's
    /// XYZ → RGB leaves of sums that are zero) with zero variance: below the images'
    /// resolution, not a difference (it was z = ∞). A real difference there still fails.
    #[test]
    fn rounding_residue_in_a_black_region_is_not_a_difference() {
        let lit = noisy(6, 32, 16, 0.1, 0.0, true);
        let with_black = |img: &Image, black: f32| {
            let mut values = img.values.clone();
            let mut var = img.variance.clone().unwrap();
            for i in 0..values.len() {
                if i % 32 >= 16 {
                    let sign = if i % 2 == 0 { 1.0 } else { -0.3 };
                    values[i] = [black * sign; 3];
                    var[i] = [0.0; 3];
                }
            }
            Image::new("test", 32, 16, ["R", "G", "B"], values, Some(var)).unwrap()
        };
        let other = noisy(7, 32, 16, 0.1, 0.0, true);
        let b = with_black(&other, 0.0);
        let c = compare(&with_black(&lit, 1.2e-19), &b, &Options::default()).unwrap();
        assert!(
            c.same() && c.regions.len() == 6,
            "{}",
            c.report("a", "b", 5)
        );
        let c = compare(&with_black(&lit, 1e-3), &b, &Options::default()).unwrap();
        assert!(!c.same(), "{}", c.report("a", "b", 5));
    }

    #[test]
    fn regions_cover_every_pixel_and_identical_images_are_the_same() {
        assert_eq!(tiles(70, 16), vec![(0, 16), (16, 16), (32, 16), (48, 22)]);
        assert_eq!(tiles(5, 16), vec![(0, 5)]);
        let a = noisy(4, 70, 20, 0.1, 0.0, false);
        let c = compare(&a, &a, &Options::default()).unwrap();
        assert!(c.same() && c.tests() == 0 && c.identical == 4 * 3);
        assert_eq!((c.rel_rmse, c.rel_mse), (0.0, 0.0));
        let b = noisy(5, 20, 70, 0.1, 0.0, false);
        let e = compare(&a, &b, &Options::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("70x20") && e.contains("20x70"), "{e}");
    }
}
