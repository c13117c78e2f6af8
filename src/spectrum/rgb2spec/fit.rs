//! The fit of Jakob & Hanika (2019), "A Low-Dimensional Function Space for Efficient
//! Spectral Upsampling", §3–4: for a target linear sRGB colour, the three coefficients
//! of s(λ) = S(c0 t² + c1 t + c2) (see the parent module) that give the spectrum that
//! colour, found by Gauss–Newton on the CIELAB difference; and the coefficient table
//! built from such fits on a grid over the sRGB cube.
//!
//! Colour of a reflectance, exactly as heron's film measures it (src/spectrum/cie.rs):
//! lit by D65 scaled to Y = 1 and integrated with CIE 1931 2° at 1 nm over 360–830 nm,
//!
//! ```text
//! XYZ = Σ s(λ) D65(λ) x̄ȳz̄(λ) / Σ D65(λ) ȳ(λ),
//! ```
//!
//! from heron's own tables ([`cie1931`], [`d65_relative`]). The film turns XYZ into linear
//! sRGB with the IEC 61966-2-1 matrix [`XYZ_TO_SRGB`]; the target's XYZ is the exact
//! (double precision) inverse of that matrix applied to the target colour, so a fit with
//! zero residual comes back through the film as the target itself. (The printed
//! [`crate::spectrum::color::SRGB_TO_XYZ`] is that inverse only to 1e-4.)
//!
//! Residual: CIELAB (CIE 1976) of the spectrum minus CIELAB of the target, with the
//! reference white the XYZ of the perfect reflector s ≡ 1 under the same D65, as the
//! paper does (unweighted ΔE*ab). The Jacobian is analytic: ∂XYZ/∂c by differentiating
//! the sum (S′(x) = ½ (1 + x²)^(−3/2)), times ∂Lab/∂XYZ.
//!
//! Everything here is double precision; only the table stores f32.
use super::{normalised_lambda, sigmoid, z_nodes, Rgb2SpecTable};
use crate::spectrum::cie::{cie1931, d65_relative};
use crate::spectrum::color::XYZ_TO_SRGB;
use crate::spectrum::{DENSE_LEN, LAMBDA_MIN};
use rayon::prelude::*;
use std::sync::OnceLock;

type Mat3 = [[f64; 3]; 3];

/// heron's colorimetry in double precision: per-wavelength weights and the sRGB matrices.
pub struct ColourModel {
    /// Normalised wavelength t of each 1 nm sample.
    t: Vec<f64>,
    /// D65(λ) · (x̄, ȳ, z̄)(λ) / Σ D65 ȳ for each 1 nm sample.
    w: Vec<[f64; 3]>,
    /// Linear sRGB → XYZ: the exact inverse of the film's XYZ → sRGB matrix.
    pub rgb_to_xyz: Mat3,
    /// XYZ of the perfect reflector (s ≡ 1): the CIELAB reference white.
    pub white: [f64; 3],
    /// Linear sRGB the film gives the perfect reflector under D65 at Y = 1:
    /// (1.0000057, 1.0000753, 0.9998329), not exactly (1, 1, 1) (spectra/README.md).
    pub white_rgb: [f64; 3],
}

/// Options of one Gauss–Newton solve.
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Stop when ΔE*ab (Euclidean norm of the Lab residual) is below this.
    pub tolerance: f64,
    /// Most Gauss–Newton iterations.
    pub max_iterations: u32,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            tolerance: 1e-8,
            max_iterations: 100,
        }
    }
}

