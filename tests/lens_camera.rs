//! The lens camera (`[camera] type = "lens"`, issue 22) through the whole renderer:
//! its exposure normalisation, where it puts an off-axis object, the off-axis film
//! window (`film_offset`), that the exit pupil's bounds lose no light, and its one-line
//! errors.
mod common;

use common::render::{compare_xyz, mean_se, render_with, y_of};
use heron::scene::load::load_scene_from_str;
use heron::settings::IntegratorKind;
use std::path::PathBuf;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scene file in the repository's scenes/ folder, so that `../lenses/…` resolves.
fn scene(text: &str) -> heron::scene::Scene {
    load_scene_from_str(text, &repo().join("scenes/test-lens.toml")).unwrap()
}

fn err(text: &str) -> String {
    load_scene_from_str(text, &repo().join("scenes/test-lens.toml"))
        .expect_err("an error")
        .to_string()
}

const UNIFORM: &str = r#"
background = 1.0
[camera]
type = "lens"
lens = "../lenses/cooke-triplet.toml"
eye = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
resolution = [48, 32]
[render]
integrator = "path"
spp = 64
"#;

/// Under a uniform radiance of 1 the film's centre reads 1 (the exposure is normalised
/// to the centre's irradiance, E₀), and the corners read less: cos⁴ fall-off and the
/// rear rim's vignetting. The centre's 4 × 4 pixels at 64 samples each (1024 samples,
/// the weight's spread across the pupil below 5%) estimate the mean to about 0.2%.
#[test]
fn uniform_radiance_reads_one_at_the_centre() {
    let s = scene(UNIFORM);
    let film = render_with(&s, |_| {});
    let y = y_of(&film);
    let (w, h) = (48usize, 32usize);
    let px = |x: usize, yy: usize| y[yy * w + x];
    let centre: Vec<f64> = (14..18)
        .flat_map(|yy| (22..26).map(move |x| (x, yy)))
        .map(|(x, yy)| px(x, yy))
        .collect();
    let (m, se) = mean_se(&centre);
    assert!((m - 1.0).abs() < 0.01 + 3.0 * se, "centre {m} ± {se}");
    let corner = (px(0, 0) + px(w - 1, 0) + px(0, h - 1) + px(w - 1, h - 1)) / 4.0;
    // cos⁴(23.4°) = 0.71 before vignetting.
    assert!(
        corner < 0.8 * m && corner > 0.3 * m,
        "corner {corner}, centre {m}"
    );
}

/// An off-axis light lands where the pinhole of the same field of view puts it, on the
/// same side (the lens's inverted image is turned upright on the film) and in the same
/// direction from the centre, a little farther out: the pinhole (at the film, with
/// d = EFL / film height) sees the light from 78 mm farther back than the lens's
/// entrance pupil (2000/1922 = 1.04), and focused at 2 m the film is 2.6% farther
/// behind the lens than at infinity, so the lens's image is about 1.07 times the
/// pinhole's (the Cooke triplet's distortion is below 1% at these angles).
#[test]
fn off_axis_light_lands_where_the_pinhole_puts_it() {
    let lights = r#"
[[shapes]]
type = "sphere"
center = [0.4, 0.25, -2.0]
radius = 0.02
emission = { spectrum = "E", scale = 50.0 }
"#;
    let lens = scene(&format!(
        "{}{lights}",
        UNIFORM
            .replace("background = 1.0", "background = 0.0")
            .replace("[48, 32]", "[120, 80]")
            .replace("spp = 64", "spp = 16\n")
            .replace("[render]", "focus_distance = 2.0\n[render]")
    ));
    let d = lens.camera.d;
    let pin = scene(&format!(
        r#"
[camera]
eye = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
resolution = [120, 80]
d = {d}
[render]
integrator = "path"
spp = 16
{lights}"#
    ));
    let centroid = |film: &heron::film::Film| {
        let y = y_of(film);
        let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
        for (i, v) in y.iter().enumerate() {
            let (x, yy) = ((i % 120) as f64 + 0.5, (i / 120) as f64 + 0.5);
            sx += v * x;
            sy += v * yy;
            s += v;
        }
        (sx / s, sy / s)
    };
    let (a, b) = (
        centroid(&render_with(&lens, |_| {})),
        centroid(&render_with(&pin, |_| {})),
    );
    // Right of and above the centre in both.
    assert!(b.0 > 60.0 && b.1 < 40.0, "pinhole {b:?}");
    let (va, vb) = ((a.0 - 60.0, a.1 - 40.0), (b.0 - 60.0, b.1 - 40.0));
    let (la, lb) = (va.0.hypot(va.1), vb.0.hypot(vb.1));
    let cos = (va.0 * vb.0 + va.1 * vb.1) / (la * lb);
    assert!(
        cos > 1.0f64.to_radians().cos(),
        "lens {a:?} vs pinhole {b:?}"
    );
    assert!(
        (1.03..1.10).contains(&(la / lb)),
        "lens {a:?} vs pinhole {b:?}"
    );
}

