//! Image textures of reflectance (`type = "lambertian"` with `texture = "file"`,
//! src/texture/image.rs): a textured square facing the camera under a uniform white
//! environment sends back ρ(uv) times the environment (it sees nothing but the sky), so
//! the image is the texture itself, texel for texel, under every integrator that sees
//! the environment; the layout of uv on a quad and a sphere; the loader's errors.
mod common;

use common::images::write_exr;

use common::render::run;
use heron::scene::load_scene;
use heron::settings::IntegratorKind;
use std::path::Path;

/// 4 × 2 texels of distinct, moderately saturated colours.
const TEXELS: [[f32; 3]; 8] = [
    [0.7, 0.2, 0.1],
    [0.2, 0.6, 0.2],
    [0.1, 0.2, 0.7],
    [0.5, 0.5, 0.5],
    [0.6, 0.6, 0.1],
    [0.1, 0.5, 0.6],
    [0.6, 0.1, 0.5],
    [0.3, 0.3, 0.3],
];

/// A 2 × 1 square at z = 0 facing +z, origin at its lower left (−1, −0.5), edge1 along
/// +x, edge2 along +y; the camera at z = 4 sees it fill a 64 × 32 image.
fn scene(dir: &Path, material: &str) -> std::path::PathBuf {
    let text = format!(
        r#"background = 1.0
[camera]
eye = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
d = 4.0
resolution = [64, 32]
[render]
max_depth = 4
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

#[test]
fn a_textured_square_under_a_white_sky_renders_its_texels_with_every_integrator() {
    let dir = tempfile::tempdir().unwrap();
    // Each colour is a 2 × 2 block of texels, so that around a block's centre the
    // bilinear lookup blends only equal texels and the colour is exact there.
    write_exr(&dir.path().join("t.exr"), 8, 4, |i, j| {
        TEXELS[(j / 2) * 4 + i / 2]
    });
    let s = load_scene(&scene(
        dir.path(),
        "type = \"lambertian\"\ntexture = \"t.exr\"",
    ))
    .unwrap();
    // The camera's d = 4 at distance 4 makes the image plane (height 1, width 2) the
    // square itself; its pixel (x, y) from the top sees uv = ((x + ½)/64, 1 − (y + ½)/32).
    for (kind, spp, tol) in [
        (IntegratorKind::Path, 64, 0.005),
        (IntegratorKind::Bdpt, 64, 0.005),
        // Light tracing reaches the camera through the square by chance: at 4096 samples
        // a pixel group is within 3% (256 leave it 8% off).
        (IntegratorKind::LightTrace, 4096, 0.03),
        (IntegratorKind::Sppm, 64, 0.005),
    ] {
        let film = run(&s, kind, spp, 5);
        let img = film.linear_srgb();
        for (k, want) in TEXELS.iter().enumerate() {
            let (i, j) = (k % 4, k / 4);
            // Block (i, j)'s centre: uv ((i + ½)/4, (j + ½)/2); v = 0 is the image's top
            // row and the quad's edge1 side (the bottom of the picture).
            let px = i * 16 + 8;
            let py = 32 - (j * 16 + 8);
            // The mean over the 4 × 4 pixels around the centre.
            let mut rgb = [0.0f64; 3];
            for dy in 0..4 {
                for dx in 0..4 {
                    let c = img[(py - 2 + dy) * 64 + px - 2 + dx];
                    for ch in 0..3 {
                        rgb[ch] += c[ch] as f64 / 16.0;
                    }
                }
            }
            for ch in 0..3 {
                // The texel's uplift (the fitted table's lookup, unpolished) and the
                // estimator's noise.
                assert!(
                    (rgb[ch] - want[ch] as f64).abs() < tol,
                    "{kind:?}: texel ({i}, {j}) channel {ch}: {} vs {}",
                    rgb[ch],
                    want[ch]
                );
            }
        }
    }
}

/// A sphere's uv is Mitsuba 3's (φ/2π, θ/π) about +z: seen from +z, its upper half
/// (y > 0, φ near 90°, u near ¼) shows the texture's left texel and its lower half the
/// right one; a PNG is sRGB-decoded.
#[test]
fn a_sphere_s_uv_and_a_png_s_srgb_decoding() {
    let dir = tempfile::tempdir().unwrap();
    // 2 × 1: left red, right green, 8-bit sRGB 188 = linear 0.5029.
    let mut png = image::RgbImage::new(2, 1);
    png.put_pixel(0, 0, image::Rgb([188, 0, 0]));
    png.put_pixel(1, 0, image::Rgb([0, 188, 0]));
    png.save(dir.path().join("t.png")).unwrap();
    let text = r#"background = 1.0
[camera]
eye = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
d = 2.0
resolution = [33, 33]
[render]
max_depth = 1
[materials.m]
type = "lambertian"
texture = "t.png"
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "m"
"#;
    let p = dir.path().join("scene.toml");
    std::fs::write(&p, text).unwrap();
    let film = run(&load_scene(&p).unwrap(), IntegratorKind::Path, 16, 1);
    let img = film.linear_srgb();
    let (top, bottom) = (img[10 * 33 + 16], img[22 * 33 + 16]);
    assert!(top[0] > 0.1 && top[1] < 0.02, "top {top:?}");
    assert!(bottom[1] > 0.1 && bottom[0] < 0.02, "bottom {bottom:?}");
    // ρ = 0.5029 at u = ¼ exactly (the left texel's centre), the sphere lit by a
    // uniform sky over the hemisphere it sees: radiance ρ · 1 · (1, only one bounce).
    let decoded = ((188.0f64 / 255.0 + 0.055) / 1.055).powf(2.4);
    assert!(
        (top[0] as f64 - decoded).abs() < 0.01,
        "{top:?} vs {decoded}"
    );
}

#[test]
fn texture_errors_name_the_material_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    write_exr(&dir.path().join("t.exr"), 2, 2, |_, _| [0.5; 3]);
    for (m, want) in [
        (
            "type = \"lambertian\"\nrho_d = 0.5\ntexture = \"t.exr\"",
            "materials.m: expected rho_d or texture, not both",
        ),
        (
            "type = \"lambertian\"",
            "materials.m: expected rho_d (a reflectance or { texture = \"NAME\" }) or texture (a [textures] table or an image file)",
        ),
        (
            "type = \"lambertian\"\ntexture = \"nope.png\"",
            "materials.m.texture: ",
        ),
        (
            "type = \"lambertian\"\ntexture = \"t.gif\"",
            "expected an image file ending in .exr, .hdr, .pfm, .png, .jpg or .jpeg, got \"gif\"",
        ),
    ] {
        let e = load_scene(&scene(dir.path(), m)).unwrap_err().to_string();
        assert!(
            e.contains(want) && e.contains("scene.toml") && !e.contains('\n'),
            "{m}: {e}"
        );
    }
}

/// A mesh's own texture coordinates: the square of the first test as an OBJ (whose v is
/// flipped on reading, as Mitsuba 3 reads OBJ) and as a PLY (not flipped) renders exactly
/// the pixels of the `quad`; a face without texture coordinates leaves the mesh with
/// none, and a bad texture index is an error with its line.
#[test]
fn obj_and_ply_texture_coordinates_place_the_texture_as_the_quad_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_exr(&d.join("t.exr"), 8, 4, |i, j| TEXELS[(j / 2) * 4 + i / 2]);
    let quad = load_scene(&scene(d, "type = \"lambertian\"\ntexture = \"t.exr\"")).unwrap();
    let reference = run(&quad, IntegratorKind::Path, 4, 9);
    // The quad's corners origin, +edge1, +edge1+edge2, +edge2 and its uv (s, t).
    std::fs::write(
        d.join("sq.obj"),
        "v -1 -0.5 0\nv 1 -0.5 0\nv 1 0.5 0\nv -1 0.5 0\nvt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sq.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n-1 -0.5 0 0 0\n1 -0.5 0 1 0\n1 0.5 0 1 1\n-1 0.5 0 0 1\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    for file in ["sq.obj", "sq.ply"] {
        let text = std::fs::read_to_string(scene(d, "type = \"lambertian\"\ntexture = \"t.exr\""))
            .unwrap();
        let text = text.replace(
            "type = \"quad\"\norigin = [-1.0, -0.5, 0.0]\nedge1 = [2.0, 0.0, 0.0]\nedge2 = [0.0, 1.0, 0.0]\n",
            &format!("type = \"mesh\"\nfile = \"{file}\"\n"),
        );
        let p = d.join("mesh.toml");
        std::fs::write(&p, &text).unwrap();
        let film = run(&load_scene(&p).unwrap(), IntegratorKind::Path, 4, 9);
        assert_eq!(film.xyz, reference.xyz, "{file}");
        // Flipped the other way, the texture is upside down: not the same image.
        let flipped = text.replace(
            &format!("file = \"{file}\"\n"),
            &format!(
                "file = \"{file}\"\nflip_tex_coords = {}\n",
                file.ends_with("ply")
            ),
        );
        std::fs::write(&p, &flipped).unwrap();
        let film = run(&load_scene(&p).unwrap(), IntegratorKind::Path, 4, 9);
        assert_ne!(film.xyz, reference.xyz, "{file} flipped");
    }
    // One face without texture coordinates: none for the mesh (barycentrics).
    let mixed = "v -1 -0.5 0\nv 1 -0.5 0\nv 1 0.5 0\nv -1 0.5 0\nvt 0 1\nvt 1 1\nvt 1 0\nf 1/1 2/2 3/3\nf 1 3 4\n";
    let g = std::fs::write(d.join("mixed.obj"), mixed);
    g.unwrap();
    let text = std::fs::read_to_string(scene(d, "type = \"lambertian\"\ntexture = \"t.exr\""))
        .unwrap()
        .replace(
            "type = \"quad\"\norigin = [-1.0, -0.5, 0.0]\nedge1 = [2.0, 0.0, 0.0]\nedge2 = [0.0, 1.0, 0.0]\n",
            "type = \"mesh\"\nfile = \"mixed.obj\"\n",
        );
    let p = d.join("mixed.toml");
    std::fs::write(&p, &text).unwrap();
    let s = load_scene(&p).unwrap();
    let heron::geometry::ShapeKind::Mesh(m) = &s.shapes[0].kind else {
        panic!()
    };
    assert!(m.uvs.is_empty());
    std::fs::write(
        d.join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/5 3/1\n",
    )
    .unwrap();
    let text = text.replace("mixed.obj", "bad.obj");
    std::fs::write(&p, &text).unwrap();
    let e = load_scene(&p).unwrap_err().to_string();
    assert!(
        e.contains("line 5: texture coordinate index 5 out of range"),
        "{e}"
    );
}

