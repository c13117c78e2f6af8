//! `heron sky lee` (src/sky/lee.rs): the colour sums, the bow's hue order, the fogbow's
//! whiteness, determinism across thread counts, and one-line errors.
mod common;

use common::cli::heron_words_threads;
use heron::sky::MieSky;
use heron::spectrum::cie;

/// Rows (radius, θ, X, Y, Z) of a `heron sky lee` CSV.
fn rows(text: &str) -> Vec<[f64; 5]> {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("radius_mm,theta_deg,X,Y,Z,R,G,B"));
    lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            assert_eq!(f.len(), 8);
            assert!(f[5..].iter().all(|c| (0.0..=1.0).contains(c)), "{l}");
            [f[0], f[1], f[2], f[3], f[4]]
        })
        .collect()
}

#[test]
fn lee_colours_are_the_mie_profiles_under_d65() {
    // Two radii, λ every 50 nm (380…780: 9 wavelengths), a few angles: seconds.
    let args = "sky lee --radius-from 0.01 --radius-to 1 --radii 2 --from 40 --to 42.5 --step 0.5 --lambda-step 50";
    let a = heron_words_threads(args, 1);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = heron_words_threads(args, 2);
    assert_eq!(a.stdout, b.stdout, "output depends on the thread count");
    let r = rows(&String::from_utf8(a.stdout).unwrap());
    assert_eq!(r.len(), 2 * 6);
    // Y = Σ p(θ, λ) D65(λ) ȳ(λ) / Σ D65(λ) ȳ(λ), with p from the mie sky itself.
    let lambdas: Vec<f32> = (0..9).map(|i| 380.0 + 50.0 * i as f32).collect();
    let (obs, d65) = (cie::cie1931(), cie::d65_relative());
    let w: Vec<f64> = lambdas
        .iter()
        .map(|&l| d65.eval(l) as f64 * obs.y.eval(l) as f64)
        .collect();
    let norm: f64 = w.iter().sum();
    for &[radius, theta, _, y, _] in &[r[3], r[10]] {
        let mut sky = MieSky::water(radius, 0.2666f64.to_radians());
        sky.window = (
            (40f64 - 0.2666 - 0.5).to_radians(),
            (42.5f64 + 0.2666 + 0.5).to_radians(),
        );
        sky.window_only = true;
        let want: f64 = lambdas
            .iter()
            .zip(&w)
            .map(|(&l, &wl)| wl * sky.profile(theta.to_radians(), l) as f64)
            .sum::<f64>()
            / norm;
        assert!(
            (y - want).abs() <= 2e-6 * want,
            "a {radius} θ {theta}: Y {y} vs {want}"
        );
    }
}

/// CIE 1931 chromaticity (x, y).
fn xy(c: &[f64; 5]) -> (f64, f64) {
    let s = c[2] + c[3] + c[4];
    (c[2] / s, c[3] / s)
}

#[test]
fn large_drops_give_a_red_outer_edge_and_fog_drops_a_white_bow() {
    let out = heron_words_threads("sky lee --radius-from 0.01 --radius-to 1 --radii 2 --from 38 --to 43 --step 0.1 --lambda-step 10", 2);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = rows(&String::from_utf8(out.stdout).unwrap());
    let (fog, rain): (Vec<_>, Vec<_>) = r.into_iter().partition(|c| c[0] < 0.5);
    // 1 mm: outside the main peak (larger θ) the bow is red (x > 0.45 somewhere past the
    // peak), inside it bluer than the white point's x = 0.3127 somewhere within 1° in.
    let peak = (0..rain.len()).fold(0, |b, i| if rain[i][3] > rain[b][3] { i } else { b });
    let red = rain[peak..].iter().map(|c| xy(c).0).fold(0.0, f64::max);
    let blue = rain[peak.saturating_sub(10)..peak]
        .iter()
        .map(|c| xy(c).0)
        .fold(1.0, f64::min);
    assert!(
        red > 0.45 && blue < 0.3127,
        "1 mm: x outside {red}, inside {blue}"
    );
    // 10 µm (fogbow): at its brightest angle the colour is within 0.03 of D65's
    // chromaticity (0.3127, 0.3290); the 1 mm bow's brightest angle is far from it.
    let dist = |c: &[f64; 5]| {
        let (x, y) = xy(c);
        ((x - 0.3127).powi(2) + (y - 0.3290).powi(2)).sqrt()
    };
    let brightest =
        |v: &[[f64; 5]]| v[(0..v.len()).fold(0, |b, i| if v[i][3] > v[b][3] { i } else { b })];
    let (df, dr) = (dist(&brightest(&fog)), dist(&brightest(&rain)));
    assert!(
        df < 0.03 && dr > 0.1,
        "distance from white: fog {df}, rain {dr}"
    );
}

#[test]
fn lee_rejects_bad_values_in_one_line_without_writing() {
    let dir = std::env::temp_dir().join(format!("heron-lee-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.csv");
    for (args, needle) in [
        ("--radius-from 0 --radius-to 1", "--radius-from"),
        ("--radius-from 0.5 --radius-to 0.1", "--radius-from"),
        ("--radius-to 3", "--radius-to"),
        ("--radii 0", "--radii"),
        ("--lambda-step 0.1", "--lambda-step"),
        ("--from 44 --to 36", "--from"),
        ("--step 0", "--step"),
        ("--sun-radius 9", "--sun-radius"),
    ] {
        let out = heron_words_threads(&format!("sky lee {args} -o {}", path.display()), 1);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args}: {err}");
        assert!(
            err.contains(needle) && err.trim().lines().count() == 1,
            "{args}: {err}"
        );
        assert!(!path.exists(), "{args}: wrote {}", path.display());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
