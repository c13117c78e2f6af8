//! A piecewise-constant 1D distribution over [0, 1) (pbrt-v4 `PiecewiseConstant1D`,
//! §A.4.2): sampling by inverting the CDF, used for light selection by power, the
//! environment's directions and the triangles of an emitting mesh.

#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// The function, one value per bin (non-negative).
    func: Vec<f32>,
    /// CDF at the bins' edges: cdf[0] = 0, cdf[n] = 1.
    cdf: Vec<f32>,
    /// ∫ f over [0, 1).
    integral: f32,
}

impl Distribution1D {
    /// `func` must be non-empty with finite values ≥ 0. When it integrates to zero the
    /// distribution is uniform (so that sampling never divides by zero; callers check
    /// `integral()` when a zero function means "never").
    pub fn new(func: &[f32]) -> Distribution1D {
        assert!(!func.is_empty());
        let n = func.len();
        let func: Vec<f32> = func.iter().map(|&f| f.max(0.0)).collect();
        let mut cdf = vec![0.0f64; n + 1];
        for i in 0..n {
            cdf[i + 1] = cdf[i] + func[i] as f64 / n as f64;
        }
        let integral = cdf[n];
        let cdf: Vec<f32> = if integral > 0.0 {
            cdf.iter().map(|&c| (c / integral) as f32).collect()
        } else {
            (0..=n).map(|i| i as f32 / n as f32).collect()
        };
        Distribution1D {
            func,
            cdf,
            integral: integral as f32,
        }
    }

    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The bin `u` falls in, the probability of that bin, and the position of `u`
    /// within it, in [0, 1).
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let n = self.func.len();
        // The last edge with cdf ≤ u, skipping empty bins.
        let i = (self.cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let p = c1 - c0;
        let t = if p > 0.0 {
            ((u - c0) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0)
        } else {
            0.0
        };
        (i, p, t)
    }

    /// Probability of bin `i` in discrete sampling.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// A point x in [0, 1) with density pdf(x) = f(x)/∫f, and that density.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, p, t) = self.sample_discrete(u);
        let n = self.func.len();
        let nf = n as f32;
        // (i + t)/n can round onto the next bin's edge in f32 (or to 1): step back to the
        // last float that `pdf` assigns to bin i, so the density reported is bin i's.
        let bin = |x: f32| bin_of(x, n);
        let mut x = ((i as f32 + t) / nf).min(1.0 - f32::EPSILON / 2.0);
        while x > 0.0 && bin(x) > i {
            x = f32::from_bits(x.to_bits() - 1);
        }
        while bin(x) < i {
            x = f32::from_bits(x.to_bits() + 1);
        }
        (x, p * nf, i)
    }

    /// Density of `sample_continuous` at x in [0, 1).
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        let n = self.func.len();
        self.pmf(bin_of(x, n)) * n as f32
    }
}

/// A piecewise-constant 2D distribution over [0, 1)² on an nx × ny grid (pbrt-v4
/// `PiecewiseConstant2D`, §A.5): a marginal over rows and one conditional per row, for
/// the cells of an environment map.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    /// One per row (y), each over the row's nx cells (x).
    conditional: Vec<Distribution1D>,
    /// Over the ny rows, by each row's integral.
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `func[y * nx + x]`, finite and ≥ 0, with `nx, ny ≥ 1`.
    pub fn new(func: &[f32], nx: usize, ny: usize) -> Distribution2D {
        assert!(nx >= 1 && ny >= 1 && func.len() == nx * ny);
        let conditional: Vec<Distribution1D> =
            func.chunks_exact(nx).map(Distribution1D::new).collect();
        let rows: Vec<f32> = conditional.iter().map(|d| d.integral()).collect();
        Distribution2D {
            conditional,
            marginal: Distribution1D::new(&rows),
        }
    }

    /// ∫ f over [0, 1)².
    pub fn integral(&self) -> f32 {
        self.marginal.integral()
    }

    /// A point of [0, 1)² with density f/∫f, and that density.
    #[inline]
    pub fn sample(&self, u: glam::Vec2) -> (glam::Vec2, f32) {
        let (y, py, row) = self.marginal.sample_continuous(u.y);
        let (x, px, _) = self.conditional[row].sample_continuous(u.x);
        (glam::Vec2::new(x, y), px * py)
    }

    /// Density of [`Self::sample`] at a point of [0, 1)².
    #[inline]
    pub fn pdf(&self, p: glam::Vec2) -> f32 {
        let ny = self.conditional.len();
        let row = bin_of(p.y, ny);
        self.marginal.pdf(p.y) * self.conditional[row].pdf(p.x)
    }
}

