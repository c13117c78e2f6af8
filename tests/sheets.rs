//! The thin dielectric sheet (src/bsdf/thin_dielectric.rs) and diffuse transmission
//! (src/bsdf/diffuse_transmission.rs) against physics and against their own sampling:
//!
//! - chi-square of diffuse transmission's `sample` against its `pdf` over the whole
//!   sphere (both lobes), each sample's f and pdf against `eval` and `pdf`;
//! - the thin sheet's delta lobes: the frequency of reflection against R' = 2R/(1 + R)
//!   (Pearson, two cells), the directions exactly mirror and −ωo;
//! - white furnace: R' + T' = 1 at every angle and lane (dispersive too), and diffuse
//!   transmission with ρ_r + τ = 1 has albedo 1 on every lane;
//! - reciprocity of both;
//! - polarisation: the sheet's reflection at Brewster's angle is completely polarised,
//!   and a rendered sheet gives the unpolarised image in S0;
//! - a render: a sheet in front of an emitter passes T' of it.
mod common;

use common::chi2::{assert_all, chi2_p_value, pearson, Chi2, Outcome, Spherical, ALPHA};
use common::render::render_with;
use glam::{Vec2, Vec3, Vec4};
use heron::bsdf::fresnel::fresnel_dielectric;
use heron::bsdf::polarization::Polarizing;
use heron::bsdf::{
    BsdfContext, DiffuseTransmission, LobeFlags, Material, ThinDielectric, TransportMode,
};
use heron::math::warp::uniform_sphere;
use heron::math::{Frame, Rng};
use heron::scene::load::load_scene_from_str;
use heron::spectrum::ior::{self, Ior};
use heron::spectrum::{DenseSpectrum, SampledWavelengths};
use std::path::Path;

fn wl1() -> SampledWavelengths<1> {
    SampledWavelengths::new([550.0], [1.0 / 470.0])
}

/// Four lanes: a hero at 450 nm and its companions 117.5 nm apart.
fn wl4() -> SampledWavelengths<4> {
    SampledWavelengths::new([450.0, 567.5, 685.0, 802.5], [1.0 / 470.0; 4])
}

fn ctx<const N: usize>() -> BsdfContext {
    BsdfContext::radiance::<N>()
}

fn wo_at(theta_deg: f32, inside: bool) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), 0.7f32);
    let w = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    if inside {
        Vec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}

fn sheet(ior: Ior) -> Material {
    Material::ThinDielectric(ThinDielectric::new(ior))
}

fn nsf11() -> Ior {
    ior::named("N-SF11").expect("N-SF11 is in the catalogue")
}

fn translucent(r: DenseSpectrum, t: DenseSpectrum) -> Material {
    Material::DiffuseTransmission(DiffuseTransmission {
        reflectance: r,
        transmittance: t,
    })
}

/// A reflectance that rises across the spectrum (0.1 at 360 nm to 0.7 at 830 nm) and
/// its complement: ρ_r + τ = 1 at every wavelength, ρ_r/τ not constant.
fn ramp() -> (DenseSpectrum, DenseSpectrum) {
    let r = DenseSpectrum::from_fn(|l| 0.1 + 0.6 * (l - 360.0) / 470.0);
    let t = DenseSpectrum::from_fn(|l| 0.9 - 0.6 * (l - 360.0) / 470.0);
    (r, t)
}

/// Samples per chi-square test: 5·10⁵. Over 24 × 48 cells a wrong lobe probability of
/// 1% (mass q = 0.5 moved) raises χ² by N q ε² ≈ 25 against a threshold of ~3.7 √(2
/// dof) ≈ 170: this catches a wrong cosine or a wrong side, while a wrong lobe choice
/// is caught exactly by the per-sample pdf check. Measured: the file runs in ~3 s.
const SAMPLES: usize = 500_000;
/// Diffuse transmission: 5 angles, masked lobes, 4 lanes (the Bonferroni divisor).
const CHI2_TESTS: usize = 7;
/// The sheet's lobe-frequency tests (their own Bonferroni divisor).
const LOBE_TESTS: usize = 10;

