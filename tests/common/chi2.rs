//! Pearson's chi-square goodness-of-fit test for sampling routines, in the manner of
//! Mitsuba 3's `chi2` test (`mitsuba/python/chi2.py`): draw N samples, histogram them
//! over a 2D parametrisation of the domain, integrate the claimed density over every
//! histogram cell to get the expected counts, pool the cells whose expected count is
//! below 5, and reject when the p-value of the statistic falls below the significance
//! level (α = 0.01, divided among the tests of a file: Bonferroni).
//!
//! Domains:
//! - [`Spherical`]: directions about a frame, bins uniform in θ ∈ [0, θmax] (angle from
//!   the frame's z axis) and φ ∈ [0, 2π); the measure is solid angle, dω = sin θ dθ dφ.
//!   θmax = π covers the sphere; a small θmax zooms on a cone (the sun's disk).
//! - [`Planar`]: points of a rectangle, bins uniform in x and y; the measure is area.
//!
//! A sample that fails (the routine returned None) or that lands outside the domain is
//! counted in one extra "no sample / outside" cell, whose expected count is
//! N·(1 − ∫ pdf over the domain): a routine that may fail (a Phong lobe below the
//! horizon) or a domain that does not hold all of the density (a cone about one lobe)
//! are tested exactly like the others.
//!
//! Expected counts come from an adaptive product Gauss–Legendre rule (8 × 8 nodes per
//! cell, a cell split into 4 until the split changes the integral by less than 1% of the
//! cell's Poisson standard deviation √(N p)/N, up to 7 levels; a cell where the density
//! is zero at some nodes or edge probes and positive at others, i.e. one that the edge
//! of the density's support crosses, is split at least 5 levels deep), with the Jacobian
//! sin θ, and with optional θ (or x) break points where the density is known to jump
//! between positive values (a piecewise-constant sky, a sphere's rim): the rule is then
//! applied on either side of each jump. The helper checks that the density integrates
//! to at most 1 + 1e-3.
//!
//! Every sample's returned pdf is compared with the pdf closure at the sampled point
//! (relative 1e-3): a routine whose `sample` and `pdf` disagree fails even when the
//! histogram cannot see it. A sample where both say the density is 0 (a cosine-weighted
//! direction exactly on the horizon) is on the rim of the support: it is left out of the
//! histogram and may occur in at most 1e-5 of the samples. Samples in a cell whose
//! expected count is exactly 0 reject the test (as in Mitsuba); a last pool of cells
//! that stays below 5 expected joins the smallest full cell.
//!
//! The p-value is Q(dof/2, χ²/2), the regularised upper incomplete gamma function,
//! implemented here in f64 (series and Lentz continued fraction, Numerical Recipes 3rd
//! ed. §6.2; ln Γ by Lanczos' approximation with g = 7).
use glam::{DVec3, Vec2, Vec3};
use heron::math::Rng;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// Significance level of a whole test file.
pub const ALPHA: f64 = 0.01;
/// Cells with a smaller expected count are pooled (Mitsuba's threshold).
pub const MIN_EXPECTED: f64 = 5.0;
/// Relative agreement required between a sample's pdf and the pdf closure.
pub const PDF_REL_TOL: f64 = 1e-3;
/// The claimed density may integrate to at most this over the domain.
pub const MAX_INTEGRAL: f64 = 1.0 + 1e-3;
const GL_POINTS: usize = 8;
const MAX_DEPTH: u32 = 7;
const MIXED_DEPTH: u32 = 5;

// ----------------------------------------------------------------------------------
// Special functions
// ----------------------------------------------------------------------------------

/// ln Γ(x) for x > 0: Lanczos' approximation with g = 7 and 9 coefficients (relative
/// error below 1e-15), with the reflection formula below 1/2.
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return PI.ln() - (PI * x).sin().ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// P(a, x) by its series, for x < a + 1 (Numerical Recipes `gser`).
fn gamma_p_series(a: f64, x: f64) -> f64 {
    let mut ap = a;
    let mut del = 1.0 / a;
    let mut sum = del;
    for _ in 0..1_000_000 {
        ap += 1.0;
        del *= x / ap;
        sum += del;
        if del.abs() < sum.abs() * 1e-16 {
            break;
        }
    }
    sum * (-x + a * x.ln() - ln_gamma(a)).exp()
}

