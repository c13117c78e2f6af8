//! Wavelengths carried along one path and the spectral quantities evaluated at them.
//!
//! One hero wavelength is drawn at random and N−1 companions are spread evenly over the
//! range by rotation (Wilkie et al. 2014, "Hero Wavelength Spectral Sampling"; pbrt-v4
//! `SampledWavelengths`). Each lane keeps its own pdf; a lane whose pdf is 0 has been
//! terminated and contributes nothing to the film.
use super::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use crate::settings::WavelengthSampler;
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign};

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

    /// Ends every lane but the hero's (lane 0), for a path throughput `self` at an event
    /// where the lanes would take different directions (wavelength-dependent
    /// refraction). The hero's throughput is multiplied by N, the other lanes' set to 0.
    ///
    /// Why this is unbiased: each lane's wavelength is distributed like the hero's, so
    /// N·f(λ_hero)/p(λ_hero) estimates the same integral as Σ_i f(λ_i)/p(λ_i). The
    /// decision is folded into the throughput rather than into the wavelengths' pdfs
    /// (pbrt-v4's `TerminateSecondary`), so radiance that the ended lanes gathered before
    /// this event keeps its own weight, nothing reaches them after it, and the film never
    /// adds an ended lane's later contribution (the mistake pbrt-v4 PR #550 fixes in its
    /// spectral buckets).
    #[inline]
    pub fn terminate_secondary(&mut self) {
        self.0[0] *= N as f32;
        for v in self.0.iter_mut().skip(1) {
            *v = 0.0;
        }
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
impl<const N: usize> DivAssign<f32> for SampledSpectrum<N> {
    #[inline]
    fn div_assign(&mut self, s: f32) {
        *self = *self / s;
    }
}
impl<const N: usize> Div<f32> for SampledSpectrum<N> {
    type Output = Self;
    #[inline]
    fn div(self, s: f32) -> Self {
        self * (1.0 / s)
    }
}

const VIS_A: f32 = 0.0072;
const VIS_MU: f32 = 538.0;

/// tanh(a(λ − 538)) at the range's ends (360 and 830 nm), as constants so that sampling
/// costs one (branch-free, vectorisable) atanh per lane; a unit test checks them against
/// tanh.
const VIS_T0: f32 = -0.856_910_6;
const VIS_T1: f32 = 0.970_591_35;

impl WavelengthSampler {
    /// Maps u in [0, 1) to a wavelength and its pdf.
    #[inline]
    pub fn sample(self, u: f32) -> (f32, f32) {
        match self {
            WavelengthSampler::Uniform => {
                let range = LAMBDA_MAX - LAMBDA_MIN;
                (LAMBDA_MIN + u * range, 1.0 / range)
            }
            WavelengthSampler::Visible => {
                // With t = tanh(a(λ − 538)) known, the pdf a/(t1 − t0) · sech² needs no
                // cosh: sech² = 1 − t².
                let t = VIS_T0 + u * (VIS_T1 - VIS_T0);
                let l = (VIS_MU + crate::math::fastmath::atanh(t) / VIS_A)
                    .clamp(LAMBDA_MIN, LAMBDA_MAX);
                (l, VIS_A / (VIS_T1 - VIS_T0) * (1.0 - t * t))
            }
        }
    }

    /// The density at `lambda` nm (0 outside 360–830 nm).
    #[inline]
    pub fn pdf(self, lambda: f32) -> f32 {
        if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
            return 0.0;
        }
        match self {
            WavelengthSampler::Uniform => 1.0 / (LAMBDA_MAX - LAMBDA_MIN),
            WavelengthSampler::Visible => {
                let c = (VIS_A * (lambda - VIS_MU)).cosh();
                VIS_A / (VIS_T1 - VIS_T0) / (c * c)
            }
        }
    }
}

/// The N wavelengths of one path (nm) and their pdfs (nm⁻¹).
///
/// Each lane's position in heron's 1 nm tables (`DenseSpectrum`) is computed once, here,
/// so that every spectrum evaluated along the path costs two loads and a lerp per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths<const N: usize> {
    pub lambda: [f32; N],
    pub pdf: [f32; N],
    /// Table row and fraction of each lane ([`DenseSpectrum::position`]).
    index: [u32; N],
    frac: [f32; N],
}

impl<const N: usize> SampledWavelengths<N> {
    /// Wavelengths (nm) with their pdfs (nm⁻¹).
    #[inline]
    pub fn new(lambda: [f32; N], pdf: [f32; N]) -> Self {
        let mut index = [0u32; N];
        let mut frac = [0.0f32; N];
        for i in 0..N {
            let (k, t) = DenseSpectrum::position(lambda[i]);
            index[i] = k as u32;
            frac[i] = t;
        }
        SampledWavelengths {
            lambda,
            pdf,
            index,
            frac,
        }
    }

    /// Uniform hero over 360–830 nm; companions at offsets of 470/N nm, wrapped.
    #[inline]
    pub fn sample_uniform(u: f32) -> Self {
        Self::sample(WavelengthSampler::Uniform, u)
    }

