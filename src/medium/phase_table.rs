//! A tabulated phase function p(θ, λ) with its CDF per wavelength node, for media whose
//! phase function comes from Lorenz–Mie theory (`homogeneous`).
//!
//! Representation: bins in v = 1 − cos θ (θ the scattering angle between the incident
//! and scattered propagation directions), shared by every wavelength node; in each bin
//! the phase function is constant per unit solid angle. This piecewise-constant function
//! *is* the medium's phase function: `eval` returns it and `sample` draws from it
//! exactly (bin by its CDF, then v uniform in the bin, φ uniform), so the sampling pdf
//! equals the evaluated value and a chi-square test can check both at once. A bin's
//! value is the trapezoid average of the Mie values at its two edges (the mass over its
//! solid angle 2π Δv), and the table is normalised to 1 over the sphere.
//!
//! Why v: the forward (diffraction) peak of a drop of size parameter x has width ~1/x rad
//! (1e-4 rad for rain), where cos θ = 1 − 5·10⁻⁹ is lost in f32. v keeps its relative
//! precision at small angles, and between two unit vectors it is computed without
//! cancellation as v = |a − b|²/2.
//!
//! Wavelengths: nodes on a uniform grid; a lane between nodes i and i+1 (fraction t) uses
//! the mixture (1 − t) p_i + t p_{i+1}, sampled by choosing node i+1 with probability t,
//! so that the mixture's pdf is still exact.
//!
//! Angle grid ([`angle_grid`]): θ edges from 0 with steps min(max(θ/20, 0.1/x), cap(θ)),
//! where x is the largest size parameter of the table: at least 10 edges across the
//! diffraction peak (first zero near 3.8/x rad), then steps growing by 5% of θ (the
//! peak's tail falls as a power of θ), capped at 0.01° in 25°–65° (the primary and
//! secondary bows, Alexander's band, the supernumeraries) and 0.05° elsewhere. For
//! x ≳ 3000 the fine ripple near the bows (period ~π/x rad) is narrower than 0.01° and is
//! averaged only at the edges (as the `mie` sky's table is).
use crate::spectrum::SampledSpectrum;
use glam::Vec3;
use std::f64::consts::PI;

/// The θ edges (radians, from 0 to π) for largest size parameter `x_max`.
pub fn angle_grid(x_max: f64) -> Vec<f64> {
    let h_min = 0.1 / x_max.max(1.0);
    let (w0, w1) = (25f64.to_radians(), 65f64.to_radians());
    let fine = 0.01f64.to_radians();
    let coarse = 0.05f64.to_radians();
    let mut g = vec![0.0];
    let mut t = 0.0f64;
    while t < PI {
        let cap = if (w0..w1).contains(&t) { fine } else { coarse };
        let h = (t / 20.0).max(h_min).min(cap);
        t = (t + h).min(PI);
        g.push(t);
    }
    g
}

/// v = 1 − cos θ, computed without cancellation (2 sin²(θ/2)).
#[inline]
pub fn v_of_theta(theta: f64) -> f64 {
    let s = (0.5 * theta).sin();
    2.0 * s * s
}

/// v = 1 − cos θ between two unit vectors, without cancellation: |a − b|²/2.
#[inline]
pub fn v_between(a: Vec3, b: Vec3) -> f32 {
    0.5 * (a - b).length_squared()
}

/// Cells of the bin search in v: uniform in √(v/2) = sin(θ/2), which spreads the
/// table's bins (dense near θ = 0) over the cells better than v itself.
const V_CELLS: usize = 4096;
/// Cells of the CDF's inversion, uniform in u.
const U_CELLS: usize = 1024;

/// The cell of v in [`PhaseTable::v_cells`] (monotonic in v).
#[inline]
fn v_cell(v: f32) -> usize {
    (((0.5 * v).max(0.0).sqrt() * V_CELLS as f32) as usize).min(V_CELLS - 1)
}

/// The cell of u in a node's `PhaseTable::u_cells` (monotonic in u).
#[inline]
fn u_cell(u: f64) -> usize {
    ((u.max(0.0) * U_CELLS as f64) as usize).min(U_CELLS - 1)
}