/// Q(a, x) by its continued fraction (modified Lentz), for x ≥ a + 1 (Numerical Recipes
/// `gcf`).
fn gamma_q_cont_frac(a: f64, x: f64) -> f64 {
    const FPMIN: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / FPMIN;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..1_000_000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < FPMIN {
            d = FPMIN;
        }
        c = b + an / c;
        if c.abs() < FPMIN {
            c = FPMIN;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x + a * x.ln() - ln_gamma(a)).exp() * h
}

/// The regularised upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "Q({a}, {x})");
    if x == 0.0 {
        1.0
    } else if x < a + 1.0 {
        1.0 - gamma_p_series(a, x)
    } else {
        gamma_q_cont_frac(a, x)
    }
}

/// P(χ² ≥ `statistic`) for `dof` degrees of freedom.
pub fn chi2_p_value(statistic: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, statistic / 2.0)
}

/// Pearson's statistic with Mitsuba's pooling: cells sorted by expected count, those
/// below [`MIN_EXPECTED`] merged in order until each pool reaches it; a last pool that
/// stays below it joins the smallest full cell (so that no cell, such as the "no sample"
/// cell of a routine that fails on a measure-zero set, is tested with an expected count
/// near zero). Returns (statistic, degrees of freedom, number of pooled cells,
/// observations in cells whose expected count is exactly zero).
pub fn pearson(observed: &[f64], expected: &[f64]) -> (f64, usize, usize, f64) {
    assert_eq!(observed.len(), expected.len());
    let mut idx: Vec<usize> = (0..observed.len()).collect();
    idx.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut cells: Vec<(f64, f64)> = Vec::new();
    let mut pooled = 0usize;
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    let mut in_zero_cells = 0.0;
    for &i in &idx {
        let (o, e) = (observed[i], expected[i]);
        if e <= 0.0 {
            in_zero_cells += o;
            continue;
        }
        if e < MIN_EXPECTED {
            pool_e += e;
            pool_o += o;
            pooled += 1;
            if pool_e >= MIN_EXPECTED {
                cells.push((pool_o, pool_e));
                pool_e = 0.0;
                pool_o = 0.0;
            }
        } else {
            cells.push((o, e));
        }
    }
    if pool_e > 0.0 {
        match cells.iter_mut().min_by(|a, b| a.1.total_cmp(&b.1)) {
            Some(c) => {
                c.0 += pool_o;
                c.1 += pool_e;
            }
            None => cells.push((pool_o, pool_e)),
        }
    }
    let stat = cells.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    (stat, cells.len().saturating_sub(1), pooled, in_zero_cells)
}

// ----------------------------------------------------------------------------------
// Quadrature over a rectangle of parameters
// ----------------------------------------------------------------------------------

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton's iteration on P_n, Numerical
/// Recipes `gauleg`).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut pp;
        loop {
            let (mut p1, mut p2) = (1.0, 0.0);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                p1 = ((2.0 * j as f64 + 1.0) * z * p2 - j as f64 * p3) / (j as f64 + 1.0);
            }
            pp = n as f64 * (z * p1 - p2) / (z * z - 1.0);
            let z1 = z;
            z = z1 - p1 / pp;
            if (z - z1).abs() < 1e-15 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * pp * pp);
        w[n - 1 - i] = w[i];
    }
    (x, w)
}

/// A rectangle [u0, u1] × [v0, v1] of parameters cut into nu × nv bins, with the
/// Jacobian sin u (spherical) or 1 (planar), and break points in u where the integrand
/// may jump.
#[derive(Clone, Debug)]
struct Param {
    u: (f64, f64, usize),
    v: (f64, f64, usize),
    u_breaks: Vec<f64>,
    sin_jacobian: bool,
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl Param {
    fn new(u: (f64, f64, usize), v: (f64, f64, usize), breaks: &[f64], sin: bool) -> Param {
        let (nodes, weights) = gauss_legendre(GL_POINTS);
        let mut u_breaks: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|&b| b > u.0 && b < u.1)
            .collect();
        u_breaks.sort_by(f64::total_cmp);
        u_breaks.dedup();
        Param {
            u,
            v,
            u_breaks,
            sin_jacobian: sin,
            nodes,
            weights,
        }
    }

