//! Rendering tests on scenes built in code: energy conservation (white furnace) for the
//! seed's specular materials, the analytic diffuse shading under point and directional
//! lights, no shadow acne at grazing light, and determinism across thread counts.
mod common;

use common::render::render_with;
use glam::Vec3;
use heron::bsdf::{Dielectric, Glossy, Lambertian, Material, Mirror};
use heron::camera::Camera;
use heron::film::Film;
use heron::geometry::{Mesh, Shape, ShapeKind};
use heron::light::{DirectionalLight, Light, PointLight};
use heron::render::{render, RenderOptions};
use heron::scene::{Scene, SceneParts};
use heron::settings::RenderSettings;
use heron::spectrum::ior::Ior;
use heron::spectrum::DenseSpectrum;
use std::f32::consts::PI;

fn camera(eye: Vec3, at: Vec3, w: u32, h: u32) -> Camera {
    Camera::new(eye, at, Vec3::Y, 1.0, w, h).unwrap()
}

fn scene(
    camera: Camera,
    shapes: Vec<Shape>,
    materials: Vec<Material>,
    lights: Vec<Light>,
    bg: f32,
) -> Scene {
    Scene::from_parts(SceneParts {
        source: "test".into(),
        camera,
        shapes,
        material_names: (0..materials.len()).map(|i| format!("m{i}")).collect(),
        materials,
        lights,
        source_sha256: String::new(),
        inputs: vec![],
        media: vec![],
        background: DenseSpectrum::constant(bg),
        sky: None,
        envmap: None,
        settings: RenderSettings {
            spp: 4,
            max_depth: 64,
            epsilon: 1e-4,
            seed: 5,
            ..Default::default()
        },
    })
}

fn quad(origin: Vec3, e1: Vec3, e2: Vec3, material: u32) -> Shape {
    Shape::new(
        ShapeKind::Mesh(Mesh {
            positions: vec![origin, origin + e1, origin + e1 + e2, origin + e2],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            uvs: Vec::new(),
        }),
        material,
    )
}

/// The square y = 0, |x|, |z| ≤ `half`, facing +y.
fn floor(half: f32, material: u32) -> Shape {
    quad(
        Vec3::new(-half, 0.0, -half),
        Vec3::new(0.0, 0.0, 2.0 * half),
        Vec3::new(2.0 * half, 0.0, 0.0),
        material,
    )
}

fn sphere(center: Vec3, radius: f32, material: u32) -> Shape {
    Shape::new(ShapeKind::Sphere { center, radius }, material)
}

/// A render with the scene's settings on `threads` threads.
fn run(scene: &Scene, threads: usize) -> Film {
    render_with(scene, |o| o.threads = threads)
}

fn lambertian(rho: f32) -> Material {
    Material::Lambertian(Lambertian {
        rho_d: DenseSpectrum::constant(rho),
    })
}

/// A lossless specular object under a uniform sky of radiance 1 must be invisible: each
/// path returns exactly the sky's radiance, so the image equals the empty sky's image
/// sample for sample (same wavelengths, same pixel positions).
#[test]
fn white_furnace_specular_objects_vanish() {
    let cam = camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 48, 48);
    let empty = run(&scene(cam.clone(), vec![], vec![], vec![], 1.0), 2);
    let materials = [
        Material::Mirror(Mirror {
            rho_s: DenseSpectrum::constant(1.0),
            texture: None,
        }),
        Material::Dielectric(Dielectric::new(Ior::Constant(1.5), true)),
        Material::Dielectric(Dielectric::new(Ior::Constant(2.42), false)),
        Material::Glossy(Glossy {
            rho_d: DenseSpectrum::constant(0.0),
            rho_s: 0.1,
            shininess: 42.0,
            base: Some(Dielectric::new(Ior::Constant(1.5), true)),
            textures: None,
        }),
    ];
    for m in materials {
        let name = format!("{m:?}");
        let s = scene(
            cam.clone(),
            vec![sphere(Vec3::ZERO, 1.0, 0)],
            vec![m],
            vec![],
            1.0,
        );
        let film = run(&s, 2);
        let mut worst = 0.0f32;
        for (a, b) in film.xyz.iter().zip(&empty.xyz) {
            for c in 0..3 {
                worst = worst.max((a[c] - b[c]).abs() / b[c].max(1e-3));
            }
        }
        assert!(worst < 2e-3, "{name}: largest relative deviation {worst}");
    }
}

