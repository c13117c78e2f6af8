//! Environment maps (`[environment]`, src/light/envmap.rs) through the whole renderer: a
//! white furnace with a closed form, the map seen directly where its layout puts it, and
//! the loader's errors for bad maps. (The sampling has its chi-square test in
//! tests/sampling.rs; Mitsuba 3 renders the same envmap-lit scene in
//! tests/python/test_mitsuba_xml.py.)
mod common;

use common::images::{write_exr, write_pfm};

use common::render::{mean_se, run};
use heron::scene::load_scene;
use heron::settings::IntegratorKind;
use heron::HeronError;
use std::path::{Path, PathBuf};

fn scene(dir: &Path, env: &str, shapes: &str, res: u32) -> PathBuf {
    let text = format!(
        r#"
[camera]
eye = [0.0, 0.0, 8.0]
look_at = [0.0, 0.0, 0.0]
d = 2.5
resolution = [{res}, {res}]
[render]
max_depth = 8
[environment]
{env}
[materials.grey]
type = "lambertian"
rho_d = 0.5
{shapes}
"#
    );
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

const SPHERE: &str =
    "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1.0\nmaterial = \"grey\"\n";

/// A convex diffuse sphere of albedo ρ under a uniform environment of radiance L sends
/// back ρL everywhere (it never sees itself): with a white map of 3 × the sRGB white, the
/// sphere's pixels are Y = 1.5 and the map's own are Y = 3, whatever the sampling of the
/// map (a map with a bright spot on one side is not uniform, so the furnace map is
/// uniform but importance-sampled through the same code).
#[test]
fn white_furnace_with_a_uniform_map_and_a_mirrored_rotation() {
    let dir = tempfile::tempdir().unwrap();
    write_exr(&dir.path().join("white.exr"), 32, 16, |_, _| [1.0; 3]);
    // A mirror (det −1) is allowed: it keeps solid angle.
    let env = "map = \"white.exr\"\nscale = 3.0\ntransform = [[-1, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]";
    let s = load_scene(&scene(dir.path(), env, SPHERE, 24)).unwrap();
    let film = run(&s, IntegratorKind::Path, 64, 7);
    let (w, h) = (film.width as usize, film.height as usize);
    let mut on = Vec::new();
    let mut off = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let (x, y) = (
                i as f32 + 0.5 - w as f32 / 2.0,
                j as f32 + 0.5 - h as f32 / 2.0,
            );
            let r = (x * x + y * y).sqrt() / (w as f32 / 2.0);
            let v = film.xyz[j * w + i][1] as f64;
            if r < 0.6 {
                on.push(v);
            } else if r > 1.3 {
                off.push(v);
            }
        }
    }
    let (m, se) = mean_se(&on);
    assert!(
        (m - 1.5).abs() < 4.0 * se + 2e-3,
        "sphere Y {m} ± {se}, expected 1.5"
    );
    for v in off {
        // Only the wavelengths' spread: the map is D65 at every texel.
        assert!((v - 3.0).abs() < 3e-3, "map Y {v}, expected 3");
    }
}

