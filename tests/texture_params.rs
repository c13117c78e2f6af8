//! Textures on the material parameters beyond the Lambertian's ρd (src/bsdf/texture_params.rs):
//! the glossy model's `rho_d` and `rho_s`, the coated material's `reflectance` and
//! `roughness`, the conductor's and the dielectric's `roughness`, the mirror's `rho_s`.
//!
//! - A parameter given as a texture of one constant renders the same bytes as the
//!   constant itself (the texture's number is the constant's exactly: a grey's
//!   luminance is its own value).
//! - A checkerboard roughness renders, in each square, what the constant roughness of
//!   that square renders: the same bytes (one quad lit by a point light, so a pixel's
//!   paths never see the other squares and each pixel draws the same random numbers).
//! - The white furnace of a textured glossy (whose ρd + ρs passes 1 and is clamped at the
//!   hit) and of a textured coat stays at most 1.
//! - Bad input names the key: an unknown texture on each new key, and a texture on a key
//!   that takes none.
//! - A textured material's `sample` agrees with its `eval` and `pdf` at the hit's uv.
//! - The importers: Mitsuba's checkerboard `alpha` (colours swapped, as its `eval_1`), a
//!   bitmap plastic, an anisotropic pair as a mix; pbrt-v4's roughness and reflectance
//!   textures with the remap warning naming the line.
//!
//! All of it runs in about 2 s in release (48 × 48 renders at 4 spp: the comparisons
//! are between renders drawing the same random numbers, so the sample count only has
//! to light the image).
mod common;

use common::render::run;
use glam::{Vec2, Vec3};
use heron::bsdf::{BsdfContext, Material};
use heron::scene::load_scene;
use heron::settings::IntegratorKind;
use heron::spectrum::SampledWavelengths;
use std::path::Path;

const W: usize = 48;

/// A 2 × 2 quad (uv over [0, 1]²) filling a 48 × 48 image, its material `material`, lit
/// by a point light beside the camera, over a dim grey sky; `textures` before it.
fn scene_text(textures: &str, material: &str) -> String {
    format!(
        r#"background = 0.05
[camera]
eye = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
d = 4.0
resolution = [{W}, {W}]
[render]
max_depth = 3
{textures}
[materials.m]
{material}
[[lights]]
type = "point"
position = [0.3, 0.2, 2.0]
intensity = 20.0
[[shapes]]
type = "quad"
origin = [-1.0, -1.0, 0.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 2.0, 0.0]
material = "m"
"#
    )
}

/// The linear sRGB pixels of the scene, 4 samples per pixel (the comparisons are of
/// renders drawing the same random numbers, so noise does not enter them).
fn render(dir: &Path, textures: &str, material: &str) -> Vec<[f32; 3]> {
    let p = dir.join("scene.toml");
    std::fs::write(&p, scene_text(textures, material)).unwrap();
    let s = load_scene(&p).unwrap();
    run(&s, IntegratorKind::Path, 4, 7).linear_srgb()
}

/// A checkerboard table `name` of the two values (TOML) `a` (color0) and `b` (color1).
fn checks(name: &str, a: &str, b: &str) -> String {
    format!("[textures.{name}]\ntype = \"checkerboard\"\ncolor0 = {a}\ncolor1 = {b}\n")
}

