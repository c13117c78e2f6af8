//! Participating media through the importers (issue 38, #6): Mitsuba 3's `homogeneous`
//! medium behind a `null` or dielectric boundary, and pbrt-v4's `MakeNamedMedium` with
//! `MediumInterface` and the `interface` material, become heron's Henyey–Greenstein
//! media inside closed shapes; what heron cannot hold (an exterior medium, a medium in
//! an open or opaque shape, other medium types) is a warning at its line, and the
//! converted scenes load. The images are held to Mitsuba's in
//! tests/python/test_mitsuba_media.py.
mod common;

use heron::medium::{Medium, Optics};
use heron::scene::import::{import_scene, ImportOptions, Imported};
use heron::scene::load::load_imported;
use heron::spectrum::uplift::rgb_to_reflectance;
use std::path::Path;

fn import(name: &str, text: &str) -> (tempfile::TempDir, heron::error::Result<Imported>) {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    let r = import_scene(&p, &ImportOptions::default());
    (dir, r)
}

fn mitsuba(body: &str) -> String {
    common::scenes::mitsuba_around(body)
}

const PBRT_CAMERA: &str = "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 30 ]\nFilm \"rgb\" \"integer xresolution\" [ 40 ] \"integer yresolution\" [ 20 ]\nWorldBegin\n";

fn shapes(imp: &Imported) -> Vec<toml::Value> {
    imp.table()["shapes"].as_array().unwrap().clone()
}

fn num(v: &toml::Value) -> f64 {
    v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap()
}

/// A coefficient's value at `nm`: a number, or a samples table (5 nm steps).
fn at(v: &toml::Value, nm: f64) -> f64 {
    match v.as_table() {
        None => num(v),
        Some(t) => {
            let rows = t["samples"].as_array().unwrap();
            let row = rows
                .iter()
                .find(|r| num(&r[0]) == nm)
                .unwrap_or_else(|| panic!("no {nm} nm in {v}"));
            num(&row[1]) * t.get("scale").map_or(1.0, num)
        }
    }
}

fn said(imp: &Imported, line: u32, s: &str) -> bool {
    imp.warnings
        .iter()
        .any(|w| w.line == line && w.message.contains(s))
}

fn media_of(imp: &Imported) -> Vec<Medium> {
    let scene = load_imported(imp).unwrap_or_else(|e| panic!("{e}"));
    std::sync::Arc::try_unwrap(scene.media.clone()).unwrap_or_else(|a| (*a).clone_media())
}

/// `Medium` is not `Clone`; the tests only read the Henyey–Greenstein coefficients.
trait CloneMedia {
    fn clone_media(&self) -> Vec<Medium>;
}

impl CloneMedia for Vec<Medium> {
    fn clone_media(&self) -> Vec<Medium> {
        self.iter()
            .map(|m| match &m.optics {
                Optics::HenyeyGreenstein(h) => {
                    Medium::homogeneous(Optics::HenyeyGreenstein(h.clone()))
                }
                other => panic!("expected a Henyey-Greenstein medium, got {other:?}"),
            })
            .collect()
    }
}

#[test]
fn mitsuba_homogeneous_media_fill_null_cubes_and_glass_spheres() {
    let (_d, r) = import(
        "scene.xml",
        &mitsuba(
            r#"    <medium type="homogeneous" id="fog">
        <rgb name="sigma_t" value="0.3, 0.6, 1.0"/>
        <float name="scale" value="3.5"/>
        <float name="albedo" value="0.9"/>
        <phase type="hg"><float name="g" value="0.5"/></phase>
    </medium>
    <shape type="cube">
        <transform name="to_world"><scale value="0.7"/><rotate y="1" angle="30"/></transform>
        <bsdf type="null"/>
        <ref name="interior" id="fog"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="2" y="0" z="0"/>
        <bsdf type="dielectric"/>
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="2"/>
            <phase type="hg"/>
        </medium>
    </shape>
    <shape type="sphere">
        <point name="center" x="-2" y="0" z="0"/>
        <bsdf type="null"/>
    </shape>"#,
        ),
    );
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let s = shapes(&imp);
    // The invisible null sphere around no medium is gone.
    assert_eq!(s.len(), 2, "{s:#?}");
    let cube = &s[0];
    assert_eq!(cube["type"].as_str(), Some("mesh"));
    assert!(cube.get("material").is_none() && cube.get("file").is_none());
    assert_eq!(cube["vertices"].as_array().unwrap().len(), 8);
    assert_eq!(cube["triangles"].as_array().unwrap().len(), 12);
    let fog = &cube["medium"];
    assert_eq!(fog["type"].as_str(), Some("henyey-greenstein"));
    assert_eq!(num(&fog["g"]), 0.5);
    // σ_s = albedo σ_t and σ_a = (1 − albedo) σ_t, σ_t = 3.5 × Mitsuba's (bounded)
    // uplift of the RGB.
    let uplift = rgb_to_reflectance([0.3, 0.6, 1.0]);
    for nm in [400.0, 550.0, 700.0] {
        let (a, sc) = (at(&fog["sigma_a"], nm), at(&fog["sigma_s"], nm));
        let t = 3.5 * uplift.eval(nm as f32) as f64;
        assert!((a + sc - t).abs() < 1e-4 * t, "{nm}: {a} + {sc} vs {t}");
        assert!((sc / (a + sc) - 0.9).abs() < 1e-4, "{nm}");
    }
    // Mitsuba's defaults: albedo 0.75; an `hg` phase without g has g = 0.8.
    let milk = &s[1]["medium"];
    assert_eq!((num(&milk["sigma_a"]), num(&milk["sigma_s"])), (0.5, 1.5));
    assert!((num(&milk["g"]) - 0.8).abs() < 1e-6);
    // Both load: the cube is closed around its medium.
    let media = media_of(&imp);
    assert_eq!(media.len(), 2);
    let Optics::HenyeyGreenstein(h) = &media[0].optics else {
        unreachable!()
    };
    assert!(h.sigma_t.eval(450.0) > h.sigma_t.eval(650.0) * 0.5);
}

