//! Heterogeneous media from other renderers' scenes (issue 39, part 5): Mitsuba 3's
//! `heterogeneous` medium with a `gridvolume` σ_t and pbrt-v4's `uniformgrid` become
//! heron media with a `grid` density, placed where the source renderer places them and
//! looked up as it looks them up; what heron cannot carry over warns at its line, and a
//! bad grid is an error at its element.
mod common;

use glam::Vec3;
use heron::medium::density::Grid;
use heron::scene::import::{import_scene, ImportOptions, Imported};
use heron::scene::load::load_imported;

fn import(dir: &std::path::Path, name: &str, text: &str) -> heron::error::Result<Imported> {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    import_scene(&p, &ImportOptions::default())
}

fn said(imp: &Imported, line: u32, s: &str) -> bool {
    imp.warnings
        .iter()
        .any(|w| w.line == line && w.message.contains(s))
}

/// A 4 × 3 × 2 grid of values x + 10 y + 100 z in the unit box.
fn grid() -> Grid {
    let mut values = Vec::new();
    for z in 0..2 {
        for y in 0..3 {
            for x in 0..4 {
                values.push(x as f32 + 10.0 * y as f32 + 100.0 * z as f32);
            }
        }
    }
    Grid {
        res: [4, 3, 2],
        lo: Vec3::ZERO,
        hi: Vec3::ONE,
        values,
        edge: Default::default(),
    }
}

fn medium_cube(volume: &str, extra: &str) -> String {
    common::scenes::mitsuba_around(&format!(
        r#"    <shape type="cube">
        <transform name="to_world"><scale value="2"/></transform>
        <bsdf type="null"/>
        <medium type="heterogeneous" name="interior">
{volume}
            <float name="scale" value="3"/>
{extra}
        </medium>
    </shape>"#
    ))
}

#[test]
fn mitsuba_grid_volumes_become_grid_densities() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("g.vol"), grid().to_vol()).unwrap();
    // The unit cube mapped onto the null cube [-2, 2]³.
    let imp = import(
        dir.path(),
        "scene.xml",
        &medium_cube(
            r#"            <volume type="gridvolume" name="sigma_t">
                <string name="filename" value="g.vol"/>
                <transform name="to_world"><translate x="-0.5" y="-0.5" z="-0.5"/><scale value="4"/></transform>
            </volume>"#,
            r#"            <float name="albedo" value="0.5"/>"#,
        ),
    )
    .unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let t = imp.table();
    let m = &t["shapes"][0]["medium"];
    assert_eq!(m["density"]["type"].as_str(), Some("grid"));
    assert_eq!(m["density"]["file"].as_str(), Some("g.vol"));
    assert_eq!(m["sigma_s"].as_float(), Some(1.5), "{m}");
    let scene = load_imported(&imp).unwrap();
    let d = scene.media[0]
        .density
        .as_ref()
        .expect("a heterogeneous medium");
    // Mitsuba's cell-centred lookup: cell (1, 2, 0)'s centre at ((1.5/4, 2.5/3, 0.5/2)
    // of the box) holds 21, and trilinear is exact on this linear grid inside.
    let at = |u: Vec3| d.eval(Vec3::splat(-2.0) + 4.0 * u);
    assert!((at(Vec3::new(1.5 / 4.0, 2.5 / 3.0, 0.25)) - 21.0).abs() < 1e-4);
    let v = at(Vec3::new(0.5, 0.5, 0.5));
    assert!((v - (1.5 + 10.0 + 50.0)).abs() < 1e-3, "{v}");
    // Clamped beyond the last centres, as Mitsuba's default wrap mode.
    assert!((at(Vec3::new(0.01, 0.01, 0.01)) - 0.0).abs() < 1e-4);

    // What heron cannot carry over warns at its line: a rotated grid, another filter,
    // a grid albedo (its mean is used).
    let mut albedo = grid();
    albedo.values.iter_mut().for_each(|v| *v /= 200.0);
    std::fs::write(dir.path().join("a.vol"), albedo.to_vol()).unwrap();
    let imp = import(
        dir.path(),
        "scene.xml",
        &medium_cube(
            r#"            <volume type="gridvolume" name="sigma_t">
                <string name="filename" value="g.vol"/>
                <string name="filter_type" value="nearest"/>
                <transform name="to_world"><rotate y="1" angle="30"/></transform>
            </volume>"#,
            r#"            <volume type="gridvolume" name="albedo"><string name="filename" value="a.vol"/></volume>"#,
        ),
    )
    .unwrap();
    let w = &imp.warnings;
    assert!(
        said(&imp, 11, "filter_type: \"nearest\" is not supported"),
        "{w:?}"
    );
    assert!(said(&imp, 11, "heron's grids are axis-aligned"), "{w:?}");
    assert!(said(&imp, 17, "a grid albedo is not supported"), "{w:?}");
    assert_eq!(w.len(), 3, "{w:?}");

    // A bad grid is an error at its element.
    let mut bad = grid().to_vol();
    bad.truncate(60);
    std::fs::write(dir.path().join("bad.vol"), bad).unwrap();
    let e = import(
        dir.path(),
        "scene.xml",
        &medium_cube(
            r#"            <volume type="gridvolume" name="sigma_t"><string name="filename" value="bad.vol"/></volume>"#,
            "",
        ),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("line 11") && e.contains("bad.vol") && e.contains("truncated"),
        "{e}"
    );
}

