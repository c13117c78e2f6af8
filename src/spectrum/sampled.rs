//! Wavelengths carried along one path and the spectral quantities evaluated at them.
//!
//! One hero wavelength is drawn at random and N−1 companions are spread evenly over the
//! range by rotation (Wilkie et al. 2014, "Hero Wavelength Spectral Sampling"; pbrt-v4
//! `SampledWavelengths`). Each lane keeps its own pdf; a lane whose pdf is 0 has been
//! terminated and contributes nothing to the film.
use super::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign};

/// A value per wavelength lane (radiance, throughput, reflectance …).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledSpectrum<const N: usize>(pub [f32; N]);

impl<const N: usize> SampledSpectrum<N> {
    #[inline]
    pub const fn splat(v: f32) -> Self {
        SampledSpectrum([v; N])
    }
    #[inline]
    pub const fn zero() -> Self {
        Self::splat(0.0)
    }
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }
    #[inline]
    pub fn max_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::MIN, f32::max)
    }
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

impl<const N: usize> Add for SampledSpectrum<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        for i in 0..N {
            self.0[i] += o.0[i];
        }
        self
    }
}
impl<const N: usize> AddAssign for SampledSpectrum<N> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        for i in 0..N {
            self.0[i] += o.0[i];
        }
    }
}
impl<const N: usize> Mul for SampledSpectrum<N> {
    type Output = Self;
    #[inline]
    fn mul(mut self, o: Self) -> Self {
        for i in 0..N {
            self.0[i] *= o.0[i];
        }
        self
    }
}
impl<const N: usize> MulAssign for SampledSpectrum<N> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        for i in 0..N {
            self.0[i] *= o.0[i];
        }
    }
}
impl<const N: usize> Mul<f32> for SampledSpectrum<N> {
    type Output = Self;
    #[inline]
    fn mul(mut self, s: f32) -> Self {
        for v in &mut self.0 {
            *v *= s;
        }
        self
    }
}
impl<const N: usize> MulAssign<f32> for SampledSpectrum<N> {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        for v in &mut self.0 {
            *v *= s;
        }
    }
}
impl<const N: usize> Div<f32> for SampledSpectrum<N> {
    type Output = Self;
    #[inline]
    fn div(self, s: f32) -> Self {
        self * (1.0 / s)
    }
}

/// The N wavelengths of one path (nm) and their pdfs (nm⁻¹).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths<const N: usize> {
    pub lambda: [f32; N],
    pub pdf: [f32; N],
}

impl<const N: usize> SampledWavelengths<N> {
    /// Hero wavelength uniform over [360, 830] nm from `u` in [0, 1), companions at
    /// offsets of (830−360)/N, wrapped into the range. Each lane is uniformly
    /// distributed, so each pdf is 1/470 nm⁻¹, and together the lanes stratify the range.
    #[inline]
    pub fn sample_uniform(u: f32) -> Self {
        let range = LAMBDA_MAX - LAMBDA_MIN;
        let hero = LAMBDA_MIN + u * range;
        let step = range / N as f32;
        let mut lambda = [0.0; N];
        for (i, l) in lambda.iter_mut().enumerate() {
            let mut x = hero + i as f32 * step;
            if x > LAMBDA_MAX {
                x -= range;
            }
            *l = x;
        }
        SampledWavelengths {
            lambda,
            pdf: [1.0 / range; N],
        }
    }

    /// Evaluates a dense spectrum at every lane.
    #[inline]
    pub fn eval(&self, s: &DenseSpectrum) -> SampledSpectrum<N> {
        let mut out = [0.0; N];
        for (o, &l) in out.iter_mut().zip(&self.lambda) {
            *o = s.eval(l);
        }
        SampledSpectrum(out)
    }

    /// Ends every lane but the hero's, for when the path can only follow one wavelength
    /// (wavelength-dependent refraction). The hero's pdf is divided by N so that the
    /// film's average over N lanes stays an unbiased estimate (pbrt-v4
    /// `TerminateSecondary`).
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for p in self.pdf.iter_mut().skip(1) {
            *p = 0.0;
        }
        self.pdf[0] /= N as f32;
    }

    pub fn secondary_terminated(&self) -> bool {
        N > 1 && self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_stay_in_range_and_are_evenly_spaced() {
        for k in 0..1000 {
            let u = k as f32 / 1000.0;
            let wl = SampledWavelengths::<4>::sample_uniform(u);
            let mut l = wl.lambda;
            l.sort_by(f32::total_cmp);
            for &x in &l {
                assert!((LAMBDA_MIN..=LAMBDA_MAX).contains(&x), "{x}");
            }
            for i in 1..4 {
                assert!((l[i] - l[i - 1] - 117.5).abs() < 1e-3, "{l:?}");
            }
        }
    }

    #[test]
    fn terminate_secondary_keeps_the_estimate_unbiased() {
        let mut wl = SampledWavelengths::<4>::sample_uniform(0.3);
        let p0 = wl.pdf[0];
        wl.terminate_secondary();
        assert_eq!(wl.pdf[1..], [0.0; 3]);
        assert!((wl.pdf[0] - p0 / 4.0).abs() < 1e-12);
        wl.terminate_secondary();
        assert!((wl.pdf[0] - p0 / 4.0).abs() < 1e-12, "idempotent");
    }
}