#[test]
fn a_texture_of_one_constant_renders_the_constants_bytes() {
    let dir = tempfile::tempdir().unwrap();
    // (material with constants, the same with every new key a texture of its constant)
    let cases = [
        (
            // A colour whose spectrum stays below 1 − ρs at every wavelength: a textured
            // glossy clamps ρd there per wavelength (src/bsdf/phong.rs), where the
            // constants' check is per RGB channel (a saturated colour's uplifted
            // spectrum passes its channels' values in the far red or blue).
            "type = \"glossy\"\nrho_d = [0.45, 0.35, 0.3]\nrho_s = 0.2\nshininess = 30.0",
            "type = \"glossy\"\nrho_d = { texture = \"d\" }\nrho_s = { texture = \"s\" }\nshininess = 30.0",
            "[0.45, 0.35, 0.3]",
            "0.2",
        ),
        (
            "type = \"coated\"\nreflectance = [0.6, 0.2, 0.1]\nroughness = 0.2",
            "type = \"coated\"\nreflectance = { texture = \"d\" }\nroughness = { texture = \"s\" }",
            "[0.6, 0.2, 0.1]",
            "0.2",
        ),
        (
            "type = \"conductor\"\nmetal = \"Au\"\nroughness = 0.15",
            "type = \"conductor\"\nmetal = \"Au\"\nroughness = { texture = \"s\" }",
            "0.5",
            "0.15",
        ),
        (
            "type = \"dielectric\"\nior = 1.5\nroughness = 0.25",
            "type = \"dielectric\"\nior = 1.5\nroughness = { texture = \"s\" }",
            "0.5",
            "0.25",
        ),
        (
            "type = \"mirror\"\nrho_s = [0.9, 0.6, 0.3]",
            "type = \"mirror\"\nrho_s = { texture = \"d\" }",
            "[0.9, 0.6, 0.3]",
            "0.5",
        ),
    ];
    for (constant, textured, d, s) in cases {
        let tables = checks("d", d, d) + &checks("s", s, s);
        let want = render(dir.path(), "", constant);
        let got = render(dir.path(), &tables, textured);
        assert!(
            want.iter().flatten().any(|&x| x > 0.01),
            "{constant}: the render is black"
        );
        let diff = want
            .iter()
            .flatten()
            .zip(got.iter().flatten())
            .fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            want == got,
            "{textured}: differs from the constants' render by up to {diff}"
        );
    }
}

/// Centres of the four checker squares (u, v) and whether each is color0's (Mitsuba's
/// rule: the halves of u and v agree).
const SQUARES: [(f32, f32, bool); 4] = [
    (0.25, 0.25, true),
    (0.75, 0.25, false),
    (0.25, 0.75, false),
    (0.75, 0.75, true),
];

/// The 8 × 8 pixels around uv (v up, the image's rows down), away from the squares'
/// edges (which a pixel's samples straddle).
fn block(img: &[[f32; 3]], u: f32, v: f32) -> Vec<[f32; 3]> {
    let (cx, cy) = ((u * W as f32) as usize, ((1.0 - v) * W as f32) as usize);
    let mut out = Vec::new();
    for y in cy - 4..cy + 4 {
        for x in cx - 4..cx + 4 {
            out.push(img[y * W + x]);
        }
    }
    out
}

fn mean(px: &[[f32; 3]]) -> f32 {
    px.iter().flatten().sum::<f32>() / (3 * px.len()) as f32
}

#[test]
fn a_checkerboard_roughness_renders_each_squares_constant() {
    let dir = tempfile::tempdir().unwrap();
    let tables = checks("r", "0.08", "0.4");
    for kind in [
        "type = \"conductor\"\nmetal = \"Ag\"",
        "type = \"dielectric\"\nior = 1.5",
        "type = \"coated\"\nreflectance = 0.02",
    ] {
        let smooth = render(dir.path(), "", &format!("{kind}\nroughness = 0.08"));
        let rough = render(dir.path(), "", &format!("{kind}\nroughness = 0.4"));
        let checked = render(
            dir.path(),
            &tables,
            &format!("{kind}\nroughness = {{ texture = \"r\" }}"),
        );
        for (u, v, first) in SQUARES {
            let want = block(if first { &smooth } else { &rough }, u, v);
            let other = block(if first { &rough } else { &smooth }, u, v);
            let got = block(&checked, u, v);
            assert!(
                want == got,
                "{kind}: square ({u}, {v}) is not its constant's"
            );
            // The two roughnesses are told apart there (else the test proves nothing).
            let (a, b) = (mean(&want), mean(&other));
            assert!(
                (a - b).abs() > 0.05 * a.max(b),
                "{kind}: square ({u}, {v}): {a} vs {b}"
            );
        }
    }
}

