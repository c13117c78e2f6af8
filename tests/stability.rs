//! The stability suite (issue 10, part 2), in release mode like every heavy test.
//!
//! * **Scale and position.** One closed box scene (diffuse walls, a glass and a rough
//!   gold sphere, a block standing on the floor, an area light) rendered at scales 1e-4,
//!   1e-2, 1, 1e2 and 1e4 and, at scale 1, moved 10³ away from the origin, under every
//!   integrator with robust ray offsets. Every image must match the scale-1 image of the
//!   same seed to within half the noise of the reference (the RMSE between two seeds,
//!   /√2), and its mean to within 3 standard errors: acne darkens, leaks brighten, either
//!   shifts the mean. The seed's fixed ε at scale 1e-4 must fail the same check (so the
//!   check can fail).
//! * **Edge cases** through `heron::stress` (the code behind `heron stress`): at least
//!   10⁷ rays per case, spread over the case's materials or shapes (a shape's rays are
//!   those aimed at it and the three that leave each hit), zero non-finite values (directions, BSDF values, pdfs,
//!   throughput weights, interactions), every direction unit length to 1e-5, zero
//!   self-intersections and zero leaks: grazing incidence down to cos θ = 1e-7, the
//!   total-internal-reflection edge (|cos²θt| ≤ 1e-7), indices 1.0–4.0, roughness 0–1,
//!   thin slabs, coincident and degenerate triangles, tiny and huge spheres. The seed's
//!   ε on the same shapes must find self-hits and leaks (so the counts can fail).
//!
//! Sizes: the images are 40×40 at 16 spp. A difference image of two such renders at one
//! seed is near zero, far below the noise, so the tolerance is loose for a correct
//! renderer; a scene with ε = 1e-4 at scale 1e-4 (the whole box is 2e-4 wide) differs
//! by many times the noise. The stress cases run 10⁷ rays each because the issue asks
//! for it; at that count a failure rate of 3e-7 is seen with probability 95%.
use glam::Vec3;
use heron::accel::embree;
use heron::geometry::RayOffset;
use heron::render::{build_accel, render, RenderOptions};
use heron::scene::load::load_scene_from_str;
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use heron::settings::OffsetMode;
use heron::stress::{self, CaseReport, Incidence};
use std::fmt::Write as _;
use std::path::Path;

const RAYS: u64 = 10_000_000;

// ----------------------------------------------------------------------------------
// Scale and position
// ----------------------------------------------------------------------------------