    /// Draws the hero from `u` with `sampler` and the companions from u + i/N (mod 1):
    /// every lane is distributed like the hero, and together they stratify [0, 1).
    #[inline]
    pub fn sample(sampler: WavelengthSampler, u: f32) -> Self {
        let mut lambda = [0.0; N];
        let mut pdf = [0.0; N];
        for i in 0..N {
            let mut ui = u + i as f32 / N as f32;
            if ui >= 1.0 {
                ui -= 1.0;
            }
            (lambda[i], pdf[i]) = sampler.sample(ui);
        }
        Self::new(lambda, pdf)
    }

    /// Lane i's row and fraction in heron's 1 nm tables ([`DenseSpectrum::position`]).
    #[inline]
    pub fn position(&self, i: usize) -> (usize, f32) {
        (self.index[i] as usize, self.frac[i])
    }

    /// Evaluates a dense spectrum at every lane (the same values as
    /// `DenseSpectrum::eval` at each λ).
    #[inline]
    pub fn eval(&self, s: &DenseSpectrum) -> SampledSpectrum<N> {
        let mut out = [0.0; N];
        for ((o, &k), &t) in out.iter_mut().zip(&self.index).zip(&self.frac) {
            *o = s.eval_at(k as usize, t);
        }
        SampledSpectrum(out)
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
}

#[cfg(test)]
mod sampler_tests {
    use super::*;
    use crate::math::Rng;
    use crate::spectrum::cie::cie1931;

    /// Chi-square of `n` samples in 47 bins of 10 nm against the sampler's own pdf
    /// (integrated per bin by the midpoint rule at 0.1 nm).
    fn chi_square(sampler: WavelengthSampler, n: usize) -> f64 {
        let bins = 47;
        let mut h = vec![0u64; bins];
        let mut rng = Rng::new(11, 3);
        for _ in 0..n / 4 {
            let wl = SampledWavelengths::<4>::sample(sampler, rng.uniform());
            for (&l, &p) in wl.lambda.iter().zip(&wl.pdf) {
                // The sampler's pdf (from 1 − tanh²) and pdf(λ) (from cosh) agree to f32
                // round-trip precision.
                assert!(
                    (p - sampler.pdf(l)).abs() <= 1e-4 * p,
                    "{p} vs {}",
                    sampler.pdf(l)
                );
                h[(((l - LAMBDA_MIN) / 10.0) as usize).min(bins - 1)] += 1;
            }
        }
        let mut chi2 = 0.0;
        for (b, &o) in h.iter().enumerate() {
            let mut p = 0.0f64;
            for k in 0..100 {
                p +=
                    sampler.pdf(LAMBDA_MIN + 10.0 * b as f32 + 0.1 * (k as f32 + 0.5)) as f64 * 0.1;
            }
            let e = p * n as f64;
            chi2 += (o as f64 - e).powi(2) / e;
        }
        chi2
    }

    #[test]
    fn samplers_pass_a_chi_square_test() {
        // 46 degrees of freedom: the 99.9th percentile is 81.4.
        for s in [WavelengthSampler::Uniform, WavelengthSampler::Visible] {
            let c = chi_square(s, 400_000);
            assert!(c < 81.4, "{s:?}: chi2 = {c}");
        }
    }

    #[test]
    fn visible_sampler_constants_are_the_tanh_of_the_range_ends() {
        let t = |l: f32| (VIS_A as f64 * (l as f64 - VIS_MU as f64)).tanh() as f32;
        assert!(
            (VIS_T0 - t(LAMBDA_MIN)).abs() <= 1e-7,
            "{VIS_T0} vs {}",
            t(LAMBDA_MIN)
        );
        assert!(
            (VIS_T1 - t(LAMBDA_MAX)).abs() <= 1e-7,
            "{VIS_T1} vs {}",
            t(LAMBDA_MAX)
        );
    }

    #[test]
    fn pdfs_integrate_to_one() {
        for s in [WavelengthSampler::Uniform, WavelengthSampler::Visible] {
            let total: f64 = (0..47_000)
                .map(|k| s.pdf(LAMBDA_MIN + 0.01 * (k as f32 + 0.5)) as f64 * 0.01)
                .sum();
            assert!((total - 1.0).abs() < 1e-4, "{s:?}: {total}");
        }
    }

    #[test]
    fn both_samplers_integrate_the_y_bar_curve() {
        // ∫ ȳ dλ over 360–830 nm by Monte Carlo with stratified lanes, against the
        // table's Riemann sum; 1e-3 relative.
        let obs = cie1931();
        let exact = obs.y_integral as f64;
        for s in [WavelengthSampler::Uniform, WavelengthSampler::Visible] {
            let mut rng = Rng::new(5, 8);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let wl = SampledWavelengths::<4>::sample(s, rng.uniform());
                for i in 0..4 {
                    sum += (obs.y.eval(wl.lambda[i]) / wl.pdf[i]) as f64 / 4.0;
                }
            }
            let est = sum / n as f64;
            assert!((est / exact - 1.0).abs() < 1e-3, "{s:?}: {est} vs {exact}");
        }
    }
}