const PBRT_CAMERA: &str = "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 30 ]\nFilm \"rgb\" \"integer xresolution\" [ 40 ] \"integer yresolution\" [ 20 ]\nWorldBegin\n";

#[test]
fn pbrt_uniform_grids_become_grid_densities() {
    let dir = tempfile::tempdir().unwrap();
    let values: Vec<String> = grid().values.iter().map(|v| v.to_string()).collect();
    let text = format!(
        "{PBRT_CAMERA}AttributeBegin\nTranslate 1 0 0\nScale 2 2 2\nMakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"float density\" [ {} ] \"integer nx\" 4 \"integer ny\" 3 \"integer nz\" 2 \"point3 p0\" [ -0.5 -0.5 -0.5 ] \"point3 p1\" [ 0.5 0.5 0.5 ] \"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 1 1 1 ] \"float scale\" 2\nAttributeEnd\nMaterial \"interface\"\nMediumInterface \"smoke\" \"\"\nShape \"sphere\" \"float radius\" 1.5\n",
        values.join(" ")
    );
    let imp = import(dir.path(), "scene.pbrt", &text).unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let scene = load_imported(&imp).unwrap();
    let d = scene.media[0]
        .density
        .as_ref()
        .expect("a heterogeneous medium");
    // The box [-0.5, 0.5]³ scaled by 2 and moved by 1 in x: [0, 2] × [-1, 1] × [-1, 1].
    let at = |u: Vec3| d.eval(Vec3::new(0.0, -1.0, -1.0) + 2.0 * u);
    assert!((at(Vec3::new(1.5 / 4.0, 2.5 / 3.0, 0.25)) - 21.0).abs() < 1e-4);
    // pbrt's grid blends with zeros beyond its cells and is empty outside its box.
    let v = at(Vec3::new(0.5, 1.0 - 0.25 / 3.0, 0.5));
    assert!((v - 0.75 * (1.5 + 20.0 + 50.0)).abs() < 1e-3, "{v}");
    assert_eq!(d.eval(Vec3::new(-0.01, 0.0, 0.0)), 0.0);

    let bad = text.replace("\"integer nz\" 2", "\"integer nz\" 3");
    let e = import(dir.path(), "scene.pbrt", &bad)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 9") && e.contains("expected nx*ny*nz = 36 values, got 24"),
        "{e}"
    );
}
