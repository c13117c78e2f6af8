//! Dispersion physics through `heron::trace` (the code behind `heron trace`, which uses
//! the renderer's own intersection, interaction and refraction code): Snell's law with
//! n(λ) at every refraction, the minimum deviation of a 60° N-BK7 prism, Descartes'
//! rainbow angle of a water drop, and the unbiasedness of ending secondary wavelengths.
use glam::Vec3;
use heron::bsdf::{Dielectric, Lambertian, Material};
use heron::camera::Camera;
use heron::geometry::{Mesh, Shape, ShapeKind};
use heron::light::{Light, PointLight};
use heron::math::Rng;
use heron::render::{render, RenderOptions, Renderer};
use heron::scene::{Scene, SceneParts};
use heron::settings::RenderSettings;
use heron::spectrum::ior::{self, Ior};
use heron::spectrum::DenseSpectrum;
use heron::trace::{trace, EventKind, TraceReport};

fn glass_scene(shapes: Vec<Shape>, ior: Ior) -> Scene {
    Scene::from_parts(SceneParts {
        source: "test".into(),
        camera: Camera::new(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO, Vec3::Y, 1.0, 8, 8).unwrap(),
        shapes,
        materials: vec![Material::Dielectric(Dielectric::new(ior, true))],
        material_names: vec!["glass".into()],
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

/// The 60° prism of scenes/meshes/prism60.obj.
fn prism() -> Shape {
    let h = 3f32.sqrt() / 2.0;
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    Shape::new(
        ShapeKind::Mesh(Mesh {
            positions: vec![
                p(-0.5, 0.0, -1.0),
                p(0.5, 0.0, -1.0),
                p(0.0, h, -1.0),
                p(-0.5, 0.0, 1.0),
                p(0.5, 0.0, 1.0),
                p(0.0, h, 1.0),
            ],
            indices: vec![
                [0, 2, 1],
                [3, 4, 5],
                [0, 1, 4],
                [0, 4, 3],
                [1, 2, 5],
                [1, 5, 4],
                [2, 0, 3],
                [2, 3, 5],
            ],
            uvs: Vec::new(),
        }),
        0,
    )
}

fn drop() -> Shape {
    Shape::new(
        ShapeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        0,
    )
}

fn v(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3().normalize(), b.as_dvec3().normalize());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

fn run(s: &Scene, r: &Renderer, o: Vec3, d: Vec3, l: f32, path: &[bool]) -> TraceReport {
    trace(s, r.accel(), o, d, l, path, None).unwrap()
}

#[test]
fn snell_holds_at_every_refraction_with_the_catalogue_index() {
    let mut rng = Rng::new(9, 9);
    for (name, shape) in [("N-SF11", prism()), ("water", drop()), ("diamond", drop())] {
        let s = glass_scene(vec![shape], ior::named(name).unwrap());
        let r = Renderer::new(&s).unwrap();
        let mut checked = 0;
        for _ in 0..300 {
            let lambda = 380.0 + 400.0 * rng.uniform();
            let o = Vec3::new(-3.0, 0.2 + 0.4 * rng.uniform(), 0.3 * rng.uniform() - 0.15);
            let target =
                Vec3::new(0.0, 0.3, 0.0) + 0.3 * Vec3::new(rng.uniform(), rng.uniform(), 0.0);
            let rep = run(&s, &r, o, target - o, lambda, &[]);
            let n = ior::named(name).unwrap().eval(lambda);
            for e in rep.events.iter().filter(|e| e.kind == EventKind::Refract) {
                let (ni, nt) = (e.n_i.unwrap(), e.n_t.unwrap());
                assert!(
                    (ni == 1.0 && nt == n) || (ni == n && nt == 1.0),
                    "{name}: indices {ni}, {nt} at {lambda} nm, catalogue n = {n}"
                );
                let nrm = v(e.normal.unwrap());
                let sin_i = v(e.incoming).cross(nrm).length();
                let sin_t = v(e.outgoing.unwrap()).cross(nrm).length();
                assert!(
                    (ni * sin_i - nt * sin_t).abs() < 1e-5,
                    "{name}: n_i sin θi = {} vs n_t sin θt = {}",
                    ni * sin_i,
                    nt * sin_t
                );
                checked += 1;
            }
        }
        assert!(checked > 200, "{name}: only {checked} refractions");
    }
}

/// Golden-section search for the minimum of `f` on [a, b].
fn minimise(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > 1e-7 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    let x = 0.5 * (a + b);
    (x, f(x))
}

#[test]
fn prism_minimum_deviation_matches_the_formula() {
    let bk7 = ior::named("N-BK7").unwrap();
    let s = glass_scene(vec![prism()], bk7.clone());
    let r = Renderer::new(&s).unwrap();
    // Aim at the middle of the left face; i is measured from its inward normal, which
    // points at -30°, so the incoming direction is at (i − 30°).
    let hit = Vec3::new(-0.25, 3f32.sqrt() / 4.0, 0.0);
    for lambda in [486.1f32, 587.6, 656.3] {
        let deviation = |i_deg: f64| {
            let a = (i_deg - 30.0).to_radians();
            let d = Vec3::new(a.cos() as f32, a.sin() as f32, 0.0);
            let rep = run(&s, &r, hit - 2.0 * d, d, lambda, &[]);
            let kinds: Vec<EventKind> = rep.events.iter().map(|e| e.kind).collect();
            assert_eq!(
                kinds,
                [EventKind::Refract, EventKind::Refract, EventKind::Escape],
                "at i = {i_deg}°"
            );
            angle_deg(d, v(rep.events[2].outgoing.unwrap()))
        };
        let (_, d_min) = minimise(deviation, 40.0, 60.0);
        let n = bk7.eval(lambda) as f64;
        let expected = 2.0 * (n * 30f64.to_radians().sin()).asin().to_degrees() - 60.0;
        assert!(
            (d_min - expected).abs() < 1e-3,
            "{lambda} nm: minimum deviation {d_min}° vs 2 asin(n sin 30°) − 60° = {expected}°"
        );
    }
}

#[test]
fn water_drop_trt_minimum_deviation_is_descartes() {
    let water = ior::named("water").unwrap();
    let s = glass_scene(vec![drop()], water.clone());
    let r = Renderer::new(&s).unwrap();
    for lambda in [400.0f32, 486.1, 587.6, 656.3, 700.0] {
        for (k, path) in [
            (1u32, vec![false, true, false]),
            (2, vec![false, true, true, false]),
        ] {
            let deviation = |b: f64| {
                let rep = run(
                    &s,
                    &r,
                    Vec3::new(0.0, b as f32, -5.0),
                    Vec3::Z,
                    lambda,
                    &path,
                );
                let last = rep.events.last().unwrap();
                // The ray must have left the drop after exactly k internal reflections.
                assert_eq!(rep.events.len(), k as usize + 3, "{lambda} nm b = {b}");
                assert_eq!(last.kind, EventKind::Escape);
                // The angle between the directions is at most 180°; the primary bow's
                // turn (about 138°) is that angle, the secondary's (about 231°) is
                // 360° minus it.
                let d = angle_deg(Vec3::Z, v(last.outgoing.unwrap()));
                if k == 1 {
                    d
                } else {
                    360.0 - d
                }
            };
            let (_, d_min) = minimise(deviation, 0.3, 0.99);
            let n = water.eval(lambda) as f64;
            let kf = k as f64;
            let cos_i = ((n * n - 1.0) / (kf * kf + 2.0 * kf)).sqrt();
            let i = cos_i.acos();
            let rr = (i.sin() / n).asin();
            let expected = (2.0 * (i - rr) + kf * (std::f64::consts::PI - 2.0 * rr)).to_degrees();
            assert!(
                (d_min - expected).abs() < 2e-3,
                "{lambda} nm, k = {k}: minimum deviation {d_min}° vs Descartes {expected}°"
            );
        }
    }
}

#[test]
fn trace_cli_prints_json_and_rejects_a_bad_path() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_heron"))
        .args([
            "trace",
            &format!("{dir}/scenes/droplet.toml"),
            "--origin",
            "0,0.86,-5",
            "--dir",
            "0,0,1",
            "--lambda",
            "589.3",
            "--path",
            "TRT",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let kinds: Vec<&str> = j["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["refract", "reflect", "refract", "escape"]);
    assert!((j["lambda_nm"].as_f64().unwrap() - 589.3).abs() < 1e-3);
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_heron"))
        .args([
            "trace",
            &format!("{dir}/scenes/droplet.toml"),
            "--origin",
            "0,0,-5",
            "--dir",
            "0,0,1",
            "--lambda",
            "589.3",
            "--path",
            "TXR",
        ])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--path"));
}

/// A dispersive glass sphere over a lit diffuse floor, seen by the camera through the
/// sphere: with 4 lanes the secondary wavelengths end at each refraction. Same seeds
/// as the 1-lane render (same hero wavelengths), so the per-pixel difference of the two
/// renders is mostly noise; its mean must be zero within 4 standard errors. Forgetting
/// the hero's factor N shifts it by 25 standard errors. (The R(λi)/R(λhero) weights
/// on reflection change the image by less than this test can resolve.)
#[test]
fn ending_secondary_wavelengths_is_unbiased() {
    let mut s = glass_scene(
        vec![
            Shape::new(
                ShapeKind::Sphere {
                    center: Vec3::new(0.0, 0.0, 0.0),
                    radius: 0.8,
                },
                0,
            ),
            Shape::new(
                ShapeKind::Mesh(Mesh {
                    positions: vec![
                        Vec3::new(-5.0, -1.0, -5.0),
                        Vec3::new(5.0, -1.0, -5.0),
                        Vec3::new(5.0, -1.0, 5.0),
                        Vec3::new(-5.0, -1.0, 5.0),
                    ],
                    indices: vec![[0, 2, 1], [0, 3, 2]],
                    uvs: Vec::new(),
                }),
                1,
            ),
        ],
        ior::named("N-SF11").unwrap(),
    );
    s.materials.push(Material::Lambertian(Lambertian {
        rho_d: DenseSpectrum::from_fn(|l| 0.2 + 0.6 * ((l - 360.0) / 470.0)),
    }));
    s.material_names.push("floor".into());
    s.lights.push(Light::Point(PointLight {
        position: Vec3::new(0.5, 3.0, -1.0),
        intensity: DenseSpectrum::constant(10.0),
    }));
    s.background = DenseSpectrum::from_fn(|l| if l < 500.0 { 1.0 } else { 0.2 });
    s.camera = Camera::new(Vec3::new(0.0, 0.5, -3.0), Vec3::ZERO, Vec3::Y, 1.2, 48, 48).unwrap();
    let mut o = RenderOptions::from_scene(&s);
    o.settings.spp = 64;
    o.settings.lanes = heron::settings::Lanes::One;
    let (one, _) = render(&s, &o).unwrap();
    o.settings.lanes = heron::settings::Lanes::Four;
    let (four, _) = render(&s, &o).unwrap();
    for c in 0..3 {
        let d: Vec<f64> = one
            .xyz
            .iter()
            .zip(&four.xyz)
            .map(|(a, b)| (b[c] - a[c]) as f64)
            .collect();
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let level = one.xyz.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        assert!(
            mean.abs() < 4.0 * sd / n.sqrt(),
            "channel {c}: mean difference {mean} (image level {level}), standard error {}",
            sd / n.sqrt()
        );
    }
}

/// A dielectric may name the index of the medium outside it (glass in water): the
/// interface then refracts with n_inside/n_outside, both functions of λ, and a sphere
/// whose outside medium has its own index (index matching) neither bends nor reflects.
#[test]
fn the_outside_medium_index_sets_the_relative_index() {
    let mut s = glass_scene(vec![drop()], ior::named("N-BK7").unwrap());
    if let heron::bsdf::Material::Dielectric(d) = &mut s.materials[0] {
        d.outside = ior::named("water").unwrap();
    }
    let r = Renderer::new(&s).unwrap();
    let mut rng = Rng::new(4, 4);
    let mut checked = 0;
    for _ in 0..200 {
        let lambda = 380.0 + 400.0 * rng.uniform();
        let o = Vec3::new(-3.0, 0.2 + 0.4 * rng.uniform(), 0.3 * rng.uniform() - 0.15);
        let target = Vec3::new(0.0, 0.3, 0.0) + 0.3 * Vec3::new(rng.uniform(), rng.uniform(), 0.0);
        let rep = run(&s, &r, o, target - o, lambda, &[]);
        let (glass, water) = (
            ior::named("N-BK7").unwrap().eval(lambda),
            ior::named("water").unwrap().eval(lambda),
        );
        for e in rep.events.iter().filter(|e| e.kind == EventKind::Refract) {
            let (ni, nt) = (e.n_i.unwrap(), e.n_t.unwrap());
            assert!(
                (ni == water && nt == glass) || (ni == glass && nt == water),
                "indices {ni}, {nt}; water {water}, glass {glass}"
            );
            let nrm = v(e.normal.unwrap());
            let sin_i = v(e.incoming).cross(nrm).length();
            let sin_t = v(e.outgoing.unwrap()).cross(nrm).length();
            assert!((ni * sin_i - nt * sin_t).abs() < 1e-5);
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked}");

    // Index-matched: the ray goes straight through, with no Fresnel reflection.
    let mut m = glass_scene(vec![drop()], Ior::Constant(1.5));
    if let heron::bsdf::Material::Dielectric(d) = &mut m.materials[0] {
        d.outside = Ior::Constant(1.5);
    }
    let r = Renderer::new(&m).unwrap();
    let dir = Vec3::new(1.0, 0.1, 0.05).normalize();
    let rep = run(&m, &r, Vec3::new(-3.0, 0.3, 0.0), dir, 550.0, &[]);
    for e in rep.events.iter().filter(|e| e.kind == EventKind::Refract) {
        assert!((v(e.outgoing.unwrap()) - dir).length() < 1e-5);
        assert!(e.fresnel_r.unwrap() < 1e-12);
    }
}
