//! Drop-size distributions of water drops, shared by the rainbow skies (`sky::airy`,
//! `sky::mie`) and by media of drops.
//!
//! A distribution is a number density n(a) over the drop radius a (mm). [`DropSizeDistribution::nodes`] turns
//! it into a quadrature: radii a_i and weights w_i, Σ w_i = 1, with
//! Σ w_i f(a_i) ≈ ∫ n(a) f(a) da / ∫ n(a) da over the distribution's stated range.
//! A quantity per drop (a cross-section) averages as Σ w_i f(a_i); the skies weight by
//! the geometric cross-section π a_i² (see `sky::airy`, `sky::mie`).
//!
//! Quadrature: Gauss–Legendre in ln a over a finite interval [ln a_lo, ln a_hi] that
//! covers both the number density and the cross-section-weighted density a² n(a)
//! (which is what the skies integrate), with the weights w_i ∝ n(a_i) a_i ω_i (ω_i the
//! Gauss–Legendre weights, a_i from the change of variable da = a d ln a) normalised to
//! sum 1. In ln a every distribution here is smooth and unimodal, so an n-point rule is
//! exact for the distribution's moments up to the errors of its tails; what limits n is
//! the integrand: a bow's supernumeraries move by ~ (2/3)·z per unit of ln a in Airy's
//! variable z (`sky::airy`), so n must resolve that phase (see `DEFAULT_NODES`).
//!
//! - Monodisperse: one node.
//! - Log-normal (median a_m, σ of ln a): ln a ∈ [ln a_m − 4σ, ln a_m + 2σ² + 4σ], i.e.
//!   ±4σ about the number mode and +4σ above the a²-weighted one (shifted by 2σ²); the
//!   tails left out hold < 7·10⁻⁵ of either.
//! - Gamma (mode a_m, shape μ ≥ 1): n(a) ∝ a^μ e^{−μ a/a_m} (the "modified gamma" of
//!   Deirmendjian 1969 with γ = 1, its mode at a_m). In u = μ a / a_m the density of ln u
//!   is ∝ u^{μ+1} e^{−u}; the interval runs from where the number density in ln u falls
//!   to e^{−18} (1.5·10⁻⁸) of its peak to where the a²-weighted one (u^{μ+3} e^{−u})
//!   does.
//! - Marshall–Palmer (rain rate R, mm/h): N(D) = N₀ e^{−ΛD}, N₀ = 8000 m⁻³ mm⁻¹,
//!   Λ = 4.1 R^{−0.21} mm⁻¹, D = 2a the diameter (Marshall & Palmer 1948, "The
//!   distribution of raindrops with size", J. Meteor. 5, 165). Truncated at
//!   D_max = [`MARSHALL_PALMER_D_MAX_MM`] (6 mm: larger drops break up, Pruppacher & Klett
//!   1997 §10.3) and below at the same e^{−18} of the number density in ln D as for
//!   gamma (the exponential's D → 0 tail carries a vanishing cross-section). The number
//!   density is N₀/Λ (1 − e^{−ΛD_max}) m⁻³.
use std::f64::consts::PI;