/// One bright square of texels: the camera sees it where Mitsuba's layout puts it (the
/// image centre column looks along +z, +y is the top row) and, turned 90° about y by
/// the map's transform, where the turn takes it.
#[test]
fn the_map_is_seen_where_its_layout_and_transform_put_it() {
    let dir = tempfile::tempdir().unwrap();
    // Texels around u = 0.5 (toward +z, behind the camera's eye at z = 8 looking −z)
    // and around u = 0 (toward −z, in front of the camera) differ: red behind, green in
    // front.
    write_exr(&dir.path().join("two.exr"), 64, 32, |i, _| {
        if (28..36).contains(&i) {
            [1.0, 0.0, 0.0]
        } else if !(4..60).contains(&i) {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 0.0]
        }
    });
    let centre = |env: &str| {
        let s = load_scene(&scene(dir.path(), env, "", 9)).unwrap();
        let film = run(&s, IntegratorKind::Path, 4, 1);
        film.xyz[4 * 9 + 4]
    };
    // Looking along −z: the map's left and right edges (u ≈ 0 and 1), green.
    let c = centre("map = \"two.exr\"");
    assert!(c[1] > 0.5 && c[0] < 0.6 * c[1], "{c:?}");
    // Turned 180° about y, the red texels come in front.
    let c = centre(
        "map = \"two.exr\"\ntransform = [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]",
    );
    assert!(c[0] > c[1] && c[0] > 0.1, "{c:?}");
    // Turned 90°: neither colour straight ahead.
    let c = centre(
        "map = \"two.exr\"\ntransform = [[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 1]]",
    );
    assert!(c[1] < 1e-6 && c[0].abs() < 1e-6, "{c:?}");
}

/// A PFM map (colour in both byte orders, and grey) is the EXR of the same texels: the
/// same image, bit for bit, so its rows come in the EXR's order (a pattern that differs
/// from top to bottom and left to right, reflected by the sphere in every direction).
#[test]
fn a_pfm_map_renders_the_pixels_of_the_exr_of_the_same_texels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let colour = |i: usize, j: usize| {
        [
            0.1 + 0.2 * j as f32,
            0.05 * i as f32,
            1.0 / (1 + i + j) as f32,
        ]
    };
    let grey = |i: usize, j: usize| [0.3 * j as f32 + 0.01 * i as f32; 3];
    write_exr(&d.join("colour.exr"), 16, 8, colour);
    write_exr(&d.join("grey.exr"), 16, 8, grey);
    write_pfm(&d.join("le.pfm"), 16, 8, false, true, colour);
    write_pfm(&d.join("be.pfm"), 16, 8, false, false, colour);
    write_pfm(&d.join("grey.pfm"), 16, 8, true, true, grey);
    let render = |map: &str| {
        let s = load_scene(&scene(d, &format!("map = \"{map}\""), SPHERE, 8)).unwrap();
        run(&s, IntegratorKind::Path, 4, 3).xyz
    };
    let want = render("colour.exr");
    assert_eq!(render("le.pfm"), want);
    assert_eq!(render("be.pfm"), want);
    assert_eq!(render("grey.pfm"), render("grey.exr"));
    // Upside down, it is another image.
    write_pfm(&d.join("flipped.pfm"), 16, 8, false, true, |i, j| {
        colour(i, 7 - j)
    });
    assert_ne!(render("flipped.pfm"), want);
}

fn load_err(path: &Path) -> String {
    match load_scene(path) {
        Ok(_) => panic!("expected an error for {}", path.display()),
        Err(HeronError::Scene { message, .. }) => {
            assert!(!message.contains('\n'), "multi-line message: {message:?}");
            message
        }
        Err(other) => panic!("expected HeronError::Scene, got {other:?}"),
    }
}