/// Result of one fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// (c0, c1, c2) in the normalised wavelength t.
    pub c: [f64; 3],
    /// ΔE*ab between the spectrum's colour and the target at the end.
    pub delta_e: f64,
    /// Gauss–Newton iterations taken (each one step, possibly shortened).
    pub iterations: u32,
}

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn mat_vec(a: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Solves a x = b by Gaussian elimination with partial pivoting; None when singular.
pub fn solve3(a: Mat3, b: [f64; 3]) -> Option<[f64; 3]> {
    let mut m = [
        [a[0][0], a[0][1], a[0][2], b[0]],
        [a[1][0], a[1][1], a[1][2], b[1]],
        [a[2][0], a[2][1], a[2][2], b[2]],
    ];
    let scale = a.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    for col in 0..3 {
        let p = (col..3)
            .max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))
            .unwrap();
        if m[p][col].abs() <= 1e-14 * scale {
            return None;
        }
        m.swap(col, p);
        let pivot = m[col];
        for row in m.iter_mut().skip(col + 1) {
            let f = row[col] / pivot[col];
            for (v, p) in row.iter_mut().zip(pivot).skip(col) {
                *v -= f * p;
            }
        }
    }
    let mut x = [0.0; 3];
    for r in (0..3).rev() {
        let s: f64 = (r + 1..3).map(|k| m[r][k] * x[k]).sum();
        x[r] = (m[r][3] - s) / m[r][r];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

fn inverse(a: &Mat3) -> Mat3 {
    let cols = [0, 1, 2].map(|j| {
        let mut e = [0.0; 3];
        e[j] = 1.0;
        solve3(*a, e).expect("invertible matrix")
    });
    [0, 1, 2].map(|i| [cols[0][i], cols[1][i], cols[2][i]])
}

/// CIELAB's f(u) = ∛u above (6/29)³, linear below; and its derivative.
fn lab_f(u: f64) -> (f64, f64) {
    const D: f64 = 6.0 / 29.0;
    if u > D * D * D {
        let c = u.cbrt();
        (c, 1.0 / (3.0 * c * c))
    } else {
        (u / (3.0 * D * D) + 4.0 / 29.0, 1.0 / (3.0 * D * D))
    }
}

impl ColourModel {
    /// heron's colorimetry: its CIE 1931 2° and D65 tables, the film's sRGB matrix.
    pub fn heron() -> &'static ColourModel {
        static M: OnceLock<ColourModel> = OnceLock::new();
        M.get_or_init(|| {
            let obs = cie1931();
            let d65 = d65_relative();
            let mut w = Vec::with_capacity(DENSE_LEN);
            let mut t = Vec::with_capacity(DENSE_LEN);
            let mut k = 0.0;
            for i in 0..DENSE_LEN {
                let d = d65.values()[i] as f64;
                let cmf = [&obs.x, &obs.y, &obs.z].map(|c| c.values()[i] as f64);
                w.push(cmf.map(|v| d * v));
                k += d * cmf[1];
                t.push(normalised_lambda(LAMBDA_MIN as f64 + i as f64));
            }
            for wi in &mut w {
                *wi = wi.map(|v| v / k);
            }
            let white = [0, 1, 2].map(|c| w.iter().map(|wi| wi[c]).sum::<f64>());
            let m = XYZ_TO_SRGB.map(|row| row.map(f64::from));
            ColourModel {
                t,
                w,
                rgb_to_xyz: inverse(&m),
                white,
                white_rgb: mat_vec(&m, white),
            }
        })
    }

    /// XYZ of the reflectance with coefficients c under D65, and ∂XYZ/∂c.
    pub fn xyz(&self, c: [f64; 3]) -> ([f64; 3], Mat3) {
        let mut xyz = [0.0; 3];
        let mut jac = [[0.0; 3]; 3];
        for (&t, w) in self.t.iter().zip(&self.w) {
            let x = (c[0] * t + c[1]) * t + c[2];
            let s = sigmoid(x);
            let q = 1.0 + x * x;
            let ds = if q.is_finite() {
                0.5 / (q * q.sqrt())
            } else {
                0.0
            };
            let basis = [t * t, t, 1.0];
            for k in 0..3 {
                xyz[k] += w[k] * s;
                for j in 0..3 {
                    jac[k][j] += w[k] * ds * basis[j];
                }
            }
        }
        (xyz, jac)
    }

    /// XYZ of a linear sRGB colour, as the film's matrix would give it back.
    pub fn xyz_of_rgb(&self, rgb: [f64; 3]) -> [f64; 3] {
        mat_vec(&self.rgb_to_xyz, rgb)
    }

    /// CIELAB of an XYZ colour relative to [`Self::white`], and ∂Lab/∂XYZ.
    pub fn lab(&self, xyz: [f64; 3]) -> ([f64; 3], Mat3) {
        let (fx, dx) = lab_f(xyz[0] / self.white[0]);
        let (fy, dy) = lab_f(xyz[1] / self.white[1]);
        let (fz, dz) = lab_f(xyz[2] / self.white[2]);
        let (dx, dy, dz) = (dx / self.white[0], dy / self.white[1], dz / self.white[2]);
        let lab = [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)];
        let jac = [
            [0.0, 116.0 * dy, 0.0],
            [500.0 * dx, -500.0 * dy, 0.0],
            [0.0, 200.0 * dy, -200.0 * dz],
        ];
        (lab, jac)
    }

    /// Lab residual (spectrum − target) and its Jacobian with respect to c.
    fn residual(&self, c: [f64; 3], target: [f64; 3]) -> ([f64; 3], Mat3) {
        let (xyz, jx) = self.xyz(c);
        let (lab, jl) = self.lab(xyz);
        (
            [lab[0] - target[0], lab[1] - target[1], lab[2] - target[2]],
            mat_mul(&jl, &jx),
        )
    }

    /// The colour the fit aims at for linear sRGB `rgb`: its grey part min(r, g, b) is
    /// taken as the film's colour of the constant reflectance min(r, g, b), the rest as
    /// is: rgb + min(rgb) · ([`Self::white_rgb`] − 1).
    ///
    /// heron's D65 table and the four-digit IEC matrix disagree on white by up to
    /// 1.7e-4, so (1, 1, 1) is no colour a reflectance ≤ 1 can have, and exact greys
    /// would need wavy spectra. Aiming greys at the constant spectrum instead keeps every
    /// grey of the table flat (c0 = c1 = 0, continuous with the exact-grey lookup) and
    /// white reachable (c2 → ∞), at the price of a round-trip error of at most
    /// min(rgb) · 1.7e-4 (none at all for colours with a zero component).
    pub fn target_rgb(&self, rgb: [f64; 3]) -> [f64; 3] {
        let m = rgb[0].min(rgb[1]).min(rgb[2]);
        [0, 1, 2].map(|i| rgb[i] + m * (self.white_rgb[i] - 1.0))
    }

    /// CIELAB of the fit's target for linear sRGB `rgb` ([`Self::target_rgb`]).
    pub fn target_lab(&self, rgb: [f64; 3]) -> [f64; 3] {
        self.lab(self.xyz_of_rgb(self.target_rgb(rgb))).0
    }

    /// ΔE*ab between the reflectance with coefficients c and the target for `rgb`.
    pub fn delta_e(&self, c: [f64; 3], rgb: [f64; 3]) -> f64 {
        let target = self.target_lab(rgb);
        norm(self.residual(c, target).0)
    }

    /// Gauss–Newton from `start` towards the linear sRGB colour `rgb` (precisely, towards
    /// [`Self::target_rgb`] of it).
    ///
    /// With three residuals and three unknowns the Gauss–Newton step solves J δ = −r.
    /// The step is halved until it lowers |r| (at most 30 times); if no shortened step
    /// does, or J is singular, a Levenberg–Marquardt step (JᵀJ + μ diag JᵀJ) δ = −Jᵀr
    /// with growing μ is tried; when that fails too the fit has stalled and stops with
    /// the best coefficients found.
    pub fn fit(&self, rgb: [f64; 3], start: [f64; 3], opt: FitOptions) -> Fit {
        let target = self.target_lab(rgb);
        let mut c = start;
        let (mut r, mut j) = self.residual(c, target);
        let mut e = norm(r);
        let mut iterations = 0;
        while e > opt.tolerance && iterations < opt.max_iterations {
            iterations += 1;
            let mut try_step = |d: [f64; 3], c: &mut [f64; 3], r: &mut [f64; 3], j: &mut Mat3| {
                let cand = [c[0] + d[0], c[1] + d[1], c[2] + d[2]];
                if !cand.iter().all(|v| v.is_finite()) {
                    return false;
                }
                let (r2, j2) = self.residual(cand, target);
                let e2 = norm(r2);
                if e2.is_finite() && e2 < e {
                    (*c, *r, *j, e) = (cand, r2, j2, e2);
                    true
                } else {
                    false
                }
            };
            let mut accepted = false;
            if let Some(d) = solve3(j, r.map(|v| -v)) {
                let mut a = 1.0;
                for _ in 0..30 {
                    if try_step(d.map(|v| a * v), &mut c, &mut r, &mut j) {
                        accepted = true;
                        break;
                    }
                    a *= 0.5;
                }
            }
            if !accepted {
                let jt = [0, 1, 2].map(|a| [0, 1, 2].map(|b| j[b][a]));
                let jtj = mat_mul(&jt, &j);
                let g = mat_vec(&jt, r).map(|v| -v);
                let mut mu = 1e-6;
                for _ in 0..16 {
                    let mut m = jtj;
                    for (i, row) in m.iter_mut().enumerate() {
                        row[i] += mu * jtj[i][i].max(1e-30);
                    }
                    if let Some(d) = solve3(m, g) {
                        if try_step(d, &mut c, &mut r, &mut j) {
                            accepted = true;
                            break;
                        }
                    }
                    mu *= 10.0;
                }
            }
            if !accepted {
                break;
            }
        }
        Fit {
            c,
            delta_e: e,
            iterations,
        }
    }

    /// Fits from each start in turn until one reaches `opt.tolerance`; the best fit.
    pub fn fit_from(&self, rgb: [f64; 3], starts: &[[f64; 3]], opt: FitOptions) -> Fit {
        let mut best: Option<Fit> = None;
        let mut iterations = 0;
        for &s in starts {
            let f = self.fit(rgb, s, opt);
            iterations += f.iterations;
            if best.map_or(true, |b| f.delta_e < b.delta_e) {
                best = Some(f);
            }
            if f.delta_e <= opt.tolerance {
                break;
            }
        }
        Fit {
            iterations,
            ..best.expect("at least one start")
        }
    }
}