#[test]
fn mitsuba_media_heron_cannot_hold_are_warnings_at_their_line() {
    let (_d, r) = import(
        "scene.xml",
        &mitsuba(
            r#"    <shape type="rectangle">
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior"/>
    </shape>
    <shape type="sphere">
        <bsdf type="diffuse"/>
        <medium type="homogeneous" name="interior"/>
        <medium type="homogeneous" name="exterior"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="3" y="0" z="0"/>
        <bsdf type="dielectric"/>
        <medium type="custom" name="interior"/>
    </shape>"#,
        ),
    );
    let imp = r.unwrap();
    let w = &imp.warnings;
    assert!(
        said(&imp, 7, "interior medium is ignored: a rectangle is open"),
        "{w:?}"
    );
    assert!(
        said(&imp, 11, "its BSDF does not let light into a medium"),
        "{w:?}"
    );
    assert!(
        said(&imp, 14, "an exterior medium is not supported"),
        "{w:?}"
    );
    assert!(
        said(&imp, 19, "medium \"custom\" is not supported"),
        "{w:?}"
    );
    assert_eq!(w.len(), 4, "{w:?}");
    assert!(shapes(&imp).iter().all(|s| s.get("medium").is_none()));
    load_imported(&imp).unwrap();
    // A medium named neither interior nor exterior is an error at its line.
    let (_d, r) = import(
        "scene.xml",
        &mitsuba(
            r#"    <shape type="sphere">
        <medium type="homogeneous"/>
    </shape>"#,
        ),
    );
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("line 8") && e.contains("name=\"interior\""),
        "{e}"
    );
}

