//! Chi-square tests of every warp in `heron::math::warp` and of `Distribution1D`
//! (tests/common/chi2.rs), the power heuristic's properties, and self-tests of the
//! chi-square helper (its special functions, and that it rejects wrong densities).
//!
//! Sample counts: 10⁶ per test. With cells pooled to expected counts ≥ 5 and a
//! Bonferroni threshold of 0.01/11 ≈ 9e-4, a density that is wrong by a relative ε over
//! a region holding a fraction q of the mass raises χ² by about N q ε², which must
//! exceed ~3.1 √(2 dof) ≈ 140 for ~1000 cells: ε ≈ 4% over q = 0.1 is seen, or 1% over
//! the whole domain.
mod common;

use common::chi2::{
    self, assert_all, chi2_p_value, discrete, gauss_legendre, ln_gamma, Chi2, Outcome, Planar,
    Spherical,
};
use glam::{Vec2, Vec3};
use heron::math::warp::{
    concentric_disk, cosine_hemisphere, cosine_hemisphere_pdf, equal_area_sphere_to_square,
    equal_area_square_to_sphere, power_heuristic, uniform_cone, uniform_cone_pdf, uniform_sphere,
    uniform_triangle, UNIFORM_SPHERE_PDF,
};
use heron::math::{Distribution1D, Rng};
use std::f64::consts::PI;

/// Chi-square tests in this file (the Bonferroni divisor): the sum over the test
/// functions, each of which checks its own count.
const CHI2_TESTS: usize = 2 + CONE_TESTS + 2 + DISTRIBUTION_TESTS + 2;
const CONE_TESTS: usize = 2;
const DISTRIBUTION_TESTS: usize = 5;
const N: usize = 1_000_000;

fn u2(rng: &mut Rng) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

fn cone_tests() -> Vec<Outcome> {
    let mut out = Vec::new();
    // 30°: a cone domain slightly wider than the cone, split at its rim.
    let a30 = 30f64.to_radians();
    let omc30 = (1.0 - a30.cos()) as f32;
    let dom = Spherical::cone(Vec3::Z, 1.1 * a30).with_theta_breaks([a30]);
    let exact = 1.0 / (2.0 * PI * (1.0 - a30.cos()));
    out.push(Chi2::new("uniform_cone 30°", N, CHI2_TESTS).sphere(
        &dom,
        |r| Some((uniform_cone(u2(r), omc30), uniform_cone_pdf(omc30))),
        |d| {
            let (t, _) = dom.angles(d);
            if t <= a30 * (1.0 + 1e-6) {
                exact as f32
            } else {
                0.0
            }
        },
    ));
    // The sun's 0.2666°: 1 − cos α kept as 2 sin²(α/2) (the form `uniform_cone` asks for),
    // and a domain that is the cone itself (24 × 48 bins of 0.011° × 7.5°). The rim is
    // widened by 1e-6 (relative) so that f32 rounding of a direction drawn at u = 1 − 2⁻²⁴
    // stays inside.
    let sun = 0.2666f64.to_radians();
    let omc = 2.0 * (0.5 * sun).sin().powi(2);
    let dom = Spherical::cone(Vec3::Z, sun * (1.0 + 1e-6));
    out.push(Chi2::new("uniform_cone sun", N, CHI2_TESTS).sphere(
        &dom,
        |r| {
            Some((
                uniform_cone(u2(r), omc as f32),
                uniform_cone_pdf(omc as f32),
            ))
        },
        |d| {
            let (t, _) = dom.angles(d);
            if t <= sun * (1.0 + 1e-6) {
                (1.0 / (2.0 * PI * omc)) as f32
            } else {
                0.0
            }
        },
    ));
    out
}

#[test]
fn chi2_cosine_hemisphere_and_uniform_sphere() {
    let dom = Spherical::sphere(Vec3::Z);
    let a = Chi2::new("cosine_hemisphere", N, CHI2_TESTS).sphere(
        &dom,
        |r| {
            let d = cosine_hemisphere(u2(r));
            assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0, "{d}");
            Some((d, cosine_hemisphere_pdf(d.z)))
        },
        |d| (d.z.max(0.0) as f64 / PI) as f32,
    );
    let b = Chi2::new("uniform_sphere", N, CHI2_TESTS).sphere(
        &Spherical::sphere(Vec3::new(0.3, -0.5, 0.81)),
        |r| {
            let d = uniform_sphere(u2(r));
            assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
            Some((d, UNIFORM_SPHERE_PDF))
        },
        |_| (0.25 / PI) as f32,
    );
    assert!((UNIFORM_SPHERE_PDF as f64 * 4.0 * PI - 1.0).abs() < 1e-7);
    assert_all(&[a, b]);
}

