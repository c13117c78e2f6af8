//! The film: per-pixel CIE XYZ accumulated from spectral samples, converted to linear
//! sRGB for output.
//!
//! Each sample adds (1/N) Σ_i L(λ_i) x̄(λ_i) / p(λ_i) / Σ ȳ Δλ over its N lanes, the
//! Monte Carlo estimate of XYZ = ∫ L x̄ dλ / ∫ ȳ dλ (a constant L = 1 has Y = 1).
//! Lanes with pdf 0 (terminated wavelengths) add nothing.
pub mod exr;
pub mod fixed;
pub mod planes;
pub mod png;
pub mod state;
pub mod tile;

use crate::spectrum::cie::cie1931;
use crate::spectrum::color::{xyz_to_linear_srgb, XYZ_TO_SRGB};
use crate::spectrum::stokes::StokesSpectrum;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, LAMBDA_MAX, LAMBDA_MIN};
use fixed::SquareSum;

/// Weights that turn one sample's lanes into XYZ: x̄(λ)/(N p(λ) Σȳ) for each lane.
#[inline]
pub fn xyz_of_sample<const N: usize>(
    l: &SampledSpectrum<N>,
    wl: &SampledWavelengths<N>,
) -> [f32; 3] {
    let obs = cie1931();
    let k = 1.0 / (N as f32 * obs.y_integral);
    let mut xyz = glam::Vec4::ZERO;
    for i in 0..N {
        let p = wl.pdf[i];
        // A select rather than a branch: an ended lane (pdf 0) adds nothing.
        let w = if p > 0.0 { l.0[i] * k / p } else { 0.0 };
        let (j, t) = wl.position(i);
        xyz += w * obs.xyz_at(j, t);
    }
    [xyz.x, xyz.y, xyz.z]
}

/// The XYZ each lane adds per unit of its radiance, x̄(λ)/(N p(λ) Σȳ) (zero for an
/// ended lane): [`xyz_of_sample`]'s weights, for a caller that weighs many samples at the
/// same wavelengths (photon mapping's deposits of one iteration).
pub fn xyz_lane_weights<const N: usize>(wl: &SampledWavelengths<N>) -> [glam::Vec3; N] {
    let obs = cie1931();
    let k = 1.0 / (N as f32 * obs.y_integral);
    std::array::from_fn(|i| {
        let p = wl.pdf[i];
        let (j, t) = wl.position(i);
        if p > 0.0 {
            (k / p) * obs.xyz_at(j, t).truncate()
        } else {
            glam::Vec3::ZERO
        }
    })
}

/// Equal-width wavelength bins over 360–830 nm for spectral output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpectralBins {
    pub count: usize,
}

impl SpectralBins {
    pub fn width(&self) -> f32 {
        (LAMBDA_MAX - LAMBDA_MIN) / self.count as f32
    }
    pub fn centre(&self, k: usize) -> f32 {
        LAMBDA_MIN + (k as f32 + 0.5) * self.width()
    }
    /// The bin of `lambda` nm (the last bin includes 830 nm).
    #[inline]
    pub fn index(&self, lambda: f32) -> usize {
        (((lambda - LAMBDA_MIN) / self.width()) as usize).min(self.count - 1)
    }
}

/// Adds one sample's lanes to spectral bins: lane i adds L(λᵢ)/(N p(λᵢ) Δλ_bin), the
/// estimate of the bin's mean spectral radiance, in fixed point (`fixed.rs`). Adds
/// nothing and returns false if any lane's value is out of the fixed-point range.
#[inline]
pub fn add_to_bins<const N: usize>(
    bins: &SpectralBins,
    out: &mut [i128],
    l: &SampledSpectrum<N>,
    wl: &SampledWavelengths<N>,
) -> bool {
    let w = 1.0 / (N as f32 * bins.width());
    // A select rather than a branch: an ended lane (pdf 0) adds nothing.
    let v: [f32; N] = std::array::from_fn(|i| {
        if wl.pdf[i] > 0.0 {
            l.0[i] * w / wl.pdf[i]
        } else {
            0.0
        }
    });
    if !v.iter().all(|x| x.abs() < fixed::LIMIT) {
        return false;
    }
    for (i, &v) in v.iter().enumerate() {
        if v != 0.0 {
            let a = &mut out[bins.index(wl.lambda[i])];
            // In range: checked above.
            *a = a.wrapping_add(fixed::to_fixed(v).unwrap_or(0));
        }
    }
    true
}

