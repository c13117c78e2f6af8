//! Mitsuba's serialized meshes (`src/scene/load/serialized.rs`): files written here by a
//! small writer of the format (versions 3 and 4, single and double precision, with and
//! without the normals and colours heron reads past, two shapes per file) load to the
//! triangles and texture coordinates of the same meshes as PLY; bad files are one-line
//! errors naming the file and the shape; and a Mitsuba XML scene with `<shape
//! type="serialized">` renders the pixels of the same scene with its meshes as PLY.
mod common;

use common::cli::heron_ok;
use common::serialized::{meshes, ply, prism, scene_with, serialized, square, Shape, LAYOUTS};
use heron::scene::import::{import_scene, ImportOptions};
use heron::scene::load::load_scene;
use std::path::Path;

#[test]
fn a_serialized_file_loads_the_triangles_of_the_same_meshes_as_ply() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let prism = prism(d);
    std::fs::write(d.join("square.ply"), ply(&square())).unwrap();
    let want = meshes(&scene_with(
        d,
        "ply.toml",
        &[
            "file = \"square.ply\"".into(),
            "file = \"prism60.ply\"".into(),
        ],
    ));
    assert_eq!(want[0].uvs.len(), 2);
    for l in LAYOUTS {
        std::fs::write(
            d.join("two.serialized"),
            serialized(&[square(), prism.clone()], l),
        )
        .unwrap();
        // The first shape by default and by index; the second by index.
        let got = meshes(&scene_with(
            d,
            "serialized.toml",
            &[
                "file = \"two.serialized\"".into(),
                "file = \"two.serialized\"\nshape_index = 0".into(),
                "file = \"two.serialized\"\nshape_index = 1".into(),
            ],
        ));
        for (g, w) in got.iter().zip([&want[0], &want[0], &want[1]]) {
            assert_eq!(g.positions, w.positions, "{l:?}");
            assert_eq!(g.indices, w.indices, "{l:?}");
            assert_eq!(g.uvs, w.uvs, "{l:?}");
        }
    }
}

impl Clone for Shape {
    fn clone(&self) -> Shape {
        Shape {
            name: self.name,
            positions: self.positions.clone(),
            indices: self.indices.clone(),
            uvs: self.uvs.clone(),
        }
    }
}

#[test]
fn bad_serialized_files_are_one_line_errors_naming_the_file_and_the_shape() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = serialized(&[square(), square()], LAYOUTS[2]);
    let check = |bytes: &[u8], entry: &str, want: &[&str]| {
        std::fs::write(d.join("bad.serialized"), bytes).unwrap();
        let p = scene_with(d, "bad.toml", &[entry.to_string()]);
        let e = load_scene(&p).unwrap_err().to_string();
        assert!(!e.contains('\n'), "{e}");
        for w in want {
            assert!(e.contains(w), "wanted {w:?} in: {e}");
        }
    };
    let file = "file = \"bad.serialized\"";
    let at1 = "file = \"bad.serialized\"\nshape_index = 1";
    // Truncated inside the first shape's stream, and inside its header.
    check(
        &good[..good.len() / 4],
        file,
        &["bad.serialized", "shapes[0].file: shape 0", "ends early"],
    );
    check(
        &good[..3],
        file,
        &["bad.serialized", "shape 0", "4-byte header"],
    );
    // Without its table, the second shape cannot be found.
    let n = good.len();
    check(
        &good[..n - 12],
        at1,
        &["bad.serialized", "shape_index 1", "expected an index below"],
    );
    let mut magic = good.clone();
    magic[0] = 0x1D;
    check(
        &magic,
        file,
        &["bad.serialized", "shape 0", "magic 0x041C, got 0x041D"],
    );
    let mut version = good.clone();
    version[2] = 5;
    check(
        &version,
        file,
        &["shape 0", "version 5", "expected version 3 or 4"],
    );
    check(
        &good,
        "file = \"bad.serialized\"\nshape_index = 2",
        &[
            "bad.serialized",
            "shape_index 2",
            "holds 2 shapes, expected an index below 2",
        ],
    );
    // An offset in the table past the data.
    let mut offset = good.clone();
    offset[n - 12..n - 4].copy_from_slice(&(n as u64).to_le_bytes());
    check(
        &offset,
        at1,
        &["shape_index 1", &format!("byte offset {n}")],
    );
    // Bad content in the second shape: named by its index.
    let mut bad = square();
    bad.indices[1] = [0, 2, 4];
    check(
        &serialized(&[square(), bad], LAYOUTS[0]),
        at1,
        &["shape 1: triangle 1", "below the 4 vertices, got 4"],
    );
    let mut nan = square();
    nan.positions[2][1] = f32::NAN;
    check(
        &serialized(&[square(), nan], LAYOUTS[3]),
        at1,
        &["shape 1: vertex 2", "expected finite coordinates"],
    );
    // shape_index belongs to serialized files only.
    std::fs::write(d.join("square.ply"), ply(&square())).unwrap();
    let p = scene_with(
        d,
        "ply.toml",
        &["file = \"square.ply\"\nshape_index = 0".into()],
    );
    let e = load_scene(&p).unwrap_err().to_string();
    assert!(
        e.contains("ply.toml")
            && e.contains("shapes[0].shape_index: applies to Mitsuba serialized meshes"),
        "{e}"
    );
}