/// `film_offset` puts a small film window where the lens images an off-axis point: a
/// distant sun 10° up and to the right of the view (azimuth 30° from the image's +x)
/// lands in a window 0.16 mm wide (32 × 32 pixels of 5 µm) centred at the paraxial
/// image height f·tanθ in that direction, with positive x and y (the offset is in the
/// output image's orientation; the lens inverts the image and the film is read turned
/// back). The film is at the d-line paraxial focus for infinity (BFL), where the
/// design's spot (Optiland, F/d/C) is 14–17 µm RMS with its centroid 3.6–3.9 µm beyond
/// f·tanθ (the triplet's distortion); the rendered centroid (measured 3.6 µm from the
/// window's centre) must be within 2 pixels of it. The window turned to the opposite
/// side (−offset) sees nothing.
#[test]
fn film_offset_puts_the_window_where_the_spot_is() {
    let base = scene(UNIFORM);
    let lens = base.camera.lens.as_ref().unwrap();
    let p = heron::camera::lens::paraxial::paraxial(&lens.system, 587.5618);
    let (theta, phi) = (10f64.to_radians(), 30f64.to_radians());
    let h = p.efl * theta.tan();
    let (ox, oy) = (h * phi.cos(), h * phi.sin());
    let (n, pixel) = (32usize, 0.005);
    let window = |ox: f64, oy: f64| {
        // The light travels away from the sun, which is up-right in front of the camera
        // (the camera looks along −z with +y up, so +x is the image's right).
        let to_sun = (
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            -theta.cos(),
        );
        let text = UNIFORM
            .replace("background = 1.0", "background = 0.0")
            .replace("[48, 32]", &format!("[{n}, {n}]"))
            .replace("spp = 64", "spp = 256")
            .replace(
                "[render]",
                &format!(
                    "film_distance = {}\nfilm_diagonal = {}\nfilm_offset = [{ox}, {oy}]\n[render]",
                    p.bfl,
                    pixel * n as f64 * 2f64.sqrt()
                ),
            )
            + &format!(
                "[[lights]]\ntype = \"sun\"\ndirection = [{}, {}, {}]\nirradiance = {{ spectrum = \"E\", scale = 1e-4 }}\nangular_radius = 0.005\n",
                -to_sun.0, -to_sun.1, -to_sun.2
            );
        y_of(&render_with(&scene(&text), |_| {}))
    };
    let y = window(ox, oy);
    let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
    for (i, v) in y.iter().enumerate() {
        // Pixel centres in mm from the window's centre, +y up.
        let x = ((i % n) as f64 + 0.5 - n as f64 / 2.0) * pixel;
        let yy = (n as f64 / 2.0 - (i / n) as f64 - 0.5) * pixel;
        sx += v * x;
        sy += v * yy;
        s += v;
    }
    assert!(s > 0.0, "no light in the window at ({ox}, {oy}) mm");
    let (cx, cy) = (sx / s, sy / s);
    assert!(
        cx.hypot(cy) < 2.0 * pixel,
        "the spot's centroid is ({:.1}, {:.1}) µm from the window's centre ({ox:.4}, {oy:.4}) mm",
        cx * 1e3,
        cy * 1e3
    );
    let opposite = window(-ox, -oy);
    assert!(
        opposite.iter().all(|&v| v == 0.0),
        "light in the window on the opposite side"
    );
}

/// Sampling the exit pupil's bounds gives the image that sampling the whole square
/// behind the rear element gives (which wastes most rays on the rims): the bounds lose
/// no light. A stripe chart across the frame, where toward the corners the bounds are
/// narrowest (the rear rim vignettes there), compared by `heron compare`'s region
/// z-test; at the prescription's f/5 and stopped down to f/16, where the exit pupil is a
/// small part of the rear square and the bounds come from the second, finer grid.
#[test]
fn pupil_bounds_lose_no_light() {
    for f_number in ["", "f_number = 16\n"] {
        bounds_match_the_rear_element(f_number);
    }
}