/// [`add_to_bins`] for the four Stokes components `s` of a polarised sample: S0's bins
/// to `s0`, S1's, S2's and S3's one after the other to `rest`. Adds nothing and returns
/// false if any value is out of the fixed-point range, so the components stay together.
#[inline]
pub fn add_stokes_to_bins<const N: usize>(
    bins: &SpectralBins,
    s0: &mut [i128],
    rest: &mut [i128],
    s: [SampledSpectrum<N>; 4],
    wl: &SampledWavelengths<N>,
) -> bool {
    let w = 1.0 / (N as f32 * bins.width());
    let v: [[f32; N]; 4] = s.map(|l| {
        std::array::from_fn(|i| {
            if wl.pdf[i] > 0.0 {
                l.0[i] * w / wl.pdf[i]
            } else {
                0.0
            }
        })
    });
    if !v.iter().flatten().all(|x| x.abs() < fixed::LIMIT) {
        return false;
    }
    let nb = bins.count;
    for (k, v) in v.iter().enumerate() {
        let out = if k == 0 {
            &mut s0[..]
        } else {
            &mut rest[(k - 1) * nb..k * nb]
        };
        for (i, &v) in v.iter().enumerate() {
            if v != 0.0 {
                let a = &mut out[bins.index(wl.lambda[i])];
                // In range: checked above.
                *a = a.wrapping_add(fixed::to_fixed(v).unwrap_or(0));
            }
        }
    }
    true
}

/// Contributions an integrator makes to pixels other than the one it samples (light
/// tracing, bidirectional connections to the camera): kept in the order they are made,
/// per tile and pass, and added to the film in tile order by `render/`, so splatting
/// keeps the image independent of the thread count. A splat is an estimate of the
/// image's value per pixel sample: the film adds Σ splats / spp. With spectral output,
/// each splat also keeps its lanes' bin contributions. A polarised render's splats
/// (polarised light tracing and BDPT) keep S1, S2 and S3 beside each of them.
#[derive(Clone, Debug, Default)]
pub struct Splats {
    /// (pixel index, row-major from the top-left; CIE XYZ; of S0 in a polarised render).
    pub list: Vec<(u32, [f32; 3])>,
    /// (pixel index, bin, value) for spectral output.
    pub spectral: Vec<(u32, u16, f32)>,
    /// Polarised renders: S1, S2 and S3 as XYZ of each splat of `list`, in its order
    /// (empty otherwise).
    pub stokes: Vec<[[f32; 3]; 3]>,
    /// Polarised renders with spectral bins: S1, S2 and S3 of each entry of `spectral`.
    pub stokes_spectral: Vec<[f32; 3]>,
    /// Splats left out because they were NaN or infinite.
    pub nonfinite: u64,
    pixels: u32,
    bins: Option<SpectralBins>,
}

impl Splats {
    pub fn new(pixels: u32) -> Self {
        Splats {
            pixels,
            ..Default::default()
        }
    }

    /// Splats that also keep spectral bins.
    pub fn with_bins(pixels: u32, bins: Option<SpectralBins>) -> Self {
        Splats {
            pixels,
            bins,
            ..Default::default()
        }
    }

    /// Adds radiance `l` at wavelengths `wl` to `pixel` (outside the image: ignored).
    #[inline]
    pub fn add<const N: usize>(
        &mut self,
        pixel: u32,
        l: &SampledSpectrum<N>,
        wl: &SampledWavelengths<N>,
    ) {
        if pixel >= self.pixels {
            return;
        }
        if !l.is_finite() {
            self.nonfinite += 1;
            return;
        }
        if l.is_zero() {
            return;
        }
        self.list.push((pixel, xyz_of_sample(l, wl)));
        if let Some(b) = &self.bins {
            let w = 1.0 / (N as f32 * b.width());
            for i in 0..N {
                if wl.pdf[i] > 0.0 && l.0[i] != 0.0 {
                    let k = b.index(wl.lambda[i]) as u16;
                    self.spectral.push((pixel, k, l.0[i] * w / wl.pdf[i]));
                }
            }
        }
    }