fn diffuse_chi2<const N: usize>(
    name: &str,
    m: &Material,
    wo: Vec3,
    wl: &SampledWavelengths<N>,
    c: BsdfContext,
) -> Outcome {
    let mut bad = Vec::new();
    let mut o = Chi2::new(name, SAMPLES, CHI2_TESTS).sphere(
        &Spherical::sphere(Vec3::Z),
        |r| {
            let s = m.sample(wo, r.uniform(), Vec2::new(r.uniform(), r.uniform()), wl, &c)?;
            let e = m.eval(wo, s.wi, wl, &c).f;
            let ok = (0..N).all(|i| (s.f.0[i] - e.0[i]).abs() <= 1e-6)
                && !s.is_specular()
                && s.is_transmission() == (s.wi.z * wo.z < 0.0)
                && c.lobes.allows(s.flags);
            if !ok && bad.len() < 4 {
                bad.push(format!("{:?}: f {:?} vs {:?}", s.wi, s.f.0, e.0));
            }
            Some((s.wi, s.pdf))
        },
        |wi| m.pdf(wo, wi, wl, &c),
    );
    if !bad.is_empty() {
        o.problems.push(format!("f ≠ eval or wrong lobe: {bad:?}"));
    }
    o
}

#[test]
fn chi2_diffuse_transmission() {
    let m = translucent(DenseSpectrum::constant(0.3), DenseSpectrum::constant(0.5));
    let mut out = Vec::new();
    for (t, inside) in [
        (0.0, false),
        (30.0, false),
        (60.0, false),
        (85.0, false),
        (30.0, true),
    ] {
        let name = format!("DiffuseTransmission θo = {t}° inside = {inside}");
        out.push(diffuse_chi2(
            &name,
            &m,
            wo_at(t, inside),
            &wl1(),
            ctx::<1>(),
        ));
    }
    // Only the transmission lobe allowed: the pdf is conditioned on it.
    let only_t = ctx::<1>().with_lobes(LobeFlags::DIFFUSE | LobeFlags::TRANSMISSION);
    out.push(diffuse_chi2(
        "DiffuseTransmission, transmission only",
        &m,
        wo_at(40.0, false),
        &wl1(),
        only_t,
    ));
    // Spectral ρ_r and τ: the hero's choose the lobe.
    let (r, t) = ramp();
    out.push(diffuse_chi2(
        "DiffuseTransmission, ramp, 4 lanes",
        &translucent(r, t),
        wo_at(50.0, true),
        &wl4(),
        ctx::<4>(),
    ));
    assert_eq!(out.len(), CHI2_TESTS);
    assert_all(&out);
}

/// R' = 2R/(1 + R) with R the unpolarised Fresnel reflectance of one face, written
/// here from the closed form.
fn r_sheet(cos: f32, eta: f32) -> f32 {
    let r = fresnel_dielectric(cos, 1.0 / eta);
    2.0 * r / (1.0 + r)
}