/// The white-furnace albedo ∫ f cos θi dωi at ωo (θo), by sampling: the mean of the
/// sample weights over a 128 × 128 stratified grid and 8 values of the lobe choice.
fn albedo(m: &Material, uv: Vec2, theta_o: f32) -> f32 {
    let wo = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
    let wl = SampledWavelengths::<4>::sample_uniform(0.37);
    let ctx = BsdfContext::radiance::<4>().at(uv);
    let (n, nc) = (128, 8);
    let mut sum = 0.0f64;
    for c in 0..nc {
        let uc = (c as f32 + 0.5) / nc as f32;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                if let Some(s) = m.sample(wo, uc, u, &wl, &ctx) {
                    // Every lane: the brightest is the one that would break 1.
                    let w = s.weight();
                    sum += w.0.iter().fold(0.0f32, |a, &x| a.max(x)) as f64;
                }
            }
        }
    }
    (sum / (n * n * nc) as f64) as f32
}

/// The material `m` of a scene with `textures` and that material.
fn material(dir: &Path, textures: &str, m: &str) -> Material {
    let p = dir.join("scene.toml");
    std::fs::write(&p, scene_text(textures, m)).unwrap();
    let s = load_scene(&p).unwrap();
    s.materials[0].clone()
}

#[test]
fn textured_glossy_and_coat_stay_under_the_white_furnace() {
    let dir = tempfile::tempdir().unwrap();
    // ρd = 0.9 and ρs = 0.6 where the checkerboard picks color0: a sum of 1.5 that the
    // constants' check would refuse; the hit clamps ρd to 1 − ρs.
    let tables =
        checks("d", "0.9", "0.3") + &checks("s", "0.6", "0.1") + &checks("r", "0.05", "0.5");
    let glossy = material(
        dir.path(),
        &tables,
        "type = \"glossy\"\nrho_d = { texture = \"d\" }\nrho_s = { texture = \"s\" }\nshininess = 2.0",
    );
    let coat = material(
        dir.path(),
        &tables,
        "type = \"coated\"\nreflectance = 1.0\nroughness = { texture = \"r\" }",
    );
    let white_coat = material(
        dir.path(),
        &checks("w", "1.0", "1.0"),
        "type = \"coated\"\nreflectance = { texture = \"w\" }",
    );
    for (name, m) in [
        ("glossy", &glossy),
        ("coat", &coat),
        ("white coat", &white_coat),
    ] {
        assert!(m.is_textured(), "{name}");
        for (u, v, _) in SQUARES {
            for deg in [0.0f32, 45.0, 75.0] {
                let a = albedo(m, Vec2::new(u, v), deg.to_radians());
                eprintln!("{name} at uv ({u}, {v}), θo = {deg}°: albedo {a:.4}");
                // The estimator's error on these smooth integrands is below 1e-2.
                assert!(a <= 1.0 + 1e-2, "{name}, uv ({u}, {v}), θo {deg}°: {a}");
            }
        }
    }
    // The clamp bites where ρd + ρs passed 1: ρs (s + 2)/(2π)-normalised lobe plus ρd ≤
    // 1 − ρs, so the albedo at normal incidence is at most 1, and near it (0.96+).
    let a = albedo(&glossy, Vec2::new(0.25, 0.25), 0.0);
    assert!(a > 0.9, "clamped glossy albedo {a}");
}

