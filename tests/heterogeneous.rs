//! Heterogeneous media (issue 39): density fields tracked with null collisions, checks
//! that fail when the estimators are wrong.
//!
//! - Closed forms: ratio tracking's transmittance and delta tracking's escape weight,
//!   per lane of a chromatic medium, equal exp(−k_λ ∫ρ) through a linear density ramp
//!   (a grid, on which trilinear lookup is exact) and through exponential height fog
//!   (integrated in closed form), within 3 standard errors; delta tracking's real
//!   collisions fall at the distances 1 − exp(−k_h ∫ρ) says.
//! - Energy: a non-absorbing heterogeneous medium (noise, chromatic σ_s) in a white
//!   furnace renders 1 within 0.5%.
//! - A grid of constant density renders what the homogeneous medium renders (heron
//!   compare's region z-test, Šidák over the image at α = 0.01).
//! - Bad grids (truncated, NaN, negative, a wrong size) are one-line errors naming the
//!   key and the file; renders do not depend on the thread count.
mod common;

use common::render::{compare_xyz, mean_se_y};
use glam::Vec3;
use heron::math::Rng;
use heron::medium::density::{grid::Edge, Density, Field, Grid, HeightFog};
use heron::medium::tracking::{delta_tracking, ratio_tracking, Flight, Weights};
use heron::scene::load::load_scene_from_str;
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use heron::spectrum::SampledSpectrum;
use std::path::{Path, PathBuf};

