//! Scene loading: the course scenes load with the numbers they state, and every kind of
//! bad input is an `Err(HeronError::Scene)` whose one-line message names the key path
//! and what was expected, never a panic.
use glam::Vec3;
use heron::bsdf::Material;
use heron::geometry::{Shape, ShapeKind};
use heron::integrator::{choose_kernel, kernel_flags};
use heron::light::Light;
use heron::scene::load::load_scene_from_str;
use heron::scene::{load_scene, Features, Scene};
use heron::settings::IntegratorKind;
use heron::settings::{flag_names, KernelChoice, ALL, EMITTERS, SHADOWS};
use heron::spectrum::uplift::{named, rgb_to_illuminant, rgb_to_reflectance};
use heron::spectrum::DenseSpectrum;
use heron::HeronError;
use std::path::{Path, PathBuf};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

fn load(name: &str) -> Scene {
    let p = scenes_dir().join(name);
    load_scene(&p).unwrap_or_else(|e| panic!("{name} failed to load: {e}"))
}

fn max_abs_diff(a: &DenseSpectrum, b: &DenseSpectrum) -> f32 {
    a.values()
        .iter()
        .zip(b.values().iter())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

fn material_of<'a>(scene: &'a Scene, shape: &Shape) -> (&'a str, &'a Material) {
    let i = shape.material as usize;
    (&scene.material_names[i], &scene.materials[i])
}

fn mesh(shape: &Shape) -> &heron::geometry::Mesh {
    match &shape.kind {
        ShapeKind::Mesh(m) => m,
        other => panic!("expected a mesh, got {other:?}"),
    }
}

/// Geometric normal as Embree computes it: (v1 − v0) × (v2 − v0), normalised.
fn tri_normal(m: &heron::geometry::Mesh, t: [u32; 3]) -> Vec3 {
    let [a, b, c] = t.map(|i| m.positions[i as usize]);
    (b - a).cross(c - a).normalize()
}

// ------------------------------------------------------------------------------------
// The course scenes

#[test]
fn default_scene_has_the_lecture_numbers() {
    let s = load("default.toml");
    assert_eq!(s.shapes.len(), 3);
    assert_eq!(s.materials.len(), 3);
    // Materials are sorted by name.
    assert_eq!(s.material_names, ["plane", "sphere", "triangle"]);

    // Plane y = 0: a square of half-extent 1000 whose triangles face +y.
    let (name, mat) = material_of(&s, &s.shapes[0]);
    assert_eq!(name, "plane");
    let Material::Lambertian(l) = mat else {
        panic!("plane material {mat:?}")
    };
    assert!(max_abs_diff(&l.rho_d, &rgb_to_reflectance([0.1, 0.7, 0.0])) == 0.0);
    let plane = mesh(&s.shapes[0]);
    assert_eq!(plane.positions.len(), 4);
    assert_eq!(plane.indices.len(), 2);
    for p in &plane.positions {
        assert_eq!(p.y, 0.0);
        assert!((p.x.abs() - 1000.0).abs() < 1e-3 && (p.z.abs() - 1000.0).abs() < 1e-3);
    }
    for &t in &plane.indices {
        assert!((tri_normal(plane, t) - Vec3::Y).length() < 1e-6);
    }

    // The triangle, vertices exactly as in the lecture.
    let (name, mat) = material_of(&s, &s.shapes[1]);
    assert_eq!(name, "triangle");
    let Material::Lambertian(l) = mat else {
        panic!("triangle material {mat:?}")
    };
    assert!(max_abs_diff(&l.rho_d, &rgb_to_reflectance([0.4, 0.3, 0.2])) == 0.0);
    let tri = mesh(&s.shapes[1]);
    assert_eq!(
        tri.positions,
        [
            Vec3::new(-0.2, 0.1, 0.9),
            Vec3::new(0.2, 0.1, 0.9),
            Vec3::new(-0.2, 0.1, -0.1)
        ]
    );
    assert_eq!(tri.indices, [[0, 1, 2]]);

    // The sphere.
    match s.shapes[2].kind {
        ShapeKind::Sphere { center, radius } => {
            assert_eq!(center, Vec3::new(0.0, 0.5, 0.0));
            assert_eq!(radius, 0.3);
        }
        ref k => panic!("shape 2 is {k:?}"),
    }
    let (name, mat) = material_of(&s, &s.shapes[2]);
    assert_eq!(name, "sphere");
    let Material::Lambertian(l) = mat else {
        panic!("sphere material {mat:?}")
    };
    // [0.8, 0.8, 0.8] through Smits' uplift is 0.8 to the table's precision.
    assert!(max_abs_diff(&l.rho_d, &DenseSpectrum::constant(0.8)) < 1e-3);

    // Camera.
    let c = &s.camera;
    assert_eq!(c.eye, Vec3::new(2.0, 1.5, 2.0));
    assert_eq!(c.look_at, Vec3::new(0.0, 0.5, 0.0));
    assert_eq!(c.up, Vec3::Y);
    assert_eq!(c.d, 1.0);
    assert_eq!((c.width, c.height), (512, 512));
    // The centre of the image looks at look_at.
    let centre = c.direction(256.0, 256.0);
    let expect = (c.look_at - c.eye).normalize();
    assert!((centre - expect).length() < 1e-6, "{centre} vs {expect}");

    // Point light of intensity π: π times D65 scaled to Y = 1; the background is the
    // environment light after it.
    assert_eq!(s.lights.len(), 2);
    assert_eq!(s.environment, Some(1));
    assert!(matches!(s.lights[1], Light::Environment(_)));
    let Light::Point(p) = &s.lights[0] else {
        panic!("light {:?}", s.lights[0])
    };
    assert_eq!(p.position, Vec3::new(0.0, 1.0, 0.0));
    let pi_d65 = named("D65").unwrap().scaled(std::f32::consts::PI);
    assert!(max_abs_diff(&p.intensity, &pi_d65) < 1e-5);
    // D65 with Y = 1 is about 1 near 560 nm, so the intensity there is about π.
    assert!((p.intensity.eval(560.0) - std::f32::consts::PI).abs() < 0.1);

    // Background (emission), settings.
    assert!(max_abs_diff(&s.background, &rgb_to_illuminant([0.1, 0.3, 0.6])) == 0.0);
    assert_eq!(s.settings.spp, 16);
    assert_eq!(s.settings.max_depth, 10);
    assert_eq!(s.settings.epsilon, 1e-4);
    assert_eq!(s.settings.seed, 0);
    assert_eq!(s.source, scenes_dir().join("default.toml"));

    assert_eq!(
        Features::of(&s),
        Features {
            shadows: true,
            nee: true,
            specular: false,
            emitters: false,
            escape: true,
            media: false,
        }
    );
}

/// The sphere's material in a default-scene variant, which must otherwise equal
/// default.toml.
fn sphere_material(name: &str) -> (Scene, Material) {
    let s = load(name);
    let d = load("default.toml");
    assert_eq!(s.shapes.len(), d.shapes.len());
    assert_eq!(s.material_names, d.material_names);
    assert_eq!(s.camera.eye, d.camera.eye);
    let (mname, m) = material_of(&s, &s.shapes[2]);
    assert_eq!(mname, "sphere");
    let m = m.clone();
    (s, m)
}

#[test]
fn default_mirror_glass_glossy_change_only_the_sphere() {
    let (s, m) = sphere_material("default-mirror.toml");
    let Material::Mirror(mi) = m else {
        panic!("{m:?}")
    };
    assert_eq!(mi.rho_s, DenseSpectrum::constant(1.0));
    assert_eq!(
        Features::of(&s),
        Features {
            shadows: true,
            nee: true,
            specular: true,
            emitters: false,
            escape: true,
            media: false,
        }
    );

    let (s, m) = sphere_material("default-glass.toml");
    let Material::Dielectric(g) = m else {
        panic!("{m:?}")
    };
    assert_eq!(g.ior, heron::spectrum::ior::Ior::Constant(1.5));
    assert!(g.fresnel);
    assert!(Features::of(&s).specular);

    let (s, m) = sphere_material("default-glossy.toml");
    let Material::Glossy(g) = m else {
        panic!("{m:?}")
    };
    assert_eq!(g.rho_s, 0.1);
    assert_eq!(g.shininess, 42.0);
    assert_eq!(g.rho_d.max_value(), 0.0);
    let base = g.base.expect("glossy over glass");
    assert_eq!(base.ior, heron::spectrum::ior::Ior::Constant(1.5));
    assert!(base.fresnel);
    assert_eq!(
        Features::of(&s),
        Features {
            shadows: true,
            nee: true,
            specular: true,
            emitters: false,
            escape: true,
            media: false,
        }
    );
}