/// The bin of x among n equal bins of [0, 1): ⌊x n⌋ computed exactly (in f64, where the
/// product of an f32 and a bin count is exact), so that x = k/n rounded to f32 falls on
/// the side of the edge it is on.
#[inline]
fn bin_of(x: f32, n: usize) -> usize {
    ((x as f64 * n as f64) as usize).min(n - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_sampling_follows_the_function_and_skips_empty_bins() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 0.0]);
        assert!((d.pmf(0) - 0.25).abs() < 1e-7 && d.pmf(1) == 0.0);
        let mut counts = [0usize; 4];
        for k in 0..10_000 {
            let u = (k as f32 + 0.5) / 10_000.0;
            let (i, p, t) = d.sample_discrete(u);
            assert!((0.0..1.0).contains(&t) && p > 0.0);
            counts[i] += 1;
        }
        assert_eq!(counts, [2500, 0, 7500, 0]);
        assert_eq!(d.sample_discrete(0.25).0, 2, "an empty bin is never chosen");
    }

    #[test]
    fn continuous_density_matches_pdf_and_integrates_to_one() {
        let f = [0.5f32, 2.0, 0.0, 1.5, 4.0];
        let d = Distribution1D::new(&f);
        let mut total = 0.0;
        for k in 0..1000 {
            let x = (k as f32 + 0.5) / 1000.0;
            total += d.pdf(x) / 1000.0;
            let (y, p, _) = d.sample_continuous(x);
            assert!((0.0..1.0).contains(&y));
            assert!((p - d.pdf(y)).abs() < 1e-5 * p.max(1.0));
        }
        assert!((total - 1.0).abs() < 1e-5);
    }

    #[test]
    fn a_zero_function_is_uniform() {
        let d = Distribution1D::new(&[0.0; 8]);
        assert_eq!(d.integral(), 0.0);
        assert!((d.pdf(0.3) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn two_dimensional_density_matches_pdf_and_integrates_to_one() {
        // 3 × 2 cells, one empty: samples land only where f > 0, with the density pdf.
        let f = [1.0f32, 0.0, 2.0, 0.5, 3.0, 1.5];
        let d = Distribution2D::new(&f, 3, 2);
        assert!((d.integral() - 8.0 / 6.0).abs() < 1e-6);
        let mut total = 0.0f64;
        let mut counts = [0usize; 6];
        // 300 points a side: a whole number of them per cell, so the midpoint sums are exact.
        let n = 300;
        for a in 0..n {
            for b in 0..n {
                let u = glam::Vec2::new((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
                total += d.pdf(u) as f64 / (n * n) as f64;
                let (p, pdf) = d.sample(u);
                assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
                assert!(
                    (pdf - d.pdf(p)).abs() < 1e-4 * pdf,
                    "{p} {pdf} {}",
                    d.pdf(p)
                );
                let cell = bin_of(p.y, 2) * 3 + bin_of(p.x, 3);
                counts[cell] += 1;
            }
        }
        assert!((total - 1.0).abs() < 1e-4, "{total}");
        assert_eq!(counts[1], 0);
        for (c, &fv) in counts.iter().zip(&f) {
            let expect = (fv / 8.0) as f64 * (n * n) as f64;
            assert!(
                (*c as f64 - expect).abs() <= 0.01 * (n * n) as f64,
                "{counts:?}"
            );
        }
    }
}
