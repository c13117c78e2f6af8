//! Materials' `sample`, `pdf` and `eval` against each other and against physics:
//!
//! - chi-square tests (tests/common/chi2.rs) of `sample` against `pdf` for every
//!   non-delta material at incident angles θo ∈ {0°, 30°, 60°, 85°} (and inside the
//!   rough dielectric), with every sample's pdf and f checked against `pdf` and `eval`;
//! - reciprocity f(ωo, ωi) = f(ωi, ωo) for reflection, and the adjoint relation of
//!   transmission (radiance against importance);
//! - consistency: `pdf` is zero exactly where `eval` is;
//! - energy: directional albedos E[f |cos θi| / pdf] of the ideal materials are 1, those
//!   of the rough ones are ≤ 1 and equal a deterministic quadrature of ∫ f |cos θi| dωi;
//!   the single-scattering losses are tabulated below;
//! - the dispersion semantics of the smooth and rough dielectrics (which lanes a sample
//!   keeps, ends or weights, and when).
//!
//! Directions are in the local shading frame, z = the outward normal, pointing away
//! from the surface (src/bsdf/mod.rs).
mod common;

use common::chi2::{assert_all, Chi2, Outcome, Spherical};
use glam::{Vec2, Vec3};
use heron::bsdf::fresnel::fresnel_dielectric;
use heron::bsdf::microfacet::TrowbridgeReitz;
use heron::bsdf::{
    BsdfContext, Conductor, Dielectric, Glossy, Lambertian, LobeFlags, Material, Mirror,
    RoughConductor, RoughDielectric, TransportMode,
};
use heron::math::warp::uniform_sphere;
use heron::math::Rng;
use heron::spectrum::ior::{self, Ior};
use heron::spectrum::metals::{self, ComplexIor};
use heron::spectrum::{DenseSpectrum, SampledWavelengths};

// ----------------------------------------------------------------------------------
// Materials and directions
// ----------------------------------------------------------------------------------

fn lambertian(rho: f32) -> Material {
    Material::Lambertian(Lambertian {
        rho_d: DenseSpectrum::constant(rho),
    })
}

fn glossy(rho_d: f32, rho_s: f32, s: f32, base: Option<Dielectric>) -> Material {
    Material::Glossy(Glossy {
        rho_d: DenseSpectrum::constant(rho_d),
        rho_s,
        shininess: s,
        base,
        textures: None,
    })
}

fn gold() -> ComplexIor {
    metals::named("Au").expect("gold is in the catalogue")
}

/// A metal with F ≥ 0.99999 at every angle: n = 1, k = 1000 (R(0°) = k²/(4 + k²)).
fn perfect_metal() -> ComplexIor {
    ComplexIor {
        n: DenseSpectrum::constant(1.0),
        k: DenseSpectrum::constant(1000.0),
    }
}

fn rough_conductor(ior: ComplexIor, alpha: f32) -> Material {
    Material::RoughConductor(RoughConductor {
        ior,
        distribution: TrowbridgeReitz { alpha },
        alpha_texture: None,
    })
}

fn rough_dielectric(ior: Ior, alpha: f32) -> Material {
    Material::RoughDielectric(RoughDielectric {
        interface: Dielectric::new(ior, true),
        distribution: TrowbridgeReitz { alpha },
        alpha_texture: None,
    })
}

fn glass() -> Ior {
    Ior::Constant(1.5)
}

fn nsf11() -> Ior {
    ior::named("N-SF11").expect("N-SF11 is in the catalogue")
}

/// One lane at 550 nm.
fn wl1() -> SampledWavelengths<1> {
    SampledWavelengths::new([550.0], [1.0 / 470.0])
}

/// Four lanes: a hero at 450 nm and its companions 117.5 nm apart.
fn wl4() -> SampledWavelengths<4> {
    SampledWavelengths::new([450.0, 567.5, 685.0, 802.5], [1.0 / 470.0; 4])
}

fn ctx<const N: usize>(mode: TransportMode) -> BsdfContext {
    BsdfContext::radiance::<N>().with_mode(mode)
}

/// The direction at θo (degrees) from the normal and azimuth 0.7 rad (not a special
/// one: the materials are isotropic, so a φ-dependence would be a bug); below the
/// surface when `inside`.
fn wo_at(theta_deg: f32, inside: bool) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), 0.7f32);
    let w = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    if inside {
        Vec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}

