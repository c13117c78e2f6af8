//! A homogeneous medium of water drops whose coefficients and phase function come from
//! heron's own Lorenz–Mie code ([`crate::optics::mie`], BHMIE with a complex index),
//! tabulated once per scene.
//!
//! Bulk coefficients of a population (Frisvad, Christensen & Jensen 2007, "Computing the
//! scattering properties of participating media using Lorenz–Mie theory", ACM TOG 26(3),
//! eqs. 7–9, for a non-absorbing host): with N(r) the number density of radius r,
//! σ_t = ∫ C_ext(r) N(r) dr, σ_s = ∫ C_sca(r) N(r) dr, and the phase function
//! p(θ) = ∫ (|S₁|² + |S₂|²)/2 N(r) dr / (k² σ_s), k = 2π/λ (in the host), normalised to 1
//! over the sphere. Here the population is a list of nodes (radius, number density),
//! [`PopulationNode`], a quadrature of N(r) that a drop-size distribution provides.
//!
//! For each wavelength node λ (every `lambda_step` nm from 360 nm to past 830 nm) and
//! each node (r, N) of the drop population:
//!
//! - the relative index m(λ) = n(λ) + i k(λ): n from heron's catalogue `water`
//!   (Daimon & Masumura 2007), k from Hale & Querry (1973), `spectra/water_k_hale_querry1973.csv`,
//!   linear in λ between its 25 nm rows (k = 0 when absorption is switched off, for the
//!   energy checks);
//! - x = 2πr/λ, BHMIE with complex m → C_ext = Q_ext πr², C_sca = Q_sca πr²,
//!   σ_t = Σ N C_ext, σ_s = Σ N C_sca (Frisvad et al. 2007, eqs. 7–8);
//! - the phase function p(θ) = Σ N (|S₁|² + |S₂|²)/2 / (k² σ_s) (their eq. 9) on the
//!   angle grid of `phase_table` for the largest size parameter.
//!
//! σ_t and σ_s are then linear in λ between nodes (as 1 nm tables, so a lane costs a
//! lookup), the phase function is the nodes' mixture (`phase_table`).
//!
//! **The phase matrix**, for polarised transport: a sphere's Mueller matrix of
//! scattering, written in the frame x̂ perpendicular to the scattering plane for both
//! beams (Collett's convention, `optics::mueller`; Bohren & Huffman 1983, eq. 4.77 with
//! their parallel and perpendicular axes swapped, which flips the sign of S12), is
//!
//!   F11  F12   0    0
//!   F12  F11   0    0
//!    0    0   F33  F34
//!    0    0  −F34  F33
//!
//! with F11 = (|S₁|² + |S₂|²)/2, F12 = (|S₁|² − |S₂|²)/2, F33 = Re(S₁S₂*), F34 =
//! −Im(S₁S₂*) (Bohren & Huffman's S34, in their e^{−iωt} amplitudes): the matrix of a
//! reflection with S₁ in the place of r_s and S₂ of r_p (`optics::mueller`, whose
//! retardance takes the same conjugate for Collett's sign of S3; so
//! backscattering, S₁ = −S₂, is a mirror's diag(1, 1, −1, −1), and the primary bow,
//! |S₁| > |S₂|, polarises along x̂, tangentially). Each is summed over the population
//! as F11 is, and the table keeps (F12, F33, F34)/F11 per bin and node
//! (`PhaseTable::with_matrix`); truncation's cone has p = 0 and nothing to polarise.
//!
//! Optional truncation of the diffraction peak (`forward_cutoff_deg` > 0; off by
//! default): the fraction f of the phase function within the cutoff angle θ_c of the
//! forward direction is counted as unscattered light, the delta-M idea (Wiscombe 1977,
//! J. Atmos. Sci. 34, 1408): σ_s' = (1 − f) σ_s, σ_t' = σ_t − f σ_s, p' = p/(1 − f) for
//! θ ≥ θ_c and 0 inside, so σ_s' p' = σ_s p at every angle outside the cone. Light
//! diffracted by less than θ_c then travels straight on, and next-event estimation
//! accounts for it through the transmittance, instead of through the rare paths whose
//! second scattering points into the sun within the peak (the sparkles of multiple
//! scattering through rain). Angles below θ_c lose their detail (the sun's aureole).
//!
//! Units: radii and lengths in metres; number densities per cubic metre; σ in m⁻¹. A
//! scene with a Lorenz–Mie medium is therefore in metres.
use super::phase_table::{angle_grid, PhaseTable};
use crate::optics::mie::{amplitudes, sphere};
use crate::spectrum::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

const WATER_K_CSV: &str = include_str!("../../spectra/water_k_hale_querry1973.csv");