fn bounds_match_the_rear_element(f_number: &str) {
    let mut chart = String::new();
    for k in 0..12 {
        let x = -0.9 + 0.15 * k as f64;
        chart += &format!(
            "[[shapes]]\ntype = \"quad\"\norigin = [{x}, -0.6, -2.0]\nedge1 = [0.07, 0.0, 0.0]\nedge2 = [0.0, 1.2, 0.0]\nemission = {{ spectrum = \"E\", scale = 1.0 }}\n"
        );
    }
    let text = format!(
        "{}{chart}",
        UNIFORM
            .replace("background = 1.0", "background = 0.0")
            .replace("spp = 64", "spp = 256")
            .replace(
                "[render]",
                &format!("{f_number}focus_distance = 2.0\n[render]")
            )
    );
    let a = render_with(&scene(&text), |_| {});
    let b = render_with(
        &scene(&text.replace("focus_distance", "pupil = \"rear-element\"\nfocus_distance")),
        |_| {},
    );
    let c = compare_xyz(&a, &b, 4, 0.01, None);
    assert!(
        c.regions.len() > 50 && c.same(),
        "{f_number}{}",
        c.report("bounds", "rear-element", 10)
    );
    // And they are not the same bytes: the test compares two estimators.
    assert_ne!(y_of(&a), y_of(&b));
}

#[test]
fn light_tracing_and_bdpt_refuse_the_lens() {
    let s = scene(UNIFORM);
    for kind in [IntegratorKind::LightTrace, IntegratorKind::Bdpt] {
        let mut o = heron::render::RenderOptions::from_scene(&s);
        o.settings.integrator = kind;
        let e = heron::render::render(&s, &o)
            .expect_err("refused")
            .to_string();
        assert!(
            e.contains("the lens camera (camera.type = \"lens\") has no importance function"),
            "{e}"
        );
    }
}

#[test]
fn bad_lens_cameras_are_one_line_errors() {
    let cases: [(&str, &str); 9] = [
        (
            "lens = \"../lenses/cooke-triplet.toml\"",
            "lens = \"../lenses/none.toml\"",
        ),
        ("type = \"lens\"", "type = \"fisheye\""),
        ("resolution = [48, 32]", "resolution = [48, 32]\nd = 2.0"),
        (
            "resolution = [48, 32]",
            "resolution = [48, 32]\nfocus_distance = 0.01",
        ),
        (
            "resolution = [48, 32]",
            "resolution = [48, 32]\npupil = \"everywhere\"",
        ),
        (
            "resolution = [48, 32]",
            "resolution = [48, 32]\nfilm_distance = 40\nfocus_distance = 2",
        ),
        ("type = \"lens\"\n", ""),
        (
            "resolution = [48, 32]",
            "resolution = [48, 32]\nfilm_offset = [nan, 1.0]",
        ),
        (
            "type = \"lens\"\nlens = \"../lenses/cooke-triplet.toml\"\n",
            "film_offset = [1.0, 2.0]\n",
        ),
    ];
    let want = [
        "camera.lens: ",
        "camera.type: expected \"pinhole\", \"lens\" or \"orthographic\", got \"fisheye\"",
        "camera.d: the pinhole's camera constant",
        "camera.focus_distance: the lens cannot focus on a point 10 mm in front of the film",
        "camera.pupil: expected one of bounds, rear-element, got \"everywhere\"",
        "camera.focus_distance: give the focus once",
        "camera.lens: a key of the lens camera; set camera.type = \"lens\"",
        "camera.film_offset: expected [x, y] with two finite numbers, got [nan, 1]",
        "camera.film_offset: a key of the lens camera; set camera.type = \"lens\"",
    ];
    for ((from, to), want) in cases.iter().zip(want) {
        let e = err(&UNIFORM.replace(from, to));
        assert!(e.contains(want), "{to}: {e}");
        assert!(e.contains("test-lens.toml"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    // An inline prescription's error names the surface.
    let inline = UNIFORM.replace("lens = \"../lenses/cooke-triplet.toml\"\n", "")
        + "[[camera.surface]]\nradius = 0\nthickness = 1\nstop = true\nsemi_aperture = 4\n"
        + "[[camera.surface]]\nradius = 10\nthickness = 5\nmedium = \"N-BK8\"\nsemi_aperture = 8\n";
    let e = err(&inline);
    assert!(
        e.contains("camera.surface 2: medium: unknown refractive-index model"),
        "{e}"
    );
}