fn mirror_dir(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// The direction refracted from `wo` by a smooth interface of relative index
/// `eta` = n_inside/n_outside (Snell's law, written out here independently of src).
fn refracted(wo: Vec3, eta: f32) -> Option<Vec3> {
    let (ni_over_nt, sign) = if wo.z > 0.0 {
        (1.0 / eta, 1.0)
    } else {
        (eta, -1.0)
    };
    let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
    let sin_t = ni_over_nt * sin_o;
    if sin_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let h = Vec2::new(wo.x, wo.y).normalize_or_zero();
    Some(Vec3::new(-h.x * sin_t, -h.y * sin_t, -sign * cos_t))
}

const ANGLES: [f32; 4] = [0.0, 30.0, 60.0, 85.0];

// ----------------------------------------------------------------------------------
// Chi-square tests
// ----------------------------------------------------------------------------------

/// Samples per chi-square test: 10⁶. With 24 × 48 cells over the sphere (300–1100 after
/// pooling) and the Bonferroni threshold 0.01/96 ≈ 1e-4, a density wrong by a relative ε
/// over a region holding a fraction q of the mass raises χ² by about N q ε², which must
/// exceed ~3.7 √(2 dof) ≈ 130 to be rejected: 10⁶ samples see ε ≈ 4% over q = 0.1, or
/// a 1% error over the whole lobe (and the zoomed α = 0.05 tests resolve those lobes in
/// 0.4° cells instead of 7.5°). Any disagreement between a sample's pdf or f and
/// `pdf`/`eval` is caught at 1e-3 per sample whatever N. The file runs in ~17 s.
const SAMPLES: usize = 1_000_000;

const LAMBERTIAN_TESTS: usize = 5;
const GLOSSY_TESTS: usize = 12;
const GLOSSY_BASE_TESTS: usize = 4;
const ROUGH_CONDUCTOR_TESTS: usize = 19;
const ROUGH_DIELECTRIC_TESTS: usize = 54;
const DISPERSIVE_TESTS: usize = 2;
/// Chi-square tests in this file (the Bonferroni divisor); each test function checks
/// its own count.
const CHI2_TESTS: usize = LAMBERTIAN_TESTS
    + GLOSSY_TESTS
    + GLOSSY_BASE_TESTS
    + ROUGH_CONDUCTOR_TESTS
    + ROUGH_DIELECTRIC_TESTS
    + DISPERSIVE_TESTS;

/// `sample` against `pdf` over `dom`. Each sample must also be a unit, non-delta
/// direction whose f is finite, non-negative and equal to `eval` (relative 1e-3, per
/// lane).
fn bsdf_chi2<const N: usize>(
    name: &str,
    m: &Material,
    wo: Vec3,
    wl: &SampledWavelengths<N>,
    ctx: BsdfContext,
    dom: &Spherical,
) -> Outcome {
    // A rough dielectric's `sample` computes f and pdf from the microfacet normal it drew,
    // `eval` and `pdf` from the half vector they recompute from (ωo, ωi); the two agree to
    // f32 rounding (~1e-7), except where the Fresnel term has its infinite slope: at the
    // critical angle, F = 1 − O(√(θc − θ)), and for a refraction that leaves the
    // microfacet at grazing angle, where T and cos θt are computed from the other side's
    // cosine (dcos θt/dcos θi = n² cos θi / cos θt). There a rounding of 1e-7 moves f
    // and the pdf by more than 1e-3: measured in 0 to 8 of 5·10⁵ samples per test.
    // (`reflection_is_reciprocal` and `transmission_obeys_the_adjoint_relation` map
    // these pairs.) Other materials must agree on every sample.
    let allowed = if matches!(m, Material::RoughDielectric(_)) {
        2e-5
    } else {
        0.0
    };
    let mut bad = Vec::new();
    let mut nbad = 0usize;
    let mut o = Chi2::new(name, SAMPLES, CHI2_TESTS)
        .allow_mismatches(allowed)
        .sphere(
            dom,
            |r| {
                let uc = r.uniform();
                let u = Vec2::new(r.uniform(), r.uniform());
                let s = m.sample(wo, uc, u, wl, &ctx)?;
                let e = m.eval(wo, s.wi, wl, &ctx);
                let f = e.f;
                // eval reports the end of the companions exactly when sample does.
                let f_ok = e.ended_companions == s.ended_companions
                    && (0..N).all(|i| {
                        let (a, b) = (s.f.0[i], f.0[i]);
                        a.is_finite() && a >= 0.0 && (a - b).abs() <= 1e-3 * a.max(b) + 1e-30
                    });
                let ok = s.wi.is_finite()
                    && (s.wi.length() - 1.0).abs() < 1e-4
                    && !s.is_specular()
                    && s.pdf > 0.0
                    && f_ok;
                if !ok {
                    nbad += 1;
                    if bad.len() < 4 {
                        bad.push(format!(
                            "wi {:?}: f {:?} vs eval {:?}, ended {} vs {}, pdf {}, flags {:?}",
                            s.wi,
                            s.f.0,
                            f.0,
                            s.ended_companions,
                            e.ended_companions,
                            s.pdf,
                            s.flags
                        ));
                    }
                }
                Some((s.wi, s.pdf))
            },
            |wi| m.pdf(wo, wi, wl, &ctx),
        );
    if nbad as f64 > allowed * SAMPLES as f64 {
        o.problems.push(format!(
            "{nbad} samples are not unit non-delta directions with f = eval: {}",
            bad.join("; ")
        ));
    }
    o
}

fn sphere() -> Spherical {
    Spherical::sphere(Vec3::Z)
}

#[test]
fn chi2_lambertian() {
    let m = lambertian(0.7);
    let mut out = Vec::new();
    let cases = ANGLES
        .iter()
        .map(|&t| (t, false))
        .chain(std::iter::once((30.0, true)));
    for (t, inside) in cases {
        let name = format!(
            "Lambertian θo = {t}°{}",
            if inside { " inside" } else { "" }
        );
        let wo = wo_at(t, inside);
        out.push(bsdf_chi2(
            &name,
            &m,
            wo,
            &wl1(),
            ctx::<1>(TransportMode::Radiance),
            &sphere(),
        ));
    }
    assert_eq!(out.len(), LAMBERTIAN_TESTS);
    assert_all(&out);
}

#[test]
fn chi2_glossy() {
    let mut out = Vec::new();
    for &(rd, rs, s) in &[
        (0.5f32, 0.4f32, 10.0f32),
        (0.0, 0.9, 42.0),
        (0.2, 0.7, 200.0),
    ] {
        let m = glossy(rd, rs, s, None);
        for &t in &ANGLES {
            out.push(bsdf_chi2(
                &format!("Glossy ρd = {rd}, ρs = {rs}, s = {s}, θo = {t}°"),
                &m,
                wo_at(t, false),
                &wl1(),
                ctx::<1>(TransportMode::Radiance),
                &sphere(),
            ));
        }
    }
    assert_eq!(out.len(), GLOSSY_TESTS);
    assert_all(&out);
}

/// The non-delta lobes of the seed's glossy-over-refractive material.
const NON_DELTA: LobeFlags = LobeFlags::DIFFUSE
    .union(LobeFlags::GLOSSY)
    .union(LobeFlags::REFLECTION)
    .union(LobeFlags::TRANSMISSION);

#[test]
fn chi2_glossy_over_dielectric_non_delta_part() {
    let m = glossy(0.1, 0.5, 42.0, Some(Dielectric::new(glass(), true)));
    let mut out = Vec::new();
    for &t in &ANGLES {
        out.push(bsdf_chi2(
            &format!("Glossy over glass, non-delta lobes, θo = {t}°"),
            &m,
            wo_at(t, false),
            &wl1(),
            ctx::<1>(TransportMode::Radiance).with_lobes(NON_DELTA),
            &sphere(),
        ));
    }
    assert_eq!(out.len(), GLOSSY_BASE_TESTS);
    assert_all(&out);
}

/// A cone of half-angle 8α about `axis`: it holds most of a GGX lobe of roughness α
/// (whose reflected directions spread about 2α), in 24 × 48 cells of α/3 × 7.5°.
fn zoom(axis: Vec3, alpha: f32) -> Spherical {
    Spherical::cone(axis, 8.0 * alpha as f64)
}

#[test]
fn chi2_rough_conductor() {
    let mut out = Vec::new();
    for &a in &[0.05f32, 0.2, 0.5, 1.0] {
        let m = rough_conductor(gold(), a);
        for &t in &ANGLES {
            out.push(bsdf_chi2(
                &format!("RoughConductor Au α = {a}, θo = {t}°"),
                &m,
                wo_at(t, false),
                &wl1(),
                ctx::<1>(TransportMode::Radiance),
                &sphere(),
            ));
        }
    }
    let m = rough_conductor(gold(), 0.05);
    for &t in &[0.0f32, 30.0, 60.0] {
        let wo = wo_at(t, false);
        out.push(bsdf_chi2(
            &format!("RoughConductor Au α = 0.05, θo = {t}°, cone about the mirror direction"),
            &m,
            wo,
            &wl1(),
            ctx::<1>(TransportMode::Radiance),
            &zoom(mirror_dir(wo), 0.05),
        ));
    }
    assert_eq!(out.len(), ROUGH_CONDUCTOR_TESTS);
    assert_all(&out);
}

#[test]
fn chi2_rough_dielectric() {
    let mut out = Vec::new();
    for &a in &[0.05f32, 0.2, 0.5] {
        let m = rough_dielectric(glass(), a);
        for inside in [false, true] {
            for &t in &ANGLES {
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    out.push(bsdf_chi2(
                        &format!(
                            "RoughDielectric n = 1.5 α = {a}, θo = {t}° {}, {mode:?}",
                            if inside { "inside" } else { "outside" }
                        ),
                        &m,
                        wo_at(t, inside),
                        &wl1(),
                        ctx::<1>(mode),
                        &sphere(),
                    ));
                }
            }
        }
    }
    // α = 0.05 zoomed on its reflection and transmission lobes.
    let m = rough_dielectric(glass(), 0.05);
    for &t in &[0.0f32, 30.0, 60.0] {
        let wo = wo_at(t, false);
        out.push(bsdf_chi2(
            &format!("RoughDielectric α = 0.05, θo = {t}°, cone about the mirror direction"),
            &m,
            wo,
            &wl1(),
            ctx::<1>(TransportMode::Radiance),
            &zoom(mirror_dir(wo), 0.05),
        ));
        out.push(bsdf_chi2(
            &format!("RoughDielectric α = 0.05, θo = {t}°, cone about the refracted direction"),
            &m,
            wo,
            &wl1(),
            ctx::<1>(TransportMode::Radiance),
            &zoom(refracted(wo, 1.5).unwrap(), 0.05),
        ));
    }
    assert_eq!(out.len(), ROUGH_DIELECTRIC_TESTS);
    assert_all(&out);
}