/// For sorted values whose cells (monotonic, < `cells`) are `of`: per k in 0 ..= cells,
/// how many have a cell below k.
fn cell_starts(of: impl Iterator<Item = usize>, cells: usize) -> Vec<u32> {
    let mut counts = vec![0u32; cells + 1];
    for c in of {
        counts[c + 1] += 1;
    }
    for k in 1..=cells {
        counts[k] += counts[k - 1];
    }
    counts
}

/// The tabulated phase function of one medium.
#[derive(Clone, Debug)]
pub struct PhaseTable {
    /// First node's wavelength and the spacing, nm.
    pub lambda0: f32,
    pub dlambda: f32,
    /// Bin edges in v = 1 − cos θ, increasing from 0 to 2 (f32 for lookup).
    v: Vec<f32>,
    /// The phase function (sr⁻¹) per bin and node, bin-major (`density[j * nodes + i]`):
    /// the lanes of a path look up one bin at nearby wavelengths, so their values share cache lines.
    density: Vec<f32>,
    nodes: usize,
    /// Per node: the CDF at the bin edges (f64, so a bin of the far tail of a peaked
    /// function keeps its probability); cdf[0] = 0, cdf[M] = 1.
    cdf: Vec<Vec<f64>>,
    /// Where the bin search looks: `v_cells[k]` is the number of edges whose cell
    /// ([`v_cell`]) is below k. The cell is monotonic in v, so for a v in cell k the
    /// edges ≤ v are the first `v_cells[k]` and some of the next `v_cells[k + 1]`: the
    /// search covers a few edges instead of the whole table, with the same result.
    v_cells: Vec<u32>,
    /// Per node, the same for the CDF's inversion ([`u_cell`]).
    u_cells: Vec<Vec<u32>>,
    /// Per node: the integral of the untruncated values before normalisation (1 when the
    /// grid resolves the function), for checks.
    pub raw_integral: Vec<f64>,
    /// The phase matrix's shape per bin and node, laid out as `density`:
    /// (F12, F33, F34) / F11, each the ratio of the bin's trapezoid averages (so that
    /// F_ij's mass in the bin is the ratio times F11's); empty when not tabulated.
    matrix: Vec<[f32; 3]>,
}

impl PhaseTable {
    /// Builds the table from values at the θ edges: `values[i][e]` is the (unnormalised)
    /// phase function of node i at `theta[e]`, per unit solid angle.
    pub fn from_values(lambda0: f32, dlambda: f32, theta: &[f64], values: &[Vec<f64>]) -> Self {
        let vd: Vec<f64> = theta.iter().map(|&t| v_of_theta(t)).collect();
        let masses: Vec<Vec<f64>> = values
            .iter()
            .map(|vals| {
                (0..vd.len() - 1)
                    .map(|j| 0.5 * (vals[j] + vals[j + 1]) * 2.0 * PI * (vd[j + 1] - vd[j]))
                    .collect()
            })
            .collect();
        Self::from_masses(lambda0, dlambda, theta, &masses)
    }

    /// Builds the table from each bin's mass: `masses[i][j]` is the (unnormalised)
    /// probability that node i scatters into θ ∈ [theta[j], theta[j + 1]) (a histogram of
    /// traced rays, which has no values at the edges to interpolate).
    pub fn from_masses(lambda0: f32, dlambda: f32, theta: &[f64], masses: &[Vec<f64>]) -> Self {
        let vd: Vec<f64> = theta.iter().map(|&t| v_of_theta(t)).collect();
        let m = vd.len() - 1;
        let mut density = Vec::with_capacity(masses.len());
        let mut cdf = Vec::with_capacity(masses.len());
        let mut raw_integral = Vec::with_capacity(masses.len());
        for bins in masses {
            let mut c = Vec::with_capacity(m + 1);
            c.push(0.0f64);
            let mut acc = 0.0f64;
            for &mass in &bins[..m] {
                acc += mass;
                c.push(acc);
            }
            raw_integral.push(acc);
            let total = acc.max(f64::MIN_POSITIVE);
            for x in c.iter_mut() {
                *x /= total;
            }
            c[m] = 1.0;
            // The density is the CDF's step over the bin's solid angle, so that the
            // probability of sampling a bin and its density agree exactly.
            let d: Vec<f32> = (0..m)
                .map(|j| ((c[j + 1] - c[j]) / (2.0 * PI * (vd[j + 1] - vd[j]))) as f32)
                .collect();
            density.push(d);
            cdf.push(c);
        }
        let v: Vec<f32> = vd.iter().map(|&x| x as f32).collect();
        let v_cells = cell_starts(v.iter().map(|&e| v_cell(e)), V_CELLS);
        let u_cells = cdf
            .iter()
            .map(|c: &Vec<f64>| cell_starts(c.iter().map(|&x| u_cell(x)), U_CELLS))
            .collect();
        PhaseTable {
            lambda0,
            dlambda,
            v,
            v_cells,
            u_cells,
            density: (0..m)
                .flat_map(|j| density.iter().map(move |d: &Vec<f32>| d[j]))
                .collect(),
            nodes: masses.len(),
            cdf,
            raw_integral,
            matrix: Vec::new(),
        }
    }