/// A Mitsuba scene: a textured square and a turned prism under a constant emitter and a
/// small light; `square` and `prism` are their shape elements' opening lines.
fn mitsuba_scene(square: &str, prism: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0.5, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="32"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.6, 0.7, 0.8"/></emitter>
    <shape type="sphere">
        <point name="center" x="2" y="3" z="3"/><float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="20, 20, 20"/></emitter>
    </shape>
    {square}
        <transform name="to_world"><translate x="-0.5" y="0" z="-1"/></transform>
        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance"><string name="filename" value="tex.png"/></texture>
        </bsdf>
    </shape>
    {prism}
        <transform name="to_world"><rotate y="1" angle="30"/><translate x="0.8" y="-0.4" z="0.5"/></transform>
        <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>
    </shape>
</scene>
"#
    )
}

/// The R, G, B channels of an EXR heron wrote.
fn exr_pixels(path: &Path) -> Vec<(f32, f32, f32, f32)> {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| vec![(0.0f32, 0.0f32, 0.0f32, 0.0f32); res.width() * res.height()],
        |px: &mut Vec<(f32, f32, f32, f32)>, pos, v: (f32, f32, f32, f32)| {
            // Row-major; the width is the image's, 48.
            px[pos.y() * 48 + pos.x()] = v;
        },
    )
    .unwrap();
    img.layer_data.channel_data.pixels
}

#[test]
fn a_mitsuba_serialized_shape_renders_the_pixels_of_the_same_ply() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let prism = prism(d);
    std::fs::create_dir(d.join("meshes")).unwrap();
    std::fs::write(d.join("meshes/square.ply"), ply(&square())).unwrap();
    std::fs::copy(d.join("prism60.ply"), d.join("meshes/prism60.ply")).unwrap();
    std::fs::write(
        d.join("meshes/two.serialized"),
        serialized(&[square(), prism], LAYOUTS[2]),
    )
    .unwrap();
    // 4 × 2 texels, so that a flipped or mirrored uv shows.
    image::RgbImage::from_fn(4, 2, |i, j| {
        image::Rgb([
            40 + 50 * i as u8,
            200 - 90 * j as u8,
            30 + 60 * (i * j) as u8,
        ])
    })
    .save(d.join("tex.png"))
    .unwrap();
    let ser = |k: u32| {
        format!(
            r#"<shape type="serialized"><string name="filename" value="meshes/two.serialized"/><integer name="shape_index" value="{k}"/><boolean name="face_normals" value="true"/>"#
        )
    };
    let ply =
        |f: &str| format!(r#"<shape type="ply"><string name="filename" value="meshes/{f}"/>"#);
    let a = d.join("serialized.xml");
    let b = d.join("ply.xml");
    std::fs::write(&a, mitsuba_scene(&ser(0), &ser(1))).unwrap();
    std::fs::write(&b, mitsuba_scene(&ply("square.ply"), &ply("prism60.ply"))).unwrap();
    // Everything in the serialized shapes is read: no warning.
    let imported = import_scene(&a, &ImportOptions::default()).unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    let text = imported.to_toml(d);
    assert!(
        text.contains("file = \"meshes/two.serialized\"") && text.contains("shape_index = 1"),
        "{text}"
    );
    let (ea, eb) = (d.join("a.exr"), d.join("b.exr"));
    for (xml, exr) in [(&a, &ea), (&b, &eb)] {
        heron_ok(&[
            "render",
            xml.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--spp",
            "4",
        ]);
    }
    let (pa, pb) = (exr_pixels(&ea), exr_pixels(&eb));
    assert!(pa.iter().any(|p| p.0 > 0.0));
    assert_eq!(pa, pb);
    // The PNG previews too, byte for byte (the EXRs' provenance names different files).
    assert_eq!(
        std::fs::read(ea.with_extension("png")).unwrap(),
        std::fs::read(eb.with_extension("png")).unwrap()
    );
    // A serialized shape's file must say so by its extension.
    let c = d.join("renamed.xml");
    std::fs::write(
        &c,
        mitsuba_scene(
            r#"<shape type="serialized"><string name="filename" value="meshes/two.bin"/>"#,
            &ser(1),
        ),
    )
    .unwrap();
    let e = import_scene(&c, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("renamed.xml") && e.contains("expected a file ending in .serialized"),
        "{e}"
    );
}