/// A dispersive rough dielectric with four lanes whose companions are alive: the
/// direction is the hero's, so the density must be the hero's.
#[test]
fn chi2_rough_dielectric_dispersive() {
    let m = rough_dielectric(nsf11(), 0.2);
    let mut out = Vec::new();
    for inside in [false, true] {
        let wo = wo_at(30.0, inside);
        let c = ctx::<4>(TransportMode::Radiance);
        assert!(c.companions_alive);
        out.push(bsdf_chi2(
            &format!(
                "RoughDielectric N-SF11 α = 0.2, 4 lanes, θo = 30° {}",
                if inside { "inside" } else { "outside" }
            ),
            &m,
            wo,
            &wl4(),
            c,
            &sphere(),
        ));
        // The density is the hero's: the same as with the hero alone.
        let hero = SampledWavelengths::<1>::new([wl4().lambda[0]], [wl4().pdf[0]]);
        let mut rng = Rng::new(17, inside as u64);
        for _ in 0..10_000 {
            let wi = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
            let p4 = m.pdf(wo, wi, &wl4(), &c);
            let p1 = m.pdf(wo, wi, &hero, &ctx::<1>(TransportMode::Radiance));
            assert!((p4 - p1).abs() <= 1e-6 * p1.max(p4), "{p4} vs {p1}");
        }
    }
    assert_eq!(out.len(), DISPERSIVE_TESTS);
    assert_all(&out);
}

/// With its delta lobes masked out, the glossy-over-dielectric material must sample
/// only its Phong lobes, with the density conditioned on that choice (BsdfContext::lobes:
/// "the pdf it returns is conditioned on this choice"; Glossy::weights: "selection
/// weights … under ctx.lobes"), i.e. the density of the same Phong lobes without a base.
#[test]
fn glossy_over_dielectric_masked_pdf_is_conditioned_on_the_allowed_lobes() {
    let with_base = glossy(0.2, 0.7, 42.0, Some(Dielectric::new(glass(), true)));
    let without = glossy(0.2, 0.7, 42.0, None);
    let masked = ctx::<1>(TransportMode::Radiance).with_lobes(NON_DELTA);
    let all = ctx::<1>(TransportMode::Radiance);
    let mut rng = Rng::new(8, 8);
    let mut worst = (1.0f32, Vec3::ZERO, Vec3::ZERO);
    for _ in 0..10_000 {
        let wo = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let wi = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let (a, b) = (
            with_base.pdf(wo, wi, &wl1(), &masked),
            without.pdf(wo, wi, &wl1(), &all),
        );
        if b > 0.0 && (a / b - 1.0).abs() > (worst.0 - 1.0).abs() {
            worst = (a / b, wo, wi);
        }
    }
    // How many samples come back empty, against the Phong lobes' own loss below the
    // horizon.
    let wo = wo_at(30.0, false);
    let lost = |m: &Material, c: &BsdfContext| {
        let mut r = Rng::new(9, 9);
        (0..100_000)
            .filter(|_| {
                let uc = r.uniform();
                let u = Vec2::new(r.uniform(), r.uniform());
                m.sample(wo, uc, u, &wl1(), c).is_none()
            })
            .count()
    };
    let (lost_base, lost_plain) = (lost(&with_base, &masked), lost(&without, &all));
    assert!(
        (worst.0 - 1.0).abs() < 1e-5 && lost_base.abs_diff(lost_plain) < 1_000,
        "with the delta lobes masked out, pdf is {} × the Phong lobes' own density \
         (wo {:?}, wi {:?}), and {lost_base} of 100000 samples return None against \
         {lost_plain} for the same lobes without a base: the base still takes its \
         selection weight 1 of ρd + ρs + 1",
        worst.0,
        worst.1,
        worst.2
    );
}

