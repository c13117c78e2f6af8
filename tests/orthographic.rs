//! The orthographic camera (`[camera] type = "orthographic"`, issue 38): parallel rays
//! from an image plane `height` scene units high, so a shape's image has the same size
//! at every distance; its keys' one-line errors; light tracing and BDPT refusing it;
//! and both importers' orthographic sensors (Mitsuba 3's `orthographic`, pbrt-v4's
//! `Camera "orthographic"`).
mod common;

use common::render::{render_with, y_of};
use glam::{DVec3, Vec2, Vec3};
use heron::camera::Projection;
use heron::scene::import::{import_scene, ImportOptions, Imported};
use heron::scene::load::{load_imported, load_scene_from_str};
use heron::settings::IntegratorKind;
use std::path::{Path, PathBuf};

fn path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/test-orthographic.toml")
}

fn scene(text: &str) -> heron::scene::Scene {
    load_scene_from_str(text, &path()).unwrap()
}

fn err(text: &str) -> String {
    load_scene_from_str(text, &path())
        .expect_err("an error")
        .to_string()
}

/// 64 × 48 pixels over a plane 3 units high: 1/16 unit per pixel.
const CAMERA: &str = r#"
[camera]
type = "orthographic"
height = 3.0
eye = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
resolution = [64, 48]
"#;

/// A unit-radiance sphere of radius 1 at (1, 0.5, −z) on black.
fn sphere_at(z: f64, integrator: &str) -> String {
    format!(
        r#"{CAMERA}
[render]
integrator = "{integrator}"
spp = 64
max_depth = 1

[[shapes]]
type = "sphere"
center = [1.0, 0.5, {}]
radius = 1.0
emission = {{ spectrum = "E", scale = 1.0 }}
"#,
        -z
    )
}

/// The image's summed Y (pixels covered, at radiance 1) and its centroid in pixels.
fn coverage(film: &heron::film::Film, w: usize) -> (f64, f64, f64) {
    let y = y_of(film);
    let sum: f64 = y.iter().sum();
    let (mut cx, mut cy) = (0.0, 0.0);
    for (i, v) in y.iter().enumerate() {
        cx += v * ((i % w) as f64 + 0.5);
        cy += v * ((i / w) as f64 + 0.5);
    }
    (sum, cx / sum, cy / sum)
}

/// Every camera ray points along the axis, and its origin is the film point's place on
/// the image plane through the eye (3 units high, 4 wide).
#[test]
fn rays_are_parallel_from_the_image_plane() {
    let s = scene(&sphere_at(3.0, "path"));
    let c = &s.camera;
    assert_eq!(c.projection, Projection::Orthographic { height: 3.0 });
    for (x, y) in [(0.0, 0.0), (64.0, 48.0), (32.0, 24.0), (10.5, 40.25)] {
        let r = c.ray(x, y, || Vec2::ZERO, 550.0).unwrap();
        assert_eq!(r.ray.dir, Vec3::NEG_Z, "({x}, {y})");
        assert_eq!(r.weight, 1.0);
        let want = Vec3::new((x / 64.0 - 0.5) * 4.0, (0.5 - y / 48.0) * 3.0, 0.0);
        assert!(
            (r.ray.origin - want).length() < 1e-6,
            "({x}, {y}): {}",
            r.ray.origin
        );
    }
    assert_eq!(c.pixel_size(), Some(3.0 / 48.0));
    assert!(!c.connectable());
}

/// A sphere of radius 1 covers π pixel areas of (1/16)² = 256π = 804.2 pixels, centred
/// 16 pixels right of and 8 above the image's centre, at 3 and at 30 units alike, for
/// every integrator that renders the camera. 64 samples per pixel (Sobol'): only the
/// ~100 edge pixels vary, each by well under 0.1 of a pixel, so the sum is within 0.2%
/// (measured 2026-12-07: −0.023% for path and whitted, −0.032% for SPPM, the same bits at
/// 3 and at 30 units; centroids within 0.001 pixel).
#[test]
fn a_sphere_s_image_has_its_true_size_at_every_distance() {
    let want = 256.0 * std::f64::consts::PI;
    for integrator in ["path", "whitted", "sppm"] {
        for z in [3.0, 30.0] {
            let s = scene(&sphere_at(z, integrator));
            let (sum, cx, cy) = coverage(&render_with(&s, |_| {}), 64);
            assert!(
                (sum / want - 1.0).abs() < 2e-3,
                "{integrator} at {z}: {sum} pixels, want {want}"
            );
            assert!(
                (cx - 48.0).abs() < 0.05 && (cy - 16.0).abs() < 0.05,
                "{integrator} at {z}: centroid ({cx}, {cy})"
            );
        }
    }
}

