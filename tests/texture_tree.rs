//! Texture trees (`[textures.NAME]`, src/texture/): a checkerboard, a product and a mix
//! on a square under a uniform white sky, which sends back ρ(uv) (the square sees only
//! the sky), so each square's colour is the tree's value there; a `texture` key naming a
//! table; and the loader's one-line errors (unknown name, cycle, bad keys).
mod common;

use common::images::write_exr;
use common::render::run;
use heron::scene::load_scene;
use heron::settings::IntegratorKind;
use std::path::{Path, PathBuf};

/// The 2 × 1 square of tests/texture.rs filling a 64 × 32 image, its material `m`, after
/// the tables `textures`.
fn scene(dir: &Path, textures: &str, material: &str) -> PathBuf {
    let text = format!(
        r#"background = 1.0
[camera]
eye = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
d = 4.0
resolution = [64, 32]
[render]
max_depth = 4
{textures}
[materials.m]
{material}
[[shapes]]
type = "quad"
origin = [-1.0, -0.5, 0.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 1.0, 0.0]
material = "m"
"#
    );
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// The mean linear sRGB over the 4 × 4 pixels around uv, and the value `want(uv)`
/// compared there, for a grid of uv points away from the squares' edges.
fn check(path: &Path, points: &[(f32, f32)], want: impl Fn(f32, f32) -> [f32; 3]) {
    let s = load_scene(path).unwrap();
    // 64 samples: the path tracer's noise on a diffuse square under a uniform sky is
    // zero (every path sees the sky); what is left is the uplift's, < 0.003.
    let film = run(&s, IntegratorKind::Path, 64, 5);
    let img = film.linear_srgb();
    for &(u, v) in points {
        let px = (u * 64.0) as usize;
        let py = 32 - (v * 32.0) as usize;
        let mut rgb = [0.0f32; 3];
        for dy in 0..4 {
            for dx in 0..4 {
                let c = img[(py - 2 + dy) * 64 + px - 2 + dx];
                for ch in 0..3 {
                    rgb[ch] += c[ch] / 16.0;
                }
            }
        }
        let w = want(u, v);
        for ch in 0..3 {
            assert!(
                (rgb[ch] - w[ch]).abs() < 0.005,
                "uv ({u}, {v}) channel {ch}: {rgb:?} vs {w:?}"
            );
        }
    }
}

const C0: [f32; 3] = [0.7, 0.2, 0.1];
const C1: [f32; 3] = [0.1, 0.2, 0.7];

/// Centres of the 4 × 2 squares of a checkerboard with to_uv = (2u, v).
fn centres() -> Vec<(f32, f32)> {
    (0..8)
        .map(|k| ((k % 4) as f32 / 4.0 + 0.125, (k / 4) as f32 / 2.0 + 0.25))
        .collect()
}

/// Mitsuba 3's rule at (s, t) = (2u, v): color0 where frac(s) > ½ and frac(t) > ½ agree.
fn mitsuba_square(u: f32, v: f32) -> bool {
    let (s, t) = (2.0 * u, v);
    (s.fract() > 0.5) == (t.fract() > 0.5)
}

const CHECKS: &str = r#"[textures.checks]
type = "checkerboard"
color0 = [0.7, 0.2, 0.1]
color1 = [0.1, 0.2, 0.7]
to_uv = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0]]"#;

#[test]
fn a_checkerboard_puts_color0_where_mitsubas_halves_agree() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(
        dir.path(),
        CHECKS,
        "type = \"lambertian\"\nrho_d = { texture = \"checks\" }",
    );
    check(
        &p,
        &centres(),
        |u, v| if mitsuba_square(u, v) { C0 } else { C1 },
    );
    // The `texture` key names a table too (before it named only files).
    let p = scene(
        dir.path(),
        CHECKS,
        "type = \"lambertian\"\ntexture = \"checks\"",
    );
    check(
        &p,
        &centres(),
        |u, v| if mitsuba_square(u, v) { C0 } else { C1 },
    );
}

#[test]
fn scale_and_mix_combine_textures_and_numbers() {
    let dir = tempfile::tempdir().unwrap();
    // An image: the left half 0.8 grey, the right half 0.2 (8 × 1 texels, so that the
    // squares' centres at u = ⅛ and ⅞ blend only equal texels): the mix's amount.
    write_exr(&dir.path().join("a.exr"), 8, 1, |i, _| {
        [if i < 4 { 0.8 } else { 0.2 }; 3]
    });
    let tables = format!(
        r#"{CHECKS}
[textures.half]
type = "scale"
tex = {{ texture = "checks" }}
scale = 0.5
[textures.amount]
type = "image"
file = "a.exr"
[textures.mixed]
type = "mix"
tex1 = {{ texture = "half" }}
tex2 = [0.9, 0.9, 0.9]
amount = {{ texture = "amount" }}"#
    );
    let p = scene(
        dir.path(),
        &tables,
        "type = \"lambertian\"\nrho_d = { texture = \"mixed\" }",
    );
    // Points away from the image's texel edge at u = ½ (bilinear there).
    let points: Vec<(f32, f32)> = centres()
        .into_iter()
        .filter(|(u, _)| (u - 0.5).abs() > 0.2)
        .collect();
    check(&p, &points, |u, v| {
        let c = if mitsuba_square(u, v) { C0 } else { C1 };
        let t = if u < 0.5 { 0.8 } else { 0.2 };
        c.map(|x| (1.0 - t) * 0.5 * x + t * 0.9)
    });
}

#[test]
fn texture_errors_name_the_key() {
    let dir = tempfile::tempdir().unwrap();
    write_exr(&dir.path().join("t.exr"), 2, 2, |_, _| [0.5; 3]);
    let m = "type = \"lambertian\"\nrho_d = { texture = \"a\" }";
    for (tables, material, want) in [
        (
            "",
            m,
            "materials.m.rho_d: no texture is named \"a\" (expected one of the [textures] tables: there are none)",
        ),
        (
            "[textures.a]\ntype = \"scale\"\ntex = { texture = \"b\" }\nscale = 2\n[textures.b]\ntype = \"mix\"\ntex1 = 0.5\ntex2 = { texture = \"a\" }",
            m,
            "the textures a → b → a name each other in a cycle",
        ),
        (
            "[textures.a]\ntype = \"checkerboard\"\ncolour0 = 0.5",
            m,
            "unknown key \"colour0\" at textures.a (expected one of type, color0, color1, to_uv)",
        ),
        (
            "[textures.a]\ntype = \"checkers\"",
            m,
            "textures.a.type: unknown variant \"checkers\", expected one of image, checkerboard, scale, mix",
        ),
        (
            "[textures.a]\ntype = \"image\"\nfile = \"t.exr\"\nencoding = \"gamma x\"",
            m,
            "textures.a.encoding: expected \"srgb\", \"linear\" or \"gamma G\" with G > 0, got \"gamma x\"",
        ),
        (
            "[textures.a]\ntype = \"checkerboard\"\ncolor0 = 1.5",
            m,
            "textures.a.color0",
        ),
        (
            "[textures.a]\ntype = \"checkerboard\"\ncolor0 = { texture = 3 }",
            m,
            "expected { texture = \"NAME\" }",
        ),
        (
            "[textures.a]\ntype = \"image\"\nfile = \"nope.png\"",
            m,
            "textures.a.file: ",
        ),
    ] {
        let e = load_scene(&scene(dir.path(), tables, material))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(want) && e.contains("scene.toml") && !e.contains('\n'),
            "{tables}: {e}"
        );
    }
}