/// Largest diameter of the Marshall–Palmer distribution, mm.
pub const MARSHALL_PALMER_D_MAX_MM: f64 = 6.0;
/// Marshall & Palmer's intercept N₀ (0.08 cm⁻⁴), per m³ per mm of diameter.
pub const MARSHALL_PALMER_N0: f64 = 8000.0;
/// Nodes used when a scene or the CLI does not say: see [`DropSizeDistribution::nodes`].
/// With σ = 0.3 the log-normal's interval spans 2.6 in ln a, over which the first
/// supernumeraries (Airy z ≲ 8, where dz/d ln a = 2z/3) move by up to ≈ 14 in z, about
/// ten fringes of Ai²; 48 Gauss–Legendre nodes give about five nodes per fringe, and
/// doubling them changes the point-sun Airy profile by < 1% of its peak (measured:
/// 0.014%; 8 nodes: 22%) (`tests/drops.rs`).
pub const DEFAULT_NODES: usize = 48;
/// Nodes of the `mie` sky when the scene or the CLI does not say: each node costs one
/// Mie series per wavelength (a 0.5 mm drop's table for a scene takes tens of seconds),
/// so the Mie sky settles for 16: with the solar disk and σ = 0.2 the supernumeraries
/// are then within 1% of the peak of 96 nodes (`tests/drops.rs`, on the Airy profile of
/// the same drops); ask for more with `nodes`.
pub const MIE_DEFAULT_NODES: usize = 16;
/// Most nodes accepted from a scene or the CLI.
pub const MAX_NODES: usize = 1024;

/// A drop-size distribution (radii in mm).
#[derive(Clone, Debug, PartialEq)]
pub enum DropSizeDistribution {
    /// Every drop of radius `radius_mm`.
    Monodisperse { radius_mm: f64 },
    /// ln a normally distributed: median radius `median_mm`, standard deviation `sigma`
    /// of ln a.
    LogNormal { median_mm: f64, sigma: f64 },
    /// n(a) ∝ a^μ e^{−μ a / a_m}: mode radius `mode_mm` (a_m), shape `mu` (μ ≥ 1).
    Gamma { mode_mm: f64, mu: f64 },
    /// Marshall & Palmer (1948) for rain rate `rain_rate_mm_h`, D ≤ 6 mm.
    MarshallPalmer { rain_rate_mm_h: f64 },
}

/// One quadrature node: a radius and its fraction of the number density (Σ = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DropNode {
    pub radius_mm: f64,
    pub weight: f64,
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n from the Chebyshev
/// guesses cos(π(i − ¼)/(n + ½)); Abramowitz & Stegun 25.4.29), to ~1e-15.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 1..=n {
        let mut z = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0f64, z);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            // P_n = p1, P_{n−1} = p0; P_n′ = n (z P_n − P_{n−1}) / (z² − 1).
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        out.push((z, 2.0 / ((1.0 - z * z) * dp * dp)));
    }
    out.reverse();
    out
}