#[test]
fn bad_maps_are_one_line_errors_naming_the_key_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_exr(&d.join("sq.exr"), 8, 8, |_, _| [1.0; 3]);
    write_exr(&d.join("wide.exr"), 16, 8, |_, _| [1.0; 3]);
    write_exr(&d.join("row.exr"), 16, 1, |_, _| [1.0; 3]);
    write_exr(&d.join("nan.exr"), 4, 4, |i, j| {
        if (i, j) == (2, 1) {
            [f32::NAN, 0.0, 0.0]
        } else {
            [1.0; 3]
        }
    });
    std::fs::write(d.join("sky.tga"), b"not an image").unwrap();
    std::fs::write(d.join("sky.jpg"), b"not an image").unwrap();
    std::fs::write(d.join("bad.exr"), b"not an exr").unwrap();
    write_pfm(&d.join("sq.pfm"), 8, 8, false, true, |_, _| [1.0; 3]);
    let pfm = std::fs::read(d.join("sq.pfm")).unwrap();
    std::fs::write(d.join("short.pfm"), &pfm[..pfm.len() - 5]).unwrap();
    std::fs::write(d.join("p6.pfm"), b"P6\n8 8\n255\n").unwrap();
    let cases: &[(&str, &[&str])] = &[
        ("map = \"missing.exr\"", &["environment.map: ", "missing.exr"]),
        ("map = \"sky.tga\"", &["environment.map: ", "expected an image file ending in .exr, .hdr, .pfm, .png, .jpg or .jpeg, got \"tga\""]),
        ("map = \"sky.jpg\"", &["environment.map: ", "sky.jpg: cannot decode it"]),
        ("map = \"short.pfm\"", &["environment.map: ", "short.pfm: the pixels end early: 8 × 8 × 3 floats need 768 bytes, the file has 763"]),
        ("map = \"p6.pfm\"", &["environment.map: ", "p6.pfm: expected the PFM header PF (colour) or Pf (grey), got \"P6\""]),
        ("map = \"bad.exr\"", &["environment.map: ", "bad.exr: cannot read it as OpenEXR"]),
        ("map = \"nan.exr\"", &["environment.map: ", "pixel (2, 1)", "expected finite values ≥ 0"]),
        ("map = \"wide.exr\"\nmapping = \"equal-area\"", &["environment.map: an equal-area map is square, wide.exr is 16 × 8"]),
        ("map = \"row.exr\"", &["environment.map: a latlong map needs at least 2 rows"]),
        ("map = \"sq.exr\"\nmapping = \"cube\"", &["environment.mapping: expected one of latlong, equal-area, got \"cube\""]),
        ("map = \"sq.exr\"\ntransform = [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]", &["environment.transform: expected a rotation"]),
        ("map = \"sq.exr\"\ntransform = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]", &["environment.transform: expected four rows of four finite numbers"]),
        ("map = \"sq.exr\"\nscale = -1", &["environment.scale"]),
        ("map = \"sq.exr\"\nsize = 3", &["unknown key \"size\" at environment"]),
    ];
    for (env, want) in cases {
        let msg = load_err(&scene(d, env, SPHERE, 4));
        for w in *want {
            assert!(msg.contains(w), "{env:?}: {msg:?} lacks {w:?}");
        }
    }
    // With a background or a sky: one or the other.
    let p = scene(d, "map = \"sq.exr\"", SPHERE, 4);
    let text = format!("background = 1.0\n{}", std::fs::read_to_string(&p).unwrap());
    std::fs::write(&p, text).unwrap();
    assert!(load_err(&p).contains("a background or an [environment] map, not both"));
}

/// Mitsuba 3's `envmap` emitter converts to `[environment]` (the file relative to the
/// converted TOML, the scale, the rotation without its translation), and renders what
/// the converted TOML renders.
#[test]
fn a_mitsuba_envmap_converts_to_an_environment_table() {
    use heron::scene::import::{import_scene, ImportOptions};
    use heron::scene::load::load_imported;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("maps")).unwrap();
    write_exr(&d.join("maps/sky.exr"), 16, 8, |i, j| {
        [0.1 * i as f32, 0.2 * j as f32, 0.5]
    });
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="envmap">
        <string name="filename" value="maps/sky.exr"/>
        <float name="scale" value="2.5"/>
        <transform name="to_world"><rotate y="1" angle="90"/><translate x="3"/></transform>
    </emitter>
    <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"/></shape>