/// Water's imaginary index k at `lambda_nm` (Hale & Querry 1973, linear between rows).
pub fn water_k(lambda_nm: f64) -> f64 {
    let rows: Vec<(f64, f64)> = WATER_K_CSV
        .lines()
        .skip(1)
        .filter_map(|l| {
            let (a, b) = l.split_once(',')?;
            Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
        })
        .collect();
    let i = rows.partition_point(|r| r.0 <= lambda_nm);
    if i == 0 {
        return rows[0].1;
    }
    if i >= rows.len() {
        return rows[rows.len() - 1].1;
    }
    let (a, b) = (rows[i - 1], rows[i]);
    a.1 + (lambda_nm - a.0) / (b.0 - a.0) * (b.1 - a.1)
}

/// The delta-M truncation of the module docs on one node: zeroes p at the θ edges below
/// the cutoff and returns (σ_t', σ_s') with f the mass removed, measured with the same
/// trapezoid rule in v that `PhaseTable` integrates with (the bin straddling θ_c keeps
/// half of its outer edge's value, and f counts exactly what was removed).
fn truncate(theta: &[f64], p: &mut [f64], st: f64, ss: f64, cutoff_deg: f64) -> (f64, f64) {
    if cutoff_deg <= 0.0 {
        return (st, ss);
    }
    let v: Vec<f64> = theta
        .iter()
        .map(|&t| super::phase_table::v_of_theta(t))
        .collect();
    let mass = |p: &[f64]| -> f64 {
        (0..theta.len() - 1)
            .map(|j| 0.5 * (p[j] + p[j + 1]) * 2.0 * PI * (v[j + 1] - v[j]))
            .sum()
    };
    let before = mass(p);
    let k = theta.partition_point(|&t| t < cutoff_deg.to_radians());
    for pe in p.iter_mut().take(k) {
        *pe = 0.0;
    }
    let f = 1.0 - mass(p) / before;
    (st - f * ss, ss * (1.0 - f))
}

/// One node of a drop population: a radius and the number of drops per unit volume
/// that it stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PopulationNode {
    /// Radius in metres.
    pub radius_m: f64,
    /// Drops per cubic metre.
    pub number_density: f64,
}

/// What a Lorenz–Mie medium is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct MieSpec {
    /// The drop population (radii in m, number densities in m⁻³).
    pub population: Vec<PopulationNode>,
    /// Water's absorption (its imaginary index); off makes σ_s = σ_t.
    pub absorption: bool,
    /// Spacing of the wavelength nodes, nm.
    pub lambda_step_nm: f32,
    /// Scattering within this angle (degrees) of forward counts as unscattered (0: off).
    pub forward_cutoff_deg: f64,
}

/// A homogeneous Lorenz–Mie medium, tabulated.
pub struct LorenzMieMedium {
    pub spec: MieSpec,
    /// Extinction and scattering coefficients, m⁻¹.
    pub sigma_t: DenseSpectrum,
    pub sigma_s: DenseSpectrum,
    pub phase: PhaseTable,
    /// Number of θ edges of the phase table.
    pub angles: usize,
}

impl std::fmt::Debug for LorenzMieMedium {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LorenzMieMedium")
            .field("spec", &self.spec)
            .field("angles", &self.angles)
            .finish()
    }
}

impl LorenzMieMedium {
    /// Tabulates the medium (seconds for rain-sized drops; see the module docs).
    pub fn new(spec: MieSpec) -> LorenzMieMedium {
        let ior = crate::spectrum::ior::named("water").expect("water in the catalogue");
        let step = spec.lambda_step_nm as f64;
        let count = ((LAMBDA_MAX - LAMBDA_MIN) as f64 / step).ceil() as usize + 1;
        let lambdas: Vec<f64> = (0..count)
            .map(|i| LAMBDA_MIN as f64 + i as f64 * step)
            .collect();
        let r_max = spec
            .population
            .iter()
            .map(|n| n.radius_m)
            .fold(0.0, f64::max);
        let x_max = 2.0 * PI * r_max / (LAMBDA_MIN as f64 * 1e-9);
        let theta = angle_grid(x_max);
        let mu: Vec<f64> = theta.iter().map(|t| t.cos()).collect();
        // Per node: (σ_t, σ_s, unnormalised p at the θ edges, and F12, F33, F34 there).
        #[allow(clippy::type_complexity)]
        let per_node: Vec<(f64, f64, Vec<f64>, Vec<[f64; 3]>)> = lambdas
            .par_iter()
            .map(|&lambda_nm| {
                let lambda_m = lambda_nm * 1e-9;
                let k_wave = 2.0 * PI / lambda_m;
                let n = ior.eval(lambda_nm as f32) as f64;
                let k = if spec.absorption {
                    water_k(lambda_nm)
                } else {
                    0.0
                };
                let m = Complex64::new(n, k);
                let (mut st, mut ss) = (0.0f64, 0.0f64);
                let mut p = vec![0.0f64; theta.len()];
                let mut f = vec![[0.0f64; 3]; theta.len()];
                for node in &spec.population {
                    let x = k_wave * node.radius_m;
                    let s = sphere(m, x);
                    let geo = PI * node.radius_m * node.radius_m;
                    st += node.number_density * s.q_ext * geo;
                    ss += node.number_density * s.q_sca * geo;
                    let w = node.number_density / (k_wave * k_wave);
                    for ((pe, fe), &mu) in p.iter_mut().zip(f.iter_mut()).zip(&mu) {
                        let (s1, s2) = amplitudes(&s.coefficients, mu);
                        *pe += w * 0.5 * (s1.norm_sqr() + s2.norm_sqr());
                        // The phase matrix in the frame x̂ ⊥ the scattering plane
                        // (module docs): S1 plays Fresnel's r_s, S2 its r_p.
                        let c = s1.conj() * s2;
                        fe[0] += w * 0.5 * (s1.norm_sqr() - s2.norm_sqr());
                        fe[1] += w * c.re;
                        fe[2] += w * c.im;
                    }
                }
                for pe in p.iter_mut() {
                    *pe /= ss;
                }
                for fe in f.iter_mut() {
                    for c in fe.iter_mut() {
                        *c /= ss;
                    }
                }
                let (st, ss) = truncate(&theta, &mut p, st, ss, spec.forward_cutoff_deg);
                (st, ss, p, f)
            })
            .collect();
        let node_spectrum = |f: &dyn Fn(usize) -> f64| {
            DenseSpectrum::from_fn(|l| {
                let s = ((l as f64 - LAMBDA_MIN as f64) / step).max(0.0);
                let i = (s as usize).min(count - 1);
                if i + 1 >= count {
                    return f(count - 1) as f32;
                }
                let t = s - i as f64;
                (f(i) * (1.0 - t) + f(i + 1) * t) as f32
            })
        };
        let sigma_t = node_spectrum(&|i| per_node[i].0);
        let sigma_s = node_spectrum(&|i| per_node[i].1);
        let (values, matrix): (Vec<Vec<f64>>, Vec<Vec<[f64; 3]>>) =
            per_node.into_iter().map(|n| (n.2, n.3)).unzip();
        let phase = PhaseTable::from_values(LAMBDA_MIN, spec.lambda_step_nm, &theta, &values)
            .with_matrix(&values, &matrix);
        LorenzMieMedium {
            spec,
            sigma_t,
            sigma_s,
            phase,
            angles: theta.len(),
        }
    }
}