#[test]
fn sheet_chooses_its_lobes_with_probability_r_prime() {
    const N: usize = 200_000;
    let threshold = ALPHA / LOBE_TESTS as f64;
    let mut tests = 0;
    let mut report = Vec::new();
    for (name, ior, eta) in [
        ("n = 1.5", Ior::Constant(1.5), 1.5f32),
        (
            "n = 0.75 (less dense than outside)",
            Ior::Constant(0.75),
            0.75,
        ),
        ("N-SF11 hero 450 nm", nsf11(), nsf11().eval(450.0)),
    ] {
        let m = sheet(ior);
        let angles: &[f32] = if name.starts_with("n = 1.5") {
            &[0.0, 30.0, 60.0, 85.0]
        } else {
            &[10.0, 45.0, 70.0]
        };
        for &t in angles {
            let wo = wo_at(t, t == 30.0);
            let mut rng = Rng::new(7 + t as u64, 3);
            let mut refl = 0.0f64;
            for _ in 0..N {
                let s = m
                    .sample(wo, rng.uniform(), Vec2::ZERO, &wl4(), &ctx::<4>())
                    .unwrap();
                assert!(s.is_specular() && !s.ended_companions && s.eta == 1.0);
                if s.is_transmission() {
                    assert!((s.wi + wo).length() < 1e-6, "{name}: {:?}", s.wi);
                } else {
                    refl += 1.0;
                    assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                }
            }
            let rp = r_sheet(wo.z.abs(), eta) as f64;
            tests += 1;
            if rp >= 1.0 {
                // Total reflection at the first face: the sheet only reflects.
                assert_eq!(refl, N as f64, "{name} θ = {t}°");
                report.push(format!("{name} θ = {t}°: R' = 1, reflected all {N}"));
                continue;
            }
            let expected = [N as f64 * rp, N as f64 * (1.0 - rp)];
            let (stat, dof, _, _) = pearson(&[refl, N as f64 - refl], &expected);
            let p = chi2_p_value(stat, dof);
            report.push(format!(
                "{name} θ = {t}°: R' = {rp:.5}, chose {refl}, p = {p:.3}"
            ));
            assert!(p > threshold, "{}", report.join("\n"));
        }
    }
    assert_eq!(tests, LOBE_TESTS);
    println!("{}", report.join("\n"));
}

#[test]
fn sheet_conserves_energy_exactly_at_every_angle_and_lane() {
    for ior in [Ior::Constant(1.5), Ior::Constant(0.7), nsf11()] {
        let m = sheet(ior.clone());
        let mut worst = 0.0f32;
        for i in 0..=1000 {
            let cos = (i as f32 / 1000.0).max(1e-4);
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let c = ctx::<4>();
            // Both branches, each with its probability: E[weight] per lane.
            let r = m.sample(wo, 0.0, Vec2::ZERO, &wl4(), &c).unwrap();
            let t = m.sample(wo, 1.0 - 1e-7, Vec2::ZERO, &wl4(), &c);
            let mut albedo = r.weight() * r.pdf;
            if let Some(t) = t.filter(|t| t.is_transmission()) {
                albedo += t.weight() * t.pdf;
                // The hero's weight on either branch is 1: the sampling is perfect.
                assert!((t.weight().0[0] - 1.0).abs() < 1e-5);
            }
            for l in 0..4 {
                worst = worst.max((albedo.0[l] - 1.0).abs());
            }
            // The lanes of a dispersive sheet keep their own R'(λ).
            for l in 0..4 {
                let lam = wl4().lambda[l];
                let eta = ior.eval(lam);
                let expect = r_sheet(cos, eta) / r_sheet(cos, ior.eval(450.0));
                assert!(
                    (r.weight().0[l] - expect).abs() <= 1e-4 * expect.max(1.0),
                    "{ior:?} λ {lam}: {} vs {expect}",
                    r.weight().0[l]
                );
            }
        }
        println!("{ior:?}: max |R' + T' − 1| over 1001 angles × 4 lanes = {worst:e}");
        assert!(worst < 2e-6, "{ior:?}: {worst}");
    }
}