</scene>"#;
    let p = d.join("scene.xml");
    std::fs::write(&p, xml).unwrap();
    let imported = import_scene(&p, &ImportOptions::default()).unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    let table = imported.table();
    let env = table["environment"].as_table().unwrap();
    assert_eq!(env["map"].as_str(), Some("maps/sky.exr"));
    assert_eq!(env["scale"].as_float(), Some(2.5));
    let rows = env["transform"].as_array().unwrap();
    let row = |r: usize| -> Vec<f64> {
        rows[r]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_float().unwrap())
            .collect()
    };
    // A 90° turn about y, and no translation.
    assert_eq!(row(0), [0.0, 0.0, 1.0, 0.0]);
    assert_eq!(row(2), [-1.0, 0.0, 0.0, 0.0]);
    assert_eq!(row(3), [0.0, 0.0, 0.0, 1.0]);
    // Written for a TOML in another folder, the map's path follows.
    let out = d.join("converted");
    std::fs::create_dir_all(&out).unwrap();
    let toml_text = imported.to_toml(&out);
    assert!(
        toml_text.contains("map = \"../maps/sky.exr\""),
        "{toml_text}"
    );
    let toml_path = out.join("scene.toml");
    std::fs::write(&toml_path, &toml_text).unwrap();
    let a = run(
        &load_imported(&imported).unwrap(),
        IntegratorKind::Path,
        4,
        3,
    );
    let b = run(&load_scene(&toml_path).unwrap(), IntegratorKind::Path, 4, 3);
    assert_eq!(a.xyz, b.xyz);
}

/// pbrt-v4's image `infinite` light becomes an `equal-area` map in the light's frame:
/// the square's centre is the light's +z, which `Rotate -90 1 0 0` (pbrt's usual turn of
/// a z-up map into a y-up scene) points straight up.
#[test]
fn a_pbrt_image_infinite_light_is_an_equal_area_map_in_its_frame() {
    use heron::scene::import::{import_scene, ImportOptions};
    use heron::scene::load::load_imported;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Bright within the square's central disk (light-space directions near +z).
    write_exr(&d.join("sky.exr"), 32, 32, |i, j| {
        let (x, y) = (i as f32 - 15.5, j as f32 - 15.5);
        if x * x + y * y < 16.0 {
            [4.0; 3]
        } else {
            [0.0; 3]
        }
    });
    let view = |look: &str, light: &str| {
        let up = if look == "0 1 0" { "0 0 1" } else { "0 1 0" };
        let text = format!(
            "Scale -1 1 1\nLookAt 0 0 0  {look}  {up}\nCamera \"perspective\" \"float fov\" [ 10 ]\nFilm \"rgb\" \"integer xresolution\" [ 5 ] \"integer yresolution\" [ 5 ]\nWorldBegin\n{light}\n"
        );
        let p = d.join("scene.pbrt");
        std::fs::write(&p, text).unwrap();
        let imp = import_scene(&p, &ImportOptions::default()).unwrap();
        assert!(
            imp.warnings.iter().all(|w| !w.message.contains("infinite")),
            "{:?}",
            imp.warnings
        );
        let env = imp.table()["environment"].as_table().unwrap().clone();
        let film = run(&load_imported(&imp).unwrap(), IntegratorKind::Path, 4, 1);
        (env, film.xyz[12][1])
    };
    let (env, up) = view("0 1 0", "AttributeBegin\nRotate -90 1 0 0\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" [ 0.5 ]\nAttributeEnd");
    assert_eq!(env["mapping"].as_str(), Some("equal-area"));
    assert_eq!(env["scale"].as_float(), Some(0.5));
    assert!((up - 2.0).abs() < 1e-2, "looking up: Y {up}");
    let (_, ahead) = view("0 0 -1", "AttributeBegin\nRotate -90 1 0 0\nLightSource \"infinite\" \"string filename\" \"sky.exr\"\nAttributeEnd");
    assert_eq!(ahead, 0.0);
    // Unturned, the bright disk is along +z.
    let (env, plus_z) = view(
        "0 0 1",
        "LightSource \"infinite\" \"string filename\" \"sky.exr\"",
    );
    assert!(env.get("transform").is_none());
    assert!((plus_z - 4.0).abs() < 2e-2, "along +z: Y {plus_z}");
}