/// ln-density maximum shift: the interval in ln u where k ln u − u lies within `depth`
/// of its maximum (at u = k), by bisection on each side.
fn ln_gamma_interval(k_lo: f64, k_hi: f64, depth: f64) -> (f64, f64) {
    let f = |k: f64, v: f64| k * v - v.exp() - (k * k.ln() - k);
    let solve = |k: f64, mut inside: f64, mut outside: f64| {
        for _ in 0..200 {
            let mid = 0.5 * (inside + outside);
            if f(k, mid) > -depth {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        0.5 * (inside + outside)
    };
    let lo = solve(k_lo, k_lo.ln(), k_lo.ln() - 200.0);
    let hi = solve(k_hi, k_hi.ln(), k_hi.ln() + 10.0);
    (lo, hi)
}

impl DropSizeDistribution {
    /// Checks the parameters (finite, positive, μ ≥ 1, σ ≤ 1, radii ≤ 10 mm); the error
    /// names each key as `name` gives it (`prefix.key` in a scene, the flag on the CLI).
    pub fn validate_named(&self, name: &dyn Fn(&str) -> String) -> Result<(), String> {
        let pos = |key: &str, v: f64, max: f64| -> Result<(), String> {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err(format!(
                    "{}: expected a number in (0, {max}], got {v}",
                    name(key)
                ))
            }
        };
        match *self {
            DropSizeDistribution::Monodisperse { radius_mm } => pos("radius_mm", radius_mm, 10.0),
            DropSizeDistribution::LogNormal { median_mm, sigma } => {
                pos("median_mm", median_mm, 10.0)?;
                pos("sigma", sigma, 1.0)
            }
            DropSizeDistribution::Gamma { mode_mm, mu } => {
                pos("mode_mm", mode_mm, 10.0)?;
                if !(mu.is_finite() && (1.0..=1000.0).contains(&mu)) {
                    return Err(format!(
                        "{}: expected a shape in [1, 1000], got {mu}",
                        name("mu")
                    ));
                }
                Ok(())
            }
            DropSizeDistribution::MarshallPalmer { rain_rate_mm_h } => {
                pos("rain_rate_mm_h", rain_rate_mm_h, 500.0)
            }
        }
    }

    /// Marshall–Palmer slope Λ = 4.1 R^{−0.21} mm⁻¹ (of the diameter).
    pub fn marshall_palmer_lambda(rain_rate_mm_h: f64) -> f64 {
        4.1 * rain_rate_mm_h.powf(-0.21)
    }

    /// The quadrature's interval in ln a (a in mm) and the number density's logarithm in
    /// ln a up to a constant, or None for one radius.
    fn ln_interval(&self) -> Option<(f64, f64)> {
        match *self {
            DropSizeDistribution::Monodisperse { .. } => None,
            DropSizeDistribution::LogNormal { median_mm, sigma } => {
                let m = median_mm.ln();
                Some((m - 4.0 * sigma, m + 2.0 * sigma * sigma + 4.0 * sigma))
            }
            DropSizeDistribution::Gamma { mode_mm, mu } => {
                let (lo, hi) = ln_gamma_interval(mu + 1.0, mu + 3.0, 18.0);
                let s = (mode_mm / mu).ln();
                Some((lo + s, hi + s))
            }
            DropSizeDistribution::MarshallPalmer { rain_rate_mm_h } => {
                // In u = Λ D: number density in ln u ∝ u e^{−u}; a²-weighted ∝ u³ e^{−u}.
                let l = Self::marshall_palmer_lambda(rain_rate_mm_h);
                let (lo, hi) = ln_gamma_interval(1.0, 3.0, 18.0);
                let s = (0.5 / l).ln(); // a = D/2 = u / (2Λ)
                let hi = (hi + s).min((0.5 * MARSHALL_PALMER_D_MAX_MM).ln());
                Some((lo + s, hi))
            }
        }
    }

    /// ln of the number density per unit ln a, up to a constant (a in mm).
    fn ln_density_ln_a(&self, a: f64) -> f64 {
        match *self {
            DropSizeDistribution::Monodisperse { .. } => 0.0,
            DropSizeDistribution::LogNormal { median_mm, sigma } => {
                let t = (a / median_mm).ln() / sigma;
                -0.5 * t * t
            }
            DropSizeDistribution::Gamma { mode_mm, mu } => (mu + 1.0) * a.ln() - mu * a / mode_mm,
            DropSizeDistribution::MarshallPalmer { rain_rate_mm_h } => {
                a.ln() - Self::marshall_palmer_lambda(rain_rate_mm_h) * 2.0 * a
            }
        }
    }

    /// The quadrature: `n` Gauss–Legendre nodes in ln a (one node for monodisperse),
    /// weights the fraction of the number density, Σ = 1 (see the module documentation).
    pub fn nodes(&self, n: usize) -> Vec<DropNode> {
        let Some((lo, hi)) = self.ln_interval() else {
            let DropSizeDistribution::Monodisperse { radius_mm } = *self else {
                unreachable!("only the monodisperse distribution has no interval")
            };
            return vec![DropNode {
                radius_mm,
                weight: 1.0,
            }];
        };
        let n = n.max(1);
        let gl = gauss_legendre(n);
        let (c, h) = (0.5 * (hi + lo), 0.5 * (hi - lo));
        // ω_i exp(ln density − its largest value): no distribution underflows.
        let pts: Vec<(f64, f64, f64)> = gl
            .iter()
            .map(|&(t, w)| {
                let a = (c + h * t).exp();
                (a, w, self.ln_density_ln_a(a))
            })
            .collect();
        let max = pts
            .iter()
            .map(|&(_, _, l)| l)
            .fold(f64::NEG_INFINITY, f64::max);
        let raw: Vec<(f64, f64)> = pts
            .iter()
            .map(|&(a, w, l)| (a, w * (l - max).exp()))
            .collect();
        let sum: f64 = raw.iter().map(|&(_, w)| w).sum();
        raw.into_iter()
            .map(|(radius_mm, w)| DropNode {
                radius_mm,
                weight: w / sum,
            })
            .collect()
    }

    /// Number of drops per m³, where the distribution defines one (Marshall–Palmer:
    /// N₀/Λ (1 − e^{−ΛD_max})); the others are shapes only and a medium gives the
    /// density (or the liquid water content) itself.
    pub fn number_density(&self) -> Option<f64> {
        match *self {
            DropSizeDistribution::MarshallPalmer { rain_rate_mm_h } => {
                let l = Self::marshall_palmer_lambda(rain_rate_mm_h);
                Some(MARSHALL_PALMER_N0 / l * (1.0 - (-l * MARSHALL_PALMER_D_MAX_MM).exp()))
            }
            _ => None,
        }
    }

    /// The mean of a^k (mm^k) over the number density by the quadrature with `n` nodes,
    /// e.g. k = 2 for the mean geometric cross-section / π, k = 3 for the liquid water
    /// content per drop / (4π/3).
    pub fn mean_radius_power(&self, k: i32, n: usize) -> f64 {
        self.nodes(n)
            .iter()
            .map(|d| d.weight * d.radius_mm.powi(k))
            .sum()
    }

    /// The nodes reweighted by the geometric cross-section, Σ = 1: the weights with which
    /// per-drop profiles normalised by π a² average into the distribution's profile
    /// ⟨dσ/dΩ⟩ / ⟨π a²⟩ (the skies' normalisation).
    pub fn cross_section_nodes(&self, n: usize) -> Vec<DropNode> {
        let nodes = self.nodes(n);
        let s: f64 = nodes.iter().map(|d| d.weight * d.radius_mm.powi(2)).sum();
        nodes
            .into_iter()
            .map(|d| DropNode {
                radius_mm: d.radius_mm,
                weight: d.weight * d.radius_mm.powi(2) / s,
            })
            .collect()
    }

    /// The largest radius the quadrature uses, mm.
    pub fn max_radius_mm(&self) -> f64 {
        match self.ln_interval() {
            None => match *self {
                DropSizeDistribution::Monodisperse { radius_mm } => radius_mm,
                _ => unreachable!(),
            },
            Some((_, hi)) => hi.exp(),
        }
    }
}

/// A drop-size distribution as a scene table, e.g.
/// `drops = { distribution = "lognormal", median_mm = 0.5, sigma = 0.1 }` (in `[sky]`,
/// and in a medium). Keys by distribution:
///
/// | distribution | keys |
/// | --- | --- |
/// | `monodisperse` | `radius_mm` |
/// | `lognormal` | `median_mm`, `sigma` (of ln a) |
/// | `gamma` | `mode_mm`, `mu` (≥ 1) |
/// | `marshall-palmer` | `rain_rate_mm_h` |
///
/// and, for all but monodisperse, `nodes` (quadrature nodes, default
/// [`DEFAULT_NODES`], at most [`MAX_NODES`]).
#[derive(Clone, Debug, Default, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DropsFile {
    pub distribution: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub median_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rain_rate_mm_h: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodes: Option<i64>,
}

