//! Zero-area triangles in meshes (issue 38, #13: one degenerate mesh among hundreds
//! rejected the whole scene). A mesh file (OBJ, PLY, Mitsuba serialized) or a mesh
//! written in heron's TOML keeps its good triangles and drops the others with one
//! warning naming the file, the entry and the count; a mesh left with none is dropped
//! with a warning and the scene still loads. The warnings reach `Scene::warnings`, and
//! `heron render` prints them, for heron's TOML and for imported scenes alike.
mod common;

use common::cli::heron_ok;
use common::serialized::{ply, serialized, Shape, LAYOUTS};
use heron::scene::load::load_scene;
use std::path::Path;

/// A unit square as two triangles, plus `bad` triangles of zero area (collinear).
fn square_with(bad: usize) -> Shape {
    let mut s = Shape {
        name: "square",
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        uvs: None,
    };
    s.indices.extend(vec![[0, 1, 4]; bad]);
    s
}

fn obj(s: &Shape) -> String {
    let mut t = String::new();
    for p in &s.positions {
        t += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for f in &s.indices {
        t += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    t
}

/// A scene of a sphere and the mesh `file` (so that it has geometry without the mesh).
fn scene(dir: &Path, file: &str) -> std::path::PathBuf {
    let text = format!(
        "background = 1.0\n[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n[materials.m]\ntype = \"lambertian\"\nrho_d = 0.5\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, -3]\nradius = 1\nmaterial = \"m\"\n[[shapes]]\ntype = \"mesh\"\nmaterial = \"m\"\nfile = \"{file}\"\n"
    );
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

#[test]
fn mesh_files_drop_zero_area_triangles_with_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, bytes) in [
        ("m.obj", obj(&square_with(3)).into_bytes()),
        ("m.ply", ply(&square_with(3))),
        ("m.serialized", serialized(&[square_with(3)], LAYOUTS[0])),
    ] {
        write(d, name, &bytes);
        let s = load_scene(&scene(d, name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.shapes.len(), 2, "{name}: the sphere and the mesh");
        let tris = match &s.shapes[1].kind {
            heron::geometry::ShapeKind::Mesh(m) => m.indices.len(),
            other => panic!("{other:?}"),
        };
        assert_eq!(tris, 2, "{name}");
        assert_eq!(
            s.warnings,
            vec![format!(
                "{}: shapes[1]: 3 triangle(s) of zero area dropped (2 kept)",
                d.join(name).display()
            )],
            "{name}"
        );

        // None left: the mesh is dropped, the scene loads with the sphere.
        let bad = Shape {
            indices: vec![[0, 1, 4]; 2],
            ..square_with(0)
        };
        let bytes = match name {
            "m.obj" => obj(&bad).into_bytes(),
            "m.ply" => ply(&bad),
            _ => serialized(&[bad], LAYOUTS[0]),
        };
        write(d, name, &bytes);
        let s = load_scene(&scene(d, name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.shapes.len(), 1, "{name}: the sphere only");
        assert_eq!(
            s.warnings,
            vec![format!(
                "{}: shapes[1]: 2 triangle(s) of zero area dropped (no triangle is left, the mesh is dropped)",
                d.join(name).display()
            )],
            "{name}"
        );
    }
}

/// The same rule for a mesh written in heron's TOML (`vertices`, `triangles`), and an
/// emitting mesh left empty is no light: the scene's only light is the other one.
#[test]
fn meshes_written_in_the_scene_follow_the_same_rule() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("scene.toml");
    let text = "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n[materials.m]\ntype = \"lambertian\"\nrho_d = 0.5\n\
        [[shapes]]\ntype = \"mesh\"\nmaterial = \"m\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 0, 0]]\ntriangles = [[0, 1, 2], [0, 1, 3]]\n\
        [[shapes]]\ntype = \"mesh\"\nemission = 1.0\nvertices = [[0, 0, 1], [1, 0, 1], [2, 0, 1]]\ntriangles = [[0, 1, 2]]\n\
        [[shapes]]\ntype = \"sphere\"\ncenter = [0, 3, 0]\nradius = 0.5\nemission = 2.0\n";
    std::fs::write(&p, text).unwrap();
    let s = load_scene(&p).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.shapes.len(), 2);
    assert_eq!(s.lights.len(), 1, "the sphere's area light only");
    let at = p.display();
    assert_eq!(
        s.warnings,
        vec![
            format!("{at}: shapes[0]: 1 triangle(s) of zero area dropped (1 kept)"),
            format!("{at}: shapes[1]: 1 triangle(s) of zero area dropped (no triangle is left, the mesh is dropped)"),
        ]
    );
    // The entry's light is gone and the scene renders.
    common::render::run(&s, heron::settings::IntegratorKind::Path, 2, 1);
}

/// `heron render` prints the loader's warnings, for heron's TOML and after an
/// importer's own (a Mitsuba scene naming the PLY).
#[test]
fn heron_render_prints_the_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "m.ply", &ply(&square_with(2)));
    let toml = scene(d, "m.ply");
    let xml = d.join("scene.xml");
    std::fs::write(
        &xml,
        common::scenes::mitsuba_around(
            r#"<shape type="ply"><string name="filename" value="m.ply"/></shape><shape type="sphere"/>"#,
        ),
    )
    .unwrap();
    for scene in [toml, xml] {
        let out = d.join("out.exr");
        let o = heron_ok(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "1",
            "--no-png",
            "--quiet",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("warning: ")
                && err.contains("m.ply: shapes[")
                && err.contains("2 triangle(s) of zero area dropped (2 kept)"),
            "{}: {err}",
            scene.display()
        );
    }
}