// ----------------------------------------------------------------------------------
// Reciprocity and consistency
// ----------------------------------------------------------------------------------

/// Every non-delta material (one lane).
fn non_delta_materials() -> Vec<(String, Material)> {
    let mut v = vec![
        ("Lambertian".to_string(), lambertian(0.7)),
        ("Glossy 0.5/0.4/10".into(), glossy(0.5, 0.4, 10.0, None)),
        ("Glossy 0/0.9/42".into(), glossy(0.0, 0.9, 42.0, None)),
        ("Glossy 0.2/0.7/200".into(), glossy(0.2, 0.7, 200.0, None)),
        (
            "Glossy over glass".into(),
            glossy(0.1, 0.5, 42.0, Some(Dielectric::new(glass(), true))),
        ),
        (
            "DiffuseTransmission 0.3/0.5".into(),
            Material::DiffuseTransmission(heron::bsdf::DiffuseTransmission {
                reflectance: DenseSpectrum::constant(0.3),
                transmittance: DenseSpectrum::constant(0.5),
            }),
        ),
    ];
    for &a in &[0.05f32, 0.2, 0.5, 1.0] {
        v.push((
            format!("RoughConductor α = {a}"),
            rough_conductor(gold(), a),
        ));
        v.push((
            format!("RoughDielectric α = {a}"),
            rough_dielectric(glass(), a),
        ));
    }
    v
}

fn random_dir(rng: &mut Rng) -> Vec3 {
    uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()))
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-30
}

/// cos θc of glass (n = 1.5) seen from inside: sin θc = 1/n.
const COS_CRITICAL: f32 = 0.745_356;

/// f(ωo, ωi) = f(ωi, ωo) for reflection pairs (relative 1e-4). For the rough
/// dielectric, inside reflections whose microfacet angle is within 1e-3 (in cosine) of
/// the critical angle are held to 1e-2 only: there F = 1 − O(√(θc − θ)) has an
/// infinite slope, and the two orders round the half vector differently (measured:
/// ~1 pair in 50 000, worst 5e-4).
#[test]
fn reflection_is_reciprocal() {
    let mut rng = Rng::new(21, 3);
    for (name, m) in non_delta_materials() {
        let dielectric = matches!(m, Material::RoughDielectric(_));
        for mode in [TransportMode::Radiance, TransportMode::Importance] {
            let c = ctx::<1>(mode);
            let mut near_critical = 0;
            for _ in 0..20_000 {
                let wo = random_dir(&mut rng);
                let mut wi = random_dir(&mut rng);
                if wi.z * wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                let a = m.eval(wo, wi, &wl1(), &c).f.0[0];
                let b = m.eval(wi, wo, &wl1(), &c).f.0[0];
                let h = (wo + wi).normalize();
                let rel =
                    if dielectric && wo.z < 0.0 && (wo.dot(h).abs() - COS_CRITICAL).abs() < 1e-3 {
                        near_critical += 1;
                        1e-2
                    } else {
                        1e-4
                    };
                assert!(
                    close(a, b, rel),
                    "{name}, {mode:?}: f(wo, wi) = {a} but f(wi, wo) = {b} (wo {wo:?}, wi {wi:?})"
                );
            }
            assert!(near_critical < 200, "{name}: {near_critical}");
        }
    }
}

/// The adjoint relation of transmission (Veach 1997, §5.2–5.3; pbrt-v4 §9.5.2).
///
/// With η′ = n_i/n_o the ratio of the index on ωi's side to that on ωo's side and the
/// generalised half vector ωm ∝ η′ωi + ωo, Walter et al.'s eq. 21 as heron writes it is
///
///   f_imp(ωo, ωi) = (1 − F) D G |ωi·ωm| |ωo·ωm| / (|cos θi| |cos θo| (ωi·ωm + ωo·ωm/η′)²)
///                 = K n_i² / S²,   K = (1 − F) D G |ωi·ωm||ωo·ωm| / (|cos θi||cos θo|),
///                                   S = n_i ωi·ωm + n_o ωo·ωm,
///
/// and f_rad(ωo, ωi) = f_imp(ωo, ωi)/η′² = K n_o²/S². K and S are symmetric in the two
/// directions (ωm is the same vector for the swapped pair, and the Fresnel transmittance
/// is the same from either side of a refraction pair), so swapping ωo and ωi swaps n_i
/// and n_o:
///
///   f_imp(ωi, ωo) = K n_o²/S² = f_rad(ωo, ωi)                (the adjoint BSDF),
///   f_rad(ωo, ωi)/n_o² = K/S² = f_rad(ωi, ωo)/n_i²           (Veach eq. 5.23).
#[test]
fn transmission_obeys_the_adjoint_relation() {
    let mut rng = Rng::new(22, 4);
    let (n_in, n_out) = (1.5f32, 1.0f32);
    for &a in &[0.05f32, 0.2, 0.5, 1.0] {
        let m = rough_dielectric(Ior::Constant(n_in), a);
        let rad = ctx::<1>(TransportMode::Radiance);
        let imp = ctx::<1>(TransportMode::Importance);
        let (mut nonzero, mut grazing) = (0, 0);
        for _ in 0..50_000 {
            let wo = random_dir(&mut rng);
            let mut wi = random_dir(&mut rng);
            if wi.z * wo.z > 0.0 {
                wi.z = -wi.z;
            }
            let f_rad = m.eval(wo, wi, &wl1(), &rad).f.0[0];
            let f_imp_swapped = m.eval(wi, wo, &wl1(), &imp).f.0[0];
            let f_rad_swapped = m.eval(wi, wo, &wl1(), &rad).f.0[0];
            let (no, ni) = if wo.z > 0.0 {
                (n_out, n_in)
            } else {
                (n_in, n_out)
            };
            // The pair's microfacet. A refraction that grazes it is ill-conditioned in
            // f32: the two orders compute the Fresnel transmittance from opposite sides,
            // and cos θt = √(1 − n²(1 − cos² θi)) turns a rounding ε ≈ 3e-7 of the inside
            // cosine into δcos θt = n² cos θi ε / cos θt, i.e. a relative change of T (∝
            // cos θt at grazing exit) of about n² cos θc ε / cos² θt ≈ 5e-7/c² for each
            // order. The tolerance is 1e-4 plus 2e-6/c², c the smaller of the two
            // cosines with the microfacet (measured: 2e-3 at c = 0.01, 13% at c ≈ 1e-3,
            // 0 against 9e-9 at the critical angle itself).
            let wm = (no * wo + ni * wi).normalize();
            let c_min = wo.dot(wm).abs().min(wi.dot(wm).abs());
            let rel = 1e-4 + 2e-6 / (c_min * c_min);
            if c_min < 0.1 && f_rad > 0.0 {
                grazing += 1;
            }
            assert!(
                (f_rad - f_imp_swapped).abs() <= rel * f_rad.max(f_imp_swapped),
                "α = {a}: f_rad(wo, wi) = {f_rad} but f_imp(wi, wo) = {f_imp_swapped} \
                 (wo {wo:?}, wi {wi:?})"
            );
            let (x, y) = (f_rad / (no * no), f_rad_swapped / (ni * ni));
            assert!(
                (x - y).abs() <= rel * x.max(y),
                "α = {a}: f_rad(wo, wi)/n_o² = {x} but f_rad(wi, wo)/n_i² = {y} \
                 (wo {wo:?}, wi {wi:?})"
            );
            if f_rad > 0.0 {
                nonzero += 1;
            }
        }
        assert!(
            nonzero > 10_000,
            "α = {a}: only {nonzero} transmitting pairs"
        );
        assert!(
            grazing < nonzero / 5,
            "α = {a}: {grazing} grazing of {nonzero}"
        );
    }
}