/// Per-pixel ratio of `film` to a reference image rendered with the same seeds and a
/// constant unit spectrum, which cancels the wavelength-sampling noise exactly.
fn unit_reference(cam: &Camera) -> Film {
    run(&scene(cam.clone(), vec![], vec![], vec![], 1.0), 2)
}

#[test]
fn lambertian_under_a_directional_light_matches_rho_over_pi_e_cos() {
    // Camera looks straight down on a plane; light at 60° from the normal.
    let cam = Camera::new(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 32, 32).unwrap();
    let theta = 60f32.to_radians();
    let light_dir = Vec3::new(theta.sin(), -theta.cos(), 0.0);
    let s = scene(
        cam.clone(),
        vec![floor(50.0, 0)],
        vec![lambertian(0.5)],
        vec![Light::Directional(DirectionalLight {
            direction: light_dir,
            radiance: DenseSpectrum::constant(PI),
        })],
        0.0,
    );
    let film = run(&s, 2);
    let unit = unit_reference(&cam);
    let expected = 0.5 / PI * PI * theta.cos();
    for (a, u) in film.xyz.iter().zip(&unit.xyz) {
        let r = a[1] / u[1];
        assert!(
            (r - expected).abs() < 1e-4,
            "ratio {r}, expected {expected}"
        );
    }
}

#[test]
fn lambertian_under_a_point_light_falls_off_as_cos_over_r_squared() {
    // One pixel's view of a plane lit by a point light at height h: the centre pixel sees
    // the point under the light, where E = I / h².
    let h = 1.5f32;
    let cam = Camera::new(Vec3::new(0.0, 4.0, 0.0), Vec3::ZERO, Vec3::Z, 40.0, 3, 3).unwrap();
    let s = scene(
        cam.clone(),
        vec![floor(5.0, 0)],
        vec![lambertian(0.8)],
        vec![Light::Point(PointLight {
            position: Vec3::new(0.0, h, 0.0),
            intensity: DenseSpectrum::constant(PI),
        })],
        0.0,
    );
    let film = run(&s, 1);
    let unit = unit_reference(&cam);
    let centre = 4;
    let expected = 0.8 / PI * PI / (h * h);
    let r = film.xyz[centre][1] / unit.xyz[centre][1];
    // The pixel covers a small patch around the foot point; cos/r² varies by < 1e-4 there.
    assert!(
        (r - expected).abs() < 1e-3 * expected,
        "ratio {r}, expected {expected}"
    );
}

#[test]
fn no_shadow_acne_at_grazing_light() {
    // Light 88° from the normal: any self-intersection of the shadow rays would darken
    // pixels to 0. Every pixel must keep the analytic value.
    let cam = Camera::new(Vec3::new(0.3, 2.0, 0.2), Vec3::ZERO, Vec3::Z, 1.0, 64, 64).unwrap();
    let theta = 88f32.to_radians();
    let s = scene(
        cam.clone(),
        vec![floor(20.0, 0)],
        vec![lambertian(1.0)],
        vec![Light::Directional(DirectionalLight {
            direction: Vec3::new(theta.sin(), -theta.cos(), 0.0),
            radiance: DenseSpectrum::constant(PI),
        })],
        0.0,
    );
    let film = run(&s, 2);
    let unit = unit_reference(&cam);
    let expected = theta.cos();
    let bad = film
        .xyz
        .iter()
        .zip(&unit.xyz)
        .filter(|(a, u)| (a[1] / u[1] - expected).abs() > 1e-3 * expected)
        .count();
    assert_eq!(
        bad,
        0,
        "{bad} of {} pixels deviate (shadow acne)",
        film.xyz.len()
    );
}

