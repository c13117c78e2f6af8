//! Debye series (src/optics/debye.rs): the terms sum to the Lorenz–Mie coefficients, and
//! p = 2 and p = 3 alone are the primary and secondary bows.
use heron::optics::{debye, mie};
use heron::sky::{airy, descartes, MieSky};
use num_complex::Complex64;
use std::f64::consts::PI;

#[test]
fn debye_terms_sum_to_the_mie_coefficients() {
    for &(m, x) in &[(1.333, 10.0), (1.333, 250.0), (1.5, 57.3), (1.335, 3000.0)] {
        let c = mie::coefficients(m, x);
        let nstop = mie::n_terms(x);
        let f = debye::interfaces(m, x, nstop);
        // Partial waves below the edge (n < x), where |R₁₁| < 1 clearly; the series then
        // converges geometrically and P = 400 terms reach 1e-10.
        for n in [1usize, 2, (x / 3.0) as usize, (0.8 * x) as usize] {
            let n = n.max(1);
            let nf = n as f64;
            let scale = (2.0 * nf + 1.0) / (nf * (nf + 1.0));
            for (pol, want) in [(0usize, c.a[n - 1] / scale), (1, c.b[n - 1] / scale)] {
                let iface = f[n - 1][pol];
                assert!(
                    (iface.total() - want).norm() < 1e-10,
                    "m {m} x {x} n {n} pol {pol}: closed sum {} vs Mie {want}",
                    iface.total()
                );
                let mut sum = Complex64::new(0.0, 0.0);
                for p in 0..=400u32 {
                    sum += iface.term(p);
                }
                assert!(
                    (sum - want).norm() < 1e-10,
                    "m {m} x {x} n {n} pol {pol}: Σ_p≤400 {sum} vs Mie {want} (|R11| {})",
                    iface.r11.norm()
                );
                // Four terms are not enough at this tolerance for b_n (TE), so the check
                // above can fail; for a_n (TM) near Brewster's angle |R₁₁| can be ~1e-4
                // and four terms do reach 1e-11.
                if pol == 0 {
                    continue;
                }
                let mut three = Complex64::new(0.0, 0.0);
                for p in 0..=3u32 {
                    three += iface.term(p);
                }
                assert!(
                    (three - want).norm() > 1e-9,
                    "m {m} x {x} n {n} pol {pol}: {} {}",
                    (three - want).norm(),
                    iface.r11.norm()
                );
            }
        }
    }
}

/// Point-sun Debye-term profile (unpolarised) of a sphere at the antisolar angle θ (deg).
fn term_profile(m: f64, x: f64, p: u32, theta_deg: &[f64]) -> Vec<f64> {
    let c = debye::coefficients(m, x, p);
    theta_deg
        .iter()
        .map(|t| {
            let (s1, s2) = mie::amplitudes(&c, (PI - t.to_radians()).cos());
            heron::sky::mie::phase_value(s1, s2, x, heron::sky::Polarisation::Unpolarised)
        })
        .collect()
}

fn argmax(v: &[f64]) -> usize {
    (0..v.len()).fold(0, |b, i| if v[i] > v[b] { i } else { b })
}

#[test]
fn debye_p2_and_p3_peak_at_airys_bows_for_large_drops() {
    // a = 0.5 mm at 550 nm: x = 5712. Airy's main maximum lies 1.01879 (h/2x²)^{1/3} on the
    // bright side of Descartes' angle; for x ~ 6000 Airy's theory and the exact p = 2 term
    // agree to a small fraction of the peak's width ((h/2x²)^{1/3} ≈ 0.13° here): within
    // 0.02° (the search step is 0.002°).
    let lambda = 550.0f32;
    let sky = MieSky::water(0.5, 0.001f64.to_radians());
    let m = sky.ior.eval(lambda) as f64;
    let x = sky.size_parameter(lambda);
    for (p, k, from, to) in [(2u32, 1u32, 40.0, 43.0), (3, 2, 49.5, 53.0)] {
        let th: Vec<f64> = (0..=((to - from) / 0.002) as usize)
            .map(|i| from + 0.002 * i as f64)
            .collect();
        let prof = term_profile(m, x, p, &th);
        let got = th[argmax(&prof)];
        let b0 = descartes::min_deviation_b(m, k);
        let theta0 = descartes::theta_of_b(b0, m, k).to_degrees();
        let off = airy::main_peak_offset(m, k, x).to_degrees();
        let want = if k == 1 { theta0 - off } else { theta0 + off };
        assert!(
            (got - want).abs() < 0.02,
            "p {p}: peak at {got}°, Airy's main maximum at {want}°"
        );
        if p == 3 {
            assert!((got - 51.0).abs() < 1.0, "secondary at {got}°");
        }
        // The other term is dark there: p = 2 has nothing at the secondary and vice versa
        // (Alexander's band aside, each term is one bow).
        let other = term_profile(m, x, 5 - p, &[got]);
        assert!(
            other[0] < 0.1 * prof[argmax(&prof)],
            "p {}: {} at the p = {p} peak",
            5 - p,
            other[0]
        );
    }
}
