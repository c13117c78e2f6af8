//! Polarised transport through the whole renderer (`[render] polarization`): Malus's
//! law with two polariser sheets and with the camera's analyser, a quarter-wave plate
//! turning 45° light circular, the degree of polarisation of light reflected at
//! Brewster's angle, an all-diffuse scene whose S0 is the unpolarised image, the same
//! bytes on one and two threads, and the errors for what polarised transport does not
//! support. The closed forms of the matrices are `optics::mueller`'s unit tests.
//!
//! The sheet scenes are noiseless: every camera ray goes straight through the sheets
//! to a uniform emitter (delta events only), so the expected values hold to rounding,
//! and the tolerances are rounding's (f32 products of a few matrices).
mod common;

use common::render::render_with;
use heron::film::Film;
use heron::scene::load::{load_scene, load_scene_from_str};
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use std::path::Path;

fn scene(toml: &str) -> Scene {
    load_scene_from_str(toml, Path::new("polarization-test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// Camera at z = 3 looking down −z at a uniform two-sided emitter at z = 0, with the
/// `sheets` (material tables) as 4 × 4 quads facing the camera at z = 1.0, 0.5, …,
/// seen through a field of ±0.3° so that every ray crosses them at normal incidence
/// within 0.3° (Malus's cos² is the law of normal incidence).
fn sheets_scene(camera_polarizer: Option<f32>, sheets: &[&str]) -> Scene {
    let mut t = String::from(
        "background = 0.0\n[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nd = 50.0\nresolution = [8, 8]\n",
    );
    if let Some(a) = camera_polarizer {
        t += &format!("polarizer = {a}\n");
    }
    t += "[render]\nintegrator = \"path\"\npolarization = true\nspp = 2\nmax_depth = 8\n";
    t += "[materials.black]\ntype = \"lambertian\"\nrho_d = 0.0\n";
    for (i, m) in sheets.iter().enumerate() {
        t += &format!("[materials.sheet{i}]\n{m}\n");
        t += &format!(
            "[[shapes]]\ntype = \"quad\"\norigin = [-2.0, -2.0, {z}]\nedge1 = [4.0, 0.0, 0.0]\nedge2 = [0.0, 4.0, 0.0]\nmaterial = \"sheet{i}\"\n",
            z = 1.0 - 0.5 * i as f32
        );
    }
    t += "[[shapes]]\ntype = \"quad\"\norigin = [-3.0, -3.0, 0.0]\nedge1 = [6.0, 0.0, 0.0]\nedge2 = [0.0, 6.0, 0.0]\nmaterial = \"black\"\nemission = 1.0\ntwo_sided = true\n";
    scene(&t)
}

/// The film's mean Stokes vector (of Y) over all pixels.
fn mean_stokes(f: &Film) -> [f64; 4] {
    let st = f.stokes.as_ref().expect("a polarised film");
    let n = f.xyz.len() as f64;
    let mut s = [0.0; 4];
    for (xyz, p) in f.xyz.iter().zip(st) {
        s[0] += xyz[1] as f64 / n;
        for k in 0..3 {
            s[k + 1] += p[k][1] as f64 / n;
        }
    }
    s
}

fn render_scene(s: &Scene) -> Film {
    render_with(s, |_| {})
}

#[test]
fn malus_law_holds_for_two_sheets_and_for_sheet_and_analyser() {
    let open = mean_stokes(&render_scene(&sheets_scene(None, &[])))[0];
    assert!(open > 0.5, "the emitter is seen: {open}");
    for theta in [0.0f64, 30.0, 60.0, 90.0] {
        // Light meets sheet 1 (z = 0.5, axis vertical) first, then sheet 0 at θ.
        let s = sheets_scene(
            None,
            &[
                &format!("type = \"polarizer\"\nangle = {theta}"),
                "type = \"polarizer\"",
            ],
        );
        let got = mean_stokes(&render_scene(&s))[0] / open;
        let want = 0.5 * theta.to_radians().cos().powi(2);
        assert!(
            (got - want).abs() < 1e-4,
            "θ = {theta}°: {got} vs ½cos²θ = {want}"
        );
    }
    // The sheet's angle (counter-clockwise seen from the camera's side, from the
    // horizontal) and the analyser's (counter-clockwise as the photographer sees it)
    // are one convention: cos²(α − β), not cos²(α + β).
    let s = sheets_scene(
        Some(50.0),
        &["type = \"polarizer\"\naxis = [1.0, 0.0, 0.0]\nangle = 20.0"],
    );
    let got = mean_stokes(&render_scene(&s))[0] / open;
    let want = 0.5 * 30f64.to_radians().cos().powi(2);
    assert!((got - want).abs() < 1e-4, "analyser: {got} vs {want}");
}

#[test]
fn crossed_sheets_extinguish_as_their_extinction_ratio_says() {
    let open = mean_stokes(&render_scene(&sheets_scene(None, &[])))[0];
    let ideal = sheets_scene(
        None,
        &["type = \"polarizer\"\nangle = 90", "type = \"polarizer\""],
    );
    let got = mean_stokes(&render_scene(&ideal))[0] / open;
    assert!(got.abs() < 1e-6, "ideal crossed sheets pass {got}");
    // Two sheets of t_x = 0.8, t_y = t_x / 100 crossed: t_x t_y of the light.
    let real = "type = \"polarizer\"\ntransmittance = 0.8\nextinction_ratio = 100.0";
    let s = sheets_scene(None, &[&format!("{real}\nangle = 90"), real]);
    let got = mean_stokes(&render_scene(&s))[0] / open;
    let want = 0.8 * 0.008;
    assert!((got - want).abs() < 1e-5, "{got} vs t_x t_y = {want}");
}

#[test]
fn a_quarter_wave_plate_turns_45_degree_light_circular() {
    let mut s3 = Vec::new();
    for fast in [0.0, 90.0] {
        // Light meets the polariser at 45° (z = 0.5) and then the plate (z = 1).
        let s = sheets_scene(
            None,
            &[
                &format!("type = \"retarder\"\nretardance = 0.25\naxis = [1.0, 0.0, 0.0]\nangle = {fast}"),
                "type = \"polarizer\"\naxis = [1.0, 0.0, 0.0]\nangle = 45",
            ],
        );
        let st = mean_stokes(&render_scene(&s));
        assert!(st[0] > 0.1);
        assert!(
            st[1].abs() < 1e-5 * st[0] && st[2].abs() < 1e-5 * st[0],
            "{st:?}"
        );
        assert!(
            (st[3].abs() - st[0]).abs() < 1e-5 * st[0],
            "S3 = ±S0: {st:?}"
        );
        s3.push(st[3].signum());
        // Without the plate the light is linear at +45°: S2 = S0.
        let lin = sheets_scene(
            None,
            &["type = \"polarizer\"\naxis = [1.0, 0.0, 0.0]\nangle = 45"],
        );
        let st = mean_stokes(&render_scene(&lin));
        assert!((st[2] - st[0]).abs() < 1e-5 * st[0], "{st:?}");
    }
    assert_eq!(
        s3[0], -s3[1],
        "turning the fast axis by 90° reverses the handedness"
    );
}

#[test]
fn light_reflected_at_brewsters_angle_is_completely_polarised() {
    // The path tracer, the seed's Whitted tracer (its delta reflection of the emitter)
    // and BDPT (its camera subpath reaching the emitter, s = 0).
    for integrator in ["path", "whitted", "bdpt"] {
        brewster_reflection(integrator);
    }
}

fn brewster_reflection(integrator: &str) {
    // A glass plane (n = 1.5) seen at θB = atan 1.5 through a narrow field (±0.3°, where (R_s − R_p)/(R_s + R_p) > 0.9998),
    // reflecting a uniform emitter; what the glass transmits leaves the scene.
    let tb = 1.5f32.atan();
    let (c, s) = (tb.cos(), tb.sin());
    let t = format!(
        "background = 0.0\n[camera]\neye = [0.0, {ey}, {ez}]\nlook_at = [0.0, 0.0, 0.0]\nd = 100.0\nresolution = [16, 16]\n\
[render]\nintegrator = \"{integrator}\"\npolarization = true\nspp = 64\nmax_depth = 3\n\
[materials.glass]\ntype = \"dielectric\"\nior = 1.5\n[materials.black]\ntype = \"lambertian\"\nrho_d = 0.0\n\
[[shapes]]\ntype = \"quad\"\norigin = [-50.0, 0.0, -50.0]\nedge1 = [0.0, 0.0, 100.0]\nedge2 = [100.0, 0.0, 0.0]\nmaterial = \"glass\"\n\
[[shapes]]\ntype = \"quad\"\norigin = [-2.0, {oy}, {oz}]\nedge1 = [4.0, 0.0, 0.0]\nedge2 = [0.0, {e2y}, {e2z}]\nmaterial = \"black\"\nemission = 1.0\ntwo_sided = true\n",
        ey = 4.0 * c,
        ez = -4.0 * s,
        oy = 4.0 * c + 2.0 * s,
        oz = 4.0 * s - 2.0 * c,
        e2y = -4.0 * s,
        e2z = 4.0 * c,
    );
    let f = render_scene(&scene(&t));
    let st = f.stokes.as_ref().unwrap();
    // The glass reflects with probability R ≈ 0.074 per sample, so some pixels saw only
    // transmission (S = 0); every light the others saw is the reflection's.
    let mut lit = 0;
    for (xyz, p) in f.xyz.iter().zip(st) {
        let s0 = xyz[1] as f64;
        if s0 == 0.0 {
            continue;
        }
        lit += 1;
        let dop = (p[0][1] as f64).hypot(p[1][1] as f64).hypot(p[2][1] as f64) / s0;
        assert!(dop > 0.9995, "{integrator}: degree of polarisation {dop}");
        // s-polarised is horizontal in this picture: S1 = +S0.
        assert!(p[0][1] > 0.0);
    }
    assert!(lit > 100, "{integrator}: {lit} pixels saw the reflection");
    // And the intensity is Fresnel's: (R_s + 0)/2 of the emitter's Y (1), within 4
    // standard errors of the 256 pixels' mean (each pixel a mean of 64 Bernoulli
    // choices; SE ≈ 3% of the mean).
    let (y, se) = common::render::mean_se_y(&f);
    let (ci, ct) = (c as f64, (1.0 - (s as f64 / 1.5).powi(2)).sqrt());
    let rs = ((ci - 1.5 * ct) / (ci + 1.5 * ct)).powi(2);
    assert!(
        (y - 0.5 * rs).abs() < 4.0 * se,
        "{integrator}: {y} ± {se} vs R_s/2 = {}",
        0.5 * rs
    );
    // With spectral bins (Fichet et al.'s polarised layout): light reflected at
    // Brewster's angle is completely polarised at every wavelength, horizontally here
    // (S1 > 0; S2 is the turn of the s direction against the picture's horizontal
    // across the ±0.3° field), as the XYZ sums above say of the whole spectrum.
    let nb = 16;
    let f = common::render::render_with(&scene(&t), |o| o.settings.spectral_bins = nb);
    let (bins, s0) = f.spectral.as_ref().expect("spectral bins");
    assert_eq!(bins.count, nb);
    let st = f.stokes_spectral.as_ref().expect("Stokes bins");
    assert_eq!(st.len(), 3 * s0.len());
    let mut lit = 0;
    for (i, s0) in s0.chunks(nb).enumerate() {
        let rest = &st[3 * i * nb..3 * (i + 1) * nb];
        for b in 0..nb {
            if s0[b] == 0.0 {
                continue;
            }
            let (s1, s2, s3) = (rest[b] as f64, rest[nb + b] as f64, rest[2 * nb + b] as f64);
            let dop = s1.hypot(s2).hypot(s3) / s0[b] as f64;
            assert!(
                (dop - 1.0).abs() < 5e-4 && s1 > 0.0,
                "{integrator}: bin {b}: degree of polarisation {dop}, S1 {s1}"
            );
            lit += 1;
        }
    }
    assert!(lit > 100, "{integrator}: {lit} bins saw the reflection");
}

/// The Cornell box, 40 × 40: Lambertian surfaces and an area light only.
fn small_cornell_box() -> Scene {
    let mut s = load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    s.camera = s.camera.resized(40, 40).unwrap();
    s
}

#[test]
fn an_all_diffuse_scene_renders_the_unpolarised_image_in_s0() {
    let s = small_cornell_box();
    let plain = render_with(&s, |o| o.settings.spp = 4);
    let pol = render_with(&s, |o| {
        o.settings.spp = 4;
        o.settings.polarization = true;
    });
    assert!(plain.stokes.is_none());
    for (a, b) in plain.xyz.iter().zip(&pol.xyz) {
        for j in 0..3 {
            assert!(
                (a[j] - b[j]).abs() <= 1e-5 + 1e-4 * a[j].abs(),
                "S0 {b:?} against the unpolarised {a:?}"
            );
        }
    }
    // Diffuse surfaces depolarise, the light is unpolarised: S1 = S2 = S3 = 0 exactly.
    assert!(pol
        .stokes
        .unwrap()
        .iter()
        .flatten()
        .flatten()
        .all(|&v| v == 0.0));
}

/// Light tracing and BDPT on the all-diffuse box: a light path's Stokes vector stays
/// (1, 0, 0, 0) times its scalar weight, so polarised light tracing's splats are the
/// unpolarised ones bit for bit, bins included, and BDPT's S1–S3 are exactly 0.
#[test]
fn polarised_splats_of_an_all_diffuse_scene_are_the_unpolarised_ones() {
    let s = small_cornell_box();
    for kind in [IntegratorKind::LightTrace, IntegratorKind::Bdpt] {
        let run = |polarization: bool| {
            render_with(&s, |o| {
                o.settings.integrator = kind;
                o.settings.spp = 2;
                o.settings.spectral_bins = 4;
                o.settings.polarization = polarization;
            })
        };
        let (plain, pol) = (run(false), run(true));
        if kind == IntegratorKind::LightTrace {
            assert_eq!(plain.xyz, pol.xyz);
            assert_eq!(plain.spectral, pol.spectral);
        }
        let zero = |v: &[f32]| v.iter().all(|&x| x == 0.0);
        assert!(pol.stokes.unwrap().iter().all(|p| zero(p.as_flattened())));
        assert!(zero(pol.stokes_spectral.as_ref().unwrap()));
        assert!(plain.xyz.iter().any(|c| c[1] > 0.0));
    }
}

#[test]
fn polarised_renders_are_the_same_bytes_on_one_and_two_threads() {
    let s = scene(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/brewster.toml"),
        )
        .unwrap(),
    );
    let run = |threads: usize| {
        render_with(&s, |o| {
            o.settings.spp = 2;
            o.threads = threads;
        })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a, b);
    assert!(a.stokes.unwrap().iter().any(|p| p[0][1] != 0.0));
}

#[test]
fn what_polarised_transport_does_not_support_is_a_clear_error() {
    let s = sheets_scene(None, &[]);
    let err = |set: &dyn Fn(&mut heron::render::RenderOptions)| {
        let mut o = heron::render::RenderOptions::from_scene(&s);
        set(&mut o);
        heron::render::render(&s, &o).unwrap_err().to_string()
    };
    let e = err(&|o| o.settings.integrator = heron::settings::IntegratorKind::Sppm);
    assert!(
        e.contains("integrator sppm") && e.contains("polarised transport"),
        "{e}"
    );
    // An analyser without polarised transport.
    let s = sheets_scene(Some(10.0), &[]);
    let mut o = heron::render::RenderOptions::from_scene(&s);
    o.settings.polarization = false;
    let e = heron::render::render(&s, &o).unwrap_err().to_string();
    assert!(
        e.contains("camera.polarizer") && e.contains("--polarization"),
        "{e}"
    );
    // Bad sheet keys name the key.
    let bad = |m: &str| {
        let t = format!("[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [8, 8]\n[materials.p]\n{m}\n");
        load_scene_from_str(&t, Path::new("bad.toml"))
            .unwrap_err()
            .to_string()
    };
    let e = bad("type = \"polarizer\"\nextinction_ratio = 0.5");
    assert!(
        e.contains("materials.p.extinction_ratio") && e.contains("at least 1"),
        "{e}"
    );
    let e = bad("type = \"polarizer\"\ntransmittance = 1.5");
    assert!(e.contains("materials.p.transmittance"), "{e}");
    let e = bad("type = \"retarder\"\nretardance = \"quarter\"");
    assert!(
        e.contains("materials.p") && e.contains("expected a number"),
        "{e}"
    );
    // A light's polarisation: its keys, ranges and degree.
    let light = |p: &str| {
        let t = format!("[camera]\neye = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [8, 8]\n[[lights]]\ntype = \"point\"\nposition = [0.0, 1.0, 0.0]\nintensity = 1.0\npolarization = {{ {p} }}\n");
        load_scene_from_str(&t, Path::new("bad.toml"))
            .unwrap_err()
            .to_string()
    };
    let e = light("linear = 1.0");
    assert!(e.contains("lights[0].polarization.axis"), "{e}");
    let e = light("axis = [0.0, 0.0, 1.0], linear = 1.5");
    assert!(
        e.contains("lights[0].polarization.linear") && e.contains("[-1, 1]"),
        "{e}"
    );
    let e = light("axis = [0.0, 0.0, 1.0], linear = 0.8, circular = 0.8");
    assert!(
        e.contains("lights[0].polarization") && e.contains("at most 1"),
        "{e}"
    );
    let e = light("axis = [0.0, 0.0, 1.0], angle = 3.0");
    assert!(e.contains("angle"), "{e}");
}

#[test]
fn heron_trace_follows_the_stokes_vector_event_by_event() {
    let s = scene(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/brewster.toml"),
        )
        .unwrap(),
    );
    let r = heron::render::Renderer::new(&s).unwrap();
    let tb = 1.5f32.atan();
    let (c, sn) = (tb.cos(), tb.sin());
    let origin = glam::Vec3::new(0.0, 4.0 * c, -4.0 * sn);
    let dir = glam::Vec3::new(0.0, -c, sn);
    // Unpolarised light reflected at Brewster's angle: (R, R, 0, 0) in the s frame, with
    // R = R_s/2 the unpolarised reflectance.
    let rep = heron::trace::trace(
        &s,
        r.accel(),
        origin,
        dir,
        550.0,
        &[true],
        Some([1.0, 0.0, 0.0, 0.0]),
    )
    .unwrap();
    let ev = &rep.events[0];
    let st = ev.stokes.unwrap();
    let rf = ev.fresnel_r.unwrap() as f64;
    assert!(
        (st[0] - rf).abs() < 1e-6 && (st[1] - st[0]).abs() < 1e-5 * st[0],
        "{st:?}"
    );
    assert!(st[2].abs() < 1e-6 && st[3].abs() < 1e-6);
    // The s direction is perpendicular to the plane of incidence (the yz plane): ±x.
    assert!((ev.stokes_x.unwrap()[0].abs() - 1.0).abs() < 1e-6);
    // p-polarised light is not reflected at all. The starting frame is the tracer's
    // choice (`any_perpendicular`: x̂ = +x for this ray, the s direction), so S1 = −S0
    // is p there, and S1 = +S0 is s, reflected with R_s = 2R.
    let run = |st: [f64; 4]| {
        heron::trace::trace(&s, r.accel(), origin, dir, 550.0, &[true], Some(st))
            .unwrap()
            .events[0]
            .stokes
            .unwrap()
    };
    assert!(run([1.0, -1.0, 0.0, 0.0])[0] < 1e-6);
    assert!((run([1.0, 1.0, 0.0, 0.0])[0] - 2.0 * rf).abs() < 1e-5);
    // Without --stokes the JSON has no Stokes fields; a non-physical state is an error.
    let plain = heron::trace::trace(&s, r.accel(), origin, dir, 550.0, &[true], None).unwrap();
    assert!(plain.events.iter().all(|e| e.stokes.is_none()));
    let e = heron::trace::trace(
        &s,
        r.accel(),
        origin,
        dir,
        550.0,
        &[],
        Some([1.0, 1.0, 1.0, 0.0]),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("--stokes") && e.contains("physical"), "{e}");
}

/// A directional light travelling at Brewster's angle for n = 1.5 onto a rough (α =
/// 0.02) glass floor, seen along the mirror direction through a field of ±0.6°, with
/// the light's `polarization` table `pol` (None: unpolarised).
fn brewster_light_scene(pol: Option<&str>) -> Scene {
    let tb = 1.5f32.atan();
    let (s, c) = tb.sin_cos();
    let pol = pol.map_or(String::new(), |p| format!("polarization = {{ {p} }}\n"));
    scene(&format!(
        "background = 0.0\n[camera]\neye = [{ex}, {ey}, 0.0]\nlook_at = [0.0, 0.0, 0.0]\nd = 50.0\nresolution = [8, 8]\n\
         [render]\nintegrator = \"path\"\npolarization = true\nspp = 4\nmax_depth = 1\n\
         [materials.glass]\ntype = \"dielectric\"\nior = 1.5\nroughness = 0.02\n\
         [[shapes]]\ntype = \"quad\"\norigin = [-5.0, 0.0, -5.0]\nedge1 = [0.0, 0.0, 10.0]\nedge2 = [10.0, 0.0, 0.0]\nmaterial = \"glass\"\n\
         [[lights]]\ntype = \"directional\"\ndirection = [{s}, {mc}, 0.0]\nradiance = 1.0\n{pol}",
        ex = 10.0 * s,
        ey = 10.0 * c,
        mc = -c,
    ))
}

/// A light's own polarisation (`polarization` on a delta light): at Brewster's angle the
/// glass reflects s-polarised light (the light's axis along z, perpendicular to the
/// plane of incidence) with R_s, twice what it reflects of unpolarised light, and
/// p-polarised light (linear = −1: across that axis) hardly at all; circular light
/// reflects as unpolarised light does (a Fresnel matrix's first row is (A, B, 0, 0)).
/// The four renders follow the same paths (the same random numbers and scalar weights),
/// so the ratios are the Mueller algebra's, not noise; the microfacets (α = 0.02) spread
/// the incidence over about ±1° of Brewster's angle, where R_p/R_s < 1e-3.
#[test]
fn a_polarised_light_is_reflected_at_brewsters_angle_as_its_state_says() {
    // The path tracer, BDPT and light tracing (whose light paths carry the light's
    // Stokes vector forward and splat it; 20 000 paths per pixel, since few of the
    // directional light's paths land in the ±0.6° field).
    for (kind, spp) in [
        (IntegratorKind::Path, 4),
        (IntegratorKind::Bdpt, 4),
        (IntegratorKind::LightTrace, 20_000),
    ] {
        polarised_light_at_brewster(kind, spp);
    }
}

fn polarised_light_at_brewster(kind: IntegratorKind, spp: u32) {
    let y = |p: Option<&str>| {
        let f = render_with(&brewster_light_scene(p), |o| {
            o.settings.integrator = kind;
            o.settings.spp = spp;
        });
        mean_stokes(&f)[0]
    };
    let unpolarised = y(None);
    assert!(unpolarised > 0.0, "{kind:?}");
    let s = y(Some("axis = [0.0, 0.0, 1.0]")) / unpolarised;
    let p = y(Some("axis = [0.0, 0.0, 1.0], linear = -1.0")) / unpolarised;
    let circular = y(Some("axis = [0.0, 0.0, 1.0], circular = 1.0")) / unpolarised;
    assert!(
        (s - 2.0).abs() < 0.01,
        "{kind:?}: s-polarised: {s} of the unpolarised light"
    );
    assert!(
        p < 0.005,
        "{kind:?}: p-polarised: {p} of the unpolarised light"
    );
    assert!(
        (circular - 1.0).abs() < 1e-4,
        "{kind:?}: circular: {circular}"
    );
    // The axis is projected across the ray: z tilted toward the light's direction of
    // travel k is still s; z tilted within the plane of incidence (toward x, which has
    // a part across k) is partly p, cos² of its angle to z after projection.
    let (sn, c) = 1.5f32.atan().sin_cos();
    let tilted = y(Some(&format!("axis = [{}, {}, 1.0]", 0.5 * sn, -0.5 * c))) / unpolarised;
    assert!((tilted - s).abs() < 1e-4, "{kind:?}: {tilted} vs {s}");
    let k = glam::Vec3::new(sn, -c, 0.0);
    let a = glam::Vec3::new(0.3, 0.0, 1.0);
    let proj = (a - k * a.dot(k)).normalize();
    let cos2 = proj.z as f64 * proj.z as f64;
    let mixed = y(Some("axis = [0.3, 0.0, 1.0]")) / unpolarised;
    let want = cos2 * s + (1.0 - cos2) * p;
    assert!((mixed - want).abs() < 1e-3, "{kind:?}: {mixed} vs {want}");
}

/// Polarised light tracing and BDPT against the polarised path tracer, S0 to S3 region
/// by region: a rough gold floor, a rough glass ball and a diffuse ball under a
/// spot light polarised elliptically (linear 0.8, circular 0.3) and an unpolarised
/// point light, seen without and with the camera's analyser. Every non-delta event
/// here polarises but the diffuse ball, so the strategies that join the subpaths
/// (BDPT's s ≥ 1, t ≥ 2), next-event estimation and the splats to the camera (t = 1,
/// light tracing) each carry Mueller matrices and Stokes vectors through their own
/// frames; three estimators that share no code past the scalar sampling agree only if
/// all the frames do.
#[test]
fn polarised_light_tracing_and_bdpt_agree_with_the_path_tracer() {
    for analyser in ["", "polarizer = 30.0\n"] {
        let s = scene(&format!(
            "background = 0.0\n[camera]\neye = [0.0, 2.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nd = 1.5\nresolution = [32, 32]\n{analyser}\
             [render]\npolarization = true\nmax_depth = 4\n\
             [materials.gold]\ntype = \"conductor\"\nmetal = \"Au\"\nroughness = 0.3\n\
             [materials.glass]\ntype = \"dielectric\"\nior = 1.5\nroughness = 0.2\n\
             [materials.white]\ntype = \"lambertian\"\nrho_d = 0.5\n\
             [[shapes]]\ntype = \"quad\"\norigin = [-2.0, 0.0, 2.0]\nedge1 = [4.0, 0.0, 0.0]\nedge2 = [0.0, 0.0, -4.0]\nmaterial = \"gold\"\n\
             [[shapes]]\ntype = \"sphere\"\ncenter = [0.4, 0.5, 0.0]\nradius = 0.5\nmaterial = \"glass\"\n\
             [[shapes]]\ntype = \"sphere\"\ncenter = [-0.7, 0.3, 0.5]\nradius = 0.3\nmaterial = \"white\"\n\
             [[lights]]\ntype = \"spot\"\nposition = [-1.0, 2.0, -1.0]\ndirection = [0.4, -1.0, 0.4]\nintensity = 6.0\ncone_angle = 60.0\n\
             polarization = {{ axis = [1.0, 0.0, 0.0], linear = 0.8, circular = 0.3 }}\n\
             [[lights]]\ntype = \"point\"\nposition = [1.5, 1.5, 1.0]\nintensity = 2.0\n"
        ));
        // Light tracing's splats are heavy-tailed where the rough glass ball focuses
        // light (at 256 paths per pixel a region of 16 pixels failed by chance): 4096
        // per pixel, and the path tracer's reference at 1024. Passed with the seeds
        // shifted by 10, 20, 30 and 40 as well; failed with either beam or chain frame
        // left unrotated.
        let path = common::render::run_lanes(&s, IntegratorKind::Path, 1024, 1, 4);
        for (kind, spp, seed) in [
            (IntegratorKind::LightTrace, 4096, 2),
            (IntegratorKind::Bdpt, 512, 3),
        ] {
            let f = common::render::run_lanes(&s, kind, spp, seed, 4);
            if !analyser.is_empty() {
                // A linear analyser passes no circular polarisation at all.
                let st = f.stokes.as_ref().unwrap();
                assert!(st.iter().all(|p| p[2] == [0.0; 3]), "{kind:?}: S3 ≠ 0");
            }
            for k in 0..if analyser.is_empty() { 4 } else { 3 } {
                // Standard errors from the spread within regions of 16 pixels; 64
                // regions × 3 channels per component at α = 0.005 (Šidák), so that
                // the four components and two integrators fail by chance at most 4% of
                // the seeds (a region fails beyond |t| ≈ 5.5, 15 degrees of freedom).
                let c = compare_stokes(&f, &path, k);
                assert!(
                    c.regions.len() > 100 && c.same(),
                    "{kind:?} against path, S{k} {analyser}:\n{}",
                    c.report(&format!("{kind:?}"), "path", 10)
                );
            }
        }
    }
}

/// `heron compare`'s test on Stokes component `k` (as XYZ) of two polarised films.
fn compare_stokes(a: &Film, b: &Film, k: usize) -> heron::compare::Comparison {
    let image = |f: &Film| {
        let v = match k {
            0 => f.xyz.clone(),
            _ => f
                .stokes
                .as_ref()
                .unwrap()
                .iter()
                .map(|p| p[k - 1])
                .collect(),
        };
        heron::compare::Image::new("film", f.width, f.height, ["X", "Y", "Z"], v, None).unwrap()
    };
    heron::compare::compare(
        &image(a),
        &image(b),
        &heron::compare::Options {
            region: 4,
            alpha: 0.005,
            correction: heron::compare::Correction::Sidak,
            mask: None,
            tolerance: 0.0,
        },
    )
    .unwrap()
}