/// The box scene with every point mapped to s·p + o (radiances are scale-invariant, so
/// the image must not change).
fn box_scene(s: f32, o: Vec3) -> Scene {
    let p = |x: f32, y: f32, z: f32| {
        let v = s * Vec3::new(x, y, z) + o;
        format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)
    };
    let d = |x: f32, y: f32, z: f32| format!("[{:?}, {:?}, {:?}]", s * x, s * y, s * z);
    let mut t = String::new();
    let _ = write!(
        t,
        "[camera]\neye = {}\nlook_at = {}\nd = 1.4\nresolution = [40, 40]\n\
         [render]\nmax_depth = 6\n\
         [materials.white]\ntype = \"lambertian\"\nrho_d = 0.75\n\
         [materials.red]\ntype = \"lambertian\"\nrho_d = [0.6, 0.05, 0.05]\n\
         [materials.green]\ntype = \"lambertian\"\nrho_d = [0.1, 0.4, 0.08]\n\
         [materials.glass]\ntype = \"dielectric\"\nior = 1.5\n\
         [materials.gold]\ntype = \"conductor\"\nmetal = \"Au\"\nroughness = 0.2\n",
        p(0.0, 0.0, 3.5),
        p(0.0, 0.0, 0.0)
    );
    let mut quad = |origin: String, e1: String, e2: String, m: &str, emit: bool| {
        let _ = write!(
            t,
            "[[shapes]]\ntype = \"quad\"\norigin = {origin}\nedge1 = {e1}\nedge2 = {e2}\nmaterial = \"{m}\"\n"
        );
        if emit {
            t.push_str("emission = 12.0\n");
        }
    };
    // Walls facing inward; the light just below the ceiling.
    quad(
        p(-1.0, -1.0, 1.0),
        d(2.0, 0.0, 0.0),
        d(0.0, 0.0, -2.0),
        "white",
        false,
    );
    quad(
        p(-1.0, 1.0, -1.0),
        d(2.0, 0.0, 0.0),
        d(0.0, 0.0, 2.0),
        "white",
        false,
    );
    quad(
        p(-1.0, -1.0, -1.0),
        d(2.0, 0.0, 0.0),
        d(0.0, 2.0, 0.0),
        "white",
        false,
    );
    quad(
        p(1.0, -1.0, -1.0),
        d(0.0, 0.0, 2.0),
        d(0.0, 2.0, 0.0),
        "green",
        false,
    );
    quad(
        p(-1.0, -1.0, 1.0),
        d(0.0, 0.0, -2.0),
        d(0.0, 2.0, 0.0),
        "red",
        false,
    );
    quad(
        p(-0.25, 0.99, -0.25),
        d(0.5, 0.0, 0.0),
        d(0.0, 0.0, 0.5),
        "white",
        true,
    );
    // A block standing on the floor: its faces meet the floor in creases.
    quad(
        p(-0.7, -1.0, -0.3),
        d(0.0, 0.8, 0.0),
        d(0.4, 0.0, 0.0),
        "white",
        false,
    );
    quad(
        p(-0.7, -1.0, -0.3),
        d(0.0, 0.0, -0.4),
        d(0.0, 0.8, 0.0),
        "white",
        false,
    );
    quad(
        p(-0.3, -1.0, -0.3),
        d(0.0, 0.8, 0.0),
        d(0.0, 0.0, -0.4),
        "white",
        false,
    );
    quad(
        p(-0.7, -0.2, -0.3),
        d(0.4, 0.0, 0.0),
        d(0.0, 0.0, -0.4),
        "white",
        false,
    );
    let mut sphere = |c: String, r: f32, m: &str| {
        let _ = write!(
            t,
            "[[shapes]]\ntype = \"sphere\"\ncenter = {c}\nradius = {:?}\nmaterial = \"{m}\"\n",
            s * r
        );
    };
    sphere(p(0.4, -0.6, 0.2), 0.4, "glass");
    sphere(p(0.45, 0.1, -0.5), 0.3, "gold");
    load_scene_from_str(&t, Path::new("box.toml")).unwrap_or_else(|e| panic!("{e}\n{t}"))
}

fn image(scene: &Scene, kind: IntegratorKind, seed: u64) -> Vec<f32> {
    let mut o = RenderOptions::from_scene(scene);
    o.settings.integrator = kind;
    o.settings.spp = 16;
    o.settings.seed = seed;
    o.threads = 2;
    let (film, stats) = render(scene, &o).unwrap();
    assert_eq!(stats.nonfinite, 0, "{}: non-finite samples", kind.name());
    film.xyz.iter().map(|c| c[1]).collect()
}

fn rmse(a: &[f32], b: &[f32]) -> f64 {
    let s: f64 = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
    (s / a.len() as f64).sqrt()
}

fn mean(a: &[f32]) -> f64 {
    a.iter().map(|&x| x as f64).sum::<f64>() / a.len() as f64
}

/// (RMSE against the reference, mean difference) in units of (reference noise, the
/// mean's standard error).
fn compare(img: &[f32], reference: &[f32], other_seed: &[f32]) -> (f64, f64) {
    let noise = rmse(reference, other_seed) / 2f64.sqrt();
    let diffs: Vec<f32> = reference
        .iter()
        .zip(other_seed)
        .map(|(a, b)| a - b)
        .collect();
    let sd = (diffs.iter().map(|&d| (d as f64).powi(2)).sum::<f64>() / diffs.len() as f64).sqrt();
    let se_mean = sd / (2.0 * diffs.len() as f64).sqrt();
    (
        rmse(img, reference) / noise,
        (mean(img) - mean(reference)).abs() / se_mean,
    )
}

