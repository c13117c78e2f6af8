//! Rainbow sky models (heron::sky): the Aristotelian bow of the seed, Descartes' geometric
//! optics, Airy theory, Lorenz–Mie, the `heron sky profile` CLI, and a Monte Carlo check
//! of the bows with heron's own tracer.
mod common;

use common::cli::heron;
use glam::Vec3;
use heron::bsdf::{Dielectric, Material};
use heron::camera::Camera;
use heron::geometry::{Shape, ShapeKind};
use heron::math::Rng;
use heron::render::Renderer;
use heron::scene::{Scene, SceneParts};
use heron::settings::RenderSettings;
use heron::sky::aristotle::{self, AristotleSky};
use heron::sky::{airy, descartes, AirySky, DescartesSky, MieSky, Polarisation, Sky};
use heron::spectrum::{cie, ior, DenseSpectrum};
use rayon::prelude::*;

const SUN: f64 = 0.2666;

fn water_n(lambda: f32) -> f64 {
    ior::named("water").unwrap().eval(lambda) as f64
}

/// θ (degrees) of the largest value of f over [from, to] on a grid of `step` degrees,
/// refined by a parabola through the three best points.
fn peak(f: impl Fn(f64) -> f64, from: f64, to: f64, step: f64) -> f64 {
    let n = ((to - from) / step).round() as usize;
    let v: Vec<f64> = (0..=n)
        .map(|i| f((from + step * i as f64).to_radians()))
        .collect();
    let i = (0..=n).max_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap();
    let t = from + step * i as f64;
    if i == 0 || i == n {
        return t;
    }
    let (a, b, c) = (v[i - 1], v[i], v[i + 1]);
    let d = a - 2.0 * b + c;
    if d >= 0.0 {
        return t;
    }
    t + 0.5 * step * (a - c) / d
}

// ---------------------------------------------------------------- Aristotle

/// spectra/aristotle_bow.csv is what `aristotle::derive_texture_csv` writes. Regenerate
/// with `HERON_REGENERATE=1 cargo test --release --test sky aristotle_texture`.
#[test]
fn aristotle_texture_is_derived() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/spectra/aristotle_bow.csv");
    let want = aristotle::derive_texture_csv();
    if std::env::var_os("HERON_REGENERATE").is_some() {
        std::fs::write(path, &want).unwrap();
    }
    let have = std::fs::read_to_string(path).unwrap();
    assert!(
        have == want,
        "{path} is stale: regenerate it (see this test)"
    );
    // λ(t) runs from violet (t = 0, inside) to red (t = 1, outside).
    assert!((aristotle::band_wavelength(0.0) - 400.0).abs() < 1e-6);
    assert!((aristotle::band_wavelength(1.0) - 700.0).abs() < 1e-6);
}

fn aristotle(alpha_deg: f64) -> AristotleSky {
    AristotleSky::new(alpha_deg.to_radians(), DenseSpectrum::constant(0.0))
}