    fn bins(&self) -> usize {
        self.u.2 * self.v.2
    }

    fn bin(&self, u: f64, v: f64) -> Option<usize> {
        let (u0, u1, nu) = self.u;
        let (v0, v1, nv) = self.v;
        if !(u >= u0 && u <= u1 && v >= v0 && v <= v1) {
            return None;
        }
        let i = (((u - u0) / (u1 - u0) * nu as f64) as usize).min(nu - 1);
        let j = (((v - v0) / (v1 - v0) * nv as f64) as usize).min(nv - 1);
        Some(i * nv + j)
    }

    fn bounds(&self, b: usize) -> (f64, f64, f64, f64) {
        let (u0, u1, nu) = self.u;
        let (v0, v1, nv) = self.v;
        let (i, j) = (b / nv, b % nv);
        let du = (u1 - u0) / nu as f64;
        let dv = (v1 - v0) / nv as f64;
        (
            u0 + i as f64 * du,
            if i + 1 == nu {
                u1
            } else {
                u0 + (i + 1) as f64 * du
            },
            v0 + j as f64 * dv,
            if j + 1 == nv {
                v1
            } else {
                v0 + (j + 1) as f64 * dv
            },
        )
    }

    /// Product Gauss–Legendre rule on one cell, and whether the integrand is zero at some
    /// of its nodes and positive at others, or at a 3 × 3 grid of probes on the cell's
    /// corners, edges and centre (inset by 1e-6 of the cell): a support boundary crosses
    /// the cell, even one in a sliver that no node reaches.
    fn cell(&self, f: &dyn Fn(f64, f64) -> f64, ua: f64, ub: f64, va: f64, vb: f64) -> (f64, bool) {
        let (hu, hv) = (0.5 * (ub - ua), 0.5 * (vb - va));
        let (cu, cv) = (0.5 * (ua + ub), 0.5 * (va + vb));
        let (mut zero, mut positive) = (false, false);
        let mut s = 0.0;
        for (xi, wi) in self.nodes.iter().zip(&self.weights) {
            let u = cu + hu * xi;
            let jac = if self.sin_jacobian { u.sin() } else { 1.0 };
            let mut row = 0.0;
            for (xj, wj) in self.nodes.iter().zip(&self.weights) {
                let y = f(u, cv + hv * xj);
                if y > 0.0 {
                    positive = true;
                } else {
                    zero = true;
                }
                row += wj * y;
            }
            s += wi * jac * row;
        }
        let (eu, ev) = (2e-6 * hu, 2e-6 * hv);
        for u in [ua + eu, cu, ub - eu] {
            for v in [va + ev, cv, vb - ev] {
                if f(u, v) > 0.0 {
                    positive = true;
                } else {
                    zero = true;
                }
            }
        }
        (s * hu * hv, zero && positive)
    }

    /// Splits a cell into 4 until the split changes its integral by at most `tol`, up to
    /// [`MAX_DEPTH`] levels; a cell that a support boundary crosses is split down to
    /// [`MIXED_DEPTH`] levels whatever its error estimate says (the estimate cannot see
    /// a boundary that no node straddles).
    fn adaptive(
        &self,
        f: &dyn Fn(f64, f64) -> f64,
        (ua, ub, va, vb): (f64, f64, f64, f64),
        (coarse, mixed): (f64, bool),
        tol: f64,
        depth: u32,
    ) -> f64 {
        let (um, vm) = (0.5 * (ua + ub), 0.5 * (va + vb));
        let kids = [
            (ua, um, va, vm),
            (ua, um, vm, vb),
            (um, ub, va, vm),
            (um, ub, vm, vb),
        ];
        let vals = kids.map(|(a, b, c, d)| self.cell(f, a, b, c, d));
        let fine: f64 = vals.iter().map(|v| v.0).sum();
        let converged = (fine - coarse).abs() <= tol;
        let refine = if mixed {
            depth < MIXED_DEPTH || (!converged && depth < MAX_DEPTH)
        } else {
            !converged && depth < MAX_DEPTH
        };
        if !refine {
            return fine;
        }
        kids.iter()
            .zip(vals)
            .map(|(&k, v)| self.adaptive(f, k, v, 0.5 * tol, depth + 1))
            .sum()
    }