#[test]
fn scaled_and_moved_scenes_render_the_same_under_every_integrator() {
    let cases: [(f32, Vec3); 5] = [
        (1e-4, Vec3::ZERO),
        (1e-2, Vec3::ZERO),
        (1e2, Vec3::ZERO),
        (1e4, Vec3::ZERO),
        (1.0, Vec3::splat(1e3)),
    ];
    let mut report = String::new();
    let mut worst: f64 = 0.0;
    for kind in [
        IntegratorKind::Whitted,
        IntegratorKind::Path,
        IntegratorKind::LightTrace,
        IntegratorKind::Bdpt,
    ] {
        let mut reference_scene = box_scene(1.0, Vec3::ZERO);
        reference_scene.settings.offset = OffsetMode::Robust;
        let reference = image(&reference_scene, kind, 1);
        let other = image(&reference_scene, kind, 2);
        assert!(mean(&reference) > 0.01, "{}: the box is dark", kind.name());
        for (s, o) in cases {
            let mut scene = box_scene(s, o);
            scene.settings.offset = OffsetMode::Robust;
            let img = image(&scene, kind, 1);
            let (r, m) = compare(&img, &reference, &other);
            let _ = writeln!(
                report,
                "{:>10} scale {s:e} at {o}: RMSE {r:.3} × noise, mean off by {m:.2} SE",
                kind.name()
            );
            worst = worst.max(r);
            assert!(
                r < 0.5 && m < 3.0,
                "{}, scale {s:e}, moved {o}: RMSE {r:.3} × the reference's noise, mean {m:.2} SE away\n{report}",
                kind.name()
            );
        }
    }
    eprintln!("{report}worst RMSE {worst:.3} × noise");
}

#[test]
fn the_seeds_fixed_epsilon_fails_the_same_check_at_scale_1e_4() {
    let kind = IntegratorKind::Whitted;
    let mut reference_scene = box_scene(1.0, Vec3::ZERO);
    reference_scene.settings.offset = OffsetMode::Epsilon;
    let reference = image(&reference_scene, kind, 1);
    let other = image(&reference_scene, kind, 2);
    let mut tiny = box_scene(1e-4, Vec3::ZERO);
    tiny.settings.offset = OffsetMode::Epsilon;
    let (r, m) = compare(&image(&tiny, kind, 1), &reference, &other);
    // The negation of the check the robust offsets pass.
    assert!(
        !(r < 0.5 && m < 3.0),
        "ε = 1e-4 in a box 2e-4 wide should fail: RMSE {r:.2} × noise, mean {m:.2} SE"
    );
}

// ----------------------------------------------------------------------------------
// Edge cases
// ----------------------------------------------------------------------------------

const HEAD: &str =
    "[camera]\neye = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [8, 8]\n";

/// A scene of the given materials (TOML tables without their `[materials.NAME]`
/// headers) and shapes; meshes are written to `dir`.
fn scene_in(dir: &Path, materials: &[(&str, &str)], shapes: &str) -> Scene {
    let mut t = HEAD.to_string();
    for (name, body) in materials {
        let _ = write!(t, "[materials.{name}]\n{body}\n");
    }
    t.push_str(shapes);
    let path = dir.join("edge.toml");
    std::fs::write(&path, &t).unwrap();
    heron::scene::load_scene(&path).unwrap_or_else(|e| panic!("{e}\n{t}"))
}

/// Runs the material cases of `regimes` over every material of `scene`, dividing `RAYS`
/// among the materials each regime applies to.
fn material_cases(scene: &Scene, regimes: &[Incidence], seed: u64) -> Vec<CaseReport> {
    let mut out = Vec::new();
    for &inc in regimes {
        let ms: Vec<usize> = (0..scene.materials.len())
            .filter(|&i| inc != Incidence::TirEdge || stress::has_tir(&scene.materials[i]))
            .collect();
        assert!(!ms.is_empty(), "{inc:?}: no material applies");
        let each = RAYS.div_ceil(ms.len() as u64);
        for &i in &ms {
            out.push(stress::material_case(
                &scene.material_names[i],
                &scene.materials[i],
                inc,
                each,
                seed,
                i as u64,
            ));
        }
    }
    out
}

/// Runs every shape case of `scene` with `offset`, dividing `rays` among the shapes.
fn shape_cases(scene: &Scene, offset: RayOffset, rays: u64, seed: u64) -> Vec<CaseReport> {
    let device = embree::Device::new("").unwrap();
    let accel = build_accel(scene, &device).unwrap();
    let each = rays.div_ceil(scene.shapes.len() as u64);
    let closed = stress::closed_shapes(scene);
    (0..scene.shapes.len())
        .map(|i| stress::shape_case(scene, &accel, offset, &closed, i, each, seed))
        .collect()
}