#[test]
fn chi2_uniform_cone_wide_and_the_sun() {
    let o = cone_tests();
    assert_eq!(o.len(), CONE_TESTS);
    assert_all(&o);
}

/// The concentric map is area preserving: points uniform on the unit disk (density 1/π),
/// histogrammed on a 16 × 16 grid over [−1, 1]².
fn disk_test() -> Outcome {
    Chi2::new("concentric_disk", N, CHI2_TESTS).plane(
        &Planar::new((-1.0, 1.0), (-1.0, 1.0), 16, 16),
        |r| Some((concentric_disk(u2(r)), (1.0 / PI) as f32)),
        // The rim is included to f32 precision (u = 0 maps onto it exactly).
        |p| {
            if p.length_squared() <= 1.0 + 1e-6 {
                (1.0 / PI) as f32
            } else {
                0.0
            }
        },
    )
}

/// Barycentrics (b0, b1) uniform over the triangle b0, b1 ≥ 0, b0 + b1 ≤ 1 (density 2):
/// uniform barycentrics are uniform points on every triangle (the map is affine).
fn triangle_test() -> Outcome {
    Chi2::new("uniform_triangle", N, CHI2_TESTS).plane(
        &Planar::new((0.0, 1.0), (0.0, 1.0), 16, 16),
        |r| {
            let b = uniform_triangle(u2(r));
            assert!(b.iter().all(|&x| x >= -1e-7), "{b:?}");
            assert!((b[0] + b[1] + b[2] - 1.0).abs() < 1e-6, "{b:?}");
            Some((Vec2::new(b[0], b[1]), 2.0))
        },
        |p| {
            if p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0 + 1e-6 {
                2.0
            } else {
                0.0
            }
        },
    )
}

#[test]
fn chi2_concentric_disk_and_uniform_triangle() {
    assert_all(&[disk_test(), triangle_test()]);
}

/// The density of a piecewise-constant function on [0, 1), written independently of
/// `Distribution1D`: f(⌊x n⌋) / mean(f).
fn step_pdf(f: &[f32], x: f64) -> f64 {
    let n = f.len();
    let mean: f64 = f.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    let i = ((x * n as f64) as usize).min(n - 1);
    f[i] as f64 / mean
}

/// `sample_continuous` against the step density, histogrammed over [0, 1) in `bins`
/// bins (a planar domain one bin high), with break points at the function's steps.
fn continuous_test(name: &str, f: &[f32], bins: usize) -> Outcome {
    let d = Distribution1D::new(f);
    let n = f.len();
    let dom = Planar::new((0.0, 1.0), (0.0, 1.0), bins, 1)
        .with_x_breaks((1..n).map(|k| k as f64 / n as f64));
    Chi2::new(name, N, CHI2_TESTS).plane(
        &dom,
        |r| {
            let (x, pdf, i) = d.sample_continuous(r.uniform());
            assert!(f[i] > 0.0, "{name}: an empty bin {i} was sampled");
            assert!((0.0..=1.0).contains(&x), "{name}: x = {x}");
            Some((Vec2::new(x, 0.5), pdf))
        },
        |p| step_pdf(f, p.x as f64) as f32,
    )
}

/// `sample_discrete` frequencies against f(i)/Σf; the returned probability must be the
/// pmf.
fn discrete_test(name: &str, f: &[f32]) -> Outcome {
    let d = Distribution1D::new(f);
    let total: f64 = f.iter().map(|&v| v as f64).sum();
    let probs: Vec<f64> = f.iter().map(|&v| v as f64 / total).collect();
    let mut counts = vec![0u64; f.len()];
    let mut rng = Rng::new(chi2::seed_of(name), 1);
    for _ in 0..N {
        let (i, p, t) = d.sample_discrete(rng.uniform());
        assert!(
            (p as f64 - probs[i]).abs() <= 1e-5 * probs[i] + 1e-7,
            "{name}: p = {p}"
        );
        assert!((p - d.pmf(i)).abs() <= 1e-7);
        assert!((0.0..1.0).contains(&t));
        counts[i] += 1;
    }
    for (i, &p) in probs.iter().enumerate() {
        assert!(
            (d.pmf(i) as f64 - p).abs() <= 1e-5 * p + 1e-7,
            "{name}: pmf({i})"
        );
    }
    discrete(name, &counts, 0, &probs, CHI2_TESTS)
}