    /// ∫ f over bin `b` (with the Jacobian), each piece between break points refined
    /// until its error estimate is below `tol(its integral)`.
    fn integrate_bin(
        &self,
        b: usize,
        f: &dyn Fn(f64, f64) -> f64,
        tol: &dyn Fn(f64) -> f64,
    ) -> f64 {
        let (ua, ub, va, vb) = self.bounds(b);
        let lo = self.u_breaks.partition_point(|&x| x <= ua);
        let hi = self.u_breaks.partition_point(|&x| x < ub);
        let mut edges = Vec::with_capacity(hi - lo + 2);
        edges.push(ua);
        edges.extend_from_slice(&self.u_breaks[lo..hi]);
        edges.push(ub);
        edges
            .windows(2)
            .map(|w| {
                let coarse = self.cell(f, w[0], w[1], va, vb);
                self.adaptive(f, (w[0], w[1], va, vb), coarse, tol(coarse.0.abs()), 0)
            })
            .sum()
    }
}

// ----------------------------------------------------------------------------------
// Domains
// ----------------------------------------------------------------------------------

/// Directions binned in (θ, φ) about a frame; see the module documentation.
#[derive(Clone, Debug)]
pub struct Spherical {
    s: DVec3,
    t: DVec3,
    n: DVec3,
    pub theta_max: f64,
    pub n_theta: usize,
    pub n_phi: usize,
    breaks: Vec<f64>,
}

impl Spherical {
    /// The whole sphere about `axis`, 24 × 48 bins.
    pub fn sphere(axis: Vec3) -> Spherical {
        Spherical::cone(axis, PI)
    }

    /// The cone θ ≤ `theta_max` (radians) about `axis`, 24 × 48 bins.
    pub fn cone(axis: Vec3, theta_max: f64) -> Spherical {
        let n = axis.as_dvec3().normalize();
        // Duff et al. 2017, "Building an Orthonormal Basis, Revisited", in f64.
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        assert!(theta_max > 0.0 && theta_max <= PI);
        Spherical {
            s,
            t,
            n,
            theta_max,
            n_theta: 24,
            n_phi: 48,
            breaks: Vec::new(),
        }
    }

    pub fn with_resolution(mut self, n_theta: usize, n_phi: usize) -> Spherical {
        self.n_theta = n_theta;
        self.n_phi = n_phi;
        self
    }

    /// Angles θ (radians) at which the density may jump; the quadrature splits there.
    pub fn with_theta_breaks(mut self, breaks: impl IntoIterator<Item = f64>) -> Spherical {
        self.breaks.extend(breaks);
        self
    }

    /// The unit direction at (θ, φ).
    pub fn direction(&self, theta: f64, phi: f64) -> Vec3 {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        (self.s * (st * cp) + self.t * (st * sp) + self.n * ct).as_vec3()
    }

    /// (θ, φ) of a direction (normalised in f64 first), φ in [0, 2π).
    pub fn angles(&self, d: Vec3) -> (f64, f64) {
        let d = d.as_dvec3().normalize();
        let (x, y, z) = (d.dot(self.s), d.dot(self.t), d.dot(self.n));
        let theta = (x * x + y * y).sqrt().atan2(z);
        let mut phi = y.atan2(x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        (theta, phi.min(2.0 * PI))
    }

    fn param(&self) -> Param {
        Param::new(
            (0.0, self.theta_max, self.n_theta),
            (0.0, 2.0 * PI, self.n_phi),
            &self.breaks,
            true,
        )
    }

    fn describe(&self, b: usize) -> String {
        let (ta, tb, pa, pb) = self.param().bounds(b);
        format!(
            "θ ∈ [{:.4}°, {:.4}°), φ ∈ [{:.1}°, {:.1}°)",
            ta.to_degrees(),
            tb.to_degrees(),
            pa.to_degrees(),
            pb.to_degrees()
        )
    }

    /// ∫ f dω over the domain by the same adaptive rule, refined until each bin's error
    /// estimate is below `tol` (absolute).
    pub fn integrate(&self, f: impl Fn(Vec3) -> f64, tol: f64) -> f64 {
        let p = self.param();
        let g = |u: f64, v: f64| f(self.direction(u, v));
        let t = |_: f64| tol;
        (0..p.bins()).map(|b| p.integrate_bin(b, &g, &t)).sum()
    }
}

/// Points of a rectangle binned in x and y.
#[derive(Clone, Debug)]
pub struct Planar {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub nx: usize,
    pub ny: usize,
    breaks: Vec<f64>,
}

impl Planar {
    pub fn new(x: (f64, f64), y: (f64, f64), nx: usize, ny: usize) -> Planar {
        Planar {
            x,
            y,
            nx,
            ny,
            breaks: Vec::new(),
        }
    }