/// The colorimetric dominant wavelength (nm) of the sky's spectrum at θ: the spectral
/// locus point in the direction of the colour's chromaticity from illuminant E.
fn dominant_wavelength(sky: &AristotleSky, theta_deg: f64) -> f64 {
    let s = DenseSpectrum::from_fn(|l| sky.profile(theta_deg.to_radians(), l));
    let xyz = cie::spectrum_to_xyz(&s);
    let sum = xyz[0] + xyz[1] + xyz[2];
    assert!(sum > 0.0, "no colour at {theta_deg}°");
    let hue = |x: f32, y: f32| ((y - 1.0 / 3.0) as f64).atan2((x - 1.0 / 3.0) as f64);
    let h = hue(xyz[0] / sum, xyz[1] / sum);
    let o = cie::cie1931();
    (400..=700)
        .map(|l| {
            let (x, y, z) = (o.x.eval(l as f32), o.y.eval(l as f32), o.z.eval(l as f32));
            let d = (hue(x / (x + y + z), y / (x + y + z)) - h).abs();
            (l as f64, d.min(2.0 * std::f64::consts::PI - d))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap()
        .0
}

#[test]
fn aristotle_bow_lies_within_42_degrees_plus_minus_the_sun_radius() {
    for alpha in [SUN, 0.5, 0.05] {
        let sky = aristotle(alpha);
        let mut inside = 0;
        for i in 0..=8000 {
            let t = 40.0 + 0.0005 * i as f64;
            let lit = [400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0]
                .iter()
                .any(|&l| sky.profile(t.to_radians(), l) > 0.0);
            if lit {
                assert!((t - 42.0).abs() < alpha + 1e-9, "α = {alpha}°: bow at {t}°");
                inside += 1;
            }
        }
        // Lit over (almost) the whole band of width 2α.
        let lit_width = inside as f64 * 0.0005;
        assert!(
            lit_width > 1.9 * alpha,
            "α = {alpha}°: lit over {lit_width}°"
        );
    }
}

#[test]
fn aristotle_hue_runs_from_red_outside_to_violet_inside() {
    let sky = aristotle(SUN);
    let thetas: Vec<f64> = (-8..=8).map(|j| 42.0 + SUN * j as f64 / 9.0).collect();
    let dom: Vec<f64> = thetas
        .iter()
        .map(|&t| dominant_wavelength(&sky, t))
        .collect();
    for w in dom.windows(2) {
        assert!(
            w[1] > w[0],
            "dominant wavelengths not increasing outward: {dom:?}"
        );
    }
    assert!(dom[0] < 440.0 && *dom.last().unwrap() > 640.0, "{dom:?}");
}

#[test]
fn aristotle_vector_formula_matches_the_profile() {
    // The seed's vector form (ω′_high/low tilted in the plane of ω and ω′) equals
    // a = cos(θ + α), b = cos(θ − α).
    let mut sky = aristotle(SUN);
    sky.background = DenseSpectrum::constant(0.25);
    sky.strength = 0.8;
    let sun = Vec3::new(0.3, 0.5, -0.8).normalize();
    let (t1, t2) = (-sun).any_orthonormal_pair();
    let mut rng = Rng::new(4, 2);
    for _ in 0..2000 {
        let th = (41.5 + rng.uniform() as f64).to_radians();
        let ph = std::f64::consts::TAU * rng.uniform() as f64;
        let v = (-sun) * th.cos() as f32
            + t1 * (th.sin() * ph.cos()) as f32
            + t2 * (th.sin() * ph.sin()) as f32;
        let lambda = 400.0 + 300.0 * rng.uniform();
        let th = heron::sky::antisolar_angle(v, sun);
        let (a, b) = (sky.radiance(v, lambda, sun), sky.profile(th, lambda));
        assert!((a - b).abs() <= 1e-3 * b.abs().max(1e-3), "{a} vs {b}");
        if (th.to_degrees() - 42.0).abs() > SUN + 1e-4 {
            assert_eq!(b, 0.25);
        }
    }
    // Over the background: composited, and the background alone outside.
    let s = Sky::Aristotle(sky);
    assert_eq!(s.profile(30f64.to_radians(), 500.0), 0.25);
}

// ---------------------------------------------------------------- Descartes

#[test]
fn descartes_point_sun_peaks_at_minimum_deviation() {
    let alpha = 0.0005f64;
    for lambda in [400.0f32, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0] {
        let n = water_n(lambda);
        for k in [1u32, 2] {
            let mut sky = DescartesSky::water(alpha.to_radians());
            sky.orders = vec![k];
            let kf = k as f64;
            let cos_i = ((n * n - 1.0) / (kf * kf + 2.0 * kf)).sqrt();
            let i = cos_i.acos();
            let r = (i.sin() / n).asin();
            let d = 2.0 * (i - r) + kf * (std::f64::consts::PI - 2.0 * r);
            let want = if k == 1 {
                180.0 - d.to_degrees()
            } else {
                d.to_degrees() - 180.0
            };
            let got = peak(
                |t| sky.profile(t, lambda) as f64,
                want - 0.05,
                want + 0.05,
                2e-4,
            );
            println!("descartes {lambda} nm k={k}: peak {got:.5}°, minimum deviation {want:.5}°");
            assert!(
                (got - want).abs() < 0.01,
                "{lambda} nm, k = {k}: peak {got}° vs {want}°"
            );
        }
    }
}

#[test]
fn alexanders_dark_band_appears_by_itself() {
    for lambda in [450.0f32, 550.0, 650.0] {
        let n = water_n(lambda);
        let (t1, t2) = (
            descartes::rainbow_angle(n, 1).to_degrees(),
            descartes::rainbow_angle(n, 2).to_degrees(),
        );
        let sky = DescartesSky::water(SUN.to_radians());
        let at = |t: f64| sky.profile(t.to_radians(), lambda) as f64;
        let (inside, outside) = (at(t1 - 0.5), at(t2 + 0.5));
        for j in 0..=20 {
            let t = t1 + 0.5 + (t2 - t1 - 1.0) * j as f64 / 20.0;
            let dark = at(t);
            assert!(
                dark <= 1e-3 * outside && dark <= 1e-3 * inside,
                "{lambda} nm: {dark} at {t}° vs {inside} inside the primary, {outside} outside the secondary"
            );
        }
        // With external reflection (k = 0) the band is lit a little, still much darker.
        let mut all = DescartesSky::water(SUN.to_radians());
        all.orders = vec![0, 1, 2];
        let dark = all.profile(46f64.to_radians(), lambda) as f64;
        let (inside, outside) = (
            all.profile((t1 - 0.5).to_radians(), lambda) as f64,
            all.profile((t2 + 0.5).to_radians(), lambda) as f64,
        );
        println!("dark band {lambda} nm with k = 0: {dark:.3e}; primary {inside:.3e}, secondary {outside:.3e}");
        assert!(
            dark < 0.05 * inside && dark < 0.5 * outside,
            "{dark} {inside} {outside}"
        );
    }
}

#[test]
fn descartes_polarisation_s_dominates_the_bow() {
    // Near the Brewster angle inside the drop the p reflection almost vanishes: the
    // primary bow is ~96 % s-polarised (e.g. Können 1985).
    let lambda = 550.0;
    let n = water_n(lambda);
    let t1 = descartes::rainbow_angle(n, 1).to_degrees() - 0.1;
    let mut s = DescartesSky::water(SUN.to_radians());
    s.orders = vec![1];
    s.polarisation = Polarisation::S;
    let mut p = s.clone();
    p.polarisation = Polarisation::P;
    let mut u = s.clone();
    u.polarisation = Polarisation::Unpolarised;
    let (vs, vp, vu) = (
        s.profile(t1.to_radians(), lambda),
        p.profile(t1.to_radians(), lambda),
        u.profile(t1.to_radians(), lambda),
    );
    assert!(((vs + vp) / 2.0 - vu).abs() < 1e-6 * vu);
    let degree = (vs - vp) / (vs + vp);
    println!("primary bow degree of polarisation {degree:.3}");
    assert!(degree > 0.9, "{degree}");
}

// ---------------------------------------------------------------- Airy

#[test]
fn airy_supernumerary_spacing_scales_as_radius_to_minus_two_thirds() {
    let lambda = 550.0;
    let n = water_n(lambda);
    let t1 = descartes::rainbow_angle(n, 1).to_degrees();
    let spacing = |a_mm: f64| {
        let mut sky = AirySky::water(a_mm, 0.0005f64.to_radians());
        sky.orders = vec![1];
        let x = sky.size_parameter(lambda);
        let off = airy::main_peak_offset(n, 1, x).to_degrees();
        let sep = off * (airy::AIRY_SECOND_MAX_Z / airy::AIRY_FIRST_MAX_Z - 1.0);
        let f = |t: f64| sky.profile(t, lambda) as f64;
        let p0 = peak(f, t1 - 1.5 * off, t1 - 0.5 * off, 1e-4);
        let p1 = peak(f, t1 - off - 1.4 * sep, t1 - off - 0.6 * sep, 1e-4);
        println!("airy a = {a_mm} mm: main {p0:.4}°, first supernumerary {p1:.4}°");
        p0 - p1
    };
    let (s1, s2) = (spacing(0.1), spacing(0.2));
    let ratio = s1 / s2;
    println!("supernumerary spacing 0.1 mm {s1:.4}°, 0.2 mm {s2:.4}°, ratio {ratio:.4} (2^(2/3) = 1.5874)");
    assert!(
        (ratio - 2f64.powf(2.0 / 3.0)).abs() < 0.01 * 1.5874,
        "{ratio}"
    );
}

#[test]
fn airy_main_peak_is_on_the_bright_side_by_the_expected_amount() {
    let lambda = 550.0;
    let n = water_n(lambda);
    for a_mm in [0.5, 1.0] {
        for k in [1u32, 2] {
            let t0 = descartes::rainbow_angle(n, k).to_degrees();
            let mut sky = AirySky::water(a_mm, 0.0005f64.to_radians());
            sky.orders = vec![k];
            let x = sky.size_parameter(lambda);
            let off = airy::main_peak_offset(n, k, x).to_degrees();
            // Primary: bright side is inside (smaller θ); secondary: outside.
            let want = if k == 1 { t0 - off } else { t0 + off };
            let got = peak(
                |t| sky.profile(t, lambda) as f64,
                want - 0.1,
                want + 0.1,
                1e-4,
            );
            let mut real = AirySky::water(a_mm, SUN.to_radians());
            real.orders = vec![k];
            let got_sun = peak(
                |t| real.profile(t, lambda) as f64,
                want - 0.6,
                want + 0.6,
                1e-3,
            );
            println!(
                "airy a = {a_mm} mm k = {k}: Descartes {t0:.4}°, expected offset {off:.4}°, point-sun peak {got:.4}°, real-sun peak {got_sun:.4}°"
            );
            assert!(
                (got - want).abs() < 0.002,
                "a = {a_mm} mm, k = {k}: {got}° vs {want}°"
            );
            assert!(off > 0.1 && off < 0.7, "{off}");
        }
    }
}

// ---------------------------------------------------------------- Mie

#[test]
fn airy_agrees_with_mie_near_the_primary_bow() {
    // Peak positions (real sun, primary): Airy theory is an asymptotic approximation for
    // large x, so the tolerance is 0.03° at a = 0.25 mm (x ≈ 2400–3500; measured 0.014°
    // and 0.006°) and 0.005° at 1 mm (x ≈ 11 400; measured < 0.001°); Mie also carries the
    // external reflection and the other orders. Peak values within 5 % (measured ≤ 1.3 %).
    for (a_mm, lambdas, tol) in [
        (0.25, vec![450.0f32, 650.0], 0.03),
        (1.0, vec![550.0f32], 0.005),
    ] {
        let mut a = AirySky::water(a_mm, SUN.to_radians());
        a.orders = vec![1];
        let m = MieSky::water(a_mm, SUN.to_radians());
        for lambda in lambdas {
            let t0 = descartes::rainbow_angle(water_n(lambda), 1).to_degrees();
            let pa = peak(|t| a.profile(t, lambda) as f64, t0 - 1.0, t0 + 0.3, 0.002);
            let pm = peak(|t| m.profile(t, lambda) as f64, t0 - 1.0, t0 + 0.3, 0.002);
            let (va, vm) = (
                a.profile(pa.to_radians(), lambda),
                m.profile(pm.to_radians(), lambda),
            );
            println!(
                "a = {a_mm} mm, {lambda} nm: Descartes {t0:.3}°, Airy peak {pa:.3}° ({va:.4}), Mie peak {pm:.3}° ({vm:.4})"
            );
            assert!((pa - pm).abs() < tol, "peaks {pa}° vs {pm}°");
            assert!((va / vm - 1.0).abs() < 0.05, "peak values {va} vs {vm}");
        }
    }
}

#[test]
fn mie_small_sphere_is_rayleigh_like_and_symmetric() {
    // x ≪ 1: |S1|² flat, |S2|² ∝ cos² of the scattering angle.
    let c = heron::optics::mie::coefficients(1.33, 0.01);
    let (s1a, s2a) = heron::optics::mie::amplitudes(&c, 1.0);
    let (s1b, s2b) = heron::optics::mie::amplitudes(&c, 0.0);
    assert!((s1a.norm() / s1b.norm() - 1.0).abs() < 1e-3);
    assert!((s2a.norm() - s1a.norm()).abs() < 1e-3 * s1a.norm());
    assert!(s2b.norm() < 1e-3 * s2a.norm());
}

// ---------------------------------------------------------------- CLI

#[test]
fn sky_profile_cli_writes_csv() {
    let out = heron(&[
        "sky",
        "profile",
        "--model",
        "descartes",
        "--lambda",
        "450,650",
        "--from",
        "40",
        "--to",
        "42",
        "--step",
        "0.5",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "theta_deg,450nm,650nm");
    assert_eq!(lines.len(), 6);
    assert!(lines[1].starts_with("40,"));
    assert!(lines[5].starts_with("42,"));
    let sky = DescartesSky::water(SUN.to_radians());
    for l in &lines[1..] {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let want = sky.profile(v[0].to_radians(), 450.0) as f64;
        assert!((v[1] - want).abs() <= 1e-6 * want.abs() + 1e-12);
    }
    // A drop radius only where the model has drops (SkySpec refuses it elsewhere).
    for (model, radius) in [
        ("constant", &[][..]),
        ("aristotle", &[]),
        ("airy", &["--droplet-radius", "0.05"]),
        ("mie", &["--droplet-radius", "0.05"]),
    ] {
        let mut args = vec![
            "sky", "profile", "--model", model, "--lambda", "550", "--from", "41", "--to", "42",
            "--step", "0.25",
        ];
        args.extend_from_slice(radius);
        let out = heron(&args);
        assert!(
            out.status.success(),
            "{model}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(String::from_utf8(out.stdout).unwrap().lines().count(), 6);
    }
}

#[test]
fn sky_profile_cli_rejects_bad_values_in_one_line() {
    let base = ["sky", "profile"];
    // Arguments after `sky profile`, split on white space, and what the error must say.
    for (args, needle) in [
        (
            "--model nope --lambda 500 --from 0 --to 1 --step 1",
            "--model: expected one of constant, aristotle, descartes, airy, mie, halo, got \"nope\"",
        ),
        (
            "--model descartes --lambda 500 --from 0 --to 1 --step -1",
            "--step",
        ),
        (
            "--model descartes --lambda 500 --from 0 --to 1 --step 0",
            "--step",
        ),
        (
            "--model descartes --lambda 500 --from 5 --to 1 --step 1",
            "--from",
        ),
        (
            "--model descartes --lambda 300 --from 0 --to 1 --step 1",
            "360–830",
        ),
        (
            "--model descartes --lambda 500,900 --from 0 --to 1 --step 1",
            "360–830",
        ),
        (
            "--model descartes --lambda abc --from 0 --to 1 --step 1",
            "--lambda",
        ),
        (
            "--model airy --lambda 500 --from 0 --to 1 --step 1",
            "--droplet-radius",
        ),
        (
            "--model mie --lambda 500 --from 0 --to 1 --step 1",
            "--droplet-radius",
        ),
        (
            "--model mie --lambda 500 --from 0 --to 1 --step 1 --droplet-radius -1",
            "--droplet-radius",
        ),
        (
            "--model descartes --lambda 500 --from 0 --to 1 --step 1 --sun-radius 0",
            "--sun-radius",
        ),
        (
            "--model descartes --lambda 500 --from 0 --to 1 --step 1 --k 3",
            "--k",
        ),
        (
            "--model descartes --lambda 500 --from 0 --to 1 --step 1 --polarisation q",
            "--polarisation",
        ),
        // SkySpec's rules, as in scene files: options that do not apply are refused.
        (
            "--model descartes --lambda 500 --from 0 --to 1 --step 1 --droplet-radius 0.5",
            "--droplet-radius: applies to airy and mie, not descartes",
        ),
        (
            "--model airy --lambda 500 --from 0 --to 1 --step 1 --droplet-radius 0.5 --k 0",
            "--k: expected a non-empty subset of [1, 2], got [0]",
        ),
        (
            "--model airy --lambda 500 --from 0 --to 1 --step 1 --droplet-radius 10.5",
            "--droplet-radius: expected at most 10 mm, got 10.5",
        ),
        (
            "--model descartes --lambda 500 --from 0 --to 200 --step 1",
            "0–180",
        ),
        (
            "--model descartes --lambda 500 --from x --to 1 --step 1",
            "--from",
        ),
    ] {
        let all: Vec<&str> = base
            .iter()
            .copied()
            .chain(args.split_whitespace())
            .collect();
        let out = heron(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

// ---------------------------------------------------------------- Monte Carlo

fn water_drop_scene() -> Scene {
    Scene::from_parts(SceneParts {
        source: "test".into(),
        camera: Camera::new(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO, Vec3::Y, 1.0, 8, 8).unwrap(),
        shapes: vec![Shape::new(
            ShapeKind::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            0,
        )],
        materials: vec![Material::Dielectric(Dielectric::new(
            ior::named("water").unwrap(),
            true,
        ))],
        material_names: vec!["water".into()],
        lights: vec![],
        source_sha256: String::new(),
        inputs: vec![],
        media: vec![],
        background: DenseSpectrum::constant(0.0),
        sky: None,
        envmap: None,
        settings: RenderSettings {
            spp: 1,
            max_depth: 32,
            epsilon: 1e-4,
            seed: 0,
            ..Default::default()
        },
    })
}

/// Parallel rays (sunlight travelling along +z) hit a unit water sphere at impact
/// parameters uniform over its disk; heron's tracer follows each through T R…R T with its
/// own intersection, refraction and reflection code; the exit directions' angles from
/// the antisolar direction (+z) are histogrammed in 0.01° bins. The caustic bin must be
/// at Descartes' angle.
#[test]
fn monte_carlo_bows_through_heron_tracer_peak_at_descartes_angles() {
    let scene = water_drop_scene();
    let renderer = Renderer::new(&scene).unwrap();
    let accel = renderer.accel();
    const RAYS: usize = 200_000;
    const BIN: f64 = 0.01;
    for lambda in [450.0f32, 650.0] {
        for (k, path) in [
            (1u32, vec![false, true, false]),
            (2, vec![false, true, true, false]),
        ] {
            let thetas: Vec<f64> = (0..RAYS)
                .into_par_iter()
                .with_min_len(4096)
                .map(|i| {
                    let mut rng = Rng::new(17 + k as u64, i as u64);
                    let b = rng.uniform().sqrt() * 0.999_999;
                    let phi = std::f32::consts::TAU * rng.uniform();
                    let o = Vec3::new(b * phi.cos(), b * phi.sin(), -5.0);
                    let rep = heron::trace::trace(&scene, accel, o, Vec3::Z, lambda, &path, None)
                        .unwrap();
                    let last = rep.events.last().unwrap();
                    assert_eq!(rep.events.len(), k as usize + 3);
                    let out = Vec3::from_array(last.outgoing.unwrap())
                        .as_dvec3()
                        .normalize();
                    // The viewer looks back along −out; θ from the antisolar direction +z.
                    let v = -out;
                    v.cross(glam::DVec3::Z).length().atan2(v.z).to_degrees()
                })
                .collect();
            let (lo, hi) = (35.0, 60.0);
            let mut hist = vec![0u32; ((hi - lo) / BIN) as usize];
            for t in thetas {
                if (lo..hi).contains(&t) {
                    hist[((t - lo) / BIN) as usize] += 1;
                }
            }
            let (imax, &cmax) = hist.iter().enumerate().max_by_key(|&(_, c)| *c).unwrap();
            let got = lo + (imax as f64 + 0.5) * BIN;
            let want = descartes::rainbow_angle(water_n(lambda), k).to_degrees();
            println!(
                "Monte Carlo {lambda} nm k = {k}: caustic bin {got:.3}° ({cmax} of {RAYS} rays), Descartes {want:.4}°"
            );
            assert!(
                (got - want).abs() < 0.05,
                "{lambda} nm k = {k}: {got}° vs {want}°"
            );
        }
    }
}
