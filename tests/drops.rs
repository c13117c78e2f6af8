//! Drop-size distributions in the rainbow skies (heron::drops, sky::airy, sky::mie): a
//! narrow log-normal is the monodisperse sky, a broad one washes out the supernumeraries,
//! the quadrature has converged at the default node count, and the CLI and scene tables
//! take distributions with one-line errors.
mod common;

use common::cli::heron_words;
use heron::drops::{DropSizeDistribution, DEFAULT_NODES};
use heron::sky::{AirySky, MieSky};

const SUN: f64 = 0.2666;

fn lognormal(median_mm: f64, sigma: f64) -> DropSizeDistribution {
    DropSizeDistribution::LogNormal { median_mm, sigma }
}

/// Primary-bow profile (k = 1) on θ = from, from + step, …, to (degrees).
fn profile(f: impl Fn(f64) -> f64, from: f64, to: f64, step: f64) -> (Vec<f64>, Vec<f64>) {
    let n = ((to - from) / step).round() as usize;
    let th: Vec<f64> = (0..=n).map(|i| from + step * i as f64).collect();
    let v = th.iter().map(|t| f(t.to_radians())).collect();
    (th, v)
}

/// Supernumerary contrast of a primary-bow profile sampled with θ increasing: from the
/// main maximum (the largest value) inward (decreasing θ), the first local minimum and
/// then the next local maximum (the first supernumerary); contrast = max / min, or 1 when
/// the profile falls or rises monotonically inward (no supernumerary left).
fn supernumerary_contrast(v: &[f64]) -> f64 {
    let main = (0..v.len()).fold(0, |b, i| if v[i] > v[b] { i } else { b });
    let mut i = main;
    while i > 0 && v[i - 1] <= v[i] {
        i -= 1;
    }
    if i == 0 {
        return 1.0;
    }
    let min = v[i];
    while i > 0 && v[i - 1] >= v[i] {
        i -= 1;
    }
    if i == 0 {
        return 1.0;
    }
    v[i] / min
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn airy(dsd: Option<&DropSizeDistribution>, radius_mm: f64, nodes: usize) -> AirySky {
    let mut s = AirySky::water(radius_mm, SUN.to_radians());
    s.orders = vec![1];
    match dsd {
        Some(d) => s.with_distribution(d, nodes),
        None => s,
    }
}

#[test]
fn airy_narrow_lognormal_is_monodisperse_and_broad_washes_out_supernumeraries() {
    let lambda = 550.0f32;
    let range = (39.0, 42.5, 0.01);
    for a in [0.2, 0.5] {
        let mono = airy(None, a, 1);
        let (_, pm) = profile(
            |t| mono.profile(t, lambda) as f64,
            range.0,
            range.1,
            range.2,
        );
        let peak = pm.iter().cloned().fold(0.0, f64::max);
        // σ = 0.001: radii within ±0.4% of a; the fringes move by (2/3)·0.004·z ≲ 0.03 in
        // Airy's z, so the profile agrees to 1e-3 of the peak.
        let narrow = airy(Some(&lognormal(a, 0.001)), a, DEFAULT_NODES);
        let (_, pn) = profile(
            |t| narrow.profile(t, lambda) as f64,
            range.0,
            range.1,
            range.2,
        );
        let d = max_abs_diff(&pm, &pn);
        assert!(d < 1e-3 * peak, "a {a}: narrow vs mono {d} (peak {peak})");
        // σ = 0.25: ln a spreads by ±0.25, the first supernumerary (z ≈ 3.25) by ±0.54 in
        // z, a quarter of its distance to the main maximum: the dip between them fills.
        let c_mono = supernumerary_contrast(&pm);
        let broad = airy(Some(&lognormal(a, 0.25)), a, DEFAULT_NODES);
        let (_, pb) = profile(
            |t| broad.profile(t, lambda) as f64,
            range.0,
            range.1,
            range.2,
        );
        let c_broad = supernumerary_contrast(&pb);
        eprintln!("airy a {a}: contrast mono {c_mono:.4}, σ 0.25 {c_broad:.4}");
        assert!(c_mono > 1.3, "a {a}: monodisperse contrast {c_mono}");
        assert!(
            c_broad - 1.0 < 0.25 * (c_mono - 1.0),
            "a {a}: contrast {c_broad} with σ 0.25 against {c_mono} for one radius"
        );
    }
}

#[test]
fn airy_quadrature_has_converged_at_the_default_node_count() {
    // The broadest case the default is sized for (σ = 0.3), point-like sun so nothing else
    // smooths the fringes: doubling the nodes changes the profile by < 1% of its peak.
    let lambda = 450.0f32;
    let d = lognormal(0.5, 0.3);
    let mk = |n| {
        let mut s = AirySky::water(0.5, 0.01f64.to_radians()).with_distribution(&d, n);
        s.orders = vec![1];
        s
    };
    let (a, b, c) = (mk(DEFAULT_NODES), mk(2 * DEFAULT_NODES), mk(8));
    let (_, pa) = profile(|t| a.profile(t, lambda) as f64, 39.0, 42.5, 0.01);
    let (_, pb) = profile(|t| b.profile(t, lambda) as f64, 39.0, 42.5, 0.01);
    let (_, pc) = profile(|t| c.profile(t, lambda) as f64, 39.0, 42.5, 0.01);
    let peak = pb.iter().cloned().fold(0.0, f64::max);
    let d_default = max_abs_diff(&pa, &pb);
    let d_few = max_abs_diff(&pc, &pb);
    eprintln!(
        "nodes {DEFAULT_NODES} vs {}: {d_default:.3e}; 8: {d_few:.3e}; peak {peak:.3e}",
        2 * DEFAULT_NODES
    );
    assert!(d_default < 0.01 * peak, "{d_default} against peak {peak}");
    // Too few nodes leave spurious fringes: the check resolves them.
    assert!(d_few > 0.02 * peak, "{d_few} against peak {peak}");
    // The mie sky's default (16 nodes), with the real sun and σ = 0.2: within 1% of the
    // peak of 96 nodes, shown on the Airy profile of the same drops (the supernumeraries
    // are what the nodes must resolve; Mie's finer ripple is left to the disk, see
    // heron::sky::MieSky).
    let mk = |n| {
        let mut s =
            AirySky::water(0.5, SUN.to_radians()).with_distribution(&lognormal(0.5, 0.2), n);
        s.orders = vec![1];
        s
    };
    let (m16, m96) = (mk(heron::drops::MIE_DEFAULT_NODES), mk(96));
    let (_, p16) = profile(|t| m16.profile(t, lambda) as f64, 39.0, 42.5, 0.01);
    let (_, p96) = profile(|t| m96.profile(t, lambda) as f64, 39.0, 42.5, 0.01);
    let peak = p96.iter().cloned().fold(0.0, f64::max);
    let d16 = max_abs_diff(&p16, &p96);
    eprintln!("σ 0.2, real sun: 16 nodes vs 96: {d16:.3e}, peak {peak:.3e}");
    assert!(d16 < 0.01 * peak, "{d16} against peak {peak}");
}

#[test]
fn mie_narrow_lognormal_is_monodisperse_and_broad_washes_out_supernumeraries() {
    // a = 0.2 mm (x = 2285 at 550 nm): one Mie series per node, 48 nodes a few seconds.
    let lambda = 550.0f32;
    let a = 0.2;
    let mono = MieSky::water(a, SUN.to_radians());
    let (_, pm) = profile(|t| mono.profile(t, lambda) as f64, 38.0, 42.5, 0.01);
    let peak = pm.iter().cloned().fold(0.0, f64::max);
    // Mie's fine ripple (the external reflection interfering with the bow rays) has a
    // phase ∝ x, so a width σ moves it by ~4σx radians across the nodes: σ = 0.001 (4σx ≈
    // 9) already averages it (the profiles then differ by 2.6% of the peak, all ripple; at σ = 1e-5, by 0.9%, from the θ grid, which follows the largest node), and
    // convergence to one radius needs σ ≪ 1/x: σ = 1e-5.
    let narrow = MieSky::water(a, SUN.to_radians()).with_distribution(&lognormal(a, 1e-5), 16);
    let (_, pn) = profile(|t| narrow.profile(t, lambda) as f64, 38.0, 42.5, 0.01);
    let d = max_abs_diff(&pm, &pn);
    eprintln!("mie narrow vs mono: {d:.3e} (peak {peak:.3e})");
    assert!(d < 0.01 * peak, "narrow vs mono {d} (peak {peak})");
    let broad =
        MieSky::water(a, SUN.to_radians()).with_distribution(&lognormal(a, 0.25), DEFAULT_NODES);
    let (_, pb) = profile(|t| broad.profile(t, lambda) as f64, 38.0, 42.5, 0.01);
    let (c_mono, c_broad) = (supernumerary_contrast(&pm), supernumerary_contrast(&pb));
    eprintln!("mie a {a}: contrast mono {c_mono:.4}, σ 0.25 {c_broad:.4}");
    assert!(c_mono > 1.3, "monodisperse contrast {c_mono}");
    assert!(
        c_broad - 1.0 < 0.25 * (c_mono - 1.0),
        "contrast {c_broad} with σ 0.25 against {c_mono} for one radius"
    );
}

#[test]
fn every_distribution_gives_a_primary_bow_near_descartes() {
    // Gamma and Marshall–Palmer through the Airy sky: a bow between 40° and 42.5° whose
    // peak is within the spread of Airy's main maximum over the distribution's radii.
    for d in [
        DropSizeDistribution::Gamma {
            mode_mm: 0.3,
            mu: 6.0,
        },
        DropSizeDistribution::MarshallPalmer {
            rain_rate_mm_h: 5.0,
        },
    ] {
        let s = airy(Some(&d), 1.0, DEFAULT_NODES);
        let (th, v) = profile(|t| s.profile(t, 600.0) as f64, 39.0, 43.0, 0.01);
        let i = (0..v.len()).fold(0, |b, i| if v[i] > v[b] { i } else { b });
        assert!((41.0..42.4).contains(&th[i]), "{d:?}: peak at {}", th[i]);
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0));
    }
}