#[test]
fn cornell_box_has_one_shape_per_mesh_material() {
    let s = load("cornell.toml");
    let names: Vec<&str> = s.shapes.iter().map(|sh| material_of(&s, sh).0).collect();
    // Mesh materials in the order their OBJ objects first appear (floor is white), then
    // the two spheres.
    assert_eq!(names, ["white", "red", "green", "mirror", "glass"]);
    let tris: Vec<usize> = s.shapes[..3]
        .iter()
        .map(|sh| mesh(sh).indices.len())
        .collect();
    assert_eq!(tris, [6, 2, 2]); // floor + ceiling + back wall; left; right
    let verts: Vec<usize> = s.shapes[..3]
        .iter()
        .map(|sh| mesh(sh).positions.len())
        .collect();
    assert_eq!(verts, [8, 4, 4]); // each shape keeps only the vertices it uses
    assert!(matches!(s.shapes[3].kind, ShapeKind::Sphere { .. }));
    assert!(matches!(s.shapes[4].kind, ShapeKind::Sphere { .. }));

    // Red wall at x = −1, green wall at x = +1, every face turned into the box.
    for &v in &mesh(&s.shapes[1]).positions {
        assert_eq!(v.x, -1.0);
    }
    for &v in &mesh(&s.shapes[2]).positions {
        assert_eq!(v.x, 1.0);
    }
    let inside = Vec3::new(0.0, 1.0, 0.0);
    for sh in &s.shapes[..3] {
        let m = mesh(sh);
        for &t in &m.indices {
            let centroid = t.iter().map(|&i| m.positions[i as usize]).sum::<Vec3>() / 3.0;
            assert!(tri_normal(m, t).dot(inside - centroid) > 0.0);
        }
    }

    let by_name = |n: &str| &s.materials[s.material_names.iter().position(|x| x == n).unwrap()];
    let Material::Lambertian(red) = by_name("red") else {
        panic!()
    };
    assert!(max_abs_diff(&red.rho_d, &rgb_to_reflectance([0.63, 0.065, 0.05])) == 0.0);
    let Material::Dielectric(glass) = by_name("glass") else {
        panic!()
    };
    assert_eq!(glass.ior, heron::spectrum::ior::Ior::Constant(1.5));
    assert!(matches!(by_name("mirror"), Material::Mirror(_)));
    assert_eq!(s.lights.len(), 1);
    // Lit diffuse walls and two specular spheres; no area light, nothing beyond the box.
    assert_eq!(
        Features::of(&s),
        Features {
            shadows: true,
            nee: true,
            specular: true,
            ..Features::default()
        }
    );
}

// ------------------------------------------------------------------------------------
// Bad input

/// A valid scene to which the cases add; keys at the top level must come before the
/// first table, so a case is split into a top-level part and a tables part.
const CAMERA: &str = "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n";
const MATERIALS: &str = "[materials.floor]\ntype = \"lambertian\"\nrho_d = 0.5\n\n\
                         [materials.glass]\ntype = \"dielectric\"\nior = 1.5\n";

struct Dir {
    dir: tempfile::TempDir,
}

impl Dir {
    fn new() -> Dir {
        Dir {
            dir: tempfile::tempdir().unwrap(),
        }
    }
    fn path(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }
    fn write(&self, rel: &str, text: &str) -> PathBuf {
        let p = self.path(rel);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(&p, text).unwrap();
        p
    }
    /// Loads `text` written as scene.toml; the error as (file, message).
    fn err(&self, text: &str) -> (PathBuf, String) {
        let p = self.write("scene.toml", text);
        match load_scene(&p) {
            Ok(_) => panic!("expected an error for:\n{text}"),
            Err(HeronError::Scene { file, message }) => {
                assert!(!message.contains('\n'), "multi-line message: {message:?}");
                (file, message)
            }
            Err(other) => panic!("expected HeronError::Scene, got {other:?}"),
        }
    }
}