#[test]
fn diffuse_transmission_with_unit_albedo_is_a_white_furnace() {
    let (r, t) = ramp();
    let m = translucent(r, t);
    let mut rng = Rng::new(5, 5);
    for &th in &[0.0f32, 45.0, 80.0] {
        for inside in [false, true] {
            let wo = wo_at(th, inside);
            let n = 100_000;
            let mut sum = [0.0f64; 4];
            for _ in 0..n {
                let s = m
                    .sample(
                        wo,
                        rng.uniform(),
                        Vec2::new(rng.uniform(), rng.uniform()),
                        &wl4(),
                        &ctx::<4>(),
                    )
                    .unwrap();
                let w = s.weight();
                // The hero's weight is exactly ρ_r + τ = 1.
                assert!((w.0[0] - 1.0).abs() < 1e-5, "{:?}", w.0);
                for (acc, wl) in sum.iter_mut().zip(w.0) {
                    *acc += wl as f64 / n as f64;
                }
            }
            // Companions: ρ_r(λ)/P(r) or τ(λ)/P(t), mean 1 within a few standard
            // errors (their weights lie in [0.3, 3], σ < 1: SE < 0.003).
            for (l, s) in sum.iter().enumerate() {
                assert!((s - 1.0).abs() < 0.012, "θ {th} lane {l}: albedo {s}");
            }
            // And the deterministic quadrature of ∫ f |cos θi| dωi: ρ_r + τ on lane 0.
            let q = Spherical::sphere(Vec3::Z).integrate(
                |wi| m.eval(wo, wi, &wl1(), &ctx::<1>()).f.0[0] as f64 * wi.z.abs() as f64,
                1e-8,
            );
            assert!((q - 1.0).abs() < 1e-4, "quadrature {q}");
        }
    }
}

#[test]
fn both_are_reciprocal() {
    let mut rng = Rng::new(9, 9);
    let m = translucent(DenseSpectrum::constant(0.3), DenseSpectrum::constant(0.6));
    for _ in 0..20_000 {
        let wo = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let wi = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        for mode in [TransportMode::Radiance, TransportMode::Importance] {
            let c = ctx::<1>().with_mode(mode);
            let (a, b) = (
                m.eval(wo, wi, &wl1(), &c).f.0[0],
                m.eval(wi, wo, &wl1(), &c).f.0[0],
            );
            assert_eq!(a, b);
            assert_eq!(a > 0.0, m.pdf(wo, wi, &wl1(), &c) > 0.0);
        }
    }
    // The sheet: scattering ωo into ωi and back has the same weight f |cos| (delta
    // lobes: the deltas' weights per lane).
    let m = sheet(nsf11());
    for _ in 0..2000 {
        let wo = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let uc = rng.uniform();
        let c = ctx::<4>();
        let s = m.sample(wo, uc, Vec2::ZERO, &wl4(), &c).unwrap();
        let back = m.sample(s.wi, uc, Vec2::ZERO, &wl4(), &c).unwrap();
        assert!((back.wi - wo).length() < 1e-6);
        for l in 0..4 {
            let (x, y) = (s.f.0[l] * s.wi.z.abs(), back.f.0[l] * back.wi.z.abs());
            assert!((x - y).abs() < 1e-6, "{x} vs {y}");
        }
    }
}

/// The sheet's reflected light at Brewster's angle (tan θB = n) is completely
/// polarised (R'_p = 0), at normal incidence not at all; the transmitted light is
/// partially polarised by (T'_s − T'_p)/(T'_s + T'_p) at any other angle.
#[test]
fn sheet_reflection_at_brewsters_angle_is_completely_polarised() {
    let m = sheet(Ior::Constant(1.5));
    let dolp = |wo: Vec3, wi: Vec3| {
        let Polarizing::Mueller { m, .. } =
            m.mueller(wo, wi, LobeFlags::ALL, &wl1(), &Frame::from_z(Vec3::Z))
        else {
            panic!("the sheet polarises")
        };
        let s = m[0] * Vec4::new(1.0, 0.0, 0.0, 0.0);
        s.y.hypot(s.z).hypot(s.w) / s.x
    };
    let tb = 1.5f32.atan();
    let wi = Vec3::new(tb.sin(), 0.0, tb.cos());
    let wo = Vec3::new(-wi.x, 0.0, wi.z);
    assert!((dolp(wo, wi) - 1.0).abs() < 1e-5, "{}", dolp(wo, wi));
    assert!(dolp(Vec3::Z, Vec3::Z) < 1e-6);
    assert!(dolp(-Vec3::Z, Vec3::Z) < 1e-6);
    // Transmitted at θB: T'_s = 1 − R'_s, T'_p = 1.
    let (rs, _) = heron::bsdf::fresnel::fresnel_dielectric_sp(tb.cos(), 1.0 / 1.5);
    let ts = 1.0 - 2.0 * rs / (1.0 + rs);
    let expect = (1.0 - ts) / (1.0 + ts);
    let got = dolp(-wi, wi);
    assert!((got - expect).abs() < 1e-5, "{got} vs {expect}");
}

