//! An image texture of reflectance over a surface's uv (Mitsuba 3 `bitmap`, pbrt-v4
//! `imagemap`), a leaf of a [`super::Texture`].
//!
//! Each texel's linear sRGB (clamped to [0, 1]) is uplifted once, when the scene is
//! loaded, to its Jakob–Hanika sigmoid (the fitted table's trilinear lookup, without the
//! Gauss–Newton polish heron gives a scene's few colours; greys exact), so that a lookup
//! costs four sigmoid evaluations per lane: the texels' spectra are interpolated
//! bilinearly at each wavelength, as Mitsuba 3's spectral `bitmap` does
//! (`interpolate_spectral`: "upsample each *before* interpolating"), not the RGB.
//!
//! Layout: uv (0, 0) is the image's top-left corner and v runs down the rows (Mitsuba
//! 3's `bitmap` has no flip: its uv (0, 0) is the first row stored), texel centres at
//! ((i + ½)/W, (j + ½)/H), wrapping around in both directions (`wrap_mode` repeat, the
//! default of both renderers).
use crate::spectrum::rgb2spec::{srgb_table, SigmoidPolynomial};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::Vec2;

#[derive(Clone, Debug)]
pub struct ImageTexture {
    width: usize,
    height: usize,
    /// Sigmoid coefficients per texel, row by row from the top.
    texels: Vec<[f32; 3]>,
    /// Luminance Y = 0.2126 r + 0.7152 g + 0.0722 b of each clamped texel (Rec. 709,
    /// Mitsuba 3's `luminance`), for a lookup as a number ([`ImageTexture::eval_scalar`]).
    grey: Vec<f32>,
}

/// Rec. 709 luminance of linear sRGB; a grey's own value exactly (the weighted sum
/// could miss it by a rounding).
pub fn luminance(c: [f32; 3]) -> f32 {
    if c[0] == c[1] && c[1] == c[2] {
        return c[0];
    }
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

impl ImageTexture {
    /// A texture of `width × height` linear sRGB reflectances (top row first); each
    /// component is clamped to [0, 1] (NaN counts as 0).
    pub fn new(width: usize, height: usize, rgb: &[[f32; 3]]) -> ImageTexture {
        assert!(width >= 1 && height >= 1 && rgb.len() == width * height);
        let clamped: Vec<[f32; 3]> = rgb
            .iter()
            .map(|c| c.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }))
            .collect();
        let texels = clamped.iter().map(|&c| srgb_table().texel(c).c).collect();
        let grey = clamped.iter().map(|&c| luminance(c)).collect();
        ImageTexture {
            width,
            height,
            texels,
            grey,
        }
    }

    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The smallest and largest texel luminance.
    pub fn grey_range(&self) -> (f32, f32) {
        self.grey
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &g| {
                (lo.min(g), hi.max(g))
            })
    }

    /// The texel indices and bilinear weights of the four texels around `uv`.
    #[inline]
    fn corners(&self, uv: Vec2) -> [(usize, f32); 4] {
        let (w, h) = (self.width, self.height);
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |k: f32, n: usize| -> usize {
            let k = k as i64;
            if k.unsigned_abs() > (1 << 40) {
                // A non-finite or absurd uv: the first texel, not an overflow.
                return 0;
            }
            k.rem_euclid(n as i64) as usize
        };
        let (i0, j0) = (wrap(x0, w), wrap(y0, h));
        let (i1, j1) = ((i0 + 1) % w, (j0 + 1) % h);
        [
            (j0 * w + i0, (1.0 - fx) * (1.0 - fy)),
            (j0 * w + i1, fx * (1.0 - fy)),
            (j1 * w + i0, (1.0 - fx) * fy),
            (j1 * w + i1, fx * fy),
        ]
    }

    /// The luminance at `uv`, bilinear over the texels' luminances: a number for a
    /// float-valued parameter (a roughness, a Phong ρs), as Mitsuba 3's `bitmap`
    /// `eval_1` (the luminance of the interpolated linear RGB).
    #[inline]
    pub fn eval_scalar(&self, uv: Vec2) -> f32 {
        self.corners(uv)
            .iter()
            .map(|&(i, wt)| if wt > 0.0 { wt * self.grey[i] } else { 0.0 })
            .sum()
    }

    /// ρ(λ) at `uv`, per lane.
    #[inline]
    pub fn eval<const N: usize>(&self, uv: Vec2, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        let corners = self.corners(uv).map(|(i, wt)| (self.texels[i], wt));
        let mut s = SampledSpectrum::<N>::zero();
        for k in 0..N {
            let l = wl.lambda[k];
            let mut acc = 0.0;
            for (c, wt) in &corners {
                if *wt > 0.0 {
                    acc += wt * SigmoidPolynomial { c: *c }.eval(l);
                }
            }
            s.0[k] = acc;
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centres_wrap_and_greys_are_exact() {
        // 2 × 2: black, white / grey 0.5, grey 0.25.
        let t = ImageTexture::new(2, 2, &[[0.0; 3], [1.0; 3], [0.5; 3], [0.25; 3]]);
        let wl = SampledWavelengths::<4>::sample_uniform(0.3);
        let at = |u: f32, v: f32| t.eval(Vec2::new(u, v), &wl).0[0];
        assert!((at(0.25, 0.25) - 0.0).abs() < 1e-6);
        assert!((at(0.75, 0.25) - 1.0).abs() < 1e-6);
        assert!((at(0.25, 0.75) - 0.5).abs() < 1e-6);
        assert!((at(0.75, 0.75) - 0.25).abs() < 1e-6);
        // Halfway between the two top texels, and across the wrap at u = 0 (1 and 0).
        assert!((at(0.5, 0.25) - 0.5).abs() < 1e-6);
        assert!((at(0.0, 0.25) - 0.5).abs() < 1e-6);
        assert!((at(1.25, -0.75) - at(0.25, 0.25)).abs() < 1e-6);
        assert!(at(f32::NAN, 0.25).is_finite());
    }
}