/// `heron sky mie-matrix` (hidden, for `tests/python/test_mie.py`): the phase table of a
/// medium of one drop radius `radius_um` (μm; 1 drop per m³) at the wavelength node
/// `lambda_nm` (a multiple of 10 nm from 360 nm: the table's nodes at `lambda_step_nm`
/// = 10), without absorption unless `absorption`. Prints the relative index and size
/// parameter, then one row per bin: `theta0_deg,theta1_deg,p,f12,f33,f34`, p the bin's
/// phase function (sr⁻¹) and f_ij = F_ij/F11 its shape (module docs).
pub fn matrix_csv(radius_um: f64, lambda_nm: f64, absorption: bool) -> crate::Result<String> {
    use std::fmt::Write as _;
    let bad = |m: String| crate::HeronError::Invalid(m);
    if !(radius_um.is_finite() && radius_um > 0.0 && radius_um <= 100.0) {
        return Err(bad(format!(
            "--radius-um: expected a radius in (0, 100] μm, got {radius_um}"
        )));
    }
    let node = (lambda_nm - LAMBDA_MIN as f64) / 10.0;
    if !(lambda_nm.is_finite()
        && node >= 0.0
        && node.fract() == 0.0
        && lambda_nm <= LAMBDA_MAX as f64)
    {
        return Err(bad(format!(
            "--lambda: expected a wavelength node, 360 to 830 nm in steps of 10, got {lambda_nm}"
        )));
    }
    let m = LorenzMieMedium::new(MieSpec {
        population: vec![PopulationNode {
            radius_m: radius_um * 1e-6,
            number_density: 1.0,
        }],
        absorption,
        lambda_step_nm: 10.0,
        forward_cutoff_deg: 0.0,
    });
    let n = crate::spectrum::ior::named("water")
        .expect("water in the catalogue")
        .eval(lambda_nm as f32) as f64;
    let k = if absorption { water_k(lambda_nm) } else { 0.0 };
    let x = 2.0 * PI * radius_um * 1e-6 / (lambda_nm * 1e-9);
    let mut out = format!("# m_re={n:.17e},m_im={k:.17e},x={x:.17e}\n");
    out.push_str("theta0_deg,theta1_deg,p,f12,f33,f34\n");
    // The table's θ edges in f64 (the same grid `new` built), not its f32 v.
    let theta = angle_grid(2.0 * PI * radius_um * 1e-6 / (LAMBDA_MIN as f64 * 1e-9));
    let rows = m.phase.rows(node as usize);
    debug_assert_eq!(rows.len() + 1, theta.len());
    for ((p, f), t) in rows.into_iter().zip(theta.windows(2)) {
        let (t0, t1) = (t[0].to_degrees(), t[1].to_degrees());
        writeln!(
            out,
            "{t0:.17e},{t1:.17e},{p:.9e},{:.9e},{:.9e},{:.9e}",
            f[0], f[1], f[2]
        )
        .unwrap();
    }
    Ok(out)
}