/// (top-level keys, tables after camera and materials, substrings the message must
/// contain). Each message must start with the key path, or with `unknown key`.
const BAD: &[(&str, &str, &[&str])] = &[
    // Numbers out of range, wrong types, non-finite values
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -0.3\nmaterial = \"glass\"\n",
     &["shapes[0].radius: expected a positive finite number, got -0.3"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0\nmaterial = \"glass\"\n",
     &["shapes[0].radius: expected a positive finite number, got 0"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = nan\nmaterial = \"glass\"\n",
     &["shapes[0].radius: expected a positive finite number, got nan"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"big\"\nmaterial = \"glass\"\n",
     &["shapes[0].radius: expected a positive finite number, got \"big\""]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, inf, 0]\nradius = 1\nmaterial = \"glass\"\n",
     &["shapes[0].center: expected [x, y, z] with three finite numbers, got [0, inf, 0]"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 1e39, 0]\nradius = 1\nmaterial = \"glass\"\n",
     &["shapes[0].center: expected [x, y, z]"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0]\nradius = 1\nmaterial = \"glass\"\n",
     &["shapes[0].center: expected [x, y, z]", "got [0, 0]"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nmaterial = \"glass\"\n",
     &["shapes[0].radius: missing required key (expected a positive finite number)"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"gold\"\n",
     &["shapes[0].material: no material named \"gold\" (defined: floor, glass)"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = 7\n",
     &["shapes[0].material: expected a string, got 7"]),
    // Tags
    ("", "[[shapes]]\ntype = \"spher\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\n",
     &["shapes[0].type: unknown variant \"spher\", expected one of sphere, triangle, plane, quad, mesh, waves"]),
    ("", "[[shapes]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\n",
     &["shapes[0].type: missing required key (expected one of sphere, triangle, plane, quad, mesh, waves)"]),
    ("", "[[shapes]]\ntype = 3\n", &["shapes[0].type: expected", "sphere", "got 3"]),
    ("", "[materials.x]\ntype = \"glas\"\n",
     &["materials.x.type: unknown variant \"glas\", expected one of lambertian, mirror, dielectric, glossy, conductor"]),
    ("", "[[lights]]\ntype = \"laser\"\n",
     &["lights[0].type: unknown variant \"laser\", expected one of point, directional, sun, spot"]),
    // Unknown keys
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = 0.5\ncolour = 1\n",
     &["unknown key \"colour\" at materials.x (expected one of type, rho_d, texture)"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\nradus = 1\n",
     &["unknown key \"radus\" at shapes[0] (expected one of type, center, radius, material, emission, two_sided, medium)"]),
    ("", "[materials.x]\ntype = \"mirror\"\nior = 1.5\n",
     &["unknown key \"ior\" at materials.x (expected one of type, rho_s)"]),
    ("", "[render]\nsamples = 4\n",
     &["unknown key \"samples\" at render (expected one of spp, max_depth, epsilon, seed, integrator, rr_depth, light_sampler, offset, medium_nee, sun_guide, sppm_photons, sppm_alpha, sppm_radius, spectral_bins, polarization, hide_emitters, filter, filter_radius, filter_stddev, filter_b, filter_c)"]),
    ("backgroun = 1\n", "", &["unknown key \"backgroun\" at the top level", "background"]),
    ("", "[camera.extra]\nx = 1\n", &["unknown key \"extra\" at camera (expected one of eye, "]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { spectrum = \"E\", scal = 1 }\n",
     &["materials.x.rho_d: unknown key \"scal\"", "spectrum, scale"]),
    // Colours
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = [1.2, 0.5, 0.0]\n",
     &["materials.x.rho_d: expected a reflectance with every component in [0, 1], got [1.2, 0.5, 0]"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = -0.1\n",
     &["materials.x.rho_d: expected a reflectance"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = [0.5, 0.5]\n",
     &["materials.x.rho_d: expected a colour"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = \"red\"\n",
     &["materials.x.rho_d: expected a colour", "got \"red\""]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = [0.5, nan, 0.5]\n",
     &["materials.x.rho_d: expected a colour with finite components"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { spectrum = \"D65\" }\n",
     &["materials.x.rho_d: expected a reflectance in [0, 1] at every wavelength", "D65"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { spectrum = \"D50\" }\n",
     &["materials.x.rho_d: unknown spectrum \"D50\", expected one of E, D65"]),
    ("", "[render]\nspectral_bins = 471\n",
     &["render.spectral_bins: expected 0 (none) or 1 to 470 bins, got 471"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { blackbody = 3000 }\n",
     &["materials.x.rho_d: expected a reflectance", "a blackbody is an emission spectrum"]),
    ("background = { blackbody = 50 }\n", "",
     &["background: expected blackbody = a temperature in kelvin within [100, 1000000], got 50"]),
    ("background = { blackbody = 5000, spectrum = \"E\" }\n", "",
     &["background: expected one of the keys spectrum, blackbody, samples in a colour"]),
    ("background = { blackbody = 5000, kelvin = 2 }\n", "",
     &["background: unknown key \"kelvin\" in a blackbody colour (expected one of blackbody, scale)"]),
    ("background = { scale = 2 }\n", "",
     &["background: expected a colour", "none of the keys spectrum, blackbody, samples is given"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { samples = [[500, 0.2], [450, 0.4]] }\n",
     &["materials.x.rho_d: expected samples with strictly increasing wavelengths, got 450 nm after 500 nm"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { samples = [[500, 0.2]] }\n",
     &["materials.x.rho_d: expected samples = [[wavelength_nm, value], ...]"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { samples = [[400, 0.2], [700, -0.1]] }\n",
     &["materials.x.rho_d: expected samples = [[wavelength_nm, value], ...]"]),
    ("", "[materials.x]\ntype = \"lambertian\"\nrho_d = { samples = [[400, 0.2], [700, 0.9]], scale = 2 }\n",
     &["materials.x.rho_d: expected a reflectance in [0, 1] at every wavelength", "whose maximum is 1.8"]),
    ("", "[materials.x]\ntype = \"mirror\"\nrho_s = 1.5\n",
     &["materials.x.rho_s: expected a reflectance"]),
    ("background = [-1, 0, 0]\n", "",
     &["background: expected an emission with every component (or the scale) >= 0, got [-1, 0, 0]"]),
    ("background = { spectrum = \"E\", scale = -2 }\n", "", &["background: expected an emission"]),
    ("", "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = -3\n",
     &["lights[0].intensity: expected an emission"]),
    ("", "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = inf\n",
     &["lights[0].intensity: expected a colour with finite components"]),
    ("", "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\n",
     &["lights[0].intensity: missing required key (expected an emission colour)"]),
    // Materials
    ("", "[materials.x]\ntype = \"dielectric\"\nior = 0\n",
     &["materials.x.ior: expected a positive finite number, got 0"]),
    ("", "[materials.x]\ntype = \"dielectric\"\nior = -inf\n",
     &["materials.x.ior: expected a positive finite number, got -inf"]),
    ("", "[materials.x]\ntype = \"dielectric\"\nior = 1.5\nfresnel = \"yes\"\n",
     &["materials.x.fresnel: expected a boolean, got \"yes\""]),
    ("", "[materials.x]\ntype = \"glossy\"\nrho_d = 0.0\nrho_s = 0.1\nshininess = 0\n",
     &["materials.x.shininess: expected a positive finite number, got 0"]),
    ("", "[materials.x]\ntype = \"glossy\"\nrho_d = 0.0\nrho_s = 1.1\nshininess = 42\n",
     &["materials.x.rho_s: expected a number in [0, 1], got 1.1"]),
    ("", "[materials.x]\ntype = \"glossy\"\nrho_d = [0.5, 0.5, 0.95]\nrho_s = 0.1\nshininess = 42\n",
     &["materials.x: expected rho_d + rho_s <= 1 in every channel (energy conservation)", "0.95"]),
    ("", "[materials.x]\ntype = \"glossy\"\nrho_d = { spectrum = \"E\", scale = 0.95 }\nrho_s = 0.1\nshininess = 42\n",
     &["materials.x: expected rho_d + rho_s <= 1"]),
    ("", "[materials.x]\ntype = \"glossy\"\nrho_d = 0\nrho_s = 0.1\nshininess = 42\nfresnel = false\n",
     &["materials.x.fresnel: expected only together with ior"]),
    ("", "[materials.x]\ntype = \"coated\"\nreflectance = 1.2\nior = 1.5\n",
     &["materials.x.reflectance: expected"]),
    ("", "[materials.x]\ntype = \"coated\"\nreflectance = 0.5\nroughness = -0.1\n",
     &["materials.x.roughness: expected a number in [0, 1], got -0.1"]),
    ("", "[materials.x]\ntype = \"coated\"\nreflectance = 0.5\nthickness = -1\n",
     &["materials.x.thickness: expected a finite optical depth >= 0, got -1"]),
    ("", "[materials.x]\ntype = \"coated\"\nreflectance = 0.5\nior = 0.8\n",
     &["materials.x.ior: expected a refractive index ≥ 1"]),
    ("", "[materials.x]\ntype = \"coated\"\nrho_d = 0.5\n",
     &["unknown key \"rho_d\" at materials.x (expected one of type, reflectance, ior, roughness, thickness, nonlinear)"]),
    ("", "[materials.\"my glass\"]\ntype = \"dielectric\"\nior = -1\n",
     &["materials.\"my glass\".ior: expected a positive finite number, got -1"]),
    // Geometry
    ("", "[[shapes]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\nmaterial = \"floor\"\n",
     &["shapes[0].vertices: expected a triangle with non-zero area"]),
    ("", "[[shapes]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [0, 0, 0], [0, 1, 0]]\nmaterial = \"floor\"\n",
     &["shapes[0].vertices: expected a triangle with non-zero area"]),
    ("", "[[shapes]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0]]\nmaterial = \"floor\"\n",
     &["shapes[0].vertices: expected an array of length 3, got 2 elements"]),
    ("", "[[shapes]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, \"a\", 0]]\nmaterial = \"floor\"\n",
     &["shapes[0].vertices[2]: expected [x, y, z] with three finite numbers"]),
    ("", "[[shapes]]\ntype = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\nmaterial = \"floor\"\n",
     &["shapes[0].normal: expected a non-zero vector [x, y, z] of finite numbers, got [0, 0, 0]"]),
    ("", "[[shapes]]\ntype = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nsize = -5\nmaterial = \"floor\"\n",
     &["shapes[0].size: expected a positive finite number, got -5"]),
    ("", "[[shapes]]\ntype = \"plane\"\npoint = [3e38, 0, 3e38]\nnormal = [0, 1, 0]\nsize = 3e38\nmaterial = \"floor\"\n",
     &["shapes[0].size: expected a size whose square has finite corners"]),
    ("", "[[shapes]]\ntype = \"quad\"\norigin = [0, 0, 0]\nedge1 = [0, 0, 0]\nedge2 = [0, 1, 0]\nmaterial = \"floor\"\n",
     &["shapes[0].edge1: expected a non-zero vector"]),
    ("", "[[shapes]]\ntype = \"quad\"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [-2, 0, 0]\nmaterial = \"floor\"\n",
     &["shapes[0]: expected edge1 and edge2 spanning a non-zero area"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"floor\"\n\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"floor\"\n\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -0.3\nmaterial = \"floor\"\n",
     &["shapes[2].radius: expected a positive finite number, got -0.3"]),
    ("", "[shapes]\ntype = \"sphere\"\n", &["shapes: expected an array of tables (write [[shapes]]), got a table"]),
    ("", "[[lights]]\ntype = \"directional\"\ndirection = [0, 0, 0]\nradiance = 1\n",
     &["lights[0].direction: expected a non-zero vector"]),
    ("", "[[shapes]]\ntype = \"mesh\"\nfile = \"\"\nmaterial = \"floor\"\n",
     &["shapes[0].file: expected the path of a mesh file (.obj, .ply or .serialized), got an empty string"]),
    ("", "[[shapes]]\ntype = \"mesh\"\nfile = \"m.obj\"\nmaterial = \"floor\"\nscale = 0\n",
     &["shapes[0].scale: expected a positive finite number, got 0"]),
    ("", "[[shapes]]\ntype = \"mesh\"\nfile = \"m.obj\"\nmaterial = \"floor\"\ngroups = { a = \"gold\" }\n",
     &["shapes[0].groups.a: no material named \"gold\" (defined: floor, glass)"]),
    // Render settings
    ("", "[render]\nspp = 0\n", &["render.spp: expected a positive integer, got 0"]),
    ("", "[render]\nspp = 2.5\n", &["render.spp: expected a positive integer, got 2.5"]),
    ("", "[render]\nmax_depth = 0\n", &["render.max_depth: expected a positive integer, got 0"]),
    ("", "[render]\nmax_depth = 5000000000\n", &["render.max_depth: expected a positive integer"]),
    ("", "[render]\nepsilon = 0\n", &["render.epsilon: expected a positive finite number, got 0"]),
    ("", "[render]\nepsilon = nan\n", &["render.epsilon: expected a positive finite number, got nan"]),
    ("", "[render]\nseed = -1\n", &["render.seed: expected a non-negative integer, got -1"]),
    // The transport core's keys
    ("", "[materials.m]\ntype = \"conductor\"\nmetal = \"Pt\"\n",
     &["materials.m.metal: unknown metal \"Pt\", expected one of Ag, Al, Au, Cu"]),
    ("", "[materials.m]\ntype = \"conductor\"\nmetal = { n = -1, k = 2 }\n",
     &["materials.m.metal: expected n > 0 and k >= 0"]),
    ("", "[materials.m]\ntype = \"conductor\"\nmetal = { table = \"missing.csv\" }\n",
     &["materials.m.metal: ", "missing.csv", "cannot read the n, k table"]),
    ("", "[materials.m]\ntype = \"conductor\"\n", &["materials.m.metal: missing required key"]),
    ("", "[materials.m]\ntype = \"conductor\"\nmetal = \"Au\"\nroughness = 1.5\n",
     &["materials.m.roughness: expected a number in [0, 1], got 1.5"]),
    ("", "[materials.m]\ntype = \"dielectric\"\nior = 1.5\nroughness = 0.2\nfresnel = false\n",
     &["materials.m.fresnel: false applies to the smooth interface"]),
    ("", "[materials.m]\ntype = \"dielectric\"\nior = 1.5\noutside_ior = 0.5\n",
     &["materials.m.outside_ior: "]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n",
     &["shapes[0].material: missing required key (expected the name of a material, or an emission)"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\ntwo_sided = true\n",
     &["shapes[0].two_sided: applies to emitting shapes"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nemission = -1\n",
     &["shapes[0].emission: expected an emission with every component (or the scale) >= 0"]),
    ("", "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nintensity = 1\ncone_angle = 20\ncone_delta = 30\n",
     &["lights[0].cone_delta: expected degrees in [0, cone_angle = 20], got 30"]),
    ("", "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nintensity = 1\ncone_angle = 120\n",
     &["lights[0].cone_angle: expected degrees in (0, 90], got 120"]),
    ("", "[render]\nintegrator = \"mlt\"\n",
     &["render.integrator: expected one of whitted, path, lighttrace, bdpt, sppm, got \"mlt\""]),
    ("", "[render]\nlight_sampler = \"bvh\"\n",
     &["render.light_sampler: expected power or uniform, got \"bvh\""]),
    ("", "[render]\noffset = \"tiny\"\n",
     &["render.offset: expected auto, epsilon or robust, got \"tiny\""]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [5e3, 0, 0]\nradius = 1e-4\nmaterial = \"glass\"\n",
     &["shapes[0].radius: expected at least 1e-6 × the centre's largest coordinate (5000)"]),
    ("", "[render]\nrr_depth = -1\n", &["render.rr_depth: "]),
    // Finite numbers whose spectra overflow f32 (found while writing the fuzzing harness's
    // checks, fuzz/regressions/scene_toml).
    ("", "[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = 3e38\n",
     &["lights[0].intensity: expected an emission whose spectrum is finite in f32, got 3e38, which overflows at "]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nemission = { spectrum = \"A\", scale = 3e38 }\n",
     &["shapes[0].emission: expected an emission whose spectrum is finite in f32, got { scale = 3e38, spectrum = \"A\" }, which overflows at "]),
    ("", "[[lights]]\ntype = \"sun\"\ndirection = [0, -1, 0]\nirradiance = 1\nangular_radius = 1e-30\n",
     &["lights[0]: the sun's radiance (irradiance / solid angle of the disk) overflows f32 with angular_radius = 1e-30 degrees and irradiance up to 1.19"]),
    ("", "[[lights]]\ntype = \"sun\"\ndirection = [0, -1, 0]\nirradiance = 0\nangular_radius = 1e-30\n",
     &["lights[0]: the sun's radiance"]),
    // Finite coordinates whose products or extent overflow f32 (fuzz/regressions/scene_toml).
    ("", "[[shapes]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [3e19, 0, 0], [0, 3e19, 0]]\nmaterial = \"glass\"\n",
     &["shapes[0].vertices: expected a triangle whose edges' cross product is finite in f32 (coordinates within about ±1e19), got [[0, 0, 0], [3e19, 0, 0], [0, 3e19, 0]]"]),
    ("", "[[shapes]]\ntype = \"quad\"\norigin = [0, 0, 0]\nedge1 = [3e19, 0, 0]\nedge2 = [0, 3e19, 0]\nmaterial = \"glass\"\n",
     &["shapes[0]: expected edge1 and edge2 whose cross product is finite in f32"]),
    ("", "[[lights]]\ntype = \"sun\"\ndirection = [0, -1, 0]\nirradiance = 1\nportal = { origin = [0, 0, 0], edge1 = [3e19, 0, 0], edge2 = [0, 0, 3e19] }\n",
     &["lights[0].portal: expected a portal whose corners and edges' cross product are finite in f32"]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\n[[shapes]]\ntype = \"triangle\"\nvertices = [[1e20, 0, 0], [1e20, 1, 0], [1e20, 0, 1]]\nmaterial = \"glass\"\n",
     &["shapes[1]: expected shapes whose bounding sphere is finite in f32 (coordinates within about ±1e19), got shapes reaching from [-1, -1, -1] to [1e20, 1, 1] with this one"]),
    ("", "[[shapes]]\ntype = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nsize = 2e38\nmaterial = \"glass\"\n",
     &["shapes[0]: expected shapes whose bounding sphere is finite in f32"]),
    // Top level
    ("shapes = 3\n", "", &["shapes: expected an array of tables (write [[shapes]]), got 3"]),
    ("lights = { type = \"point\" }\n", "", &["lights: expected an array of tables (write [[lights]]), got a table"]),
    ("render = [1]\n", "", &["render: expected a table, got [1]"]),
    ("shapes = [[\"sphere\", [0, 0, 0], 1, \"glass\"]]\n", "", &["shapes[0]: expected a table, got [\"sphere\""]),
    ("", "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\n[[shapes]]\n", &["shapes[1].type: missing required key"]),
    ("", "[materials]\nx = [\"lambertian\", 0.5]\n", &["materials.x: expected a table, got [\"lambertian\", 0.5]"]),
    ("lights = [1]\n", "", &["lights[0]: expected a table, got 1"]),
    ("background = \"blue\"\n", "", &["background: expected a colour"]),
    ("", "[[shapes]]\ntype = \"waves\"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"floor\"\nwaves = [{ amplitude = -0.1, wavelength = 0.5, direction = [1, 0] }]\n",
     &["shapes[0].waves[0].amplitude: expected a finite height >= 0, got -0.1"]),
    ("", "[[shapes]]\ntype = \"waves\"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"floor\"\nwaves = [{ amplitude = 0.1, wavelength = 0.5, direction = [0, 0] }]\n",
     &["shapes[0].waves[0].direction: expected a non-zero direction [along edge1, along edge2], got [0, 0]"]),
    ("", "[[shapes]]\ntype = \"waves\"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"floor\"\nwaves = [{ amplitude = 0.1, wavelength = 0, direction = [1, 0] }]\n",
     &["shapes[0].waves[0].wavelength"]),
    ("", "[[shapes]]\ntype = \"waves\"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"floor\"\nresolution = [8192, 8192]\n",
     &["shapes[0].resolution: expected at most 16777216 cells (2 triangles each), got [8192, 8192]"]),
    ("", "[[shapes]]\ntype = \"waves\"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"floor\"\nwaves = [{ amplitude = 0.1, wavelength = 0.5, direction = [1, 0], speed = 2 }]\n",
     &["unknown key \"speed\""]),
];

#[test]
fn bad_inputs_name_the_key_path_and_the_expectation() {
    let dir = Dir::new();
    let mut failures = Vec::new();
    for (top, tables, wants) in BAD {
        let text = format!("{top}\n{CAMERA}\n{MATERIALS}\n{tables}");
        let (file, msg) = dir.err(&text);
        assert_eq!(file, dir.path("scene.toml"), "{msg}");
        for w in *wants {
            if !msg.contains(w) {
                failures.push(format!("want {w:?}\n got {msg:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn bad_cameras() {
    let dir = Dir::new();
    let cases: &[(&str, &str)] = &[
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [0, 4]\n",
         "camera.resolution: expected [width, height] with positive integers (at most 16384), got [0, 4]"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4]\n",
         "camera.resolution: expected [width, height] with positive integers"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4.5, 4]\n",
         "camera.resolution: expected [width, height] with positive integers"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [20000, 4]\n",
         "camera.resolution: expected [width, height] with positive integers (at most 16384), got [20000, 4]"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\n",
         "camera.resolution: missing required key"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 5]\nresolution = [4, 4]\n",
         "camera: eye and look_at must be distinct finite points"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nresolution = [4, 4]\n",
         "camera: up must not be parallel to the view direction"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nd = 0\nresolution = [4, 4]\n",
         "camera.d: expected a positive finite number, got 0"),
        // Ray directions overflowed (zero vectors) at d = 1e20; the image area the light
        // tracers divide by was infinite at d = 1e-20.
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nd = 1e20\nresolution = [4, 4]\n",
         "camera.d: expected a camera constant in [1e-6, 1e6] (a vertical field of view from about 180° down to 1e-6 rad), got 1e20"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nd = 1e-20\nresolution = [4, 4]\n",
         "camera.d: expected a camera constant in [1e-6, 1e6]"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 0, 0]\nresolution = [4, 4]\n",
         "camera.up: expected a non-zero vector"),
        ("eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\nfov = 40\n",
         "unknown key \"fov\" at camera (expected one of eye, look_at, up, d, resolution, type, height, lens, surface, film_diagonal, film_distance, focus_distance, focus_wavelength, mm_per_unit, f_number, polarizer, pupil, film_offset)"),
    ];
    for (cam, want) in cases {
        let (_, msg) = dir.err(&format!("[camera]\n{cam}"));
        assert!(msg.contains(want), "want {want:?}\n got {msg:?}");
    }
    // serde would read a struct from an array of its fields in order; not here.
    let (_, msg) = dir.err("camera = [[0, 0, 5], [0, 0, 0], [0, 1, 0], 1, [4, 4]]\n");
    assert!(
        msg.starts_with("camera: expected a table, got [[0, 0, 5]"),
        "{msg}"
    );
    let (_, msg) = dir.err("[render]\nspp = 4\n");
    assert!(msg.contains("camera: missing required key"), "{msg}");
}

#[test]
fn toml_syntax_errors_give_line_and_column() {
    let dir = Dir::new();
    let (_, msg) = dir.err("[camera]\neye = [0, 0, 5]\nlook_at = [0, 0 0]\n");
    assert!(msg.starts_with("line 3, column "), "{msg}");
    assert!(msg.contains("TOML syntax error"), "{msg}");
    let (_, msg) = dir.err("[camera]\neye = [0, 0, 5]\neye = [1, 1, 1]\n");
    assert!(
        msg.starts_with("line 3, column 1: TOML syntax error"),
        "{msg}"
    );
    assert!(msg.contains("duplicate key"), "{msg}");
    let (_, msg) = dir.err("[camera\n");
    assert!(msg.starts_with("line 1, column "), "{msg}");
}

#[test]
fn unreadable_scene_file_is_an_error() {
    let dir = Dir::new();
    let p = dir.path("missing.toml");
    let Err(HeronError::Scene { file, message }) = load_scene(&p) else {
        panic!("expected an error")
    };
    assert_eq!(file, p);
    assert!(message.contains("cannot read the scene file"), "{message}");
    let p = dir.path("latin1.toml");
    std::fs::write(&p, b"[camera]\n# caf\xe9\n").unwrap();
    let Err(HeronError::Scene { message, .. }) = load_scene(&p) else {
        panic!("expected an error")
    };
    assert!(message.contains("cannot read the scene file"), "{message}");
}

// ------------------------------------------------------------------------------------
// Meshes

const SQUARE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\no front\nf 1 2 3 4\n\
                          o back\nf 1 4 3\ng side\nf 1 3 2\n";

fn mesh_scene(mesh_keys: &str) -> String {
    format!(
        "{CAMERA}\n{MATERIALS}\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"floor\"\n\n[[shapes]]\ntype = \"mesh\"\n{mesh_keys}"
    )
}

#[test]
fn mesh_groups_scale_and_translate() {
    let dir = Dir::new();
    dir.write("meshes/sq.obj", SQUARE_OBJ);
    let p = dir.write(
        "scene.toml",
        &mesh_scene(
            "file = \"meshes/sq.obj\"\nmaterial = \"floor\"\ngroups = { back = \"glass\" }\nscale = 2.0\ntranslate = [0, 0, 1]\n",
        ),
    );
    let s = load_scene(&p).unwrap();
    // Sphere, then the mesh: "front" and "side" share floor, "back" is glass.
    assert_eq!(s.shapes.len(), 3);
    let names: Vec<&str> = s.shapes.iter().map(|sh| material_of(&s, sh).0).collect();
    assert_eq!(names, ["floor", "floor", "glass"]);
    let floor = mesh(&s.shapes[1]);
    assert_eq!(floor.indices.len(), 3); // front's two fan triangles + side
    let glass = mesh(&s.shapes[2]);
    assert_eq!(glass.indices.len(), 1);
    // The unused vertex (5, 5, 5) is not carried; positions are scaled then translated.
    assert_eq!(floor.positions.len(), 4);
    assert!(floor.positions.contains(&Vec3::new(2.0, 2.0, 1.0)));
    assert!(floor.positions.iter().all(|p| p.z == 1.0));
    for m in [floor, glass] {
        for t in &m.indices {
            assert!(t.iter().all(|&i| (i as usize) < m.positions.len()));
        }
    }

    // All groups listed: no default material needed.
    let p = dir.write(
        "scene.toml",
        &mesh_scene(
            "file = \"meshes/sq.obj\"\ngroups = { back = \"glass\", front = \"glass\", side = \"floor\" }\n",
        ),
    );
    let s = load_scene(&p).unwrap();
    assert_eq!(s.shapes.len(), 3);
}

#[test]
fn mesh_errors_name_the_mesh_file_and_the_key_path() {
    let dir = Dir::new();
    let mesh_path = dir.path("meshes/m.obj");
    let scene = mesh_scene("file = \"meshes/m.obj\"\nmaterial = \"floor\"\n");
    let cases: &[(Option<&str>, &[&str])] = &[
        (None, &["shapes[1].file: cannot read the mesh file"]),
        (Some("v 0 0 0\nv 1 0 0\nv 1 1 0\n"),
         &["shapes[1].file: expected a mesh with at least one triangle"]),
        (Some("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n"),
         &["shapes[1].file: line 4: face vertex index 4 out of range (the file has 3 vertices)"]),
        (Some("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -4 -2 -1\n"),
         &["shapes[1].file: line 4: relative face vertex index -4"]),
        (Some("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n"),
         &["shapes[1].file: line 4: face vertex index 0"]),
        (Some("v 0 0 0\nv 1 nan 0\nv 1 1 0\nf 1 2 3\n"),
         &["shapes[1].file: line 2: vertex 2 has a non-finite coordinate"]),
        (Some("v 0 0 0\nv 1 inf 0\nv 1 1 0\nf 1 2 3\n"),
         &["shapes[1].file: line 2: vertex 2 has a non-finite coordinate"]),
        (Some("v 0 0 0\nv 1 zero 0\nv 1 1 0\nf 1 2 3\n"),
         &["shapes[1].file: line 2: expected `v x y z` with three numbers"]),
        (Some("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 x\n"),
         &["shapes[1].file: line 4: cannot read the face vertex \"x\""]),
        (Some("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2\n"),
         &["shapes[1].file: line 4: expected a face with at least 3 vertices"]),
        (Some("v 0 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"),
         &["shapes[1].file: cannot parse the OBJ file"]),
        // Dropped as "degenerate" before (its cross product overflows f32), so the mesh
        // silently lost it.
        (Some("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 3e19 0 0\nv 0 0 3e19\nf 1 2 3\nf 1 4 5\n"),
         &["shapes[1].file: a triangle of object \"unnamed_object\" is too large for f32 after scale 1 and translate [0, 0, 0]"]),
    ];
    for (obj, wants) in cases {
        let _ = std::fs::remove_file(&mesh_path);
        if let Some(obj) = obj {
            dir.write("meshes/m.obj", obj);
        }
        let (file, msg) = dir.err(&scene);
        assert_eq!(file, mesh_path, "{msg}");
        for w in *wants {
            assert!(msg.contains(w), "want {w:?}\n got {msg:?}");
        }
    }

    // A group that the OBJ does not have.
    dir.write("meshes/m.obj", SQUARE_OBJ);
    let (file, msg) = dir.err(&mesh_scene(
        "file = \"meshes/m.obj\"\nmaterial = \"floor\"\ngroups = { frnt = \"glass\" }\n",
    ));
    assert_eq!(file, mesh_path);
    assert!(
        msg.contains("shapes[1].groups.frnt: no object or group named \"frnt\" in the mesh (it has: front, back, side)"),
        "{msg}"
    );
    // Objects without a material.
    let (file, msg) = dir.err(&mesh_scene(
        "file = \"meshes/m.obj\"\ngroups = { front = \"glass\" }\n",
    ));
    assert_eq!(file, dir.path("scene.toml"));
    assert!(
        msg.contains("shapes[1].material: missing required key"),
        "{msg}"
    );
    assert!(msg.contains("\"back\""), "{msg}");
    // The Display form names the mesh path for a missing mesh.
    std::fs::remove_file(&mesh_path).unwrap();
    let e = load_scene(&dir.write("scene.toml", &scene)).unwrap_err();
    assert!(
        e.to_string().contains(&mesh_path.display().to_string()),
        "{e}"
    );
}

// ------------------------------------------------------------------------------------
// Never a panic

fn no_panic_load(text: &str, path: &Path) -> std::result::Result<Scene, String> {
    let r = std::panic::catch_unwind(|| load_scene_from_str(text, path));
    match r {
        Err(_) => panic!("panic while loading:\n{text}"),
        Ok(Ok(s)) => Ok(s),
        Ok(Err(HeronError::Scene { message, .. })) => {
            assert!(!message.contains('\n'), "multi-line message {message:?}");
            assert!(!message.is_empty());
            Err(message)
        }
        Ok(Err(e)) => panic!("not a scene error: {e:?}"),
    }
}

/// Every prefix of the course scenes (cut at each character) loads or fails cleanly.
#[test]
fn truncated_scene_files_never_panic() {
    for name in ["default-glossy.toml", "cornell.toml"] {
        let path = scenes_dir().join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let mut errors = 0;
        for (cut, _) in text.char_indices() {
            if no_panic_load(&text[..cut], &path).is_err() {
                errors += 1;
            }
        }
        // Almost every prefix lacks the camera or breaks the syntax.
        assert!(errors > text.len() / 2, "{name}: only {errors} errors");
        assert!(no_panic_load(&text, &path).is_ok());
    }
}

/// Every `key = value` line of the course scenes, with its value replaced by a wrong one,
/// is an error whose message names the key.
#[test]
fn wrong_values_everywhere_are_errors_naming_the_key() {
    let wrong = [
        "\"x\"", "true", "[]", "{}", "nan", "-1", "1e39", "[1, 2]", "[[1]]",
    ];
    let mut failures = Vec::new();
    let mut checked = 0;
    for name in ["default-glossy.toml", "default-mirror.toml", "cornell.toml"] {
        let path = scenes_dir().join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let Some((k, _)) = line.split_once(" = ") else {
                continue;
            };
            let k = k.trim();
            if k.starts_with('#') || k.starts_with('[') {
                continue;
            }
            for w in wrong {
                // Values that are right for these keys.
                if (k == "fresnel" && w == "true")
                    || (k == "groups" && w == "{}")
                    || (k == "resolution" && w == "[1, 2]")
                {
                    continue;
                }
                let mut edited = lines.clone();
                let replacement = format!("{k} = {w}");
                edited[i] = &replacement;
                let edited = edited.join("\n");
                checked += 1;
                match no_panic_load(&edited, &path) {
                    Ok(_) => failures.push(format!("{name}: `{k} = {w}` loaded")),
                    Err(msg) if !msg.contains(k) => {
                        failures.push(format!("{name}: `{k} = {w}`: {msg}"))
                    }
                    Err(_) => {}
                }
            }
        }
    }
    assert!(checked > 200, "only {checked} cases");
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Assorted malformed documents.
#[test]
fn malformed_documents_are_errors() {
    let path = Path::new("/nonexistent/scene.toml");
    let docs = [
        "",
        "\u{feff}",
        "camera = 1",
        "camera = []",
        "camera = \"front\"",
        "[camera]",
        "[[camera]]\neye = [0, 0, 1]",
        "[camera]\neye = [[0, 0, 1]]\nlook_at = [0, 0, 0]\nresolution = [2, 2]",
        "[camera]\neye = { x = 0 }\nlook_at = [0, 0, 0]\nresolution = [2, 2]",
        "[camera]\neye = 1979-05-27\nlook_at = [0, 0, 0]\nresolution = [2, 2]",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [-1, -1]",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [9223372036854775807, 1]",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[[shapes]]",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[[shapes]]\ntype = \"mesh\"",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[[lights]]\ntype = \"point\"",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[materials]\nx = 1",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[materials.x]",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\nshapes = [1, 2]",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\nlights = \"sun\"",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[render]\nspp = 1e100",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[render]\nseed = 1.0",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\nrender = 3",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n\"\" = 1",
        "[camera]\neye = [0, 0, 1e38]\nlook_at = [0, 0, -1e38]\nresolution = [2, 2]",
        "= 1",
        "[camera]\neye = [0, 0, 1]\nlook_at = \"",
        "[camera]\neye = [0, 0, 1]\nlook_at = '''",
        "[camera]\neye = [0, 0, 1]\nlook_at = [0, 0, 0]\nresolution = [2, 2]\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"\"",
    ];
    for d in docs {
        assert!(no_panic_load(d, path).is_err(), "loaded:\n{d}");
    }
    // Deep nesting is refused by the TOML parser, not a stack overflow.
    let deep = format!("x = {}{}", "[".repeat(100_000), "]".repeat(100_000));
    assert!(no_panic_load(&deep, path).is_err());
    let deep = format!("x = {}1{}", "{ a = ".repeat(10_000), " }".repeat(10_000));
    assert!(no_panic_load(&deep, path).is_err());
}

// ------------------------------------------------------------------------------------
// Features

#[test]
fn features_follow_the_materials_in_use() {
    let dir = Dir::new();
    let scene_top = |top: &str, materials: &str, shapes: &str, lights: &str| {
        let p = dir.write(
            "scene.toml",
            &format!("{top}\n{CAMERA}\n{materials}\n{shapes}\n{lights}"),
        );
        Features::of(&load_scene(&p).unwrap())
    };
    let scene =
        |materials: &str, shapes: &str, lights: &str| scene_top("", materials, shapes, lights);
    let sphere = |m: &str| {
        format!(
            "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"{m}\"\n"
        )
    };
    let light = "[[lights]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = 1\n";
    let dark = "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nradiance = 0\n";
    let mats = "[materials.d]\ntype = \"lambertian\"\nrho_d = 0.5\n\
                [materials.m]\ntype = \"mirror\"\n\
                [materials.g]\ntype = \"glossy\"\nrho_d = 0.5\nrho_s = 0.5\nshininess = 10\n\
                [materials.gg]\ntype = \"glossy\"\nrho_d = 0\nrho_s = 0.1\nshininess = 42\nior = 1.5\n";
    let none = Features::default();

    assert_eq!(scene(mats, &sphere("d"), ""), none); // no light
    assert_eq!(scene(mats, &sphere("d"), dark), none); // a light that emits nothing
    assert_eq!(
        scene(mats, &sphere("d"), light),
        Features {
            shadows: true,
            nee: true,
            ..none
        }
    );
    // Only a mirror: lights are not seen in it.
    assert_eq!(
        scene(mats, &sphere("m"), light),
        Features {
            specular: true,
            ..none
        }
    );
    // Glossy: its Phong lobe is lit by shadow rays; over a refractive base it also
    // continues specularly.
    assert_eq!(
        scene(mats, &sphere("g"), light),
        Features {
            shadows: true,
            nee: true,
            ..none
        }
    );
    assert_eq!(
        scene(mats, &sphere("gg"), light),
        Features {
            shadows: true,
            nee: true,
            specular: true,
            ..none
        }
    );
    // Defined but unused materials do not count.
    assert_eq!(scene(mats, "", light), none);
    // A background (or sky, or sun) is what an escaping ray can find.
    assert_eq!(
        scene_top("background = 0.2", mats, &sphere("d"), light),
        Features {
            shadows: true,
            nee: true,
            escape: true,
            ..none
        }
    );
    // An emitting shape is an area light: it lights the sphere and is seen.
    let lamp = "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 3, 0]\nradius = 0.5\n\
                material = \"d\"\nemission = 2\n";
    let f = scene(mats, &format!("{}{lamp}", sphere("d")), "");
    assert_eq!(
        f,
        Features {
            shadows: true,
            nee: true,
            emitters: true,
            ..none
        }
    );
    assert_eq!(
        kernel_flags(IntegratorKind::Whitted, &f),
        SHADOWS | EMITTERS
    );
    assert_eq!(
        flag_names(kernel_flags(IntegratorKind::Whitted, &f)),
        "shadows+emitters"
    );
    assert_eq!(
        choose_kernel(IntegratorKind::Whitted, &f, KernelChoice::General),
        Ok(ALL)
    );
    assert_eq!(
        choose_kernel(IntegratorKind::Whitted, &f, KernelChoice::Auto),
        Ok(SHADOWS | EMITTERS)
    );
}

// ------------------------------------------------------------------------------------
// Refractive-index models: `ior` as a number, a catalogue name, Sellmeier or Cauchy
// coefficients, or a table file

use heron::spectrum::ior::{catalogue, Ior};

/// The d line (helium, 587.56 nm), where catalogues quote n_d.
const LAMBDA_D: f32 = 587.56;

/// A scene with one dielectric `glass` (index `ior`, written as TOML) on a sphere and one
/// glossy `coat` over the same index.
fn ior_scene(ior: &str) -> String {
    format!(
        "{CAMERA}\n[materials.glass]\ntype = \"dielectric\"\nior = {ior}\n\n\
         [materials.coat]\ntype = \"glossy\"\nrho_d = 0.2\nrho_s = 0.1\nshininess = 20\nior = {ior}\n\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"glass\"\n"
    )
}

/// The index of `glass` (and checks that `coat`'s base has the same one).
fn load_ior(dir: &Dir, ior: &str) -> Ior {
    let p = dir.write("scene.toml", &ior_scene(ior));
    let s = load_scene(&p).unwrap_or_else(|e| panic!("ior = {ior}: {e}"));
    let by_name = |n: &str| {
        let i = s.material_names.iter().position(|m| m == n).unwrap();
        s.materials[i].clone()
    };
    let Material::Dielectric(d) = by_name("glass") else {
        panic!("glass is not a dielectric")
    };
    let Material::Glossy(g) = by_name("coat") else {
        panic!("coat is not glossy")
    };
    assert_eq!(g.base.expect("coat has a base").ior, d.ior, "ior = {ior}");
    d.ior
}

/// n² = 1 + Σ B λ²/(λ² − C), λ in µm, in f64.
fn sellmeier_n(b: &[f64], c: &[f64], lambda_nm: f64) -> f64 {
    let l2 = (lambda_nm * 1e-3).powi(2);
    (1.0 + b.iter().zip(c).map(|(b, c)| b * l2 / (l2 - c)).sum::<f64>()).sqrt()
}

#[test]
fn ior_catalogue_names_load_as_the_catalogue() {
    let dir = Dir::new();
    let names: Vec<&String> = catalogue().keys().collect();
    for want in ["N-BK7", "fused-silica", "N-SF11", "F2", "diamond", "water"] {
        assert!(
            catalogue().contains_key(want),
            "{want} missing from {names:?}"
        );
    }
    for (name, m) in catalogue() {
        let ior = load_ior(&dir, &format!("\"{name}\""));
        assert_eq!(
            Some(&ior),
            heron::spectrum::ior::named(name).as_ref(),
            "{name}"
        );
        assert!(ior.is_dispersive(), "{name}");
        let tol = if name == "water" { 5e-4 } else { 1e-4 };
        assert!(
            (ior.eval(LAMBDA_D) - m.n_d).abs() < tol,
            "{name}: n_d {}",
            ior.eval(LAMBDA_D)
        );
    }
    // A plain number is still a constant index.
    assert_eq!(load_ior(&dir, "1.5"), Ior::Constant(1.5));
    assert_eq!(load_ior(&dir, "2"), Ior::Constant(2.0));
}

#[test]
fn ior_sellmeier_coefficients_load() {
    let dir = Dir::new();
    // N-BK7's coefficients written out: the same model as the catalogue entry, n_d 1.5168.
    let ior = load_ior(
        &dir,
        "{ sellmeier = { b = [1.03961212, 0.231792344, 1.01046945], c = [0.00600069867, 0.0200179144, 103.560653] } }",
    );
    assert_eq!(Some(&ior), heron::spectrum::ior::named("N-BK7").as_ref());
    assert!(
        (ior.eval(LAMBDA_D) - 1.5168).abs() < 1e-4,
        "{}",
        ior.eval(LAMBDA_D)
    );
    // 1, 2 and 4 terms, against the formula in f64.
    let cases: &[(&[f64], &[f64])] = &[
        (&[1.2], &[0.01]),
        (&[0.6961663, 0.4079426], &[0.004679148, 0.01351206]),
        (
            &[0.5684, 0.1726, 0.02086, 0.1131],
            &[0.005102, 0.01821, 0.02621, 10.698],
        ),
    ];
    for (b, c) in cases {
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let ior = load_ior(
            &dir,
            &format!(
                "{{ sellmeier = {{ b = [{}], c = [{}] }} }}",
                list(b),
                list(c)
            ),
        );
        for lambda in [360.0, LAMBDA_D as f64, 830.0] {
            let want = sellmeier_n(b, c, lambda);
            let got = ior.eval(lambda as f32) as f64;
            assert!(
                (got - want).abs() < 2e-6,
                "b {b:?} c {c:?} at {lambda} nm: {got} vs {want}"
            );
        }
    }
}

#[test]
fn ior_cauchy_coefficients_load() {
    let dir = Dir::new();
    // A + B/λ² (λ in µm): a BK7-like fit, n_d = 1.5046 + 0.0042/0.58756² = 1.516766.
    let ior = load_ior(&dir, "{ cauchy = [1.5046, 0.0042] }");
    assert_eq!(
        ior,
        Ior::Cauchy {
            a: 1.5046,
            b: 0.0042,
            c: 0.0
        }
    );
    assert!(
        (ior.eval(LAMBDA_D) - 1.516766).abs() < 2e-6,
        "{}",
        ior.eval(LAMBDA_D)
    );
    // A + B/λ² + C/λ⁴.
    let ior = load_ior(&dir, "{ cauchy = [1.7, 0.01, 0.0005] }");
    let l2 = (LAMBDA_D as f64 * 1e-3).powi(2);
    let want = 1.7 + 0.01 / l2 + 0.0005 / (l2 * l2);
    assert!((ior.eval(LAMBDA_D) as f64 - want).abs() < 2e-6);
    assert!(ior.eval(400.0) > ior.eval(700.0), "normal dispersion");
    // B = C = 0: not dispersive.
    assert!(!load_ior(&dir, "{ cauchy = [1.5, 0] }").is_dispersive());
}

#[test]
fn ior_table_loads_relative_to_the_scene_and_interpolates() {
    let dir = Dir::new();
    dir.write(
        "data/ior.csv",
        "# a made-up glass\nwavelength_nm,n\n\n360, 1.53\n600,1.515\n830,1.51\n",
    );
    let ior = load_ior(&dir, "{ table = \"data/ior.csv\" }");
    assert!(matches!(ior, Ior::Table(_)), "{ior:?}");
    assert!(ior.is_dispersive());
    for (lambda, want) in [
        (360.0, 1.53),
        (480.0, 1.5225),       // halfway between 360 and 600
        (LAMBDA_D, 1.5157775), // 1.53 − 0.015 · 227.56/240
        (600.0, 1.515),
        (715.0, 1.5125),
        (830.0, 1.51),
    ] {
        assert!(
            (ior.eval(lambda) - want).abs() < 2e-6,
            "n({lambda}) = {}, expected {want}",
            ior.eval(lambda)
        );
    }
    // A table covering only part of the range holds its end values.
    dir.write("short.csv", "500,1.6\n600,1.58\n");
    let ior = load_ior(&dir, "{ table = \"short.csv\" }");
    assert!((ior.eval(400.0) - 1.6).abs() < 1e-6 && (ior.eval(800.0) - 1.58).abs() < 1e-6);
    // A constant table is not dispersive.
    dir.write("flat.csv", "360,1.4\n830,1.4\n");
    assert!(!load_ior(&dir, "{ table = \"flat.csv\" }").is_dispersive());
}

/// The error for `ior` (as TOML) in the dielectric and in the glossy material; both must
/// name their key path, and contain every string of `wants`.
fn ior_errors(dir: &Dir, ior: &str, wants: &[&str]) -> String {
    let (_, msg) = dir.err(&ior_scene(ior));
    // Materials are checked in name order: coat before glass.
    assert!(
        msg.contains("materials.coat.ior"),
        "ior = {ior}: no key path in {msg:?}"
    );
    for w in wants {
        assert!(msg.contains(w), "ior = {ior}\nwant {w:?}\n got {msg:?}");
    }
    let p = dir.write(
        "scene.toml",
        &format!("{CAMERA}\n[materials.\"my glass\"]\ntype = \"dielectric\"\nior = {ior}\n"),
    );
    let Err(HeronError::Scene { message, .. }) = load_scene(&p) else {
        panic!("ior = {ior}: expected a scene error")
    };
    assert!(message.contains("materials.\"my glass\".ior"), "{message}");
    for w in wants {
        assert!(
            message.contains(w),
            "ior = {ior}\nwant {w:?}\n got {message:?}"
        );
    }
    msg
}

#[test]
fn ior_errors_name_the_key_path() {
    let dir = Dir::new();
    // Unknown catalogue name: the message lists the names.
    let msg = ior_errors(&dir, "\"BK7\"", &["unknown refractive-index model \"BK7\""]);
    for name in catalogue().keys() {
        assert!(msg.contains(name.as_str()), "{name} not listed in {msg:?}");
    }
    // Sellmeier shapes.
    let shape = "expected sellmeier = { b = [B1, ..], c = [C1, ..] } with 1 to 4";
    ior_errors(
        &dir,
        "{ sellmeier = { b = [1.0, 0.2], c = [0.01] } }",
        &[shape],
    );
    ior_errors(
        &dir,
        "{ sellmeier = { b = [1, 1, 1, 1, 1], c = [0.01, 0.01, 0.01, 0.01, 0.01] } }",
        &[shape],
    );
    ior_errors(&dir, "{ sellmeier = { b = [], c = [] } }", &[shape]);
    ior_errors(&dir, "{ sellmeier = { b = [1.0] } }", &[shape]);
    ior_errors(
        &dir,
        "{ sellmeier = { b = [1.0], c = [0.01], d = [1] } }",
        &[shape],
    );
    ior_errors(
        &dir,
        "{ sellmeier = { b = [\"1\"], c = [0.01] } }",
        &[shape],
    );
    ior_errors(&dir, "{ sellmeier = { b = [nan], c = [0.01] } }", &[shape]);
    // A pole inside 360–830 nm: C = 0.2 µm² puts it at √0.2 µm = 447 nm.
    let range = "expected a refractive index ≥ 1 over 360–830 nm";
    ior_errors(&dir, "{ sellmeier = { b = [1], c = [0.2] } }", &[range]);
    // Negative B: n² < 1 (n < 1 or NaN).
    ior_errors(&dir, "{ sellmeier = { b = [-0.5], c = [0.01] } }", &[range]);
    // Cauchy below 1 at the red end: 0.99 + 0.005/λ² < 1 beyond √0.5 µm = 707.1 nm.
    ior_errors(
        &dir,
        "{ cauchy = [0.99, 0.005] }",
        &[range, "n(708 nm) = 0.99"],
    );
    ior_errors(
        &dir,
        "{ cauchy = [1.5] }",
        &["expected cauchy = [A, B] or [A, B, C] (λ in µm), got [1.5]"],
    );
    ior_errors(
        &dir,
        "{ cauchy = [1.5, 0.01, 0, 0] }",
        &["expected cauchy = [A, B] or [A, B, C]"],
    );
    // Not one of the forms.
    ior_errors(
        &dir,
        "{ sellmeier = { b = [1], c = [0.01] }, cauchy = [1.5, 0] }",
        &["expected a positive number, a catalogue name"],
    );
    ior_errors(
        &dir,
        "{ table = 3 }",
        &["expected a positive number, a catalogue name"],
    );
    ior_errors(
        &dir,
        "[1.5]",
        &["expected a positive number, a catalogue name"],
    );
    ior_errors(&dir, "0.5", &[range]);
}

#[test]
fn ior_table_errors_name_the_file_and_the_line() {
    let dir = Dir::new();
    // A missing file: its path is named.
    let _ = std::fs::remove_file(dir.path("missing.csv"));
    let msg = ior_errors(&dir, "{ table = \"missing.csv\" }", &["missing.csv"]);
    assert!(
        msg.contains(&dir.path("missing.csv").display().to_string()),
        "{msg}"
    );
    // Malformed rows: the file and the line number.
    let cases: &[(&str, &[&str])] = &[
        (
            "wavelength_nm,n\n400,1.5\n500,x\n",
            &["bad.csv", "line 3", "expected a number, got \"x\""],
        ),
        (
            "400,1.5\n500;1.49\n",
            &["bad.csv", "line 2", "expected two comma-separated numbers"],
        ),
        (
            "400,1.5\n500,1.49,7\n",
            &["bad.csv", "line 2", "found 3 fields"],
        ),
        (
            "# comment\n\n400,1.5\n400,1.49\n",
            &["bad.csv", "line 4", "strictly increasing"],
        ),
        ("400,1.5\n", &["bad.csv", "expected at least 2 rows"]),
        // Well-formed, but n < 1 somewhere: the range check.
        (
            "360,1.5\n600,0.99\n830,1.5\n",
            &["expected a refractive index ≥ 1 over 360–830 nm"],
        ),
    ];
    for (csv, wants) in cases {
        dir.write("bad.csv", csv);
        ior_errors(&dir, "{ table = \"bad.csv\" }", wants);
    }
}

/// A `waves` surface is its quad's grid moved along edge1 × edge2 by the sum of its sine
/// waves: every vertex at its height, two triangles per cell, each facing the normal's
/// side.
#[test]
fn waves_are_the_quad_grid_displaced_by_the_sum_of_sines() {
    let scene = load_scene_from_str(
        r#"
[camera]
eye = [0, 3, 0.1]
look_at = [0, 0, 0]
resolution = [4, 4]
[materials.water]
type = "dielectric"
ior = "water"
[[shapes]]
type = "waves"
origin = [-1.0, 0.5, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
resolution = [20, 10]
material = "water"
waves = [
  { amplitude = 0.05, wavelength = 0.7, direction = [1.0, 0.0], phase = 30.0 },
  { amplitude = 0.02, wavelength = 0.3, direction = [0.0, 2.0] },
]
"#,
        std::path::Path::new("w.toml"),
    )
    .unwrap();
    let ShapeKind::Mesh(m) = &scene.shapes[0].kind else {
        panic!("waves make a mesh")
    };
    assert_eq!((m.positions.len(), m.indices.len()), (21 * 11, 2 * 20 * 10));
    let tau = std::f64::consts::TAU;
    for (k, p) in m.positions.iter().enumerate() {
        let (i, j) = ((k % 21) as f64, (k / 21) as f64);
        // Along edge1 (x) from −1, along edge2 (−z) from 1.
        let (u, v) = (2.0 * i / 20.0, 2.0 * j / 10.0);
        assert!((p.x as f64 - (u - 1.0)).abs() < 1e-6 && (p.z as f64 - (1.0 - v)).abs() < 1e-6);
        let h = 0.05 * (tau * u / 0.7 + 30f64.to_radians()).sin() + 0.02 * (tau * v / 0.3).sin();
        assert!(
            (p.y as f64 - 0.5 - h).abs() < 1e-6,
            "vertex {k}: {} vs {}",
            p.y,
            0.5 + h
        );
    }
    for t in &m.indices {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        assert!((b - a).cross(c - a).y > 0.0, "a triangle faces down");
    }
}

/// `{ blackbody = T }` is Planck's law at T scaled to luminance 1 (times `scale`), and
/// `{ samples = [...] }` a table linear between its rows and held beyond them.
#[test]
fn blackbody_and_tabulated_colours_load_as_their_spectra() {
    use heron::spectrum::blackbody::{blackbody, blackbody_luminance};
    use heron::spectrum::cie::spectrum_to_xyz;
    let dir = Dir::new();
    let p = dir.write(
        "scene.toml",
        &format!(
            "background = {{ blackbody = 2700, scale = 3 }}\n{CAMERA}\
             [materials.x]\ntype = \"lambertian\"\nrho_d = {{ samples = [[450, 0.2], [650, 0.8]], scale = 0.5 }}\n\
             [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"x\"\n"
        ),
    );
    let s = load_scene(&p).unwrap();
    let y = spectrum_to_xyz(&s.background)[1];
    assert!((y - 3.0).abs() < 1e-4, "{y}");
    let abs = blackbody(2700.0);
    let k = 3.0 / blackbody_luminance(2700.0) as f32;
    for l in [400.0f32, 555.0, 700.0] {
        let (a, b) = (s.background.eval(l), k * abs.eval(l));
        assert!((a / b - 1.0).abs() < 1e-4, "{l}: {a} vs {b}");
    }
    let heron::bsdf::Material::Lambertian(m) = &s.materials[0] else {
        panic!("{:?}", s.materials[0]);
    };
    for (l, want) in [
        (400.0f32, 0.1f32),
        (450.0, 0.1),
        (550.0, 0.25),
        (650.0, 0.4),
        (800.0, 0.4),
    ] {
        let v = m.rho_d.eval(l);
        assert!((v - want).abs() < 1e-6, "{l}: {v} vs {want}");
    }
}

/// The schema writes back what it read (`Serialize` beside `Deserialize`, the importers'
/// path to `heron convert`): every scene of `scenes/`, read, written as TOML and read
/// again, is the same `SceneFile`, and writing it twice gives the same text.
#[test]
fn every_scene_file_round_trips_through_the_schema() {
    use heron::scene::load::parse_scene_file;
    let mut n = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let file = parse_scene_file(&text).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        let written = toml::to_string(&toml::Table::try_from(&file).unwrap()).unwrap();
        let again = parse_scene_file(&written)
            .unwrap_or_else(|e| panic!("{path:?} written back: {e}\n{written}"));
        assert_eq!(format!("{file:?}"), format!("{again:?}"), "{path:?}");
        let twice = toml::to_string(&toml::Table::try_from(&again).unwrap()).unwrap();
        assert_eq!(written, twice, "{path:?}");
        n += 1;
    }
    assert!(n >= 20, "{n} scene files");
}