/// A 1 × 1 quad seen face-on is 16 × 16 pixels at 2 and at 20 units, pixel for pixel
/// the same image (the hits' distances differ, the covered film points do not).
#[test]
fn a_quad_s_image_does_not_depend_on_its_distance() {
    let quad = |z: f64| {
        scene(&format!(
            r#"{CAMERA}
[render]
integrator = "path"
spp = 16
max_depth = 1

[[shapes]]
type = "quad"
origin = [-0.3, -0.6, {}]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 1.0, 0.0]
two_sided = true
emission = {{ spectrum = "E", scale = 1.0 }}
"#,
            -z
        ))
    };
    let (a, b) = (
        y_of(&render_with(&quad(2.0), |_| {})),
        y_of(&render_with(&quad(20.0), |_| {})),
    );
    let sum: f64 = a.iter().sum();
    assert!((sum - 256.0).abs() < 0.5, "{sum} pixels, want 256");
    let differ = a
        .iter()
        .zip(&b)
        .filter(|(p, q)| (*p - *q).abs() > 0.07)
        .count();
    assert_eq!(differ, 0, "pixels differing by more than one sample");
}

#[test]
fn light_tracing_and_bdpt_refuse_it_in_one_line() {
    let s = scene(&sphere_at(3.0, "path"));
    for kind in [IntegratorKind::LightTrace, IntegratorKind::Bdpt] {
        let mut o = heron::render::RenderOptions::from_scene(&s);
        o.settings.integrator = kind;
        let Err(e) = heron::render::render(&s, &o) else {
            panic!("{kind:?} rendered the orthographic camera")
        };
        let e = e.to_string();
        assert!(
            e.contains(&format!(
                "integrator {}: the orthographic camera",
                kind.name()
            )) && e.contains("no light path can connect to it")
                && !e.contains('\n'),
            "{e}"
        );
    }
}

#[test]
fn bad_keys_are_one_line_errors() {
    let base = "eye = [0.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, -1.0]\nresolution = [8, 8]\n";
    for (keys, want) in [
        (
            "height = 2.0\n",
            "camera.height: the orthographic camera's image plane height; set camera.type = \"orthographic\"",
        ),
        (
            "type = \"orthographic\"\n",
            "camera.height: an orthographic camera needs its image plane's height",
        ),
        (
            "type = \"orthographic\"\nheight = 2.0\nd = 1.5\n",
            "camera.d: the pinhole's camera constant; an orthographic camera's view is set by camera.height",
        ),
        (
            "type = \"orthographic\"\nheight = 2.0\nf_number = 4.0\n",
            "camera.f_number: a key of the lens camera",
        ),
        ("type = \"orthographic\"\nheight = -1.0\n", "height"),
        (
            "type = \"fisheye\"\n",
            "camera.type: expected \"pinhole\", \"lens\" or \"orthographic\", got \"fisheye\"",
        ),
    ] {
        let e = err(&format!("[camera]\n{base}{keys}"));
        assert!(e.contains(want) && !e.contains('\n'), "{keys}: {e}");
    }
    let e = err("[camera]\neye = [0.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, -1.0]\nresolution = [8, 8]\ntype = \"orthographic\"\nheight = -1.0\n");
    assert!(e.contains("positive"), "{e}");
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn import(name: &str, text: &str) -> (tempfile::TempDir, heron::error::Result<Imported>) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), name, text);
    let r = import_scene(&p, &ImportOptions::default());
    (dir, r)
}

fn v3(v: &toml::Value) -> DVec3 {
    let a = v.as_array().unwrap();
    let f = |v: &toml::Value| v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap();
    DVec3::new(f(&a[0]), f(&a[1]), f(&a[2]))
}

fn camera_of(i: &Imported) -> toml::Table {
    i.table()["camera"].as_table().unwrap().clone()
}

fn messages(i: &Imported) -> Vec<String> {
    i.warnings.iter().map(|w| w.to_string()).collect()
}