/// Extinction per unit density of four lanes, the hero first: lanes both thinner and
/// thicker than the hero, so the null collisions' ratios go both ways.
const K: [f32; 4] = [1.0, 0.5, 2.0, 0.25];

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("heron-het-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// ρ = 0.03 + 0.03 x on cell centres x = 0 … 8 (a grid over [−0.5, 8.5] in x), constant
/// in y and z: linear between the centres, so trilinear lookup is exact for x in [0, 8].
fn ramp_grid() -> Grid {
    let res = [9, 2, 2];
    let mut values = Vec::new();
    for _z in 0..2 {
        for _y in 0..2 {
            for x in 0..9 {
                values.push(0.03 + 0.03 * x as f32);
            }
        }
    }
    Grid {
        res,
        lo: Vec3::new(-0.5, 0.0, 0.0),
        hi: Vec3::new(8.5, 8.0, 8.0),
        values,
        edge: Edge::Clamp,
    }
}

/// Per lane: mean and standard error of `n` estimates.
fn mean_se(samples: &[[f64; 4]]) -> [(f64, f64); 4] {
    let n = samples.len() as f64;
    std::array::from_fn(|i| {
        let m = samples.iter().map(|s| s[i]).sum::<f64>() / n;
        let v = samples.iter().map(|s| (s[i] - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, (v / n).sqrt())
    })
}

fn assert_lanes(what: &str, est: [(f64, f64); 4], expected: [f64; 4]) {
    for i in 0..4 {
        let (m, se) = est[i];
        println!(
            "{what} lane {i}: {m:.5} ± {se:.5}, exp(-k tau) = {:.5}",
            expected[i]
        );
        assert!(
            se > 0.0 && se < 0.01,
            "{what} lane {i}: standard error {se}"
        );
        assert!(
            (m - expected[i]).abs() < 3.0 * se,
            "{what} lane {i}: {m} ± {se}, expected {}",
            expected[i]
        );
    }
}

/// Checks both trackers against exp(−k_λ τ) along o + t d, t ∈ [0, len], where τ = ∫ρ,
/// with 20 000 estimates each: the standard errors are 0.002–0.004, so 3 of them resolve
/// a 1% error in the transmittance at every lane.
fn check_tracking(what: &str, density: &Density, (o, d, len): (Vec3, Vec3, f32), tau: f64) {
    let k = SampledSpectrum(K);
    let expected: [f64; 4] = std::array::from_fn(|i| (-(K[i] as f64) * tau).exp());
    let n = 20_000;
    let mut rng = Rng::new(11, 3);
    let ratio: Vec<[f64; 4]> = (0..n)
        .map(|_| {
            let (tr, _) =
                ratio_tracking(density, (o, d, len), k, |p| k * density.eval(p), &mut rng);
            tr.0.map(|v| v as f64)
        })
        .collect();
    assert_lanes(
        &format!("{what}, ratio tracking"),
        mean_se(&ratio),
        expected,
    );
    // Delta tracking: a path that reaches the end carries β T̄/T̄_h, one that collides
    // nothing; the expectation is each lane's transmittance.
    let delta: Vec<[f64; 4]> = (0..n)
        .map(|_| {
            let one = SampledSpectrum::splat(1.0);
            let mut w = Weights {
                beta: one,
                r_u: one,
                r_l: one,
            };
            let u0 = rng.uniform();
            let at = |p| k * density.eval(p);
            match delta_tracking(density, (o, d, len), k, at, u0, &mut rng, &mut w) {
                Flight::Escaped { tr } => (w.beta * tr * (1.0 / tr.0[0])).0.map(|v| v as f64),
                Flight::Collided { .. } => [0.0; 4],
            }
        })
        .collect();
    assert_lanes(
        &format!("{what}, delta tracking"),
        mean_se(&delta),
        expected,
    );
}

#[test]
fn tracking_matches_closed_form_transmittance() {
    // A linear ramp: ρ = 0.03 + 0.03 x from x = 0.5 to 7.5, so τ = len (0.03 + 0.03 x̄)
    // ≈ 1.1.
    let ramp = Density::new(Field::Grid(ramp_grid()), Vec3::ZERO, Vec3::splat(8.0));
    let o = Vec3::new(0.5, 2.0, 3.0);
    let d = Vec3::new(1.0, 0.3, 0.2).normalize();
    let len = 7.0 / d.x;
    let tau = len as f64 * (0.03 + 0.03 * 4.0);
    check_tracking("linear ramp", &ramp, (o, d, len), tau);

    // Exponential height fog, climbing out of it (τ ≈ 1.1).
    let fog = HeightFog {
        up: Vec3::Y,
        base: 0.0,
        scale_height: 1.0,
    };
    let density = Density::new(
        Field::HeightFog(fog.clone()),
        Vec3::new(-4.0, -1.0, -4.0),
        Vec3::new(4.0, 6.0, 4.0),
    );
    let (a, b) = (Vec3::new(-3.0, 0.5, -3.0), Vec3::new(3.0, 5.5, 2.0));
    let (d, len) = ((b - a).normalize(), (b - a).length());
    let tau = fog.integral(a, d, len);
    check_tracking("height fog", &density, (a, d, len), tau);

    // Where the hero's real collisions fall: P(t ≤ s) = 1 − exp(−k_h τ(s)).
    let n = 20_000;
    let mut rng = Rng::new(5, 9);
    let k = SampledSpectrum(K);
    let ts: Vec<f32> = (0..n)
        .filter_map(|_| {
            let one = SampledSpectrum::splat(1.0);
            let mut w = Weights {
                beta: one,
                r_u: one,
                r_l: one,
            };
            let u0 = rng.uniform();
            let at = |p| k * density.eval(p);
            match delta_tracking(&density, (a, d, len), k, at, u0, &mut rng, &mut w) {
                Flight::Collided { t, .. } => Some(t),
                Flight::Escaped { .. } => None,
            }
        })
        .collect();
    for s in [0.5f32, 1.5, 3.0, 6.0] {
        let p = 1.0 - (-(K[0] as f64) * fog.integral(a, d, s)).exp();
        let f = ts.iter().filter(|&&t| t <= s).count() as f64 / n as f64;
        let se = (p * (1.0 - p) / n as f64).sqrt();
        println!("collisions before {s}: {f:.4}, expected {p:.4} ± {se:.4}");
        assert!(
            (f - p).abs() < 3.0 * se,
            "collisions before {s}: {f}, expected {p}"
        );
    }
}

fn load_in(dir: &Path, toml: &str) -> Result<Scene, String> {
    load_scene_from_str(toml, &dir.join("het-test.toml")).map_err(|e| e.to_string())
}

fn run(scene: &Scene, spp: u32) -> heron::film::Film {
    common::render::run(scene, IntegratorKind::Path, spp, scene.settings.seed)
}

#[test]
fn white_furnace_of_a_heterogeneous_medium_stays_at_one() {
    // Noise clouds (a third of the sphere clear air) of a non-absorbing medium whose σ_s
    // varies sixfold over the visible, in an environment of radiance 1: every lane must
    // come back to 1 through real and null collisions alike. 32² pixels × 128 spp give a
    // standard error near 0.13%; the check is 0.5% and 4 standard errors.
    let dir = temp_dir("furnace");
    let scene = load_in(
        &dir,
        &common::scenes::furnace_sphere(
            r#"{ type = "henyey-greenstein", sigma_a = 0.0, sigma_s = [1.0, 3.0, 6.0], g = 0.5, density = { type = "noise", scale = 0.8, seed = 3, threshold = 0.3 } }"#,
            "",
        ),
    )
    .unwrap();
    let (m, se) = mean_se_y(&run(&scene, 128));
    println!("heterogeneous furnace: {m:.5} ± {se:.5}");
    assert!(se < 0.002, "standard error {se}");
    assert!(
        (m - 1.0).abs() < 0.005 && (m - 1.0).abs() < 4.0 * se.max(1e-4),
        "{m} ± {se}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sphere of an absorbing, scattering medium lit by the sun in front of a dim sky.
fn lit_sphere(medium: &str) -> String {
    format!(
        r#"
background = 0.2
[camera]
eye = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
d = 2.5
resolution = [32, 32]
[render]
max_depth = 50
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
medium = {medium}
[[lights]]
type = "sun"
direction = [0.4, -1.0, -0.5]
irradiance = 2.0
"#
    )
}

/// Writes `two.vol` into `dir`: a grid of density 2 over the sphere's box.
fn write_density_two(dir: &Path) {
    let grid = Grid {
        res: [3, 3, 3],
        lo: Vec3::splat(-1.0),
        hi: Vec3::splat(1.0),
        values: vec![2.0; 27],
        edge: Edge::Clamp,
    };
    std::fs::write(dir.join("two.vol"), grid.to_vol()).unwrap();
}

#[test]
fn a_constant_grid_renders_the_homogeneous_medium() {
    // σ_t = 1.5 per unit either way: given, or as half the coefficients times a grid
    // of density 2. Both are unbiased estimates of the same image, so heron compare's
    // region z-test (4×4-pixel regions, Šidák over the image at α = 0.01) must find
    // them the same; at 128 spp the regions resolve about 3% of their mean.
    let dir = temp_dir("constant");
    write_density_two(&dir);
    let hom = load_in(
        &dir,
        &lit_sphere(
            r#"{ type = "henyey-greenstein", sigma_a = [0.2, 0.5, 0.8], sigma_s = 1.0, g = 0.4 }"#,
        ),
    )
    .unwrap();
    let het = load_in(
        &dir,
        &lit_sphere(
            r#"{ type = "henyey-greenstein", sigma_a = [0.1, 0.25, 0.4], sigma_s = 0.5, g = 0.4, density = { type = "grid", file = "two.vol" } }"#,
        ),
    )
    .unwrap();
    let c = compare_xyz(&run(&hom, 128), &run(&het, 128), 4, 0.01, None);
    let report = c.report("homogeneous", "constant grid", 10);
    println!("{report}");
    assert!(c.same(), "{report}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_grids_are_one_line_errors() {
    let dir = temp_dir("bad");
    let good = ramp_grid().to_vol();
    let mut nan = good.clone();
    nan[48 + 4 * 10..48 + 4 * 11].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut negative = good.clone();
    negative[48..52].copy_from_slice(&(-0.5f32).to_le_bytes());
    let mut wrong = good.clone();
    wrong[8..12].copy_from_slice(&10i32.to_le_bytes());
    let cases: [(&str, Vec<u8>, &str); 4] = [
        (
            "truncated.vol",
            good[..good.len() - 10].to_vec(),
            "(truncated)",
        ),
        ("nan.vol", nan, "got NaN at cell (1, 1, 0)"),
        ("negative.vol", negative, "got -0.5 at cell (0, 0, 0)"),
        ("wrong.vol", wrong, "for a 10 x 2 x 2 grid"),
    ];
    for (name, bytes, says) in cases {
        std::fs::write(dir.join(name), bytes).unwrap();
        let e = load_in(
            &dir,
            &lit_sphere(&format!(
                r#"{{ type = "henyey-greenstein", sigma_s = 1.0, density = {{ type = "grid", file = "{name}" }} }}"#
            )),
        )
        .unwrap_err();
        println!("{e}");
        assert!(!e.trim().contains('\n'), "{e}");
        assert!(
            e.contains("shapes[0].medium.density.file") && e.contains(name),
            "{e}"
        );
        assert!(e.contains(says), "{e}");
    }
    let e = load_in(
        &dir,
        &lit_sphere(r#"{ type = "henyey-greenstein", sigma_s = 1.0, density = { type = "grid", file = "none.vol" } }"#),
    )
    .unwrap_err();
    assert!(
        e.contains("shapes[0].medium.density.file: cannot read"),
        "{e}"
    );
    std::fs::write(dir.join("cloud.vdb"), b" BDV").unwrap();
    let e = load_in(
        &dir,
        &lit_sphere(r#"{ type = "henyey-greenstein", sigma_s = 1.0, density = { type = "grid", file = "cloud.vdb" } }"#),
    )
    .unwrap_err();
    assert!(
        e.contains("OpenVDB and NanoVDB grids are not read") && e.contains("Mitsuba .vol"),
        "{e}"
    );
    let e = load_in(
        &dir,
        &lit_sphere(
            r#"{ type = "henyey-greenstein", sigma_s = 1.0, density = { type = "clouds" } }"#,
        ),
    )
    .unwrap_err();
    assert!(e.contains("height-fog, rain-shaft, noise, grid"), "{e}");
    let e = load_in(
        &dir,
        &lit_sphere(r#"{ type = "henyey-greenstein", sigma_s = 1.0, density = { type = "height-fog", scale_height = 1, hieght = 2 } }"#),
    )
    .unwrap_err();
    assert!(e.contains("hieght"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn heterogeneous_renders_do_not_depend_on_the_thread_count() {
    // Null collisions draw from streams keyed by their rays, never by the thread.
    let dir = temp_dir("threads");
    let scene = load_in(
        &dir,
        &lit_sphere(
            r#"{ type = "henyey-greenstein", sigma_s = [1.0, 2.0, 3.0], g = 0.5, density = { type = "height-fog", scale_height = 0.5 } }"#,
        ),
    )
    .unwrap();
    assert_eq!(
        common::render::path_bits(&scene, 8, 1),
        common::render::path_bits(&scene, 8, 2)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tracking_stays_finite_and_non_negative_under_stress() {
    // heron stress's medium case: rays through the box uniformly, in its faces' planes
    // and along its axes (zero direction components in the grid walk), 8 chromatic
    // lanes; every weight, rescaled probability and transmittance finite and ≥ 0.
    let dir = temp_dir("stress");
    for density in [
        r#"{ type = "noise", scale = 0.5, seed = 1, threshold = 0.2, taper = true }"#,
        r#"{ type = "height-fog", scale_height = 0.05, base = -1.0 }"#,
        r#"{ type = "rain-shaft", center = [0.0, 0.8, 0.0], radius = 0.3, edge = 0.2, spread = 10.0, falloff = 0.5 }"#,
    ] {
        let scene = load_in(
            &dir,
            &lit_sphere(&format!(
                r#"{{ type = "henyey-greenstein", sigma_a = [0.1, 0.0, 2.0], sigma_s = [5.0, 0.5, 40.0], density = {density} }}"#
            )),
        )
        .unwrap();
        let r = heron::stress::medium_case(0, &scene.media[0], 30_000, 1);
        println!(
            "{density}: {} rays, {} failures {:?}",
            r.rays,
            r.failures(),
            r.first
        );
        assert_eq!(r.rays, 30_000);
        assert_eq!(r.failures(), 0, "{:?}", r.first);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sphere of radius 1 holding 2 µm drops below and 0.5 µm drops aloft, blending
/// from height `from` to `to` (`extra`: more keys of the medium).
fn two_populations(from: f64, to: f64, extra: &str) -> String {
    format!(
        r#"{{ type = "mie", radius_mm = 0.002, number_density = 4e10, aloft = {{ radius_mm = 0.0005, number_density = 6e11, from = {from}, to = {to} }}{extra} }}"#
    )
}

#[test]
fn drops_that_vary_with_height_mix_their_populations() {
    // Issue 39, part 3. The coefficients: the drops below under `from`, the drops aloft
    // over `to`, and halfway up (the smoothstep's midpoint) the mean of the two.
    let dir = temp_dir("aloft");
    let scene = load_in(&dir, &lit_sphere(&two_populations(-0.5, 0.5, ""))).unwrap();
    let m = &scene.media[0];
    let wl = heron::spectrum::SampledWavelengths::<4>::new([450.0, 500.0, 600.0, 700.0], [1.0; 4]);
    let below = m.sigma_t(&wl);
    let aloft = m.aloft.as_ref().unwrap();
    let (t_low, _, s_low) = m.coefficients_at(Vec3::new(0.0, -0.8, 0.0), &wl);
    let (t_high, _, s_high) = m.coefficients_at(Vec3::new(0.0, 0.8, 0.0), &wl);
    let (t_mid, _, s_mid) = m.coefficients_at(Vec3::new(0.3, 0.0, 0.1), &wl);
    let up = m.extinction_at(Vec3::new(0.0, 0.8, 0.0), &wl);
    assert_eq!((s_low, s_high, s_mid), (0.0, 1.0, 0.5));
    for i in 0..4 {
        let a = (t_high.0[i], up.0[i]);
        assert_eq!(t_low.0[i], below.0[i]);
        assert_eq!(a.0, a.1);
        assert!((t_mid.0[i] - 0.5 * (below.0[i] + a.0)).abs() < 1e-5 * a.0);
        // The two populations differ (else the test would not see a mix-up).
        assert!(
            (a.0 / below.0[i] - 1.0).abs() > 0.05,
            "{a:?} {}",
            below.0[i]
        );
    }
    let _ = aloft;

    // Energy: without absorption the mixture conserves it (white furnace, L = 1), with
    // the populations changing across the sphere. 32² × 64 spp: standard error ~0.2%.
    let furnace = load_in(
        &dir,
        &common::scenes::furnace_sphere(&two_populations(-0.5, 0.5, ", absorption = false"), ""),
    )
    .unwrap();
    let (mean, se) = mean_se_y(&run(&furnace, 64));
    println!("two-population furnace: {mean:.5} ± {se:.5}");
    assert!(
        se < 0.003 && (mean - 1.0).abs() < 0.005 && (mean - 1.0).abs() < 4.0 * se.max(1e-4),
        "{mean} ± {se}"
    );

    // All aloft (the blend ends below the sphere): the image of the drops aloft alone,
    // by region z-test (4×4-pixel regions, Šidák over the image at α = 0.01).
    let all_aloft = load_in(&dir, &lit_sphere(&two_populations(-3.0, -2.0, ""))).unwrap();
    let alone = load_in(
        &dir,
        &lit_sphere(r#"{ type = "mie", radius_mm = 0.0005, number_density = 6e11 }"#),
    )
    .unwrap();
    let c = compare_xyz(&run(&all_aloft, 128), &run(&alone, 128), 4, 0.01, None);
    let report = c.report("all aloft", "aloft drops alone", 10);
    println!("{report}");
    assert!(c.same(), "{report}");
    // And it is not the image of the drops below.
    let below_alone = load_in(
        &dir,
        &lit_sphere(r#"{ type = "mie", radius_mm = 0.002, number_density = 4e10 }"#),
    )
    .unwrap();
    let c = compare_xyz(
        &run(&all_aloft, 128),
        &run(&below_alone, 128),
        4,
        0.01,
        None,
    );
    assert!(!c.same(), "{}", c.report("all aloft", "drops below", 10));

    // Errors name the key.
    let e = load_in(
        &dir,
        &lit_sphere(r#"{ type = "henyey-greenstein", sigma_s = 1.0, aloft = { radius_mm = 0.001, number_density = 1e9, from = 0, to = 1 } }"#),
    )
    .unwrap_err();
    assert!(
        e.contains("shapes[0].medium.aloft: applies to type = \"mie\""),
        "{e}"
    );
    let e = load_in(&dir, &lit_sphere(&two_populations(1.0, 0.5, ""))).unwrap_err();
    assert!(
        e.contains("shapes[0].medium.aloft: expected heights from < to"),
        "{e}"
    );
    let e = load_in(
        &dir,
        &lit_sphere(r#"{ type = "mie", radius_mm = 0.002, number_density = 4e10, aloft = { number_density = 1e9, from = 0, to = 1 } }"#),
    )
    .unwrap_err();
    assert!(
        e.contains("shapes[0].medium.aloft.radius_mm: missing required key"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn polarisation_in_a_heterogeneous_medium_is_the_homogeneous_one() {
    // 2 µm drops polarise the light they scatter (their phase matrix): a constant grid
    // of density 2 under half the drops must give the same Stokes S1 as the homogeneous
    // medium. Mean S1 (Y) over the image's pixels, a two-sample z-test of the pixel
    // means (independent pixels); the polarisation is resolved (|S1| > 10 standard
    // errors), so a heterogeneous medium that dropped the matrix would fail.
    let dir = temp_dir("polarised");
    write_density_two(&dir);
    let s1 = |medium: &str| {
        let scene = load_in(&dir, &lit_sphere(medium)).unwrap();
        let film = common::render::render_with(&scene, |o| {
            o.settings.integrator = IntegratorKind::Path;
            o.settings.spp = 64;
            o.settings.polarization = true;
        });
        let v: Vec<f64> = film
            .stokes
            .as_ref()
            .unwrap()
            .iter()
            .map(|s| s[0][1] as f64)
            .collect();
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, (var / n).sqrt())
    };
    let (a, sa) = s1(r#"{ type = "mie", radius_mm = 0.002, number_density = 4e10 }"#);
    let (b, sb) = s1(
        r#"{ type = "mie", radius_mm = 0.002, number_density = 2e10, density = { type = "grid", file = "two.vol" } }"#,
    );
    let z = (a - b) / (sa * sa + sb * sb).sqrt();
    println!("S1: homogeneous {a:.5} ± {sa:.5}, constant grid {b:.5} ± {sb:.5}, z {z:.2}");
    assert!(
        a.abs() > 10.0 * sa,
        "the polarisation is not resolved: {a} ± {sa}"
    );
    assert!(z.abs() < 3.5, "z = {z}");
    let _ = std::fs::remove_dir_all(&dir);
}