/// Fits `rgb` with heron's colorimetry from `start` with the default options.
pub fn fit(rgb: [f64; 3], start: [f64; 3]) -> Fit {
    ColourModel::heron().fit(rgb, start, FitOptions::default())
}

/// Coefficients of the constant reflectance g (the grey start of the fits).
pub fn grey_start(g: f64) -> [f64; 3] {
    let g = g.clamp(1e-4, 1.0 - 1e-4);
    [0.0, 0.0, (g - 0.5) / (g * (1.0 - g)).sqrt()]
}

/// Per-node record of a table build.
#[derive(Clone, Copy, Debug, Default)]
pub struct NodeStats {
    pub delta_e: f64,
    pub iterations: u32,
}

/// A built table and how its fits went.
pub struct BuiltTable {
    pub table: Rgb2SpecTable,
    /// Per node, indexed like the table's coefficients / 3; z node 0 (black) is copied
    /// from z node 1 and not fitted (ΔE recorded as 0).
    pub nodes: Vec<NodeStats>,
}

impl BuiltTable {
    /// Largest ΔE*ab over the fitted nodes, and where (l, k, yi, xi).
    pub fn worst(&self) -> (f64, [usize; 4]) {
        let n = self.table.res();
        let (i, s) = self
            .nodes
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.delta_e.total_cmp(&b.1.delta_e))
            .unwrap();
        let (xi, rest) = (i % n, i / n);
        let (yi, rest) = (rest % n, rest / n);
        let (k, l) = (rest % n, rest / n);
        (s.delta_e, [l, k, yi, xi])
    }
}