#[test]
fn sky_profile_takes_a_distribution_and_debye_terms() {
    let base = "sky profile --lambda 550 --from 40 --to 42 --step 0.5";
    let out = heron_words(&format!(
        "{base} --model airy --k 1 --distribution lognormal --median-mm 0.5 --sigma 0.1"
    ));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let want = airy(Some(&lognormal(0.5, 0.1)), 1.0, DEFAULT_NODES);
    for line in text.lines().skip(1) {
        let mut f = line.split(',').map(|s| s.parse::<f64>().unwrap());
        let (t, v) = (f.next().unwrap(), f.next().unwrap());
        let w = want.profile(t.to_radians(), 550.0) as f64;
        assert!((v - w).abs() <= 1e-6 * w, "θ {t}: {v} vs {w}");
    }
    let out = heron_words(&format!(
        "{base} --model mie --droplet-radius 0.05 --debye 2"
    ));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (args, needle) in [
        (
            "--model airy --distribution lognormal --median-mm 0.5",
            "--sigma:",
        ),
        (
            "--model airy --distribution lognormal --median-mm 0.5 --sigma 0",
            "--sigma:",
        ),
        ("--model airy --distribution weibull", "--distribution:"),
        (
            "--model airy --sigma 0.1 --droplet-radius 1",
            "--sigma: needs --distribution",
        ),
        (
            "--model airy --distribution gamma --mode-mm 0.3 --mu 6 --sigma 1",
            "--sigma: does not apply",
        ),
        (
            "--model airy --distribution monodisperse",
            "--droplet-radius:",
        ),
        (
            "--model airy --distribution lognormal --median-mm 0.5 --sigma 0.1 --nodes 0",
            "--nodes:",
        ),
        (
            "--model airy --distribution lognormal --median-mm 0.5 --sigma 0.1 --droplet-radius 1",
            "--droplet-radius:",
        ),
        (
            "--model mie --distribution marshall-palmer --rain-rate-mm-h 5",
            "--distribution: the mie sky takes radii up to 2 mm",
        ),
        (
            "--model descartes --distribution lognormal --median-mm 0.5 --sigma 0.1",
            "--distribution: applies to airy and mie",
        ),
        (
            "--model airy --droplet-radius 0.5 --debye 2",
            "--debye: applies to mie",
        ),
        ("--model mie --droplet-radius 0.5 --debye 99", "--debye:"),
    ] {
        let out = heron_words(&format!("{base} {args}"));
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args}: {err}");
        assert!(out.stdout.is_empty(), "{args}");
        assert!(
            err.contains(needle) && err.trim().lines().count() == 1,
            "{args}: {err}"
        );
    }
}