    /// Values of x at which the density may jump.
    pub fn with_x_breaks(mut self, breaks: impl IntoIterator<Item = f64>) -> Planar {
        self.breaks.extend(breaks);
        self
    }

    fn param(&self) -> Param {
        Param::new(
            (self.x.0, self.x.1, self.nx),
            (self.y.0, self.y.1, self.ny),
            &self.breaks,
            false,
        )
    }

    fn describe(&self, b: usize) -> String {
        let (xa, xb, ya, yb) = self.param().bounds(b);
        format!("x ∈ [{xa:.4}, {xb:.4}), y ∈ [{ya:.4}, {yb:.4})")
    }
}

// ----------------------------------------------------------------------------------
// The test
// ----------------------------------------------------------------------------------

/// The result of one chi-square test.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub name: String,
    pub samples: usize,
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// α / (tests in the file).
    pub threshold: f64,
    /// ∫ pdf over the domain.
    pub integral: f64,
    /// Samples the routine did not return.
    pub failed: usize,
    /// Samples outside the domain.
    pub outside: usize,
    /// Samples whose returned pdf differs from the pdf closure.
    pub mismatches: usize,
    /// Reasons to reject other than the p-value.
    pub problems: Vec<String>,
    /// The cells that contribute most to the statistic, for diagnosis.
    pub detail: String,
}

impl Outcome {
    pub fn passed(&self) -> bool {
        self.problems.is_empty() && self.p_value > self.threshold && self.p_value.is_finite()
    }

    pub fn summary(&self) -> String {
        format!(
            "{}: χ² = {:.2}, dof = {}, p = {:.3e} (threshold {:.2e}); N = {}, ∫pdf = {:.6}, \
             failed = {}, outside = {}, pdf mismatches = {}",
            self.name,
            self.statistic,
            self.dof,
            self.p_value,
            self.threshold,
            self.samples,
            self.integral,
            self.failed,
            self.outside,
            self.mismatches
        )
    }

    /// Panics with the full report unless the test passed.
    pub fn assert_passed(&self) {
        assert!(self.passed(), "{}", self.report());
    }

    pub fn report(&self) -> String {
        let mut s = format!("REJECTED {}\n", self.summary());
        for p in &self.problems {
            let _ = writeln!(s, "  problem: {p}");
        }
        s + &self.detail
    }
}

/// Panics listing every outcome that did not pass (after all have run, so that one
/// failure does not hide another).
pub fn assert_all(outcomes: &[Outcome]) {
    for o in outcomes {
        println!("{}", o.summary());
    }
    let failed: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.passed())
        .map(|o| o.report())
        .collect();
    assert!(
        failed.is_empty(),
        "{} of {} chi-square tests failed:\n{}",
        failed.len(),
        outcomes.len(),
        failed.join("\n")
    );
}