/// The load error of material `m` after `textures`.
fn error(dir: &Path, textures: &str, m: &str) -> String {
    let p = dir.join("scene.toml");
    std::fs::write(&p, scene_text(textures, m)).unwrap();
    match load_scene(&p) {
        Ok(_) => panic!("{m}: loaded"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_texture_keys_name_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let t = checks("t", "0.5", "0.2");
    for (m, key) in [
        (
            "type = \"glossy\"\nrho_d = { texture = \"nope\" }\nrho_s = 0.1\nshininess = 3.0",
            "materials.m.rho_d",
        ),
        (
            "type = \"glossy\"\nrho_d = 0.1\nrho_s = { texture = \"nope\" }\nshininess = 3.0",
            "materials.m.rho_s",
        ),
        (
            "type = \"coated\"\nreflectance = { texture = \"nope\" }",
            "materials.m.reflectance",
        ),
        (
            "type = \"coated\"\nreflectance = 0.5\nroughness = { texture = \"nope\" }",
            "materials.m.roughness",
        ),
        (
            "type = \"conductor\"\nmetal = \"Cu\"\nroughness = { texture = \"nope\" }",
            "materials.m.roughness",
        ),
        (
            "type = \"dielectric\"\nior = 1.5\nroughness = { texture = \"nope\" }",
            "materials.m.roughness",
        ),
        (
            "type = \"mirror\"\nrho_s = { texture = \"nope\" }",
            "materials.m.rho_s",
        ),
    ] {
        let e = error(dir.path(), &t, m);
        assert!(
            e.contains(key) && e.contains("no texture is named \"nope\""),
            "{m}: {e}"
        );
    }
    // Keys that take no texture.
    for (m, key) in [
        (
            "type = \"glossy\"\nrho_d = 0.1\nrho_s = 0.1\nshininess = { texture = \"t\" }",
            "shininess",
        ),
        (
            "type = \"coated\"\nreflectance = 0.5\nthickness = { texture = \"t\" }",
            "thickness",
        ),
        ("type = \"dielectric\"\nior = { texture = \"t\" }", "ior"),
    ] {
        let e = error(dir.path(), &t, m);
        assert!(e.contains(key), "{m}: {e}");
    }
    // The constants' energy check stays.
    let e = error(
        dir.path(),
        "",
        "type = \"glossy\"\nrho_d = 0.8\nrho_s = 0.5\nshininess = 3.0",
    );
    assert!(e.contains("rho_d + rho_s <= 1"), "{e}");
    // A smooth-only setting refuses a textured roughness as it refuses a constant one.
    let e = error(
        dir.path(),
        &t,
        "type = \"dielectric\"\nior = 1.5\nfresnel = false\nroughness = { texture = \"t\" }",
    );
    assert!(
        e.contains("materials.m.fresnel") && e.contains("texture = \"t\""),
        "{e}"
    );
}

fn import(dir: &Path, name: &str, text: &str) -> heron::scene::import::Imported {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    heron::scene::import::import_scene(&p, &heron::scene::import::ImportOptions::default()).unwrap()
}

/// The TOML value at the dotted `path` of `t`.
fn at<'a>(t: &'a toml::Table, path: &str) -> &'a toml::Value {
    let mut v = t.get(path.split('.').next().unwrap()).unwrap();
    for k in path.split('.').skip(1) {
        v = v.get(k).unwrap_or_else(|| panic!("no {path} in {t:#?}"));
    }
    v
}