/// `pdf` is zero exactly where `eval` is: no sample is wasted where f = 0, and no
/// direction that carries light is unreachable by sampling (which would bias every
/// estimator that relies on `sample`).
#[test]
fn pdf_is_zero_exactly_where_eval_is() {
    let mut rng = Rng::new(23, 5);
    let mut check =
        |name: &str, eval: &dyn Fn(Vec3, Vec3) -> bool, pdf: &dyn Fn(Vec3, Vec3) -> f32| {
            let mut bad = Vec::new();
            for _ in 0..50_000 {
                let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
                let (f, p) = (eval(wo, wi), pdf(wo, wi));
                if f != (p > 0.0) || !p.is_finite() || p < 0.0 {
                    bad.push((wo, wi, f, p));
                }
            }
            assert!(
            bad.is_empty(),
            "{name}: {} pairs where f > 0 and pdf > 0 disagree, e.g. (wo, wi, f > 0, pdf) = {:?}",
            bad.len(),
            &bad[..bad.len().min(3)]
        );
        };
    for (name, m) in non_delta_materials() {
        for mode in [TransportMode::Radiance, TransportMode::Importance] {
            let c = ctx::<1>(mode);
            check(
                &format!("{name}, {mode:?}"),
                &|wo, wi| !m.eval(wo, wi, &wl1(), &c).f.is_zero(),
                &|wo, wi| m.pdf(wo, wi, &wl1(), &c),
            );
        }
    }
    // Four lanes, dispersive, companions alive and ended.
    let m = rough_dielectric(nsf11(), 0.3);
    for alive in [true, false] {
        let mut c = ctx::<4>(TransportMode::Radiance);
        c.companions_alive = alive;
        check(
            &format!("RoughDielectric N-SF11, 4 lanes, alive = {alive}"),
            &|wo, wi| !m.eval(wo, wi, &wl4(), &c).f.is_zero(),
            &|wo, wi| m.pdf(wo, wi, &wl4(), &c),
        );
    }
    // The density does not depend on the transport mode (only f does).
    let mut rng = Rng::new(24, 6);
    for (name, m) in non_delta_materials() {
        for _ in 0..20_000 {
            let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
            let a = m.pdf(wo, wi, &wl1(), &ctx::<1>(TransportMode::Radiance));
            let b = m.pdf(wo, wi, &wl1(), &ctx::<1>(TransportMode::Importance));
            assert_eq!(a, b, "{name}: the pdf depends on the mode");
        }
    }
    // The glossy-over-glass material with its delta lobes masked out.
    let m = glossy(0.1, 0.5, 42.0, Some(Dielectric::new(glass(), true)));
    let c = ctx::<1>(TransportMode::Radiance).with_lobes(NON_DELTA);
    check(
        "Glossy over glass, non-delta lobes",
        &|wo, wi| !m.eval(wo, wi, &wl1(), &c).f.is_zero(),
        &|wo, wi| m.pdf(wo, wi, &wl1(), &c),
    );
}

// ----------------------------------------------------------------------------------
// Energy
// ----------------------------------------------------------------------------------

/// Mean and standard error of the sample weights f |cos θi| / pdf (lane 0) over `n`
/// samples (a failed sample weighs 0), and the largest single weight.
fn albedo_by_sampling<const N: usize>(
    m: &Material,
    wo: Vec3,
    wl: &SampledWavelengths<N>,
    c: &BsdfContext,
    n: usize,
    seed: u64,
) -> (f64, f64, f64) {
    let mut rng = Rng::new(seed, 11);
    let (mut s, mut s2, mut max) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..n {
        let uc = rng.uniform();
        let u = Vec2::new(rng.uniform(), rng.uniform());
        let w = m
            .sample(wo, uc, u, wl, c)
            .map_or(0.0, |s| s.weight().0[0] as f64);
        s += w;
        s2 += w * w;
        max = max.max(w);
    }
    let mean = s / n as f64;
    let var = (s2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt(), max)
}

/// ∫ f(ωo, ωi) |cos θi| dωi over the sphere by the adaptive Gauss–Legendre rule of the
/// chi-square helper (error per cell below 1e-8).
fn albedo_by_quadrature(m: &Material, wo: Vec3, c: &BsdfContext) -> f64 {
    Spherical::sphere(Vec3::Z).integrate(
        |wi| m.eval(wo, wi, &wl1(), c).f.0[0] as f64 * wi.z.abs() as f64,
        1e-8,
    )
}