/// A JPEG texture is sRGB-decoded as a PNG is: it renders the pixels of the PNG of its own
/// decoded 8-bit values (JPEG is lossy, so the PNG is made from what the JPEG decodes to).
#[test]
fn a_jpeg_texture_renders_the_pixels_of_the_png_of_its_decoded_values() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let img = image::RgbImage::from_fn(32, 16, |i, j| {
        let t = TEXELS[(j as usize / 8) * 4 + i as usize / 8];
        image::Rgb(t.map(|c| (c * 255.0) as u8))
    });
    let mut f = std::fs::File::create(d.join("t.jpeg")).unwrap();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut f, 90)
        .encode_image(&img)
        .unwrap();
    drop(f);
    image::open(d.join("t.jpeg"))
        .unwrap()
        .to_rgb8()
        .save(d.join("t.png"))
        .unwrap();
    let render = |file: &str| {
        let s = load_scene(&scene(
            d,
            &format!("type = \"lambertian\"\ntexture = \"{file}\""),
        ))
        .unwrap();
        run(&s, IntegratorKind::Path, 4, 2).xyz
    };
    let want = render("t.png");
    std::fs::rename(d.join("t.jpeg"), d.join("t.JPG")).unwrap();
    assert_eq!(render("t.JPG"), want);
}