/// Mitsuba: a roughconductor's checkerboard `alpha` becomes a table with the colours
/// swapped (Mitsuba's `eval_1` does), a roughplastic's bitmap `diffuse_reflectance` an
/// image table and its `alpha` a texture too; a roughdielectric's two different alpha_u
/// / alpha_v (one a texture) a mix, with a warning naming the line. The scene loads.
#[test]
fn mitsuba_textured_parameters_import() {
    let dir = tempfile::tempdir().unwrap();
    common::images::write_exr(&dir.path().join("d.exr"), 4, 4, |i, j| {
        [0.1 + 0.2 * i as f32, 0.5, 0.1 + 0.2 * j as f32]
    });
    let body = r#"
<texture type="checkerboard" id="cb">
    <float name="color0" value="0.05"/>
    <float name="color1" value="0.3"/>
</texture>
<bsdf type="roughconductor" id="metal">
    <string name="material" value="Au"/>
    <string name="distribution" value="ggx"/>
    <ref name="alpha" id="cb"/>
</bsdf>
<bsdf type="roughplastic" id="plastic">
    <string name="distribution" value="ggx"/>
    <texture type="bitmap" name="diffuse_reflectance">
        <string name="filename" value="d.exr"/>
    </texture>
    <float name="alpha" value="0.2"/>
</bsdf>
<bsdf type="roughdielectric" id="glass">
    <string name="distribution" value="ggx"/>
    <ref name="alpha_u" id="cb"/>
    <float name="alpha_v" value="0.1"/>
</bsdf>
<shape type="rectangle"><ref id="metal"/></shape>
<shape type="rectangle"><ref id="plastic"/></shape>
<shape type="rectangle"><ref id="glass"/></shape>
"#;
    let imp = import(
        dir.path(),
        "scene.xml",
        &common::scenes::mitsuba_around(body),
    );
    let t = imp.table();
    let metal_alpha = at(&t, "materials.metal.roughness.texture")
        .as_str()
        .unwrap();
    let table = at(&t, &format!("textures.{metal_alpha}"))
        .as_table()
        .unwrap();
    assert_eq!(table["color0"].as_float(), Some(0.3), "{table:#?}");
    assert_eq!(table["color1"].as_float(), Some(0.05), "{table:#?}");
    let rho = at(&t, "materials.plastic.reflectance.texture")
        .as_str()
        .unwrap();
    assert_eq!(
        at(&t, &format!("textures.{rho}.type")).as_str(),
        Some("image")
    );
    let glass = at(&t, "materials.glass.roughness.texture")
        .as_str()
        .unwrap();
    assert_eq!(
        at(&t, &format!("textures.{glass}.type")).as_str(),
        Some("mix")
    );
    let w: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        w.iter()
            .any(|m| m.contains("anisotropic roughness") && m.contains("mix texture")),
        "{w:#?}"
    );
    let s = heron::scene::load::load_imported(&imp).unwrap();
    assert!(s.materials.iter().filter(|m| m.is_textured()).count() >= 3);
}

/// pbrt-v4: `coateddiffuse` with a reflectance texture and a float roughness texture,
/// `conductor` and `dielectric` with roughness textures; pbrt's remap α = √r is applied
/// to a checkerboard's values (a copy of its table), and warns, naming the line, for an
/// image, which heron cannot remap; `remaproughness false` takes the values as they are.
#[test]
fn pbrt_textured_parameters_import() {
    let dir = tempfile::tempdir().unwrap();
    let quad = "Shape \"trianglemesh\" \"point3 P\" [ -4 -4 0  4 -4 0  4 4 0  -4 4 0 ] \"integer indices\" [ 0 1 2  0 2 3 ]\n";
    let text = format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 30 ]\nFilm \"rgb\" \"integer xresolution\" [ 20 ] \"integer yresolution\" [ 20 ]\nWorldBegin\n\
Texture \"r\" \"float\" \"checkerboard\" \"float tex1\" 0.04 \"float tex2\" 0.3\n\
Texture \"c\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [ 0.7 0.2 0.1 ] \"rgb tex2\" [ 0.1 0.2 0.7 ]\n\
Texture \"img\" \"float\" \"imagemap\" \"string filename\" \"g.exr\"\n\
Material \"coateddiffuse\" \"texture reflectance\" \"c\" \"texture roughness\" \"r\" \"bool remaproughness\" false\n{quad}\
Material \"conductor\" \"texture roughness\" \"r\"\n{quad}\
Material \"dielectric\" \"texture uroughness\" \"r\" \"float vroughness\" 0.2 \"bool remaproughness\" false\n{quad}\
Material \"conductor\" \"texture roughness\" \"img\"\n{quad}"
    );
    common::images::write_exr(&dir.path().join("g.exr"), 2, 2, |i, _| [0.1 * i as f32; 3]);
    let imp = import(dir.path(), "scene.pbrt", &text);
    let t = imp.table();
    assert_eq!(
        at(&t, "materials.coateddiffuse-1.reflectance.texture").as_str(),
        Some("c")
    );
    // pbrt's float texture "r" (its table named for its kind when a spectrum texture
    // could share the name).
    let r = at(&t, "materials.coateddiffuse-1.roughness.texture")
        .as_str()
        .unwrap();
    assert!(r.starts_with('r'), "{r}");
    // pbrt's float texture "r" (its table named for its kind when a spectrum texture
    // could share the name).
    // pbrt's remap α = √r, applied to the checkerboard's leaves in a copy of the table.
    let r = at(&t, "materials.conductor-2.roughness.texture")
        .as_str()
        .unwrap();
    assert!(r.starts_with('r') && r.ends_with("(alpha)"), "{r}");
    let sq = |k: &str| at(&t, &format!("textures.{r}.{k}")).as_float().unwrap();
    assert!((sq("color0") - 0.2).abs() < 1e-12 && (sq("color1") - 0.3f64.sqrt()).abs() < 1e-12);
    let mix = at(&t, "materials.dielectric-3.roughness.texture")
        .as_str()
        .unwrap();
    assert_eq!(
        at(&t, &format!("textures.{mix}.type")).as_str(),
        Some("mix")
    );
    let w: Vec<(u32, String)> = imp
        .warnings
        .iter()
        .map(|w| (w.line, w.message.clone()))
        .collect();
    let remap: Vec<u32> = w
        .iter()
        .filter(|(_, m)| m.contains("√value"))
        .map(|(l, _)| *l)
        .collect();
    assert_eq!(remap, vec![14], "{w:#?}");
    assert!(
        w.iter()
            .any(|(l, m)| *l == 12 && m.contains("anisotropic roughness")),
        "{w:#?}"
    );
    heron::scene::load::load_imported(&imp).unwrap();
}

