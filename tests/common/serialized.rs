//! A writer of Mitsuba's serialized meshes (versions 3 and 4) and the meshes the tests
//! write with it, shared by tests/serialized.rs and tests/corpus.rs.
use heron::geometry::{Mesh, ShapeKind};
use heron::scene::load::load_scene;
use std::path::Path;

/// One shape of a serialized file.
pub struct Shape {
    pub name: &'static str,
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    pub uvs: Option<Vec<[f32; 2]>>,
}

/// How a file is written: its version (3: no names, u32 offsets; 4: names, u64
/// offsets), double precision, and whether vertex normals and colours are stored too.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    pub version: u16,
    pub double: bool,
    pub extras: bool,
}

pub const LAYOUTS: [Layout; 4] = [
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
pub fn serialized(shapes: &[Shape], l: Layout) -> Vec<u8> {
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
pub fn ply(s: &Shape) -> Vec<u8> {
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
pub fn square() -> Shape {
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
pub fn scene_with(dir: &Path, name: &str, meshes: &[String]) -> std::path::PathBuf {
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

pub fn meshes(path: &Path) -> Vec<Mesh> {
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
pub fn prism(dir: &Path) -> Shape {
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