#[test]
fn shadow_rays_are_blocked_between_but_not_beyond_the_light() {
    // A point light at height 2 above the origin; the camera looks obliquely at the
    // origin with a narrow field of view. A sphere between light and origin shadows it;
    // the same sphere above the light must not (the shadow ray stops at ‖p − x‖ − ε).
    let cam = Camera::new(Vec3::new(3.0, 0.5, 0.0), Vec3::ZERO, Vec3::Y, 40.0, 3, 3).unwrap();
    let lit = |sphere_y: f32| {
        let s = scene(
            cam.clone(),
            vec![floor(5.0, 0), sphere(Vec3::new(0.0, sphere_y, 0.0), 0.2, 0)],
            vec![lambertian(0.8)],
            vec![Light::Point(PointLight {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: DenseSpectrum::constant(PI),
            })],
            0.0,
        );
        let film = run(&s, 1);
        let unit = unit_reference(&cam);
        film.xyz[4][1] / unit.xyz[4][1]
    };
    assert_eq!(
        lit(1.0),
        0.0,
        "sphere between light and surface must shadow it"
    );
    let expected = 0.8 / PI * PI / 4.0;
    let r = lit(3.0);
    assert!(
        (r - expected).abs() < 2e-3 * expected,
        "sphere beyond the light: {r} vs {expected}"
    );
}

#[test]
fn image_is_identical_for_any_thread_count() {
    let cam = camera(Vec3::new(2.0, 1.5, 2.0), Vec3::new(0.0, 0.5, 0.0), 37, 29);
    let s = scene(
        cam,
        vec![floor(5.0, 0), sphere(Vec3::new(0.0, 0.5, 0.0), 0.3, 1)],
        vec![
            lambertian(0.6),
            Material::Dielectric(Dielectric::new(Ior::Constant(1.5), true)),
        ],
        vec![Light::Point(PointLight {
            position: Vec3::new(0.0, 1.0, 0.0),
            intensity: DenseSpectrum::constant(PI),
        })],
        0.3,
    );
    let a = run(&s, 1);
    let b = run(&s, 2);
    let c = run(&s, 7);
    assert!(a == b && b == c, "films differ between thread counts");
    let mut o = RenderOptions::from_scene(&s);
    o.settings.packets = heron::settings::Packets::Off;
    let (d, _) = render(&s, &o).unwrap();
    // Embree's packet and single-ray kernels may round t differently in the last bits,
    // so the two images agree closely but not bit for bit.
    let mut far = 0;
    for (p, q) in a.xyz.iter().zip(&d.xyz) {
        if (p[1] - q[1]).abs() > 1e-3 * p[1].abs().max(1e-2) {
            far += 1;
        }
    }
    assert!(
        far * 100 <= a.xyz.len(),
        "packet and single-ray camera rays disagree in {far} of {} pixels",
        a.xyz.len()
    );
}