/// A function of `n` values with some empty bins, from a fixed stream.
fn random_function(n: usize, seed: u64) -> Vec<f32> {
    let mut r = Rng::new(seed, 7);
    (0..n)
        .map(|_| {
            let u = r.uniform();
            if u < 0.15 {
                0.0
            } else {
                u * u * 10.0
            }
        })
        .collect()
}

fn distribution_tests() -> Vec<Outcome> {
    let small = [0.5f32, 2.0, 0.0, 1.5, 4.0, 0.0, 0.1, 3.0];
    let big = random_function(1000, 3);
    vec![
        // 40 histogram bins: 5 per step of the function.
        continuous_test("Distribution1D continuous, aligned", &small, 40),
        // 37 bins: steps inside histogram bins (the quadrature splits at them).
        continuous_test("Distribution1D continuous, 37 bins", &small, 37),
        continuous_test("Distribution1D continuous, 1000 steps", &big, 50),
        discrete_test("Distribution1D discrete, 8", &small),
        discrete_test("Distribution1D discrete, 1000", &big),
    ]
}

#[test]
fn chi2_distribution1d() {
    let o = distribution_tests();
    assert_eq!(o.len(), DISTRIBUTION_TESTS);
    assert_all(&o);
}

/// A sample of `sample_continuous` lies in the bin it reports and its pdf is the one
/// `pdf(x)` gives, for every u: checked on a dense grid of u (every 2⁻²⁴ near the top
/// of each bin, where (i + t)/n rounds).
#[test]
fn distribution1d_samples_lie_in_their_bin_and_agree_with_pdf() {
    let f = random_function(1000, 3);
    let d = Distribution1D::new(&f);
    let n = f.len();
    let mut bad = Vec::new();
    let mut checked = 0usize;
    for (i, &fi) in f.iter().enumerate() {
        if fi == 0.0 {
            continue;
        }
        // The top of bin i in u: just below the CDF's next edge.
        let c1 = (0..=i).map(|k| d.pmf(k)).sum::<f32>();
        let mut u = c1;
        for _ in 0..64 {
            u = f32::from_bits(u.to_bits() - 1);
            let (x, pdf, j) = d.sample_continuous(u);
            if j != i {
                continue;
            }
            checked += 1;
            // ⌊x n⌋ exactly (in f64), the bin x lies in.
            let in_bin = (x as f64 * n as f64) as usize == i && x < 1.0;
            if !in_bin || (pdf - d.pdf(x)).abs() > 1e-3 * pdf {
                bad.push((i, u, x, pdf, d.pdf(x)));
            }
        }
    }
    assert!(checked > 10_000, "{checked}");
    assert!(
        bad.is_empty(),
        "{} of {checked} samples near the top of their bin are reported in bin i but lie at \
         x with ⌊x n⌋ ≠ i, where pdf(x) is the next bin's; e.g. (i, u, x, pdf, pdf(x)) = {:?}",
        bad.len(),
        &bad[..bad.len().min(4)]
    );
}

#[test]
fn power_heuristic_properties_over_realistic_densities() {
    // pdfs between 1e-6 and 1e6 (a sun cone gives 1.5e4, a GGX lobe at α = 1e-3 about
    // 1e5–1e8 at grazing angles; see the f32-range test below for the extremes).
    let mut rng = Rng::new(5, 5);
    let logu = |r: &mut Rng| 10f32.powf(12.0 * r.uniform() - 6.0);
    for _ in 0..100_000 {
        let (p, q) = (logu(&mut rng), logu(&mut rng));
        let (w, v) = (power_heuristic(p, q), power_heuristic(q, p));
        // Veach 1997 eq. 9.13 with β = 2.
        let exact = (p as f64).powi(2) / ((p as f64).powi(2) + (q as f64).powi(2));
        assert!(
            (w as f64 - exact).abs() <= 1e-6,
            "w({p}, {q}) = {w} vs {exact}"
        );
        assert!((0.0..=1.0).contains(&w));
        // The weights of the two strategies partition unity (unbiased MIS).
        assert!(
            (w + v - 1.0).abs() <= 1e-6,
            "w({p},{q}) + w({q},{p}) = {}",
            w + v
        );
        // Invariant under a common scale of the densities.
        let k = 10f32.powf(4.0 * rng.uniform() - 2.0);
        assert!((power_heuristic(k * p, k * q) - w).abs() <= 1e-5);
        // Increasing in its own density.
        let w2 = power_heuristic(1.5 * p, q);
        assert!(w2 >= w, "{w2} < {w}");
    }
    for &p in &[1e-6f32, 0.3, 1.0, 7.0, 1e6] {
        assert!((power_heuristic(p, p) - 0.5).abs() < 1e-7);
        assert_eq!(power_heuristic(p, 0.0), 1.0);
        assert_eq!(power_heuristic(0.0, p), 0.0);
        assert_eq!(power_heuristic(f32::INFINITY, p), 1.0);
        assert_eq!(power_heuristic(p, f32::INFINITY), 0.0);
    }
    assert_eq!(power_heuristic(0.0, 0.0), 0.0);
}