/// Builds the table of resolution `res` (Jakob & Hanika 2019, §4), in parallel on
/// rayon's pool. For each ordering l:
///
/// 1. the z slice nearest z = ½ is solved sequentially from the grey corner (x = y = 1,
///    started from the exact constant spectrum) outward to the saturated corner
///    (x = y = 0), each node starting from its solved neighbour at x + 1 (or y + 1);
/// 2. from there every (x, y) column is solved up to z = 1 and down to the first z node
///    above 0, each node starting from the previous one in the column.
///
/// A node whose fit stalls above the tolerance is retried from the grey of the same
/// luminance and from c = 0, and keeps the best fit. z node 0 (z = 0: every colour is
/// black there, which no finite c reaches) copies node 1; colours with the largest
/// component below z node 1 are within z node 1 of black anyway.
pub fn build_table(res: usize) -> BuiltTable {
    assert!(res >= 3);
    let model = ColourModel::heron();
    let opt = FitOptions::default();
    let zn = z_nodes(res);
    let k0 = zn
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - 0.5).abs().total_cmp(&(b.1 - 0.5).abs()))
        .unwrap()
        .0;
    let rgb_at = |l: usize, k: usize, yi: usize, xi: usize| {
        let z = zn[k] as f64;
        let s = (res - 1) as f64;
        let mut rgb = [0.0; 3];
        rgb[l] = z;
        rgb[(l + 1) % 3] = xi as f64 / s * z;
        rgb[(l + 2) % 3] = yi as f64 / s * z;
        rgb
    };
    let fit_node = |rgb: [f64; 3], start: [f64; 3]| {
        let y = mat_vec(&model.rgb_to_xyz, rgb)[1];
        model.fit_from(rgb, &[start, grey_start(y), [0.0; 3]], opt)
    };
    // Per ordering: [k][yi][xi] fits.
    let per_l: Vec<Vec<Fit>> = (0..3)
        .into_par_iter()
        .map(|l| {
            // 1. The start slice, from the grey corner outward.
            let mut slice: Vec<Option<Fit>> = vec![None; res * res];
            for yi in (0..res).rev() {
                for xi in (0..res).rev() {
                    let start = if xi + 1 < res {
                        slice[yi * res + xi + 1].unwrap().c
                    } else if yi + 1 < res {
                        slice[(yi + 1) * res + xi].unwrap().c
                    } else {
                        grey_start(zn[k0] as f64)
                    };
                    slice[yi * res + xi] = Some(fit_node(rgb_at(l, k0, yi, xi), start));
                }
            }
            // 2. Every column up and down from the start slice.
            let columns: Vec<Vec<Fit>> = (0..res * res)
                .into_par_iter()
                .map(|i| {
                    let (yi, xi) = (i / res, i % res);
                    let mut col = vec![slice[i].unwrap(); res];
                    for k in k0 + 1..res {
                        col[k] = fit_node(rgb_at(l, k, yi, xi), col[k - 1].c);
                    }
                    for k in (1..k0).rev() {
                        col[k] = fit_node(rgb_at(l, k, yi, xi), col[k + 1].c);
                    }
                    col[0] = Fit {
                        delta_e: 0.0,
                        iterations: 0,
                        ..col[1]
                    };
                    col
                })
                .collect();
            let mut out = Vec::with_capacity(res * res * res);
            for k in 0..res {
                for col in &columns {
                    out.push(col[k]);
                }
            }
            out
        })
        .collect();
    let fits: Vec<Fit> = per_l.into_iter().flatten().collect();
    let coeffs = fits
        .iter()
        .flat_map(|f| f.c.map(|v| v as f32))
        .collect::<Vec<f32>>();
    let nodes = fits
        .iter()
        .map(|f| NodeStats {
            delta_e: f.delta_e,
            iterations: f.iterations,
        })
        .collect();
    BuiltTable {
        table: Rgb2SpecTable::new(res, coeffs),
        nodes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::cie::{d65_unit, spectrum_to_xyz};

    #[test]
    fn solve3_solves_and_detects_singular_systems() {
        let a = [[2.0, 1.0, -1.0], [-3.0, -1.0, 2.0], [-2.0, 1.0, 2.0]];
        let x = solve3(a, [8.0, -11.0, -3.0]).unwrap();
        for (v, w) in x.iter().zip([2.0, 3.0, -1.0]) {
            assert!((v - w).abs() < 1e-12, "{x:?}");
        }
        assert!(solve3(
            [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]],
            [1.0; 3]
        )
        .is_none());
        let m = ColourModel::heron();
        let id = mat_mul(&m.rgb_to_xyz, &XYZ_TO_SRGB.map(|r| r.map(f64::from)));
        for (i, row) in id.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12, "{id:?}");
            }
        }
    }

    #[test]
    fn model_xyz_is_the_films_xyz_and_its_jacobian_is_right() {
        let m = ColourModel::heron();
        let c = [1.3, -2.1, 0.4];
        let p = super::super::SigmoidPolynomial {
            c: c.map(|v| v as f32),
        };
        let film = spectrum_to_xyz(&p.to_dense().mul(d65_unit()));
        let (xyz, jac) = m.xyz(c);
        for i in 0..3 {
            assert!((film[i] as f64 - xyz[i]).abs() < 2e-6, "{film:?} {xyz:?}");
        }
        // White of the perfect reflector is D65's XYZ at Y = 1.
        assert!((m.white[1] - 1.0).abs() < 1e-12);
        assert!((m.white[0] - 0.95047).abs() < 1e-4 && (m.white[2] - 1.08883).abs() < 1e-4);
        // Central differences.
        for j in 0..3 {
            let h = 1e-6;
            let mut a = c;
            let mut b = c;
            a[j] += h;
            b[j] -= h;
            let (xa, _) = m.xyz(a);
            let (xb, _) = m.xyz(b);
            for k in 0..3 {
                let num = (xa[k] - xb[k]) / (2.0 * h);
                assert!(
                    (num - jac[k][j]).abs() < 1e-7,
                    "∂{k}/∂c{j}: {num} vs {}",
                    jac[k][j]
                );
            }
        }
        let (lab, jl) = m.lab(xyz);
        for j in 0..3 {
            let h = 1e-7;
            let mut a = xyz;
            a[j] += h;
            let (la, _) = m.lab(a);
            for k in 0..3 {
                let num = (la[k] - lab[k]) / h;
                assert!(
                    (num - jl[k][j]).abs() < 1e-3 * (1.0 + num.abs()),
                    "{num} {}",
                    jl[k][j]
                );
            }
        }
    }

    #[test]
    fn fit_reaches_a_soft_colour_and_white_of_the_perfect_reflector_is_lab_100() {
        let m = ColourModel::heron();
        let (lab, _) = m.lab(m.white);
        assert!((lab[0] - 100.0).abs() < 1e-12 && lab[1].abs() < 1e-12 && lab[2].abs() < 1e-12);
        let f = fit([0.3, 0.5, 0.2], [0.0; 3]);
        assert!(f.delta_e < 1e-8, "{f:?}");
        assert!(f.iterations < 30, "{f:?}");
    }
}