    /// The table with the phase matrix's shape: `f11[i][e]` and `rest[i][e]` = (F12,
    /// F33, F34) of node i at θ edge e, unnormalised like `from_values`' values (the
    /// same F11).
    pub fn with_matrix(mut self, f11: &[Vec<f64>], rest: &[Vec<[f64; 3]>]) -> Self {
        let m = self.v.len() - 1;
        let mut matrix = vec![[0.0f32; 3]; m * self.nodes];
        for (i, (a, r)) in f11.iter().zip(rest).enumerate() {
            for j in 0..m {
                let d = a[j] + a[j + 1];
                matrix[j * self.nodes + i] = std::array::from_fn(|c| {
                    if d > 0.0 {
                        ((r[j][c] + r[j + 1][c]) / d).clamp(-1.0, 1.0) as f32
                    } else {
                        0.0
                    }
                });
            }
        }
        self.matrix = matrix;
        self
    }

    /// Whether the phase matrix is tabulated.
    pub fn has_matrix(&self) -> bool {
        !self.matrix.is_empty()
    }

    /// (F12, F33, F34) / F11 at v for each lane's wavelength: the nodes' mixture of the
    /// module docs, each node's F_ij weighted by its share of F11. Zero without a matrix.
    #[inline]
    pub fn eval_matrix<const N: usize>(&self, v: f32, lambda: &[f32; N]) -> [[f32; 3]; N] {
        if self.matrix.is_empty() {
            return [[0.0; 3]; N];
        }
        let j = self.bin(v);
        let row = &self.density[j * self.nodes..(j + 1) * self.nodes];
        let mat = &self.matrix[j * self.nodes..(j + 1) * self.nodes];
        std::array::from_fn(|k| {
            let (i, t) = self.node(lambda[k]);
            if t == 0.0 {
                return mat[i];
            }
            let (a, b) = (row[i] * (1.0 - t), row[i + 1] * t);
            let d = a + b;
            if !(d > 0.0) {
                return mat[i];
            }
            std::array::from_fn(|c| (a * mat[i][c] + b * mat[i + 1][c]) / d)
        })
    }

    /// At node `node`, each bin's p (sr⁻¹) and (F12, F33, F34) / F11: the table as a
    /// polarised render looks it up, for checks (`heron sky mie-matrix`).
    pub fn rows(&self, node: usize) -> Vec<(f32, [f32; 3])> {
        (0..self.v.len() - 1)
            .map(|j| {
                (
                    self.density[j * self.nodes + node],
                    self.matrix
                        .get(j * self.nodes + node)
                        .copied()
                        .unwrap_or([0.0; 3]),
                )
            })
            .collect()
    }

    /// The number of wavelength nodes.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// Node index i and fraction t of `lambda` between nodes i and i + 1 (held at the
    /// ends).
    #[inline]
    fn node(&self, lambda: f32) -> (usize, f32) {
        let n = self.nodes;
        let s = ((lambda - self.lambda0) / self.dlambda).max(0.0);
        let i = (s as usize).min(n - 1);
        if i + 1 >= n {
            return (n - 1, 0.0);
        }
        (i, s - i as f32)
    }

    /// The bin of v: the last edge ≤ v (bins 0 … M − 1), searched between the bins
    /// its cell bounds.
    #[inline]
    fn bin(&self, v: f32) -> usize {
        let m = self.v.len() - 1;
        let k = v_cell(v);
        let (lo, hi) = (self.v_cells[k] as usize, self.v_cells[k + 1] as usize);
        (lo + self.v[lo..hi].partition_point(|&e| e <= v)).clamp(1, m) - 1
    }

