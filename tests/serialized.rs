//! Mitsuba's serialized meshes (`src/scene/load/serialized.rs`): files written here by a
//! small writer of the format (versions 3 and 4, single and double precision, with and
//! without the normals and colours heron reads past, two shapes per file) load to the
//! triangles and texture coordinates of the same meshes as PLY; bad files are one-line
//! errors naming the file and the shape; and a Mitsuba XML scene with `<shape
//! type="serialized">` renders the pixels of the same scene with its meshes as PLY.
mod common;

use common::cli::heron_ok;
use heron::geometry::{Mesh, ShapeKind};
use heron::scene::import::{import_scene, ImportOptions};
use heron::scene::load::load_scene;
use std::path::Path;

/// One shape of a serialized file.
struct Shape {
    name: &'static str,
    positions: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
    uvs: Option<Vec<[f32; 2]>>,
}

/// How a file is written: its version (3: no names, u32 offsets; 4: names, u64
/// offsets), double precision, and whether vertex normals and colours are stored too.
#[derive(Clone, Copy, Debug)]
struct Layout {
    version: u16,
    double: bool,
    extras: bool,
}

const LAYOUTS: [Layout; 4] = [
    Layout {
        version: 3,
        double: false,
        extras: false,
    },
    Layout {
        version: 3,
        double: true,
        extras: true,
    },
    Layout {
        version: 4,
        double: false,
        extras: true,
    },
    Layout {
        version: 4,
        double: true,
        extras: false,
    },
];

/// The format of Mitsuba 3's `src/shapes/serialized.cpp` (as Mitsuba 0.6 wrote it): per
/// shape a header and a zlib stream, then the shapes' offsets and their count.
fn serialized(shapes: &[Shape], l: Layout) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for s in shapes {
        offsets.push(out.len() as u64);
        out.extend(0x041Cu16.to_le_bytes());
        out.extend(l.version.to_le_bytes());
        let mut flags = if l.double { 0x2000u32 } else { 0x1000 };
        if l.extras {
            flags |= 0x0001 | 0x0008;
        }
        if s.uvs.is_some() {
            flags |= 0x0002;
        }
        let mut d = flags.to_le_bytes().to_vec();
        if l.version == 4 {
            d.extend(s.name.as_bytes());
            d.push(0);
        }
        d.extend((s.positions.len() as u64).to_le_bytes());
        d.extend((s.indices.len() as u64).to_le_bytes());
        let floats = |d: &mut Vec<u8>, v: &[f32]| {
            for &x in v {
                if l.double {
                    d.extend((x as f64).to_le_bytes());
                } else {
                    d.extend(x.to_le_bytes());
                }
            }
        };
        floats(&mut d, s.positions.as_flattened());
        if l.extras {
            floats(&mut d, &[0.0, 0.0, 1.0].repeat(s.positions.len()));
        }
        if let Some(uv) = &s.uvs {
            floats(&mut d, uv.as_flattened());
        }
        if l.extras {
            floats(&mut d, &vec![0.5; 3 * s.positions.len()]);
        }
        for i in s.indices.as_flattened() {
            d.extend(i.to_le_bytes());
        }
        out.extend(miniz_oxide::deflate::compress_to_vec_zlib(&d, 6));
    }
    for o in &offsets {
        if l.version == 3 {
            out.extend((*o as u32).to_le_bytes());
        } else {
            out.extend(o.to_le_bytes());
        }
    }
    out.extend((shapes.len() as u32).to_le_bytes());
    out
}

/// A binary PLY of positions, optional u, v and triangles.
fn ply(s: &Shape) -> Vec<u8> {
    let uv = if s.uvs.is_some() {
        "property float u\nproperty float v\n"
    } else {
        ""
    };
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n{uv}element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        s.positions.len(),
        s.indices.len()
    )
    .into_bytes();
    for (k, p) in s.positions.iter().enumerate() {
        for c in p {
            b.extend(c.to_le_bytes());
        }
        if let Some(uv) = &s.uvs {
            for c in uv[k] {
                b.extend(c.to_le_bytes());
            }
        }
    }
    for t in &s.indices {
        b.push(3);
        for &i in t {
            b.extend((i as i32).to_le_bytes());
        }
    }
    b
}

/// A square with texture coordinates, as two triangles.
fn square() -> Shape {
    Shape {
        name: "square",
        positions: vec![
            [-1.0, -0.5, 0.0],
            [1.0, -0.5, 0.0],
            [1.0, 0.5, 0.0],
            [-1.0, 0.5, 0.0],
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
    }
}

/// A scene of one grey material and the mesh entries `meshes` (TOML lines each).
fn scene_with(dir: &Path, name: &str, meshes: &[String]) -> std::path::PathBuf {
    let mut text = String::from(
        "background = 1.0\n[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n[materials.m]\ntype = \"lambertian\"\nrho_d = 0.5\n",
    );
    for m in meshes {
        text.push_str(&format!(
            "[[shapes]]\ntype = \"mesh\"\nmaterial = \"m\"\n{m}\n"
        ));
    }
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn meshes(path: &Path) -> Vec<Mesh> {
    load_scene(path)
        .unwrap_or_else(|e| panic!("{e}"))
        .shapes
        .iter()
        .map(|s| match &s.kind {
            ShapeKind::Mesh(m) => m.clone(),
            other => panic!("{other:?}"),
        })
        .collect()
}

/// The prism of `scenes/meshes/prism60.ply` as heron reads it, as a shape to write.
fn prism(dir: &Path) -> Shape {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/meshes/prism60.ply");
    std::fs::copy(src, dir.join("prism60.ply")).unwrap();
    let p = scene_with(dir, "prism.toml", &["file = \"prism60.ply\"".into()]);
    let m = meshes(&p).remove(0);
    assert_eq!(m.indices.len(), 8);
    Shape {
        name: "prism",
        positions: m.positions.iter().map(|v| v.to_array()).collect(),
        indices: m.indices.clone(),
        uvs: None,
    }
}

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
