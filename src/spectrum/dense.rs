//! A spectrum tabulated every 1 nm over 360–830 nm. Every spectrum a scene defines
//! (reflectances, emitters, background) is turned into one of these on load, so the
//! transport has a single, branch-free way to evaluate a spectrum.
use super::{DENSE_LEN, LAMBDA_MIN};

#[derive(Clone, Debug, PartialEq)]
pub struct DenseSpectrum {
    values: Box<[f32; DENSE_LEN]>,
}

impl DenseSpectrum {
    pub fn constant(c: f32) -> Self {
        DenseSpectrum {
            values: Box::new([c; DENSE_LEN]),
        }
    }

    /// Builds a table by evaluating `f(λ)` at 360, 361, …, 830 nm.
    pub fn from_fn(f: impl Fn(f32) -> f32) -> Self {
        let mut values = Box::new([0.0f32; DENSE_LEN]);
        for (i, v) in values.iter_mut().enumerate() {
            *v = f(LAMBDA_MIN + i as f32);
        }
        DenseSpectrum { values }
    }

    /// A spectral table (wavelength nm, value; wavelengths strictly increasing) on the
    /// 1 nm grid as colour-science aligns it: Sprague for uniform data, a not-a-knot
    /// cubic spline otherwise, held constant beyond the ends ([`super::interp`]). Every
    /// spectral CSV heron reads goes through this.
    pub fn from_table(samples: &[(f32, f32)]) -> Self {
        Self::from_table_with(samples, super::interp::Interpolation::Cie167)
    }

    /// A spectral table on the 1 nm grid interpolated as `how` says
    /// ([`super::interp::Interpolation`]: the CIE 167 rules of [`Self::from_table`], or
    /// straight lines as colour-science interpolates its illuminants), held constant
    /// beyond the ends.
    pub fn from_table_with(samples: &[(f32, f32)], how: super::interp::Interpolation) -> Self {
        let v = super::interp::interpolate_with(
            samples,
            (0..DENSE_LEN).map(|i| LAMBDA_MIN + i as f32),
            how,
        );
        let mut values = Box::new([0.0f32; DENSE_LEN]);
        values.copy_from_slice(&v);
        DenseSpectrum { values }
    }

    /// Piecewise-linear interpolation from (wavelength nm, value) samples sorted by
    /// wavelength; held constant beyond the first and last sample.
    pub fn from_samples(samples: &[(f32, f32)]) -> Self {
        assert!(!samples.is_empty());
        Self::from_fn(|l| {
            let i = samples.partition_point(|&(w, _)| w <= l);
            if i == 0 {
                samples[0].1
            } else if i == samples.len() {
                samples[samples.len() - 1].1
            } else {
                let (w0, v0) = samples[i - 1];
                let (w1, v1) = samples[i];
                let t = (l - w0) / (w1 - w0);
                v0 + t * (v1 - v0)
            }
        })
    }

    pub fn values(&self) -> &[f32; DENSE_LEN] {
        &self.values
    }

    /// Value at `lambda` nm by linear interpolation; clamped to the table's ends.
    #[inline]
    pub fn eval(&self, lambda: f32) -> f32 {
        let (i, t) = Self::position(lambda);
        self.eval_at(i, t)
    }

    /// The row i and fraction t in [0, 1] at which `lambda` nm falls (clamped to the
    /// table's ends), so that the value there is values[i] + t (values[i+1] − values[i]).
    #[inline]
    pub fn position(lambda: f32) -> (usize, f32) {
        let x = (lambda - LAMBDA_MIN).clamp(0.0, (DENSE_LEN - 1) as f32);
        // Through i32, which converts four lanes at once (usize does not vectorise).
        let i = (x as i32).min(DENSE_LEN as i32 - 2);
        (i as usize, x - i as f32)
    }

    /// The value at a [`Self::position`].
    #[inline]
    pub fn eval_at(&self, i: usize, t: f32) -> f32 {
        let a = self.values[i];
        let b = self.values[i + 1];
        a + t * (b - a)
    }

    pub fn scaled(&self, s: f32) -> Self {
        Self::from_fn(|l| self.eval(l) * s)
    }

    pub fn mul(&self, other: &DenseSpectrum) -> Self {
        Self::from_fn(|l| self.eval(l) * other.eval(l))
    }

    pub fn max_value(&self) -> f32 {
        self.values.iter().copied().fold(f32::MIN, f32::max)
    }

    /// Mean of the table over 360–830 nm.
    pub fn mean(&self) -> f32 {
        (self.values.iter().map(|&v| v as f64).sum::<f64>() / self.values.len() as f64) as f32
    }

    pub fn min_value(&self) -> f32 {
        self.values.iter().copied().fold(f32::MAX, f32::min)
    }

    /// True when the table is the same value at every wavelength.
    pub fn is_constant(&self) -> bool {
        let v0 = self.values[0];
        self.values.iter().all(|&v| v == v0)
    }
}