#[test]
fn ideal_materials_conserve_energy_exactly() {
    let mut rng = Rng::new(31, 1);
    let rad = ctx::<1>(TransportMode::Radiance);
    let imp = ctx::<1>(TransportMode::Importance);
    let white = lambertian(1.0);
    let mirror = Material::Mirror(Mirror {
        rho_s: DenseSpectrum::constant(1.0),
        texture: None,
    });
    let metal = Material::Conductor(Conductor {
        ior: perfect_metal(),
    });
    for &t in &ANGLES {
        for inside in [false, true] {
            let wo = wo_at(t, inside);
            for _ in 0..2_000 {
                let uc = rng.uniform();
                let u = Vec2::new(rng.uniform(), rng.uniform());
                // Every sample of these carries exactly its albedo (1, or F ≈ 1).
                for (name, m, tol) in [
                    ("Lambertian ρ = 1", &white, 1e-6f32),
                    ("Mirror ρ = 1", &mirror, 1e-6),
                    ("Conductor n = 1, k = 1000", &metal, 1e-4),
                ] {
                    let s = m.sample(wo, uc, u, &wl1(), &rad).expect(name);
                    let w = s.weight().0[0];
                    assert!((w - 1.0).abs() <= tol, "{name}, θo = {t}°: weight {w}");
                }
                // A smooth dielectric in importance mode: R + T = 1, so every sample
                // (reflection with probability R, weight R/R; transmission with
                // probability T, weight T/T) weighs exactly 1, with or without Fresnel.
                for fresnel in [true, false] {
                    let d = Material::Dielectric(Dielectric::new(glass(), fresnel));
                    let s = d.sample(wo, uc, u, &wl1(), &imp).unwrap();
                    let w = s.weight().0[0];
                    assert!(
                        (w - 1.0).abs() < 1e-5,
                        "Dielectric fresnel = {fresnel}, θo = {t}° inside = {inside}: {w}"
                    );
                }
            }
            // In radiance mode the transmitted radiance is scaled by (n_o/n_i)²:
            // E = R + T (n_o/n_i)², with n_o on ωo's side.
            let d = Material::Dielectric(Dielectric::new(glass(), true));
            let (mean, se, _) = albedo_by_sampling(&d, wo, &wl1(), &rad, 200_000, 3);
            let (ni, no) = if inside { (1.0f32, 1.5f32) } else { (1.5, 1.0) };
            let r = fresnel_dielectric(wo.z.abs(), no / ni);
            let tir = (1.0 - wo.z * wo.z) * (no / ni).powi(2) >= 1.0;
            let expected = if tir {
                1.0
            } else {
                r + (1.0 - r) * (no / ni).powi(2)
            };
            assert!(
                (mean - expected as f64).abs() <= 4.0 * se + 1e-5,
                "Dielectric radiance θo = {t}° inside = {inside}: {mean} ± {se} vs {expected}"
            );
        }
    }
}

/// Directional albedo of the Phong lobe alone (ρd = 0, ρs = 1): the sampling estimate
/// equals a quadrature of `eval`, and both are 1 at normal incidence (the lobe's
/// normalisation (s+2)/(2π)).
#[test]
fn glossy_albedo_by_sampling_matches_quadrature() {
    let c = ctx::<1>(TransportMode::Radiance);
    for &s in &[10.0f32, 42.0, 200.0] {
        let m = glossy(0.0, 1.0, s, None);
        for &t in &ANGLES {
            let wo = wo_at(t, false);
            let (mean, se, max) = albedo_by_sampling(&m, wo, &wl1(), &c, 400_000, 5);
            let q = albedo_by_quadrature(&m, wo, &c);
            println!("Phong s = {s}, θo = {t}°: sampled {mean:.5} ± {se:.5}, quadrature {q:.5}");
            assert!(
                (mean - q).abs() <= 4.0 * se + 2e-5,
                "s = {s}, θo = {t}°: sampled {mean} ± {se}, quadrature {q}"
            );
            assert!(q <= 1.0 + 1e-4 && mean <= 1.0 + 4.0 * se, "{q} {mean}");
            // Each weight is (s+2)/(s+1) cos θi ≤ (s+2)/(s+1).
            assert!(max <= (s as f64 + 2.0) / (s as f64 + 1.0) + 1e-5);
            if t == 0.0 {
                assert!((q - 1.0).abs() < 1e-4 && (mean - 1.0).abs() < 4.0 * se + 1e-5);
            }
        }
    }
}