/// The course's sphere variants must look different where the sphere is and the same
/// elsewhere: the material, not the setup, changes.
#[test]
fn course_variants_differ_only_where_the_sphere_is() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let render_small = |name: &str| {
        let mut s = heron::scene::load_scene(&dir.join(format!("{name}.toml"))).unwrap();
        s.camera = Camera::new(
            s.camera.eye,
            s.camera.look_at,
            s.camera.up,
            s.camera.d,
            64,
            64,
        )
        .unwrap();
        s.settings.spp = 8;
        run(&s, 2)
    };
    // Mean Y over a window: the sphere (centre of the view) and a patch of floor far
    // in front of it (bottom-left corner, in no sphere's reflection or shadow).
    let mean = |f: &Film, x0: usize, y0: usize, w: usize| {
        let mut m = 0.0;
        for y in y0..y0 + w {
            for x in x0..x0 + w {
                m += f.xyz[y * 64 + x][1];
            }
        }
        m / (w * w) as f32
    };
    let base = render_small("default");
    for v in ["default-mirror", "default-glass", "default-glossy"] {
        let f = render_small(v);
        let (a, b) = (mean(&base, 28, 24, 8), mean(&f, 28, 24, 8));
        assert!(
            (a - b).abs() > 0.2 * a.max(b),
            "{v}: sphere {b} vs default {a}"
        );
        let (c, d) = (mean(&base, 0, 56, 6), mean(&f, 0, 56, 6));
        assert!((c - d).abs() < 0.05 * c, "{v}: floor {d} vs default {c}");
    }
}

/// The sun: a Lambertian floor under it has ρ/π E cos θ (the disk sampled over its
/// extent), and a camera looking at it sees a disk of radiance E/Ω and the solar
/// angular radius.
#[test]
fn sun_lights_like_its_irradiance_and_shows_its_disk() {
    use heron::light::SunLight;
    let theta = 50f32.to_radians();
    let alpha = 0.2666f32.to_radians();
    let sun = SunLight::new(
        Vec3::new(theta.sin(), -theta.cos(), 0.0),
        DenseSpectrum::constant(2.0),
        alpha,
    );
    let cam = Camera::new(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 16, 16).unwrap();
    let s = scene(
        cam.clone(),
        vec![floor(50.0, 0)],
        vec![lambertian(0.5)],
        vec![Light::Sun(sun.clone())],
        0.0,
    );
    // Same spp as the unit reference, so the two share their wavelengths sample for
    // sample.
    let film = run(&s, 2);
    let unit = unit_reference(&cam);
    let expected = 0.5 / PI * 2.0 * theta.cos();
    // Each shadow ray sees cos θ of one point of the disk: a spread of about
    // α sin θ = 0.4% per sample, so 1% per pixel and 5e-4 over the image.
    let mut mean = 0.0;
    for (a, u) in film.xyz.iter().zip(&unit.xyz) {
        let r = a[1] / u[1];
        mean += r / film.xyz.len() as f32;
        assert!(
            (r - expected).abs() < 1e-2 * expected,
            "ratio {r}, expected {expected}"
        );
    }
    assert!(
        (mean - expected).abs() < 5e-4 * expected,
        "mean {mean}, expected {expected}"
    );
    // Look straight at the sun through a narrow field: 0.01 rad across 64 pixels.
    let to_sun = -sun.direction;
    let d = 64.0 / 0.01 / 64.0; // image height 1 at distance d spans 1/d rad
    let cam = Camera::new(Vec3::ZERO, to_sun, Vec3::Z, d, 64, 64).unwrap();
    let mut sky = scene(
        cam.clone(),
        vec![],
        vec![],
        vec![Light::Sun(sun.clone())],
        0.0,
    );
    sky.settings.spp = 4;
    let film = run(&sky, 2);
    let unit = unit_reference(&cam);
    let l = sun.radiance.eval(550.0);
    let mut inside = 0;
    for (a, u) in film.xyz.iter().zip(&unit.xyz) {
        let r = a[1] / u[1];
        if r > 0.0 {
            inside += 1;
            // Pixels on the rim are partly covered.
            assert!(r <= l * 1.0001, "{r} > disk radiance {l}");
        }
    }
    // Disk area in pixels: π (α / (0.01 rad / 64 px))².
    let px = std::f32::consts::PI * (alpha / (0.01 / 64.0)).powi(2);
    assert!(
        (inside as f32 - px).abs() < 0.1 * px,
        "{inside} pixels see the disk, expected about {px}"
    );
    assert!((l * sun.solid_angle() - 2.0).abs() < 1e-4);
}