/// The partition of unity w(p, q) + w(q, p) = 1 must hold for every pair of finite,
/// positive f32 densities; squaring in f32 overflows above ~1.8e19 (both weights become
/// 1) and underflows below ~4e-23 (both become 0).
#[test]
fn power_heuristic_weights_sum_to_one_for_every_finite_density() {
    let mut bad = Vec::new();
    for &p in &[1e-30f32, 1e-25, 1e-22, 1e-10, 1.0, 1e10, 1e19, 1e20, 1e30] {
        for &k in &[1.0f32, 2.0, 0.5] {
            let q = p * k;
            let s = power_heuristic(p, q) + power_heuristic(q, p);
            if (s - 1.0).abs() > 1e-6 {
                bad.push((p, q, s));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "w(p, q) + w(q, p) ≠ 1 for (p, q, sum) = {bad:?}"
    );
}

// ----------------------------------------------------------------------------------
// The helper itself
// ----------------------------------------------------------------------------------

#[test]
fn chi2_helper_special_functions() {
    // ln Γ at known points.
    assert!(ln_gamma(1.0).abs() < 1e-13);
    assert!(ln_gamma(2.0).abs() < 1e-13);
    assert!((ln_gamma(0.5) - 0.5 * PI.ln()).abs() < 1e-13);
    assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    assert!((ln_gamma(0.1) - 2.252_712_651_734_206).abs() < 1e-12);
    // For even dof the tail is a finite sum: Q(k, x) = e^(−x) Σ_{j<k} x^j/j!.
    for &dof in &[2usize, 4, 10, 46, 100, 1000] {
        for &r in &[0.3f64, 0.8, 1.0, 1.2, 2.0] {
            let stat = r * dof as f64;
            let (k, x) = (dof / 2, stat / 2.0);
            let (mut term, mut sum) = (1.0f64, 0.0f64);
            for j in 0..k {
                if j > 0 {
                    term *= x / j as f64;
                }
                sum += term;
            }
            // Sum in log space for large k.
            let exact = if k < 200 {
                (-x).exp() * sum
            } else {
                let mut lt = 0.0f64;
                let mut acc = f64::NEG_INFINITY;
                for j in 0..k {
                    if j > 0 {
                        lt += (x / j as f64).ln();
                    }
                    let m = acc.max(lt);
                    acc = m + ((acc - m).exp() + (lt - m).exp()).ln();
                }
                (acc - x).exp()
            };
            let p = chi2_p_value(stat, dof);
            assert!(
                (p - exact).abs() <= 1e-10 + 1e-8 * exact,
                "dof {dof}, χ² {stat}: {p} vs {exact}"
            );
        }
    }
    // dof = 1: the 95th percentile is 3.841458820694124.
    assert!((chi2_p_value(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-9);
    // Gauss–Legendre with 8 nodes integrates x^14 exactly.
    let (x, w) = gauss_legendre(8);
    let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(14)).sum();
    assert!((s - 2.0 / 15.0).abs() < 1e-14);
}

/// The helper must reject what is wrong: a density that is not the sampler's, a
/// sampler that loses samples its density claims, and a sample whose pdf disagrees
/// with pdf().
#[test]
fn chi2_helper_rejects_wrong_densities() {
    let dom = Spherical::sphere(Vec3::Z);
    // Cosine-weighted samples against a uniform hemisphere.
    let o = Chi2::new("wrong density", 200_000, 1).sphere(
        &dom,
        |r| Some((cosine_hemisphere(u2(r)), (0.5 / PI) as f32)),
        |d| if d.z > 0.0 { (0.5 / PI) as f32 } else { 0.0 },
    );
    assert!(!o.passed() && o.p_value < 1e-10, "{}", o.summary());
    // 1% of the samples lost while the density claims all of them.
    let o = Chi2::new("lost samples", 200_000, 1).sphere(
        &dom,
        |r| {
            if r.uniform() < 0.01 {
                return None;
            }
            let d = cosine_hemisphere(u2(r));
            Some((d, cosine_hemisphere_pdf(d.z)))
        },
        |d| cosine_hemisphere_pdf(d.z),
    );
    assert!(!o.passed(), "{}", o.summary());
    // A correct histogram with a returned pdf 1% off.
    let o = Chi2::new("pdf mismatch", 100_000, 1).sphere(
        &dom,
        |r| {
            let d = cosine_hemisphere(u2(r));
            Some((d, 1.01 * cosine_hemisphere_pdf(d.z)))
        },
        |d| cosine_hemisphere_pdf(d.z),
    );
    assert!(!o.passed() && o.mismatches > 90_000, "{}", o.summary());
    // And the same helper accepts the right answer for that case.
    let o = Chi2::new("right density", 200_000, 1).sphere(
        &dom,
        |r| {
            let d = cosine_hemisphere(u2(r));
            Some((d, cosine_hemisphere_pdf(d.z)))
        },
        |d| cosine_hemisphere_pdf(d.z),
    );
    o.assert_passed();
    // Integration: ∫ cos θ/π over the sphere is 1.
    let i = dom.integrate(|d| d.z.max(0.0) as f64 / PI, 1e-9);
    assert!((i - 1.0).abs() < 1e-6, "{i}");
}

/// Clarberg's equal-area map (pbrt-v4's environment-map layout): uniform on the square is
/// uniform on the sphere, and the inverse takes every direction back to its point.
#[test]
fn chi2_equal_area_square_to_sphere_and_its_inverse() {
    let mut worst = 0.0f32;
    let o = Chi2::new("equal_area_square_to_sphere", N, CHI2_TESTS).sphere(
        &Spherical::sphere(Vec3::new(0.2, 0.7, -0.4)),
        |r| {
            let u = u2(r);
            let d = equal_area_square_to_sphere(u);
            assert!((d.length() - 1.0).abs() < 1e-5, "{u} -> {d}");
            worst = worst.max((equal_area_sphere_to_square(d) - u).abs().max_element());
            Some((d, UNIFORM_SPHERE_PDF))
        },
        |_| (0.25 / PI) as f32,
    );
    o.assert_passed();
    assert!(worst < 2e-5, "round trip off by {worst}");
    // The layout pbrt-v4 documents: the centre is +z, the corners −z, the edges' middles
    // the equator.
    assert!((equal_area_square_to_sphere(Vec2::splat(0.5)) - Vec3::Z).length() < 1e-6);
    assert!((equal_area_square_to_sphere(Vec2::ZERO) + Vec3::Z).length() < 1e-6);
    assert!(equal_area_square_to_sphere(Vec2::new(1.0, 0.5)).z.abs() < 1e-6);
}

/// An environment map's importance sampling (src/light/envmap.rs, latlong): texels of a
/// ramp with a 40× bright spot, 16 × 9 (8 rows of cells, whose θ edges are the
/// quadrature's breaks), against the density the light reports.
#[test]
fn chi2_environment_map_latlong() {
    use heron::light::{EnvMap, EnvMapping};
    let (w, h) = (16usize, 9usize);
    let rgb: Vec<[f32; 3]> = (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            let b = if (i, j) == (5, 3) { 40.0 } else { 1.0 };
            [
                b * (0.2 + i as f32 / w as f32),
                b * (0.1 + j as f32 / h as f32),
                0.3 * b,
            ]
        })
        .collect();
    let m = EnvMap::new(EnvMapping::LatLong, w, h, &rgb, 1.0, glam::Mat3::IDENTITY);
    let dom = Spherical::sphere(Vec3::Y)
        .with_resolution(32, 64)
        .with_theta_breaks((1..h - 1).map(|j| PI * j as f64 / (h - 1) as f64));
    let o = Chi2::new("envmap latlong", N, CHI2_TESTS).sphere(
        &dom,
        |r| {
            let (d, pdf) = m.sample(u2(r));
            (pdf > 0.0).then_some((d, pdf))
        },
        |d| m.pdf(d),
    );
    o.assert_passed();
}