/// A textured material's `sample` agrees with its `eval` and `pdf` at the same uv (the
/// parameters are looked up alike in all three): for each sampled direction, f equals
/// eval's and the pdf equals pdf's, on both squares of the checkerboards.
#[test]
fn textured_sample_eval_and_pdf_agree() {
    let dir = tempfile::tempdir().unwrap();
    let tables = checks("d", "[0.7, 0.3, 0.2]", "0.2")
        + &checks("s", "0.3", "0.05")
        + &checks("r", "0.05", "0.5");
    let materials = [
        "type = \"glossy\"\nrho_d = { texture = \"d\" }\nrho_s = { texture = \"s\" }\nshininess = 20.0",
        "type = \"coated\"\nreflectance = { texture = \"d\" }\nroughness = { texture = \"r\" }",
        "type = \"conductor\"\nmetal = \"Cu\"\nroughness = { texture = \"r\" }",
        "type = \"dielectric\"\nior = 1.5\nroughness = { texture = \"r\" }",
    ];
    let wl = SampledWavelengths::<4>::sample_uniform(0.61);
    for text in materials {
        let m = material(dir.path(), &tables, text);
        let mut checked = 0;
        for (u, v, _) in SQUARES {
            let ctx = BsdfContext::radiance::<4>().at(Vec2::new(u, v));
            let wo = Vec3::new(0.5, 0.1, 0.86).normalize();
            for k in 0..64 {
                let uc = (k as f32 + 0.5) / 64.0;
                let s2 = Vec2::new(
                    (k * 37 % 64) as f32 / 64.0 + 0.007,
                    (k * 11 % 64) as f32 / 64.0 + 0.003,
                );
                let Some(s) = m.sample(wo, uc, s2, &wl, &ctx) else {
                    continue;
                };
                if s.is_specular() || s.ended_companions {
                    continue;
                }
                let f = m.eval(wo, s.wi, &wl, &ctx).f;
                let pdf = m.pdf(wo, s.wi, &wl, &ctx);
                let rel = |a: f32, b: f32| (a - b).abs() <= 1e-3 * a.abs().max(b.abs()) + 1e-6;
                assert!(
                    rel(pdf, s.pdf),
                    "{text} at ({u}, {v}): pdf {pdf} vs {}",
                    s.pdf
                );
                for i in 0..4 {
                    assert!(
                        rel(f.0[i], s.f.0[i]),
                        "{text} at ({u}, {v}): f {f:?} vs {:?}",
                        s.f
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 100, "{text}: only {checked} samples checked");
    }
}
