//! Textured emission (`emission = { texture = "NAME", scale = S }` on a shape): the
//! texture at the point's uv times D65 at Y = 1 times S, read the same way by every
//! path that meets an area light: a camera ray hitting it, next-event estimation
//! (`sample_li` at the sampled point's uv), MIS, light tracing and BDPT (`sample_le`),
//! and the light's power (the texture's mean).
mod common;

use common::render::{compare_xyz, first_hit_mask, run};
use heron::light::Light;
use heron::render::Renderer;
use heron::scene::load::load_scene_from_str;
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use std::path::Path;

fn load(text: &str) -> Result<Scene, String> {
    load_scene_from_str(text, Path::new("emission.toml")).map_err(|e| e.to_string())
}

/// A 2 × 1 quad facing the camera and filling a 64 × 32 image, emitting `emission`
/// after the tables `textures`; nothing else is in the scene.
fn quad_seen(textures: &str, emission: &str) -> String {
    format!(
        r#"[camera]
eye = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
d = 4.0
resolution = [64, 32]
[render]
max_depth = 2
{textures}
[[shapes]]
type = "quad"
origin = [-1.0, -0.5, 0.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 1.0, 0.0]
emission = {emission}
"#
    )
}

/// A grey floor seen from above at an angle, lit by a quad light `quad` and a sphere
/// light `sphere` (their `emission` values), after the tables `textures`. The camera
/// sees only the floor, so light tracing renders every pixel.
fn lit_floor(textures: &str, quad: &str, sphere: &str, res: u32) -> String {
    format!(
        r#"[camera]
eye = [0.0, 3.0, 3.0]
look_at = [0.0, 0.0, 0.0]
d = 3.0
resolution = [{res}, {res}]
[render]
max_depth = 3
{textures}
[materials.grey]
type = "lambertian"
rho_d = 0.5
[[shapes]]
type = "quad"
origin = [-4.0, 0.0, 4.0]
edge1 = [8.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -8.0]
material = "grey"
[[shapes]]
type = "quad"
origin = [-1.0, 1.0, -1.0]
edge1 = [0.0, 0.0, 2.0]
edge2 = [2.0, 0.0, 0.0]
emission = {quad}
[[shapes]]
type = "sphere"
center = [1.2, 0.5, 0.8]
radius = 0.3
emission = {sphere}
"#
    )
}

const CHECKS: &str = r#"[textures.checks]
type = "checkerboard"
color0 = [0.9, 0.3, 0.1]
color1 = [0.1, 0.3, 0.9]
to_uv = [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]
[textures.greys]
type = "checkerboard"
color0 = 0.8
color1 = 0.2
[textures.white]
type = "checkerboard"
color0 = 1.0
color1 = 1.0
"#;

#[test]
fn a_constant_texture_renders_the_bytes_of_the_constant_emission() {
    // A texture of 1 everywhere times D65 × 2 is the colour 2 (D65 × 2) exactly, so
    // every path (camera rays, NEE, MIS, emission sampling) gives the same numbers.
    let a = load(&lit_floor(CHECKS, "2.0", "1.0", 24)).unwrap();
    let b = load(&lit_floor(
        CHECKS,
        r#"{ texture = "white", scale = 2.0 }"#,
        r#"{ texture = "white" }"#,
        24,
    ))
    .unwrap();
    for kind in [
        IntegratorKind::Path,
        IntegratorKind::Bdpt,
        IntegratorKind::LightTrace,
    ] {
        let (fa, fb) = (run(&a, kind, 8, 3), run(&b, kind, 8, 3));
        assert!(fa.xyz == fb.xyz, "{kind:?}: the images differ");
    }
}