/// FNV-1a of the test's name: each test has its own deterministic random stream.
pub fn seed_of(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One chi-square test: its name (which also seeds its random numbers), the number of
/// samples and the number of chi-square tests in its file (Bonferroni).
#[derive(Clone, Debug)]
pub struct Chi2 {
    pub name: String,
    pub samples: usize,
    pub tests_in_file: usize,
    /// Largest fraction of samples allowed to disagree with the pdf closure (0 unless a
    /// test states why).
    pub max_mismatch_fraction: f64,
}

impl Chi2 {
    pub fn new(name: impl Into<String>, samples: usize, tests_in_file: usize) -> Chi2 {
        Chi2 {
            name: name.into(),
            samples,
            tests_in_file,
            max_mismatch_fraction: 0.0,
        }
    }

    pub fn allow_mismatches(mut self, fraction: f64) -> Chi2 {
        self.max_mismatch_fraction = fraction;
        self
    }

    /// Tests a direction sampler (returning the direction and its solid-angle density,
    /// or None) against a solid-angle density.
    pub fn sphere(
        &self,
        domain: &Spherical,
        sample: impl FnMut(&mut Rng) -> Option<(Vec3, f32)>,
        pdf: impl Fn(Vec3) -> f32,
    ) -> Outcome {
        let param = domain.param();
        self.run(
            &param,
            |d: Vec3| {
                let (t, p) = domain.angles(d);
                Some((t, p))
            },
            |u, v| domain.direction(u, v),
            sample,
            pdf,
            |b| domain.describe(b),
        )
    }

    /// Tests a point sampler (returning the point and its area density, or None) against
    /// an area density.
    pub fn plane(
        &self,
        domain: &Planar,
        sample: impl FnMut(&mut Rng) -> Option<(Vec2, f32)>,
        pdf: impl Fn(Vec2) -> f32,
    ) -> Outcome {
        let param = domain.param();
        self.run(
            &param,
            |p: Vec2| Some((p.x as f64, p.y as f64)),
            |u, v| Vec2::new(u as f32, v as f32),
            sample,
            pdf,
            |b| domain.describe(b),
        )
    }

    fn run<P: Copy + std::fmt::Debug>(
        &self,
        param: &Param,
        to_uv: impl Fn(P) -> Option<(f64, f64)>,
        from_uv: impl Fn(f64, f64) -> P,
        mut sample: impl FnMut(&mut Rng) -> Option<(P, f32)>,
        pdf: impl Fn(P) -> f32,
        describe: impl Fn(usize) -> String,
    ) -> Outcome {
        let n = self.samples;
        let mut rng = Rng::new(seed_of(&self.name), 0x5eed);
        let bins = param.bins();
        let mut hist = vec![0.0f64; bins + 1];
        let (mut failed, mut outside, mut mismatches) = (0usize, 0usize, 0usize);
        let mut zero_density = 0usize;
        let mut examples = Vec::new();
        for _ in 0..n {
            let Some((p, ps)) = sample(&mut rng) else {
                failed += 1;
                hist[bins] += 1.0;
                continue;
            };
            let pc = pdf(p);
            let (a, b) = (ps as f64, pc as f64);
            if a == 0.0 && b == 0.0 {
                // A point where the routine and the closure agree the density is zero:
                // the rim of its support (a cosine-weighted direction on the horizon),
                // reached with probability ~2⁻²⁴ per boundary. Left out of the
                // histogram, and must stay that rare.
                zero_density += 1;
                continue;
            }
            let ok = a.is_finite() && a >= 0.0 && (a - b).abs() <= PDF_REL_TOL * a.max(b);
            if !ok {
                mismatches += 1;
                if examples.len() < 6 {
                    examples.push(format!("{p:?}: sampled pdf {ps:e}, pdf() {pc:e}"));
                }
            }
            match to_uv(p).and_then(|(u, v)| param.bin(u, v)) {
                Some(b) => hist[b] += 1.0,
                None => {
                    outside += 1;
                    hist[bins] += 1.0;
                }
            }
        }

        // The samples in the histogram.
        let nf = (n - zero_density) as f64;
        let f = |u: f64, v: f64| pdf(from_uv(u, v)) as f64;
        let tol = |i: f64| 0.01 * (i.max(1.0 / nf) / nf).sqrt();
        let probs: Vec<f64> = (0..bins)
            .map(|b| param.integrate_bin(b, &f, &tol))
            .collect();
        let integral: f64 = probs.iter().sum();
        let mut expected: Vec<f64> = probs.iter().map(|p| p * nf).collect();
        expected.push(nf * (1.0 - integral).max(0.0));

        let mut problems = Vec::new();
        if integral.is_nan() || integral > MAX_INTEGRAL {
            problems.push(format!(
                "the pdf integrates to {integral} > {MAX_INTEGRAL} over the domain"
            ));
        }
        if let Some(b) = probs.iter().position(|&p| p < 0.0) {
            problems.push(format!("negative density in {}", describe(b)));
        }
        if zero_density as f64 > 1e-5 * n as f64 + 2.0 {
            problems.push(format!(
                "{zero_density} of {n} samples have density zero (both returned and pdf())"
            ));
        }
        if mismatches as f64 > self.max_mismatch_fraction * nf {
            problems.push(format!(
                "{mismatches} of {n} samples have a pdf that differs from pdf() by more than \
                 {PDF_REL_TOL} (relative), e.g. {}",
                examples.join("; ")
            ));
        }
        let (statistic, dof, pooled, in_zero) = pearson(&hist, &expected);
        if in_zero > 0.0 {
            problems.push(format!(
                "{in_zero} samples fell in cells whose expected count is zero"
            ));
        }
        if dof < 1 {
            problems.push("fewer than 2 cells after pooling".into());
        }
        let p_value = chi2_p_value(statistic, dof.max(1));

        // The worst cells, for the report.
        let mut contrib: Vec<(f64, usize)> = (0..=bins)
            .map(|b| {
                let (o, e) = (hist[b], expected[b]);
                let c = if e > 0.0 {
                    (o - e).powi(2) / e
                } else if o > 0.0 {
                    f64::INFINITY
                } else {
                    0.0
                };
                (c, b)
            })
            .collect();
        contrib.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut detail =
            format!("  {pooled} cells pooled; worst cells (observed, expected, contribution):\n");
        for &(c, b) in contrib.iter().take(8) {
            let what = if b == bins {
                "no sample / outside the domain".to_string()
            } else {
                describe(b)
            };
            let _ = writeln!(
                detail,
                "    {what}: {:.0}, {:.2}, {c:.2}",
                hist[b], expected[b]
            );
        }
        Outcome {
            name: self.name.clone(),
            samples: n,
            statistic,
            dof,
            p_value,
            threshold: ALPHA / self.tests_in_file as f64,
            integral,
            failed,
            outside,
            mismatches,
            problems,
            detail,
        }
    }
}

/// Chi-square test of discrete choices: `observed[i]` draws of outcome i (`failed`
/// draws returned nothing) against probabilities `probs`.
pub fn discrete(
    name: &str,
    observed: &[u64],
    failed: u64,
    probs: &[f64],
    tests_in_file: usize,
) -> Outcome {
    assert_eq!(observed.len(), probs.len());
    let n: u64 = observed.iter().sum::<u64>() + failed;
    let nf = n as f64;
    let total: f64 = probs.iter().sum();
    let mut obs: Vec<f64> = observed.iter().map(|&o| o as f64).collect();
    obs.push(failed as f64);
    let mut exp: Vec<f64> = probs.iter().map(|p| p * nf).collect();
    exp.push(nf * (1.0 - total).max(0.0));
    let mut problems = Vec::new();
    if total.is_nan() || total > MAX_INTEGRAL {
        problems.push(format!("the probabilities sum to {total}"));
    }
    let (statistic, dof, pooled, in_zero) = pearson(&obs, &exp);
    if in_zero > 0.0 {
        problems.push(format!(
            "{in_zero} draws of outcomes whose probability is zero"
        ));
    }
    if dof < 1 {
        problems.push("fewer than 2 cells after pooling".into());
    }
    let detail = format!(
        "  {pooled} cells pooled; observed {:?}; expected {:?}\n",
        obs,
        exp.iter()
            .map(|e| (e * 10.0).round() / 10.0)
            .collect::<Vec<_>>()
    );
    Outcome {
        name: name.to_string(),
        samples: n as usize,
        statistic,
        dof,
        p_value: chi2_p_value(statistic, dof.max(1)),
        threshold: ALPHA / tests_in_file as f64,
        integral: total,
        failed: failed as usize,
        outside: 0,
        mismatches: 0,
        problems,
        detail,
    }
}