    /// Adds the Stokes radiance `s` at wavelengths `wl` to `pixel` (outside the image:
    /// ignored): its S0 as [`Splats::add`] adds radiance, and S1–S3 beside it. A splat
    /// any of whose components is not finite is left out whole.
    #[inline]
    pub fn add_stokes<const N: usize>(
        &mut self,
        pixel: u32,
        s: &StokesSpectrum<N>,
        wl: &SampledWavelengths<N>,
    ) {
        if pixel >= self.pixels {
            return;
        }
        if !s.is_finite() {
            self.nonfinite += 1;
            return;
        }
        let [s0, s1, s2, s3] = [0, 1, 2, 3].map(|k| s.component(k));
        // |S1..S3| ≤ S0: light with no intensity has no polarisation either.
        if s0.is_zero() {
            return;
        }
        self.list.push((pixel, xyz_of_sample(&s0, wl)));
        self.stokes
            .push([s1, s2, s3].map(|c| xyz_of_sample(&c, wl)));
        if let Some(b) = &self.bins {
            let w = 1.0 / (N as f32 * b.width());
            for i in 0..N {
                if wl.pdf[i] > 0.0 && s0.0[i] != 0.0 {
                    let k = b.index(wl.lambda[i]) as u16;
                    // As `add` computes it, so that S0's bins round as radiance's do.
                    let p = wl.pdf[i];
                    self.spectral.push((pixel, k, s0.0[i] * w / p));
                    self.stokes_spectral
                        .push([s1.0[i] * w / p, s2.0[i] * w / p, s3.0[i] * w / p]);
                }
            }
        }
    }
}

/// Linear sRGB of an XYZ triple in f64, with the film's matrix (IEC 61966-2-1).
#[inline]
pub fn linear_srgb_f64(xyz: [f64; 3]) -> [f64; 3] {
    let m = &XYZ_TO_SRGB;
    std::array::from_fn(|r| {
        m[r][0] as f64 * xyz[0] + m[r][1] as f64 * xyz[1] + m[r][2] as f64 * xyz[2]
    })
}

/// The squares of one contribution's linear sRGB components, in fixed point, for the
/// variance estimate (`heron render --variance`); None if any is out of range.
#[inline]
pub fn rgb_squares(xyz: [f32; 3]) -> Option<[SquareSum; 3]> {
    let rgb = linear_srgb_f64(xyz.map(f64::from));
    Some([
        SquareSum::of(rgb[0] * rgb[0])?,
        SquareSum::of(rgb[1] * rgb[1])?,
        SquareSum::of(rgb[2] * rgb[2])?,
    ])
}

/// Adds the squares of one pixel sample's splats to `out`, per pixel: the splats a
/// sample made (`new`, in the order made) are first summed per pixel, since a sample
/// may splat into one pixel more than once and its contribution to that pixel is their
/// sum. `scratch` is reused between samples. Splats out of the film's range are left
/// out, as the film leaves them out of its sums.
pub fn add_splat_squares(
    new: &[(u32, [f32; 3])],
    scratch: &mut Vec<(u32, [f32; 3])>,
    out: &mut Vec<(u32, [SquareSum; 3])>,
) {
    scratch.clear();
    for &(p, c) in new {
        if fixed::to_fixed3(c).is_none() {
            continue;
        }
        match scratch.iter_mut().find(|(q, _)| *q == p) {
            Some((_, s)) => {
                for j in 0..3 {
                    s[j] += c[j];
                }
            }
            None => scratch.push((p, c)),
        }
    }
    for &(p, c) in scratch.iter() {
        if let Some(sq) = rgb_squares(c) {
            out.push((p, sq));
        }
    }
}

/// A finished image: mean XYZ per pixel, row-major from the top-left, optionally the
/// mean spectral radiance in each of `bins` per pixel (pixel-major), and optionally the
/// variance of each pixel's linear sRGB mean (`heron render --variance`).
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub xyz: Vec<[f32; 3]>,
    pub spectral: Option<(SpectralBins, Vec<f32>)>,
    /// Per pixel, the estimated variance of the pixel's value in linear sRGB (R, G, B):
    /// of the mean, not of one sample (`state.rs` says how it is estimated).
    /// Infinite where a pixel has fewer than two finite samples.
    pub variance: Option<Vec<[f32; 3]>>,
    /// Polarised renders: per pixel, the Stokes components S1, S2, S3 as CIE XYZ (signed;
    /// S0 is `xyz`), in the camera's frame (`Camera::stokes_x`: S1 > 0 horizontal).
    pub stokes: Option<Vec<[[f32; 3]; 3]>>,
    /// Polarised renders with spectral bins: per pixel, the mean of S1 in each of
    /// `spectral`'s bins, then of S2, then of S3 (3 × bins per pixel, pixel-major; S0's
    /// are `spectral`'s).
    pub stokes_spectral: Option<Vec<f32>>,
}

impl Film {
    pub fn linear_srgb(&self) -> Vec<[f32; 3]> {
        self.xyz.iter().map(|&c| xyz_to_linear_srgb(c)).collect()
    }
}