/// The weighted mean radius of `nodes` in nm: for cross-section nodes, the radius the
/// `airy` and `mie` skies report and size their tables by.
pub fn mean_radius_nm(nodes: &[DropNode]) -> f64 {
    1e6 * nodes.iter().map(|d| d.weight * d.radius_mm).sum::<f64>()
}

/// The distribution names [`DropsFile::distribution`] accepts.
pub const DISTRIBUTION_NAMES: [&str; 4] = ["monodisperse", "lognormal", "gamma", "marshall-palmer"];

impl DropsFile {
    /// The distribution and its node count; errors are one line naming `prefix.key`
    /// (e.g. `sky.drops.sigma`).
    pub fn parse(&self, prefix: &str) -> Result<(DropSizeDistribution, usize), String> {
        self.parse_named(&|k| format!("{prefix}.{k}"))
    }

    /// As [`DropsFile::parse`], with the name of each key in errors given by `name` (the
    /// CLI names its flags).
    pub fn parse_named(
        &self,
        name: &dyn Fn(&str) -> String,
    ) -> Result<(DropSizeDistribution, usize), String> {
        let keys: [(&str, Option<f64>); 6] = [
            ("radius_mm", self.radius_mm),
            ("median_mm", self.median_mm),
            ("sigma", self.sigma),
            ("mode_mm", self.mode_mm),
            ("mu", self.mu),
            ("rain_rate_mm_h", self.rain_rate_mm_h),
        ];
        let d = self.distribution.as_str();
        let wants: &[&str] = match d {
            "monodisperse" => &["radius_mm"],
            "lognormal" | "log-normal" => &["median_mm", "sigma"],
            "gamma" => &["mode_mm", "mu"],
            "marshall-palmer" | "marshall_palmer" => &["rain_rate_mm_h"],
            other => {
                return Err(format!(
                    "{}: expected one of {}, got {other:?}",
                    name("distribution"),
                    DISTRIBUTION_NAMES.join(", ")
                ))
            }
        };
        for (k, v) in keys {
            if v.is_some() && !wants.contains(&k) {
                return Err(format!(
                    "{}: does not apply to the {d} distribution (it takes {})",
                    name(k),
                    wants.iter().map(|k| name(k)).collect::<Vec<_>>().join(", ")
                ));
            }
        }
        let get = |k: &str| -> Result<f64, String> {
            keys.iter()
                .find(|(name, _)| *name == k)
                .and_then(|(_, v)| *v)
                .ok_or_else(|| format!("{}: the {d} distribution needs it", name(k)))
        };
        let dist = match wants[0] {
            "radius_mm" => DropSizeDistribution::Monodisperse {
                radius_mm: get("radius_mm")?,
            },
            "median_mm" => DropSizeDistribution::LogNormal {
                median_mm: get("median_mm")?,
                sigma: get("sigma")?,
            },
            "mode_mm" => DropSizeDistribution::Gamma {
                mode_mm: get("mode_mm")?,
                mu: get("mu")?,
            },
            _ => DropSizeDistribution::MarshallPalmer {
                rain_rate_mm_h: get("rain_rate_mm_h")?,
            },
        };
        dist.validate_named(name)?;
        let nodes = match self.nodes {
            None => DEFAULT_NODES,
            Some(_) if matches!(dist, DropSizeDistribution::Monodisperse { .. }) => {
                return Err(format!(
                    "{}: does not apply to the monodisperse distribution",
                    name("nodes")
                ))
            }
            Some(n) if (1..=MAX_NODES as i64).contains(&n) => n as usize,
            Some(n) => {
                return Err(format!(
                    "{}: expected a count in 1..={MAX_NODES}, got {n}",
                    name("nodes")
                ))
            }
        };
        Ok((dist, nodes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in [1usize, 2, 5, 16, 48, 200] {
            let q = gauss_legendre(n);
            assert_eq!(q.len(), n);
            for k in 0..(2 * n).min(40) {
                let got: f64 = q.iter().map(|&(t, w)| w * t.powi(k as i32)).sum();
                let want = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k as f64 + 1.0)
                };
                assert!((got - want).abs() < 1e-13, "n {n} k {k}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn moments_match_the_closed_forms() {
        // Log-normal: ⟨a^k⟩ = a_m^k e^{k²σ²/2}.
        let d = DropSizeDistribution::LogNormal {
            median_mm: 0.5,
            sigma: 0.3,
        };
        for k in [1, 2, 3] {
            let want = 0.5f64.powi(k) * (0.5 * (k * k) as f64 * 0.09).exp();
            let got = d.mean_radius_power(k, 48);
            assert!((got / want - 1.0).abs() < 2e-4, "k {k}: {got} vs {want}");
        }
        // Gamma a^μ e^{−μa/a_m}: ⟨a^k⟩ = (a_m/μ)^k Γ(μ+1+k)/Γ(μ+1).
        let d = DropSizeDistribution::Gamma {
            mode_mm: 0.2,
            mu: 4.0,
        };
        let want2 = (0.2f64 / 4.0).powi(2) * 5.0 * 6.0;
        assert!((d.mean_radius_power(2, 48) / want2 - 1.0).abs() < 1e-6);
        // Marshall–Palmer, untruncated moments: ⟨D^k⟩ = k!/Λ^k; at 1 mm/h the 6 mm cut
        // removes e^{−24.6}, far below the check.
        let r = 1.0;
        let l = DropSizeDistribution::marshall_palmer_lambda(r);
        let d = DropSizeDistribution::MarshallPalmer { rain_rate_mm_h: r };
        let want2 = 2.0 / (l * l) / 4.0; // ⟨a²⟩ = ⟨D²⟩/4
        assert!((d.mean_radius_power(2, 48) / want2 - 1.0).abs() < 1e-6);
        let n = d.number_density().unwrap();
        assert!((n - 8000.0 / l).abs() < 1e-6 * n);
    }

    #[test]
    fn weights_sum_to_one_and_monodisperse_is_one_node() {
        let m = DropSizeDistribution::Monodisperse { radius_mm: 0.3 };
        assert_eq!(
            m.nodes(48),
            vec![DropNode {
                radius_mm: 0.3,
                weight: 1.0
            }]
        );
        let d = DropSizeDistribution::MarshallPalmer {
            rain_rate_mm_h: 50.0,
        };
        let nodes = d.nodes(32);
        assert!((nodes.iter().map(|n| n.weight).sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(d.max_radius_mm() <= 3.0 + 1e-12);
    }

    #[test]
    fn scene_tables_parse_with_errors_naming_the_key() {
        let t = |s: &str| -> Result<(DropSizeDistribution, usize), String> {
            let f: DropsFile = toml::from_str(s).map_err(|e| e.to_string())?;
            f.parse("sky.drops")
        };
        assert_eq!(
            t("distribution = \"lognormal\"\nmedian_mm = 0.5\nsigma = 0.1").unwrap(),
            (
                DropSizeDistribution::LogNormal {
                    median_mm: 0.5,
                    sigma: 0.1
                },
                DEFAULT_NODES
            )
        );
        for (s, key) in [
            (
                "distribution = \"lognormal\"\nmedian_mm = 0.5",
                "sky.drops.sigma:",
            ),
            (
                "distribution = \"gamma\"\nmode_mm = 0.5\nmu = 0.5",
                "sky.drops.mu:",
            ),
            ("distribution = \"cauchy\"", "sky.drops.distribution:"),
            (
                "distribution = \"monodisperse\"\nradius_mm = -1",
                "sky.drops.radius_mm:",
            ),
            (
                "distribution = \"monodisperse\"\nradius_mm = 1\nsigma = 1",
                "sky.drops.sigma:",
            ),
            (
                "distribution = \"marshall-palmer\"\nrain_rate_mm_h = 5\nnodes = 0",
                "sky.drops.nodes:",
            ),
        ] {
            let e = t(s).unwrap_err();
            assert!(e.starts_with(key) && !e.contains('\n'), "{s}: {e}");
        }
    }
}