/// Camera at z = 3 looking down −z through a sheet tilted by `tilt_deg` about x at
/// z = 1 to a uniform two-sided emitter (Y = 1) at z = 0; the field is ±0.3°.
fn sheet_in_front_of_light(material: &str, tilt_deg: f32, polarization: bool) -> String {
    let (s, c) = tilt_deg.to_radians().sin_cos();
    format!(
        "background = 0.0\n[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nd = 50.0\nresolution = [8, 8]\n\
[render]\nintegrator = \"path\"\nspp = 256\nmax_depth = 8\npolarization = {polarization}\n\
[materials.sheet]\n{material}\n[materials.black]\ntype = \"lambertian\"\nrho_d = 0.0\n\
[[shapes]]\ntype = \"quad\"\norigin = [-2.0, {oy}, {oz}]\nedge1 = [4.0, 0.0, 0.0]\nedge2 = [0.0, {ey}, {ez}]\nmaterial = \"sheet\"\n\
[[shapes]]\ntype = \"quad\"\norigin = [-3.0, -3.0, 0.0]\nedge1 = [6.0, 0.0, 0.0]\nedge2 = [0.0, 6.0, 0.0]\nmaterial = \"black\"\nemission = 1.0\ntwo_sided = true\n",
        oy = -2.0 * c,
        oz = 1.0 - 2.0 * s,
        ey = 4.0 * c,
        ez = 4.0 * s,
    )
}

/// A sheet in front of a light passes T' of it: at normal incidence (T' = 1 − 2R/(1 + R)
/// with R = 0.04, 0.9231) and at 30° (0.9203; tilted further, the mirror direction would
/// point at the emitter); the sheet's reflection sends the rest back
/// into a black scene. Every camera ray meets one sheet and the emitter, so a pixel's
/// value is Bernoulli(T') × 1 averaged over 256 samples: the 64 pixels' mean has a
/// standard error of √(T'(1 − T')/16384) < 0.003; held to 4 of them. With polarised
/// transport, S0 is the unpolarised image (the one event's Mueller matrix has [0][0]
/// = 1 after normalising, and the renders draw the same random numbers), and the
/// transmitted light's degree of polarisation at 30° is (T'_s − T'_p)/(T'_s + T'_p).
#[test]
fn a_sheet_in_front_of_a_light_passes_t_prime_of_it() {
    for tilt in [0.0f32, 30.0] {
        let load = |pol: bool| {
            load_scene_from_str(
                &sheet_in_front_of_light("type = \"thin-dielectric\"\nior = 1.5", tilt, pol),
                Path::new("sheet.toml"),
            )
            .unwrap()
        };
        let plain = render_with(&load(false), |_| {});
        let (y, se) = common::render::mean_se_y(&plain);
        let cos = tilt.to_radians().cos();
        let t = 1.0 - r_sheet(cos, 1.5) as f64;
        println!("tilt {tilt}°: Y = {y:.5} ± {se:.5}, T' = {t:.5}");
        assert!((y - t).abs() < 4.0 * se.max(1e-4), "{y} ± {se} vs T' {t}");
        let pol = render_with(&load(true), |_| {});
        for (a, b) in plain.xyz.iter().zip(&pol.xyz) {
            for j in 0..3 {
                assert!(
                    (a[j] - b[j]).abs() <= 1e-5 + 1e-4 * a[j].abs(),
                    "S0 {b:?} against the unpolarised {a:?}"
                );
            }
        }
        let (rs, rp) = heron::bsdf::fresnel::fresnel_dielectric_sp(cos, 1.0 / 1.5);
        let (ts, tp) = (1.0 - 2.0 * rs / (1.0 + rs), 1.0 - 2.0 * rp / (1.0 + rp));
        let expect = ((ts - tp) / (ts + tp)).abs() as f64;
        let st = pol.stokes.as_ref().unwrap();
        for (xyz, p) in pol.xyz.iter().zip(st) {
            let s0 = xyz[1] as f64;
            if s0 > 0.0 {
                let d = (p[0][1] as f64).hypot(p[1][1] as f64).hypot(p[2][1] as f64) / s0;
                assert!(
                    (d - expect).abs() < 2e-3,
                    "tilt {tilt}: DoLP {d} vs {expect}"
                );
            }
        }
    }
}