/// Mitsuba 3's `orthographic`: camera space [-1, 1] across the width and
/// [-1/aspect, 1/aspect] across the height, scaled by `to_world`; rays from the near
/// plane (default 0.01).
#[test]
fn mitsuba_orthographic_sensors_import() {
    let sensor = |scale: &str, extra: &str| {
        format!(
            r#"<scene version="3.0.0"><sensor type="orthographic">{extra}
            <transform name="to_world">{scale}<lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/><rfilter type="box"/></film>
            </sensor><shape type="sphere"/></scene>"#
        )
    };
    let (_d, r) = import("s.xml", &sensor(r#"<scale x="2" y="2"/>"#, ""));
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", messages(&imp));
    let c = camera_of(&imp);
    assert_eq!(c["type"].as_str(), Some("orthographic"));
    // Width 2 · 2 = 4, so the height is 4 / aspect 2.
    assert_eq!(c["height"].as_float(), Some(2.0));
    assert!(c.get("d").is_none());
    assert!(v3(&c["eye"]).abs_diff_eq(DVec3::new(0.0, 0.0, 4.99), 1e-12));
    assert!(v3(&c["look_at"]).abs_diff_eq(DVec3::new(0.0, 0.0, 3.99), 1e-12));
    let s = load_imported(&imp).unwrap();
    assert_eq!(
        s.camera.projection,
        Projection::Orthographic { height: 2.0 }
    );

    // near_clip is kept (scaled by to_world's z); far_clip and an uneven scale warn.
    let (_d, r) = import(
        "s.xml",
        &sensor(
            r#"<scale x="3" y="2" z="2"/>"#,
            r#"<float name="near_clip" value="0.5"/><float name="far_clip" value="100"/>"#,
        ),
    );
    let imp = r.unwrap();
    let w = messages(&imp);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("line 1") && w[0].contains("far_clip"),
        "{w:?}"
    );
    assert!(w[1].contains("heron's pixels are square"), "{w:?}");
    let c = camera_of(&imp);
    assert_eq!(c["height"].as_float(), Some(2.0));
    assert!(v3(&c["eye"]).abs_diff_eq(DVec3::new(0.0, 0.0, 4.0), 1e-12));
}

const PBRT_FILM: &str =
    "Film \"rgb\" \"integer xresolution\" [ 40 ] \"integer yresolution\" [ 20 ]\n";

/// pbrt-v4's orthographic camera: the screen window [-aspect, aspect] × [-1, 1] by
/// default (so 2 units high here), or `screenwindow`, whose centre moves the eye.
#[test]
fn pbrt_orthographic_cameras_import() {
    let cam = |params: &str| {
        format!("Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"orthographic\" {params}\n{PBRT_FILM}WorldBegin\nShape \"sphere\"\n")
    };
    let (_d, r) = import("s.pbrt", &cam(""));
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", messages(&imp));
    let c = camera_of(&imp);
    assert_eq!(c["type"].as_str(), Some("orthographic"));
    assert_eq!(c["height"].as_float(), Some(2.0));
    assert!(v3(&c["eye"]).abs_diff_eq(DVec3::new(0.0, 0.0, 5.0), 1e-12));
    load_imported(&imp).unwrap();

    // A window of the image's shape off the centre: the eye moves to its centre, 1.5
    // units along the camera's +x (world −x after LookAt, +x after the Scale −1).
    let (_d, r) = import(
        "s.pbrt",
        &cam("\"float screenwindow\" [ 0.5 2.5 -0.5 0.5 ]"),
    );
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", messages(&imp));
    let c = camera_of(&imp);
    assert_eq!(c["height"].as_float(), Some(1.0));
    assert!(
        v3(&c["eye"]).abs_diff_eq(DVec3::new(1.5, 0.0, 5.0), 1e-12),
        "{c:?}"
    );

    // frameaspectratio sets the default window; a window not of the image's shape and a
    // lens warn; a malformed window and an unknown camera are errors at their line.
    let (_d, r) = import(
        "s.pbrt",
        &cam("\"float frameaspectratio\" [ 0.5 ] \"float lensradius\" [ 0.1 ]"),
    );
    let imp = r.unwrap();
    let w = messages(&imp);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("line 3") && w[0].contains("lensradius 0.1"),
        "{w:?}"
    );
    assert!(w[1].contains("heron's pixels are square"), "{w:?}");
    assert_eq!(camera_of(&imp)["height"].as_float(), Some(4.0));
    for (params, want) in [
        (
            "\"float screenwindow\" [ 1 0 0 1 ]",
            "screenwindow: expected four finite numbers",
        ),
        (
            "\"float screenwindow\" [ 0 1 0 ]",
            "screenwindow: expected four finite numbers",
        ),
    ] {
        let (_d, r) = import("s.pbrt", &cam(params));
        let e = r.expect_err(params).to_string();
        assert!(e.contains("line 3") && e.contains(want), "{e}");
    }
    let (_d, r) = import(
        "s.pbrt",
        &format!("Camera \"realistic\"\n{PBRT_FILM}WorldBegin\n"),
    );
    let e = r.expect_err("realistic").to_string();
    assert!(
        e.contains("expected \"perspective\" or \"orthographic\", got \"realistic\""),
        "{e}"
    );
}
