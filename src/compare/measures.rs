//! The error measures heron compare and heron converge share: relative RMSE and relMSE
//! (defined once here), and the heat map's colour scale.
use super::*;

/// The ε of the relMSE, in the images' own units (linear sRGB for heron's films, where
/// a white surface under unit light is about 1): pixels much darker than √ε = 0.1 count
/// their absolute rather than their relative error, so a black pixel that one sample
/// lit does not dominate the mean (Rousselle, Knaus & Zwicker 2011 use 10⁻²).
pub const REL_MSE_EPSILON: f64 = 1e-2;

/// The relative squared error of a value whose reference is `r`, from their difference
/// `d` = x − r: d² / (r² + ε), ε = [`REL_MSE_EPSILON`].
pub fn rel_squared_error(d: f64, r: f64) -> f64 {
    d * d / (r * r + REL_MSE_EPSILON)
}

/// The relative RMSE and the relMSE of one comparison.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Errors {
    /// √(Σ (x − r)² / Σ r²): 0 when x = r everywhere, +∞ when the reference is black
    /// and x is not.
    pub rel_rmse: f64,
    /// (1/n) Σ (x − r)² / (r² + ε) over the n values (pixels × channels).
    pub rel_mse: f64,
}

/// The sums behind [`Errors`], one value (a pixel's channel) at a time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorSums {
    squared: f64,
    reference_squared: f64,
    relative: f64,
    values: u64,
}

impl ErrorSums {
    /// Adds one value by its difference `d` = x − r from its reference `r`.
    pub fn add(&mut self, d: f64, r: f64) {
        self.squared += d * d;
        self.reference_squared += r * r;
        self.relative += rel_squared_error(d, r);
        self.values += 1;
    }

    pub fn errors(&self) -> Errors {
        let rel_rmse = if self.squared == 0.0 {
            0.0
        } else if self.reference_squared == 0.0 {
            f64::INFINITY
        } else {
            (self.squared / self.reference_squared).sqrt()
        };
        Errors {
            rel_rmse,
            rel_mse: self.relative / self.values.max(1) as f64,
        }
    }
}

/// The errors of `x` against `reference` (row-major pixels of three channels) over the
/// pixels whose indices `pixels` lists, every channel.
pub fn errors(
    x: &[[f32; 3]],
    reference: &[[f32; 3]],
    pixels: impl IntoIterator<Item = usize>,
) -> Errors {
    let mut s = ErrorSums::default();
    for i in pixels {
        for c in 0..3 {
            let r = reference[i][c] as f64;
            s.add(x[i][c] as f64 - r, r);
        }
    }
    s.errors()
}

/// The heat maps' colour of `s` in [−1, 1] (clamped): white at 0, fading linearly to
/// full red at +1 and full blue at −1. `heron compare` colours z-scores with it and
/// `heron converge --heatmap` relative squared errors.
pub fn heat_colour(s: f64) -> [u8; 3] {
    let s = s.clamp(-1.0, 1.0);
    let fade = (255.0 * (1.0 - s.abs())).round() as u8;
    if s >= 0.0 {
        [255, fade, fade]
    } else {
        [fade, fade, 255]
    }
}

/// The heat maps' colour of pixels left out (outside the mask or the region of
/// interest).
pub const HEAT_LEFT_OUT: [u8; 3] = [128, 128, 128];