/// Single-scattering albedo of the GGX microfacet materials, by sampling (E[weight],
/// 4·10⁵ samples) and by quadrature of `eval`; they must agree to 4 standard errors
/// (which checks `sample`, `pdf` and `eval` against each other), and each weight must
/// be at most 1: with visible-normal sampling f |cos θi| / pdf = F G2(ωo, ωi)/G1(ωo)
/// (Heitz 2018, eq. 19 with the height-correlated G2), and G2 ≤ G1 (1 + Λo ≤
/// 1 + Λo + Λi), so with F ≤ 1 (conductor) or in importance mode (dielectric, where the
/// Fresnel choice cancels F and 1 − F) no sample exceeds 1. The loss 1 − E is what
/// single scattering leaves out (multiple scattering between microfacets): it grows
/// with α and toward grazing incidence.
///
/// At normal incidence with α = 1 and F = 1 the loss is known in closed form: the
/// visible normals are then cosine-distributed (D = 1/π), a normal beyond 45° reflects
/// below the horizon, and the others keep G2/G1 = 1/(1 + Λ(ωi)) = 2x/(1 + x) with
/// x = cos θi = cos 2θm, so E = ∫₀¹ x/(1 + x) dx = 1 − ln 2 and the loss is ln 2.
///
/// Measured by quadrature (sampling, 4·10⁵ samples, agrees to ≤ 0.0007, within 4 SE);
/// F ≥ 0.99999 for the metal, n = 1.5 for the glass in importance mode, "in" = ωo
/// inside the glass:
///
/// | loss 1 − E          | α = 0.1 | α = 0.5 | α = 1.0 |
/// |---------------------|---------|---------|---------|
/// | metal θo = 0°       | 0.0117  | 0.3122  | 0.6931  |
/// | metal θo = 60°      | 0.0308  | 0.3018  | 0.5493  |
/// | metal θo = 85°      | 0.1136  | 0.1280  | 0.2200  |
/// | glass out θo = 0°   | 0.0012  | 0.0319  | 0.1067  |
/// | glass out θo = 60°  | 0.0078  | 0.1074  | 0.2582  |
/// | glass out θo = 85°  | 0.0785  | 0.1420  | 0.2486  |
/// | glass in θo = 0°    | 0.0110  | 0.2461  | 0.5829  |
/// | glass in θo = 60°   | 0.0366  | 0.3403  | 0.4872  |
/// | glass in θo = 85°   | 0.1360  | 0.3061  | 0.4848  |
#[test]
fn microfacet_single_scattering_loss() {
    let imp = ctx::<1>(TransportMode::Importance);
    let alphas = [0.1f32, 0.5, 1.0];
    let mut table = String::new();
    for (label, inside) in [("metal", false), ("glass out", false), ("glass in", true)] {
        for &t in &[0.0f32, 60.0, 85.0] {
            let wo = wo_at(t, inside);
            let mut row = format!("| {label} θo = {t}° |");
            let mut last_loss = -1.0;
            for &a in &alphas {
                let m = if label == "metal" {
                    rough_conductor(perfect_metal(), a)
                } else {
                    rough_dielectric(glass(), a)
                };
                let (mean, se, max) = albedo_by_sampling(&m, wo, &wl1(), &imp, 400_000, 7);
                let q = albedo_by_quadrature(&m, wo, &imp);
                let loss = 1.0 - q;
                row += &format!(" {loss:.4} ({:.4} ± {se:.4}) |", 1.0 - mean);
                assert!(
                    (mean - q).abs() <= 4.0 * se + 1e-4,
                    "{label}, α = {a}, θo = {t}°: sampled {mean} ± {se}, quadrature {q}"
                );
                assert!(
                    max <= 1.0 + 1e-5,
                    "{label}, α = {a}, θo = {t}°: a weight {max} > 1"
                );
                assert!(
                    q <= 1.0 + 1e-4 && loss >= -1e-4,
                    "{label} α = {a} θo = {t}°: {q}"
                );
                // Rougher loses more.
                assert!(
                    loss >= last_loss - 1e-3,
                    "{label}, θo = {t}°: loss {loss} at α = {a} < {last_loss}"
                );
                last_loss = loss;
                if label == "metal" && t == 0.0 && a == 1.0 {
                    let ln2 = std::f64::consts::LN_2;
                    assert!(
                        (loss - ln2).abs() < 2e-4,
                        "α = 1, θo = 0°: loss {loss} vs ln 2"
                    );
                }
            }
            table += &row;
            table += "\n";
        }
    }
    println!("single-scattering loss 1 − E by quadrature (by sampling ± SE):\n{table}");
}

// ----------------------------------------------------------------------------------
// Dispersion semantics
// ----------------------------------------------------------------------------------

/// R(λ) of the N-SF11 interface for light leaving along `wo` (n_i on ωo's side).
fn r_nsf11(wo: Vec3, lambda: f32) -> f32 {
    let n = nsf11().eval(lambda);
    let eta_io = if wo.z > 0.0 { 1.0 / n } else { n };
    fresnel_dielectric(wo.z.abs(), eta_io)
}

#[test]
fn smooth_dielectric_dispersion_semantics() {
    let wl = wl4();
    let d = Material::Dielectric(Dielectric::new(nsf11(), true));
    for inside in [false, true] {
        // 30° stays below N-SF11's critical angle (34°) from inside.
        let wo = wo_at(30.0, inside);
        let r0 = r_nsf11(wo, wl.lambda[0]);
        let n0 = nsf11().eval(wl.lambda[0]);
        // η′ = n_t/n_i for the hero's refraction.
        let etap = if inside { 1.0 / n0 } else { n0 };
        for mode in [TransportMode::Radiance, TransportMode::Importance] {
            let alive = ctx::<4>(mode);
            // uc < R: reflection. Every lane kept, lane i weighted R(λi)/R(λ0).
            let s = d.sample(wo, 0.5 * r0, Vec2::ZERO, &wl, &alive).unwrap();
            assert!(!s.is_transmission() && !s.ended_companions);
            let w = s.weight();
            for i in 0..4 {
                let expected = r_nsf11(wo, wl.lambda[i]) / r0;
                assert!(
                    (w.0[i] - expected).abs() <= 1e-4 * expected,
                    "reflection lane {i}: {} vs {expected}",
                    w.0[i]
                );
            }
            // uc > R: transmission along the hero's direction; the companions end, the
            // hero carries N × T/T, times (n_o/n_i)² = 1/η′² for radiance.
            let s = d
                .sample(wo, 0.5 + 0.5 * r0, Vec2::ZERO, &wl, &alive)
                .unwrap();
            assert!(s.is_transmission() && s.ended_companions);
            assert!(s.flags.contains(LobeFlags::WAVELENGTH_DEPENDENT));
            assert!((s.eta - etap).abs() < 1e-6);
            let expected = refracted(wo, n0).unwrap();
            assert!(
                (s.wi - expected).length() < 1e-5,
                "{:?} vs {expected:?}",
                s.wi
            );
            let w = s.weight();
            let scale = if mode == TransportMode::Radiance {
                1.0 / (etap * etap)
            } else {
                1.0
            };
            assert!(
                (w.0[0] - 4.0 * scale).abs() < 1e-4 * scale,
                "{mode:?}: {:?}",
                w.0
            );
            assert!(w.0[1..].iter().all(|&v| v == 0.0), "{:?}", w.0);
            // Once ended, nothing is ended or multiplied again.
            let mut dead = alive;
            dead.companions_alive = false;
            let s = d
                .sample(wo, 0.5 + 0.5 * r0, Vec2::ZERO, &wl, &dead)
                .unwrap();
            assert!(s.is_transmission() && !s.ended_companions);
            assert!((s.weight().0[0] - scale).abs() < 1e-4 * scale);
            let s = d.sample(wo, 0.5 * r0, Vec2::ZERO, &wl, &dead).unwrap();
            assert!(!s.is_transmission() && !s.ended_companions);
            assert!((s.weight().0[0] - 1.0).abs() < 1e-5);
        }
    }
    // A non-dispersive index keeps every lane, on either branch.
    let d = Material::Dielectric(Dielectric::new(glass(), true));
    let wo = wo_at(30.0, false);
    let r = fresnel_dielectric(wo.z, 1.0 / 1.5);
    for uc in [0.5 * r, 0.5 + 0.5 * r] {
        let s = d
            .sample(wo, uc, Vec2::ZERO, &wl, &ctx::<4>(TransportMode::Radiance))
            .unwrap();
        assert!(!s.ended_companions);
        assert!(!s.flags.contains(LobeFlags::WAVELENGTH_DEPENDENT));
        let w = s.weight();
        assert!(
            w.0.iter().all(|&v| (v - w.0[0]).abs() < 1e-6 && v > 0.0),
            "{:?}",
            w.0
        );
    }
}