#[test]
fn pbrt_named_media_fill_interface_and_glass_shapes() {
    let cube = "\"point3 P\" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1 ] \"integer indices\" [ 0 2 1  0 3 2  4 5 6  4 6 7  0 1 5  0 5 4  1 2 6  1 6 5  2 3 7  2 7 6  3 0 4  3 4 7 ]";
    let text = format!(
        "MediumInterface \"\" \"water\"\n{PBRT_CAMERA}\
MakeNamedMedium \"smoke\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.1 0.2 0.3 ] \"rgb sigma_s\" [ 1 2 3 ] \"float scale\" 2 \"float g\" 0.3\n\
MakeNamedMedium \"water\" \"string type\" \"homogeneous\"\n\
MakeNamedMedium \"cloud\" \"string type\" \"nanovdb\" \"string filename\" \"c.nvdb\"\n\
AttributeBegin\n  MediumInterface \"smoke\" \"\"\n  Material \"interface\"\n  Shape \"sphere\"\nAttributeEnd\n\
AttributeBegin\n  MediumInterface \"water\" \"\"\n  Material \"dielectric\"\n  Translate 3 0 0\n  Shape \"trianglemesh\" {cube}\nAttributeEnd\n\
AttributeBegin\n  Material \"interface\"\n  Shape \"sphere\"\nAttributeEnd\n\
AttributeBegin\n  MediumInterface \"smoke\" \"water\"\n  Material \"diffuse\"\n  Translate -3 0 0\n  Shape \"sphere\"\nAttributeEnd\n\
AttributeBegin\n  MediumInterface \"cloud\" \"\"\n  Material \"interface\"\n  Shape \"sphere\"\nAttributeEnd\n"
    );
    let (_d, r) = import("scene.pbrt", &text);
    let imp = r.unwrap();
    let w = &imp.warnings;
    assert!(
        said(&imp, 4, "the camera is inside the medium \"water\""),
        "{w:?}"
    );
    assert!(said(&imp, 9, "type \"nanovdb\" is not supported"), "{w:?}");
    // Said once, at the first shape it surrounds (the interface sphere at line 23).
    assert!(
        said(&imp, 23, "the outside medium \"water\" is not rendered"),
        "{w:?}"
    );
    assert!(
        said(&imp, 29, "its material does not let light into a medium"),
        "{w:?}"
    );
    assert_eq!(w.len(), 4, "{w:?}");
    let s = shapes(&imp);
    // The interface sphere around no medium, and the one in an unsupported medium, are
    // invisible boundaries: not converted.
    assert_eq!(s.len(), 3, "{s:#?}");
    let smoke = &s[0]["medium"];
    assert!(s[0].get("material").is_none());
    // RGB coefficients times scale, uplifted unbounded by heron as pbrt-v4 does.
    let rgb = |v: &toml::Value| v.as_array().unwrap().iter().map(num).collect::<Vec<_>>();
    assert_eq!(rgb(&smoke["sigma_a"]), [0.2, 0.4, 0.6]);
    assert_eq!(rgb(&smoke["sigma_s"]), [2.0, 4.0, 6.0]);
    assert!((num(&smoke["g"]) - 0.3).abs() < 1e-6);
    // pbrt-v4's defaults: σ_a = σ_s = 1, g = 0; the triangle mesh as one closed mesh.
    let water = &s[1];
    assert_eq!(water["type"].as_str(), Some("mesh"));
    assert_eq!(water["triangles"].as_array().unwrap().len(), 12);
    assert_eq!(
        (
            num(&water["medium"]["sigma_a"]),
            num(&water["medium"]["sigma_s"])
        ),
        (1.0, 1.0)
    );
    assert!(s[2].get("medium").is_none());
    assert_eq!(media_of(&imp).len(), 2);
    // A medium never made is an error at the shape.
    let (_d, r) = import(
        "scene.pbrt",
        &format!("{PBRT_CAMERA}MediumInterface \"fog\" \"\"\nShape \"sphere\"\n"),
    );
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("line 7") && e.contains("no medium named \"fog\""),
        "{e}"
    );
}

#[test]
fn a_converted_medium_scene_reads_back_the_same() {
    // `heron convert` writes the inline mesh and the tabulated coefficients as TOML that
    // loads to the same scene.
    let (d, r) = import(
        "scene.xml",
        &mitsuba(
            r#"    <shape type="cube">
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior">
            <float name="sigma_t" value="1.5"/>
            <rgb name="albedo" value="0.9, 0.5, 0.2"/>
        </medium>
    </shape>"#,
        ),
    );
    let imp = r.unwrap();
    let toml_text = imp.to_toml(d.path());
    let p = d.path().join("converted.toml");
    std::fs::write(&p, &toml_text).unwrap();
    let again = heron::scene::load::load_scene(Path::new(&p)).unwrap_or_else(|e| panic!("{e}"));
    let first = media_of(&imp);
    let (Optics::HenyeyGreenstein(a), Optics::HenyeyGreenstein(b)) =
        (&first[0].optics, &again.media[0].optics)
    else {
        unreachable!()
    };
    assert_eq!(a.sigma_s, b.sigma_s);
    assert_eq!(a.sigma_a, b.sigma_a);
}

#[test]
fn meshes_written_in_the_scene_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let load = |mesh: &str| {
        let text = format!(
            "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n[materials.m]\ntype = \"lambertian\"\nrho_d = 0.5\n[[shapes]]\ntype = \"mesh\"\nmaterial = \"m\"\n{mesh}\n"
        );
        heron::scene::load::load_scene_from_str(&text, &dir.path().join("s.toml"))
            .map(|s| s.shapes.len())
            .map_err(|e| e.to_string())
    };
    let tri = "vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]";
    assert_eq!(load(&format!("{tri}\ntriangles = [[0, 1, 2]]")), Ok(1));
    // Of zero area only: dropped with a warning (tests/degenerate_mesh.rs), no shape.
    assert_eq!(
        load("vertices = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]\ntriangles = [[0, 1, 2]]"),
        Ok(0)
    );
    for (mesh, says) in [
        (
            format!("{tri}\ntriangles = [[0, 1, 3]]"),
            "shapes[0].triangles[0]: expected vertex indices below 3 (the number of vertices), got 3",
        ),
        (tri.to_string(), "shapes[0].triangles: missing required key"),
        (
            "triangles = [[0, 1, 2]]".to_string(),
            "shapes[0].vertices: missing required key",
        ),
        (
            format!("file = \"m.obj\"\n{tri}\ntriangles = [[0, 1, 2]]"),
            "shapes[0]: expected either file or vertices and triangles, got both",
        ),
    ] {
        let e = load(&mesh).unwrap_err();
        assert!(e.contains(says), "{mesh}: {e}");
    }
}