    #[inline]
    fn value_in_bin(&self, lambda: f32, j: usize) -> f32 {
        let (i, t) = self.node(lambda);
        let row = &self.density[j * self.nodes..(j + 1) * self.nodes];
        let a = row[i];
        if t == 0.0 {
            a
        } else {
            a + t * (row[i + 1] - a)
        }
    }

    /// p at v = 1 − cos θ for each lane's wavelength.
    #[inline]
    pub fn eval<const N: usize>(&self, v: f32, lambda: &[f32; N]) -> SampledSpectrum<N> {
        let j = self.bin(v);
        SampledSpectrum(std::array::from_fn(|k| self.value_in_bin(lambda[k], j)))
    }

    /// Samples v for the hero wavelength `lambda[0]` (`u_node` picks the node of the
    /// mixture, `u` the bin and the place in it) and returns v with every lane's p there
    /// (lane 0's is the sampling pdf).
    #[inline]
    pub fn sample<const N: usize>(
        &self,
        u_node: f32,
        u: f32,
        lambda: &[f32; N],
    ) -> (f32, SampledSpectrum<N>) {
        let (i, t) = self.node(lambda[0]);
        let node = if t > 0.0 && u_node < t { i + 1 } else { i };
        let c = &self.cdf[node];
        let uu = u as f64;
        let m = c.len() - 1;
        let k = u_cell(uu);
        let (lo, hi) = (
            self.u_cells[node][k] as usize,
            self.u_cells[node][k + 1] as usize,
        );
        let j = ((lo + c[lo..hi].partition_point(|&x| x <= uu)).clamp(1, m) - 1).min(m - 1);
        let span = c[j + 1] - c[j];
        let f = if span > 0.0 {
            ((uu - c[j]) / span).clamp(0.0, 1.0) as f32
        } else {
            0.5
        };
        let v = self.v[j] + f * (self.v[j + 1] - self.v[j]);
        let p = SampledSpectrum(std::array::from_fn(|k| self.value_in_bin(lambda[k], j)));
        (v, p)
    }
}

/// The unit direction at v = 1 − cos θ from `axis` and azimuth 2π u_phi, keeping the
/// precision of small angles (sin θ from v).
#[inline]
pub fn direction_at(axis: Vec3, v: f32, u_phi: f32) -> Vec3 {
    let cos_t = 1.0 - v;
    let sin_t = (v * (2.0 - v)).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u_phi;
    let local = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
    crate::math::frame::Frame::from_z(axis)
        .to_world(local)
        .normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cell-bounded searches find what a search of the whole table finds: at every
    /// edge, between edges, near θ = π (where bins are narrowest in v) and for u at and
    /// between the CDF's values.
    #[test]
    fn cell_bounded_searches_equal_whole_table_searches() {
        let theta = angle_grid(8727.0);
        let values: Vec<Vec<f64>> = (0..3)
            .map(|i| {
                theta
                    .iter()
                    .map(|&t| 1.0 / (1e-4 + t * t) + i as f64 * (10.0 * t).cos().abs())
                    .collect()
            })
            .collect();
        let table = PhaseTable::from_values(400.0, 10.0, &theta, &values);
        let m = table.v.len() - 1;
        let whole = |v: f32| table.v.partition_point(|&e| e <= v).clamp(1, m) - 1;
        let mut probes: Vec<f32> = table.v.clone();
        probes.extend(table.v.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        probes.extend(
            table
                .v
                .iter()
                .map(|&e| f32::from_bits(e.to_bits().saturating_sub(1))),
        );
        probes.extend([0.0, 2.0, 2.5, -0.0, f32::NAN]);
        for v in probes {
            assert_eq!(table.bin(v), whole(v), "v = {v:e}");
        }
        for (node, c) in table.cdf.iter().enumerate() {
            let whole = |u: f64| (c.partition_point(|&x| x <= u).clamp(1, m) - 1).min(m - 1);
            let mut us: Vec<f64> = c.clone();
            us.extend(c.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            us.extend((0..4096).map(|k| k as f64 / 4096.0));
            for u in us.into_iter().filter(|&u| u < 1.0) {
                let (v, _) = table.sample(0.0, u as f32, &[400.0 + 10.0 * node as f32]);
                let j = whole(u as f32 as f64);
                assert!(
                    v >= table.v[j] && v <= table.v[j + 1],
                    "node {node}, u = {u}"
                );
            }
        }
    }
}