/// Asserts that the case group drew at least 10⁷ rays and found nothing.
fn assert_clean(group: &str, reports: &[CaseReport]) {
    let table = stress::format_table(reports);
    eprintln!("{group}\n{table}");
    let rays: u64 = reports.iter().map(|r| r.rays).sum();
    assert!(rays >= RAYS, "{group}: only {rays} rays\n{table}");
    let failures: u64 = reports.iter().map(CaseReport::failures).sum();
    eprintln!(
        "{group}: {rays} rays in {} cases, {failures} failures",
        reports.len()
    );
    assert_eq!(failures, 0, "{group}\n{table}");
}

const LAMBERTIAN: &str = "type = \"lambertian\"\nrho_d = 0.8";

fn dielectric(ior: f32, roughness: f32) -> String {
    format!("type = \"dielectric\"\nior = {ior:?}\nroughness = {roughness:?}")
}

fn conductor(roughness: f32) -> String {
    format!("type = \"conductor\"\nmetal = \"Au\"\nroughness = {roughness:?}")
}

/// Every kind of material heron has, smooth and rough, dispersive and not.
fn every_material() -> Vec<(String, String)> {
    vec![
        ("lambertian".into(), LAMBERTIAN.into()),
        ("mirror".into(), "type = \"mirror\"".into()),
        ("glass".into(), dielectric(1.5, 0.0)),
        (
            "flint".into(),
            "type = \"dielectric\"\nior = \"N-SF11\"".into(),
        ),
        (
            "rough_flint".into(),
            "type = \"dielectric\"\nior = \"N-SF11\"\nroughness = 0.3".into(),
        ),
        ("rough_glass".into(), dielectric(1.5, 0.2)),
        ("gold".into(), conductor(0.0)),
        ("rough_gold".into(), conductor(0.3)),
        (
            "phong".into(),
            "type = \"glossy\"\nrho_d = 0.3\nrho_s = 0.6\nshininess = 50.0".into(),
        ),
        (
            "phong_on_glass".into(),
            "type = \"glossy\"\nrho_d = 0.1\nrho_s = 0.5\nshininess = 1000.0\nior = 1.5".into(),
        ),
    ]
}

/// The material cases need a valid scene around the materials, nothing more.
const ONE_SHAPE: &str =
    "[[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"lambertian\"\n";

fn borrowed(m: &[(String, String)]) -> Vec<(&str, &str)> {
    m.iter().map(|(a, b)| (a.as_str(), b.as_str())).collect()
}

#[test]
fn grazing_incidence_down_to_cos_1e_7() {
    let dir = tempfile::tempdir().unwrap();
    let ms = every_material();
    let scene = scene_in(dir.path(), &borrowed(&ms), ONE_SHAPE);
    assert_clean(
        "grazing incidence",
        &material_cases(&scene, &[Incidence::Grazing], 11),
    );
}

#[test]
fn the_edge_of_total_internal_reflection() {
    let dir = tempfile::tempdir().unwrap();
    let ms = every_material();
    let scene = scene_in(dir.path(), &borrowed(&ms), ONE_SHAPE);
    assert_clean(
        "TIR edge",
        &material_cases(&scene, &[Incidence::TirEdge], 12),
    );
}

#[test]
fn indices_from_1_to_4() {
    let dir = tempfile::tempdir().unwrap();
    let mut ms = vec![("lambertian".to_string(), LAMBERTIAN.to_string())];
    for (i, ior) in [1.0f32, 1.0001, 1.2, 1.5, 2.0, 2.4, 3.0, 4.0]
        .iter()
        .enumerate()
    {
        ms.push((format!("smooth_{i}"), dielectric(*ior, 0.0)));
        ms.push((format!("rough_{i}"), dielectric(*ior, 0.25)));
    }
    let scene = scene_in(dir.path(), &borrowed(&ms), ONE_SHAPE);
    assert_clean(
        "indices 1.0–4.0",
        &material_cases(
            &scene,
            &[Incidence::Uniform, Incidence::Grazing, Incidence::TirEdge],
            13,
        ),
    );
}