/// Diffuse transmission through a sheet in front of the light: the camera sees τ of
/// the emitter's radiance (a Lambertian transmitter lit by a uniform emitter filling
/// its far hemisphere, seen from any direction: τ/π × π L), the reflection side sees
/// black. ρ_r = 0.3, τ = 0.5: the emitter (6 × 6 at distance 1) fills most but not all
/// of the far hemisphere, so the expected value is τ times the form factor of the
/// square seen from the sheet's centre region, held to 2%.
#[test]
fn a_diffuse_transmitter_in_front_of_a_light_passes_tau_of_it() {
    let toml = sheet_in_front_of_light(
        "type = \"diffuse-transmission\"\nreflectance = 0.3\ntransmittance = 0.5",
        0.0,
        false,
    );
    let s = load_scene_from_str(&toml, Path::new("translucent.toml")).unwrap();
    let f = render_with(&s, |o| o.settings.spp = 64);
    let (y, se) = common::render::mean_se_y(&f);
    // Form factor of a 6 × 6 square at distance 1 from a point on its axis (a sheet
    // point near the centre: the camera's ±0.3° field sees |x| < 0.02):
    // F = 4 × (1/2π)[a/√(1+a²) atan(b/√(1+a²)) + b/√(1+b²) atan(a/√(1+b²))], a = b = 3.
    let a = 3.0f64;
    let k = (1.0 + a * a).sqrt();
    let ff = 4.0 / (2.0 * std::f64::consts::PI) * 2.0 * (a / k * (a / k).atan());
    let expect = 0.5 * ff;
    println!("diffuse transmission: Y = {y:.5} ± {se:.5}, τ F = {expect:.5}");
    assert!((y - expect).abs() < 0.02 * expect, "{y} vs {expect}");
}

#[test]
fn bad_values_are_one_line_errors() {
    let bad = |m: &str| {
        let t = format!(
            "[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [8, 8]\n[materials.p]\n{m}\n"
        );
        load_scene_from_str(&t, Path::new("bad.toml"))
            .unwrap_err()
            .to_string()
    };
    let e = bad("type = \"diffuse-transmission\"\nreflectance = 0.6\ntransmittance = 0.6");
    assert!(
        e.contains("materials.p") && e.contains("reflectance + transmittance <= 1"),
        "{e}"
    );
    let e = bad("type = \"diffuse-transmission\"\nreflectance = 1.5\ntransmittance = 0");
    assert!(e.contains("materials.p") && !e.contains('\n'), "{e}");
    let e = bad("type = \"diffuse-transmission\"\nreflectance = 0.5");
    assert!(e.contains("transmittance"), "{e}");
    let e = bad("type = \"thin-dielectric\"\nior = \"unobtainium\"");
    assert!(e.contains("materials.p.ior"), "{e}");
    let e = bad("type = \"thin-dielectric\"\nior = 1.5\nroughness = 0.1");
    assert!(e.contains("roughness"), "{e}");
    assert!(!e.trim_end().contains('\n'), "{e}");
    // A thin sheet cannot hold a medium: it is not an interface.
    let t = "[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [8, 8]\n\
[materials.pane]\ntype = \"thin-dielectric\"\nior = 1.5\n\
[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"pane\"\nmedium = { type = \"henyey-greenstein\", sigma_a = 0.1, sigma_s = 0.5 }\n";
    let e = load_scene_from_str(t, Path::new("m.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("not an interface"), "{e}");
}