#[test]
fn a_checkerboard_light_seen_directly_shows_its_two_radiances() {
    let s = load(&quad_seen(CHECKS, r#"{ texture = "greys", scale = 1.5 }"#)).unwrap();
    // Seen directly, a pixel's value is the texture at its uv (no noise but the
    // wavelengths'); greys times D65 at Y = 1 are greys in linear sRGB (to 2e-4).
    // 64 samples and 4 × 4 pixels: the wavelengths' noise per pixel at 16 samples is
    // about 1% (measured), under 0.3% here.
    let img = run(&s, IntegratorKind::Path, 64, 1).linear_srgb();
    // The quad's 2 × 2 squares (to_uv identity): 0.8 where u and v are both below or
    // both above ½, 0.2 elsewhere; pixel (x, y) is uv (x/64, 1 − y/32).
    for (u, v) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
        let want = 1.5 * if (u > 0.5) == (v > 0.5) { 0.8 } else { 0.2 };
        let (px, py) = ((u * 64.0) as usize, 32 - (v * 32.0) as usize);
        let mut c = [0.0f32; 3];
        for dy in 0..4 {
            for dx in 0..4 {
                let p = img[(py - 2 + dy) * 64 + px - 2 + dx];
                for ch in 0..3 {
                    c[ch] += p[ch] / 16.0;
                }
            }
        }
        for ch in c {
            assert!(
                (ch - want).abs() < 0.01 * want,
                "uv ({u}, {v}): {c:?}, expected {want}"
            );
        }
    }
}

#[test]
fn next_event_estimation_light_tracing_and_bdpt_agree_on_textured_lights() {
    // A coloured checkerboard on the quad light and a grey one on the sphere: the path
    // tracer's NEE reads sample_li's emission at the sampled point's uv and MIS weighs
    // it against BSDF hits (the interaction's uv); light tracing starts from sample_le's
    // point and its uv; BDPT mixes both. A uv read wrongly (every point in one square)
    // would brighten or tint the floor under the light. 32 × 32 at 256 spp (path) and
    // 128 spp (light tracing, BDPT): region z-tests over 8 × 8-pixel regions at a
    // family-wise 1%, measured to pass in about 6 s in release.
    let text = lit_floor(
        CHECKS,
        r#"{ texture = "checks", scale = 3.0 }"#,
        r#"{ texture = "greys", scale = 4.0 }"#,
        32,
    );
    let s = load(&text).unwrap();
    let path = run(&s, IntegratorKind::Path, 256, 11);
    let r = Renderer::new(&s).unwrap();
    let mask = first_hit_mask(&r, &s, |_| true);
    for (kind, spp) in [
        (IntegratorKind::LightTrace, 128),
        (IntegratorKind::Bdpt, 128),
    ] {
        let other = run(&s, kind, spp, 12);
        let c = compare_xyz(&path, &other, 8, 0.01, Some(mask.clone()));
        assert!(
            c.same(),
            "path vs {kind:?}:\n{}",
            c.report("path", "other", 8)
        );
    }
    // A light whose emission ignored its texture (color0 everywhere) is told apart.
    let wrong = load(&lit_floor(
        CHECKS,
        "[2.7, 0.9, 0.3]",
        r#"{ texture = "greys", scale = 4.0 }"#,
        32,
    ))
    .unwrap();
    let w = run(&wrong, IntegratorKind::Path, 256, 13);
    assert!(!compare_xyz(&path, &w, 8, 0.01, Some(mask)).same());
}

#[test]
fn the_power_of_a_checkerboard_light_is_its_mean() {
    let s = load(&quad_seen(CHECKS, r#"{ texture = "greys", scale = 3.0 }"#)).unwrap();
    let d65 = heron::spectrum::uplift::named("D65").unwrap().mean();
    let light = s
        .lights
        .iter()
        .find(|l| matches!(l, Light::Area(_)))
        .unwrap();
    let phi = light.phi(&s.bounds) as f64;
    // Φ = π A S (0.8 + 0.2)/2 mean(D65), A = 2.
    let want = std::f64::consts::PI * 2.0 * 3.0 * 0.5 * d65 as f64;
    assert!((phi / want - 1.0).abs() < 1e-4, "{phi} vs {want}");
}

#[test]
fn bad_textured_emissions_name_their_key() {
    let cases = [
        (
            r#"{ texture = "nope" }"#,
            "shapes[0].emission: no texture is named \"nope\"",
        ),
        (
            r#"{ texture = "greys", scale = -1.0 }"#,
            "expected scale = a finite number >= 0",
        ),
        (
            r#"{ texture = "greys", brightness = 2.0 }"#,
            "unknown key \"brightness\" in a textured emission",
        ),
        (r#"{ texture = 3 }"#, "expected { texture = \"NAME\" }"),
    ];
    for (emission, want) in cases {
        let e = load(&quad_seen(CHECKS, emission)).err().unwrap();
        assert!(e.contains(want), "{emission}: {e}");
        assert!(e.contains("emission"), "{emission}: {e}");
    }
}

/// The shapes' `emission` of an imported scene, as TOML.
fn emissions(imp: &heron::scene::import::Imported) -> Vec<toml::Value> {
    imp.table()["shapes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|s| s.get("emission").cloned())
        .collect()
}

#[test]
fn mitsuba_radiance_textures_import_as_textured_emission() {
    use heron::scene::import::{import_mitsuba_str, ImportOptions};
    let xml = |radiance: &str| {
        common::scenes::mitsuba_around(&format!(
            r#"<texture type="checkerboard" id="checks"><rgb name="color0" value="0.9, 0.3, 0.1"/></texture>
<shape type="rectangle"><emitter type="area">{radiance}</emitter></shape>"#
        ))
    };
    let opts = ImportOptions::default();
    // Inside Mitsuba's d65 texture, with its scale: exactly heron's meaning, no warning.
    let d65 = r#"<texture type="d65" name="radiance"><float name="scale" value="4"/><ref id="checks" name="nested"/></texture>"#;
    let imp = import_mitsuba_str(&xml(d65), Path::new("a.xml"), &opts).unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let e = emissions(&imp);
    assert_eq!(e[0]["texture"].as_str(), Some("checks"));
    assert_eq!(e[0]["scale"].as_float(), Some(4.0));
    assert!(imp.table()["textures"]["checks"]["type"].as_str() == Some("checkerboard"));
    // A bare texture: the same texture, scale 1, and a warning naming the line.
    let imp = import_mitsuba_str(
        &xml(r#"<ref id="checks" name="radiance"/>"#),
        Path::new("a.xml"),
        &opts,
    )
    .unwrap();
    assert_eq!(emissions(&imp)[0]["texture"].as_str(), Some("checks"));
    assert_eq!(imp.warnings.len(), 1, "{:?}", imp.warnings);
    let w = imp.warnings[0].to_string();
    assert!(w.contains("a.xml: line") && w.contains("D65"), "{w}");
    // The converted scene loads and its light is textured.
    let dir = tempfile::tempdir().unwrap();
    let toml = dir.path().join("a.toml");
    std::fs::write(&toml, imp.to_toml(dir.path())).unwrap();
    let s = heron::scene::load_scene(&toml).unwrap();
    assert!(s
        .lights
        .iter()
        .any(|l| matches!(l, Light::Area(a) if a.is_textured())));
}

#[test]
fn pbrt_image_area_lights_import_as_textured_emission() {
    use heron::scene::import::{import_pbrt_str, ImportOptions};
    let pbrt = |params: &str| {
        format!(
            "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 30 ]\nFilm \"rgb\" \"integer xresolution\" [ 40 ] \"integer yresolution\" [ 20 ]\nWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" {params}\nShape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\nAttributeEnd\n"
        )
    };
    let opts = ImportOptions::default();
    let imp = import_pbrt_str(
        &pbrt("\"string filename\" \"glow.png\" \"float scale\" 2"),
        Path::new("a.pbrt"),
        &opts,
    )
    .unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let e = &emissions(&imp)[0];
    assert_eq!(e["scale"].as_float(), Some(2.0));
    let t = &imp.table()["textures"][e["texture"].as_str().unwrap()];
    assert_eq!(t["file"].as_str(), Some("glow.png"));
    // pbrt-v4 looks the image up at (u, 1 − v).
    assert_eq!(t["to_uv"][1][1].as_float(), Some(-1.0));
    assert_eq!(t["to_uv"][1][2].as_float(), Some(1.0));
    // An EXR and `power` warn, naming the file and line; L with filename is an error.
    let imp = import_pbrt_str(
        &pbrt("\"string filename\" \"glow.exr\" \"float power\" 10"),
        Path::new("a.pbrt"),
        &opts,
    )
    .unwrap();
    let w: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w.iter().all(|w| w.contains("a.pbrt: line 7")), "{w:?}");
    let e = import_pbrt_str(
        &pbrt("\"string filename\" \"glow.png\" \"rgb L\" [1 1 1]"),
        Path::new("a.pbrt"),
        &opts,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("both \"L\" and \"filename\""), "{e}");
}