#[test]
fn rough_dielectric_dispersion_semantics() {
    let wl = wl4();
    let m = rough_dielectric(nsf11(), 0.3);
    let glass_m = rough_dielectric(glass(), 0.3);
    let n0 = nsf11().eval(wl.lambda[0]);
    for inside in [false, true] {
        let wo = wo_at(25.0, inside);
        let alive = ctx::<4>(TransportMode::Radiance);
        let mut dead = alive;
        dead.companions_alive = false;
        // A transmission pair: the hero's smooth refraction direction, tilted a little.
        let wt = refracted(wo, n0).unwrap();
        let wi = (wt + Vec3::new(0.05, -0.03, 0.0)).normalize();
        assert!(wi.z * wo.z < 0.0);
        let e_alive = m.eval(wo, wi, &wl, &alive);
        let e_dead = m.eval(wo, wi, &wl, &dead);
        // The evaluation says it ended the companions, once.
        assert!(e_alive.ended_companions && !e_dead.ended_companions);
        let (f_alive, f_dead) = (e_alive.f, e_dead.f);
        assert!(f_dead.0[0] > 0.0);
        assert!(
            (f_alive.0[0] - 4.0 * f_dead.0[0]).abs() <= 1e-5 * f_alive.0[0],
            "{:?} vs {:?}",
            f_alive.0,
            f_dead.0
        );
        assert!(f_alive.0[1..].iter().all(|&v| v == 0.0), "{:?}", f_alive.0);
        // A reflection pair keeps every lane, lane i with F(λi).
        let wr = (mirror_dir(wo) + Vec3::new(0.04, 0.02, 0.0)).normalize();
        let e = m.eval(wo, wr, &wl, &alive);
        assert!(!e.ended_companions);
        let f = e.f;
        let h = (wo + wr).normalize();
        let h = if h.z < 0.0 { -h } else { h };
        let cos = wo.dot(h).abs();
        let f_of = |l: f32| {
            let n = nsf11().eval(l);
            fresnel_dielectric(cos, if inside { n } else { 1.0 / n })
        };
        for i in 1..4 {
            let expected = f.0[0] * f_of(wl.lambda[i]) / f_of(wl.lambda[0]);
            assert!(
                (f.0[i] - expected).abs() <= 1e-4 * expected,
                "lane {i}: {} vs {expected}",
                f.0[i]
            );
        }
        // Samples: transmissions end the companions, reflections keep them.
        let mut rng = Rng::new(41, inside as u64);
        let (mut nt, mut nr) = (0, 0);
        for _ in 0..20_000 {
            let uc = rng.uniform();
            let u = Vec2::new(rng.uniform(), rng.uniform());
            let Some(s) = m.sample(wo, uc, u, &wl, &alive) else {
                continue;
            };
            if s.is_transmission() {
                nt += 1;
                assert!(s.ended_companions && s.flags.contains(LobeFlags::WAVELENGTH_DEPENDENT));
                assert!(s.f.0[1..].iter().all(|&v| v == 0.0) && s.f.0[0] > 0.0);
            } else {
                nr += 1;
                assert!(!s.ended_companions && s.f.0.iter().all(|&v| v > 0.0));
            }
            let sd = m.sample(wo, uc, u, &wl, &dead).unwrap();
            assert!(!sd.ended_companions);
            if sd.is_transmission() {
                assert!((s.f.0[0] - 4.0 * sd.f.0[0]).abs() <= 1e-5 * s.f.0[0]);
            }
        }
        assert!(nt > 1000 && nr > 1000, "{nt} {nr}");
        // A non-dispersive index keeps every lane on a transmission too.
        let e = glass_m.eval(wo, refracted(wo, 1.5).unwrap(), &wl, &alive);
        assert!(!e.ended_companions);
        let f = e.f;
        assert!(
            f.0.iter()
                .all(|&v| v > 0.0 && (v - f.0[0]).abs() < 1e-6 * v),
            "{:?}",
            f.0
        );
    }
}

/// Smooth materials are deltas: `eval` and `pdf` are zero for every pair, and `sample`
/// reports a specular lobe in the mirror (or refracted) direction.
#[test]
fn delta_materials_have_no_density() {
    let mats = [
        Material::Mirror(Mirror {
            rho_s: DenseSpectrum::constant(0.8),
            texture: None,
        }),
        Material::Conductor(Conductor { ior: gold() }),
        Material::Dielectric(Dielectric::new(glass(), true)),
    ];
    let mut rng = Rng::new(51, 1);
    for m in &mats {
        let c = ctx::<1>(TransportMode::Radiance);
        for _ in 0..1000 {
            let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
            assert!(m.eval(wo, wi, &wl1(), &c).f.is_zero());
            assert_eq!(m.pdf(wo, wi, &wl1(), &c), 0.0);
            let s = m.sample(wo, rng.uniform(), Vec2::ZERO, &wl1(), &c).unwrap();
            assert!(s.is_specular());
            let expected = if s.is_transmission() {
                refracted(wo, 1.5).unwrap()
            } else {
                mirror_dir(wo)
            };
            assert!(
                (s.wi - expected).length() < 1e-5,
                "{:?} vs {expected:?}",
                s.wi
            );
        }
    }
}