#[test]
fn roughness_from_0_to_1() {
    let dir = tempfile::tempdir().unwrap();
    let mut ms = vec![("lambertian".to_string(), LAMBERTIAN.to_string())];
    for (i, a) in [0.0f32, 1e-4, 1e-3, 0.01, 0.1, 0.5, 0.9, 1.0]
        .iter()
        .enumerate()
    {
        ms.push((format!("glass_{i}"), dielectric(1.5, *a)));
        ms.push((format!("diamond_{i}"), dielectric(2.42, *a)));
        ms.push((format!("gold_{i}"), conductor(*a)));
    }
    let scene = scene_in(dir.path(), &borrowed(&ms), ONE_SHAPE);
    assert_clean(
        "roughness 0–1",
        &material_cases(&scene, &[Incidence::Uniform, Incidence::Grazing], 14),
    );
}

/// An axis-aligned box as an OBJ, sizes (sx, sy, sz), centred at c.
fn box_obj(dir: &Path, name: &str, size: Vec3, c: Vec3) -> String {
    let mut t = String::new();
    for x in [-0.5f32, 0.5] {
        for y in [-0.5f32, 0.5] {
            for z in [-0.5f32, 0.5] {
                let v = Vec3::new(x, y, z) * size + c;
                let _ = writeln!(t, "v {:?} {:?} {:?}", v.x, v.y, v.z);
            }
        }
    }
    for [a, b, c, d] in [
        [1, 2, 4, 3],
        [5, 7, 8, 6],
        [1, 5, 6, 2],
        [3, 4, 8, 7],
        [1, 3, 7, 5],
        [2, 6, 8, 4],
    ] {
        let _ = writeln!(t, "f {a} {b} {c}\nf {a} {c} {d}");
    }
    std::fs::write(dir.join(name), t).unwrap();
    format!("[[shapes]]\ntype = \"mesh\"\nfile = \"{name}\"\nmaterial = \"glass\"\n")
}

fn glass_and_white() -> Vec<(String, String)> {
    vec![
        ("glass".into(), dielectric(1.5, 0.0)),
        ("rough".into(), dielectric(2.42, 0.3)),
        ("white".into(), LAMBERTIAN.into()),
    ]
}

/// Thin glass slabs (1 × 1 × t for t = 1e-3, 1e-5 at the origin, 1e-3 at 10³ away):
/// rays refracted in must meet the far face, never escape between the faces.
fn slabs(dir: &Path) -> Scene {
    let shapes = [
        box_obj(dir, "slab3.obj", Vec3::new(1.0, 1.0, 1e-3), Vec3::ZERO),
        box_obj(
            dir,
            "slab5.obj",
            Vec3::new(1.0, 1.0, 1e-5),
            Vec3::new(0.0, 0.0, 2.0),
        ),
        box_obj(
            dir,
            "slab_far.obj",
            Vec3::new(1.0, 1.0, 1e-3),
            Vec3::splat(1e3),
        ),
    ]
    .concat();
    scene_in(dir, &borrowed(&glass_and_white()), &shapes)
}

/// Tiny and huge spheres, at the origin and far from it (down to the smallest radius
/// the loader accepts there, 1e-6 of the centre's coordinate).
fn spheres(dir: &Path) -> Scene {
    let mut shapes = String::new();
    for (c, r, m) in [
        (Vec3::ZERO, 1e-6f32, "glass"),
        (Vec3::new(0.0, 0.0, 1e-3), 2e-9, "rough"),
        (Vec3::new(1e3, 0.0, 0.0), 1e-3, "glass"),
        // Below the others, not through them: a ground-like sphere whose surface
        // crossed the tiny ones would hide their leaks.
        (Vec3::new(0.0, -1e6 - 10.0, 0.0), 1e6, "rough"),
        (Vec3::splat(1e4), 1e4, "glass"),
        (Vec3::new(-3.0, 0.0, 0.0), 1e-4, "white"),
    ] {
        let _ = write!(
            shapes,
            "[[shapes]]\ntype = \"sphere\"\ncenter = [{:?}, {:?}, {:?}]\nradius = {r:?}\nmaterial = \"{m}\"\n",
            c.x, c.y, c.z
        );
    }
    scene_in(dir, &borrowed(&glass_and_white()), &shapes)
}

/// Coincident quads (the same quad twice with different materials, and once facing
/// the other way), slivers (aspect ratio 1e-7), tiny triangles (1e-9) and a sliver far
/// from the origin. Triangles of exactly zero area are dropped by the loader.
fn triangles(dir: &Path) -> Scene {
    let quad = |m: &str, e1: &str, e2: &str| {
        format!("[[shapes]]\ntype = \"quad\"\norigin = [-1.0, -1.0, 0.0]\nedge1 = {e1}\nedge2 = {e2}\nmaterial = \"{m}\"\n")
    };
    let mut shapes = quad("white", "[2.0, 0.0, 0.0]", "[0.0, 2.0, 0.0]")
        + &quad("glass", "[2.0, 0.0, 0.0]", "[0.0, 2.0, 0.0]")
        + &quad("rough", "[0.0, 2.0, 0.0]", "[2.0, 0.0, 0.0]");
    std::fs::write(
        dir.join("slivers.obj"),
        "v 0 0 3\nv 1 0 3\nv 0.5 1e-7 3\n\
         v 0 0 5\nv 1e-9 0 5\nv 0 1e-9 5\n\
         v 1000 0 0\nv 1001 0 0\nv 1000.5 1e-4 0\n\
         f 1 2 3\nf 4 5 6\nf 7 8 9\n",
    )
    .unwrap();
    shapes.push_str("[[shapes]]\ntype = \"mesh\"\nfile = \"slivers.obj\"\nmaterial = \"glass\"\n");
    scene_in(dir, &borrowed(&glass_and_white()), &shapes)
}

#[test]
fn thin_slabs() {
    let dir = tempfile::tempdir().unwrap();
    assert_clean(
        "thin slabs",
        &shape_cases(&slabs(dir.path()), RayOffset::Robust, RAYS, 21),
    );
}

#[test]
fn tiny_and_huge_spheres() {
    let dir = tempfile::tempdir().unwrap();
    assert_clean(
        "tiny and huge spheres",
        &shape_cases(&spheres(dir.path()), RayOffset::Robust, RAYS, 22),
    );
}

#[test]
fn coincident_and_degenerate_triangles() {
    let dir = tempfile::tempdir().unwrap();
    assert_clean(
        "coincident and degenerate triangles",
        &shape_cases(&triangles(dir.path()), RayOffset::Robust, RAYS, 23),
    );
}

/// The counts can fail: the seed's fixed ε on the same slabs and spheres lets grazing
/// continuations re-hit the surface they left and skip thin interiors.
#[test]
fn the_seeds_epsilon_self_intersects_and_leaks_on_the_same_shapes() {
    let dir = tempfile::tempdir().unwrap();
    let eps = RayOffset::Epsilon(1e-4);
    let mut found = (0, 0);
    for scene in [slabs(dir.path()), spheres(dir.path())] {
        for r in shape_cases(&scene, eps, 600_000, 24) {
            found.0 += r.self_hits;
            found.1 += r.leaks;
        }
    }
    assert!(found.0 > 0 && found.1 > 0, "self-hits, leaks: {found:?}");
}

#[test]
fn the_loader_refuses_a_sphere_below_float_precision_where_it_is() {
    let t = format!(
        "{HEAD}[materials.m]\n{LAMBERTIAN}\n[[shapes]]\ntype = \"sphere\"\ncenter = [3.0, 0.0, 0.0]\nradius = 1e-9\nmaterial = \"m\"\n"
    );
    let e = load_scene_from_str(&t, Path::new("tiny.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tiny.toml")
            && e.contains("shapes[0].radius")
            && e.contains("expected at least"),
        "{e}"
    );
}

/// `heron stress` on a course scene: the table, the summary, and status 0 when clean.
#[test]
fn the_stress_command_reports_each_case() {
    let bin = env!("CARGO_BIN_EXE_heron");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/default-glass.toml");
    let out = std::process::Command::new(bin)
        .args([
            "stress",
            scene.to_str().unwrap(),
            "--rays",
            "20000",
            "--offset",
            "robust",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("material sphere: TIR edge"), "{text}");
    assert!(text.contains("shape 2 (sphere r = 3e-1, sphere)"), "{text}");
    assert!(text.contains("offsets robust, 0 failures"), "{text}");
    // The seed's ε, at grazing angles, does self-intersect: status 3 and a first failure.
    let out = std::process::Command::new(bin)
        .args([
            "stress",
            scene.to_str().unwrap(),
            "--rays",
            "200000",
            "--offset",
            "epsilon",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(3), "{text}");
    assert!(text.contains("first failure in shape"), "{text}");
}
