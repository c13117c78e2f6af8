//! Mitsuba 3 XML scenes through heron's importer (`heron::scene::import`): each
//! supported element converted to the heron scene it should be, the Cornell box written
//! as XML rendering exactly the pixels of heron's own `cornell-box.toml`, meshes (OBJ
//! and PLY with a `to_world`) placed where the transform puts them, what heron does not
//! support named in a warning with its line (an error under `--strict`), and malformed
//! files as one-line errors naming the file and line.
mod common;

use common::render::run;
use glam::{DMat4, DVec3};
use heron::geometry::ShapeKind;
use heron::scene::import::{import_scene, ImportOptions, Imported};
use heron::scene::load::{load_imported, load_scene};
use heron::settings::IntegratorKind;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A scene around `body` with a sensor, so that the body's elements are what is tested.
fn scene(body: &str) -> String {
    common::scenes::mitsuba_around(body)
}

fn import_text(text: &str) -> (tempfile::TempDir, heron::error::Result<Imported>) {
    import_with(text, &ImportOptions::default())
}

fn import_with(
    text: &str,
    o: &ImportOptions,
) -> (tempfile::TempDir, heron::error::Result<Imported>) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "scene.xml", text);
    let r = import_scene(&p, o);
    (dir, r)
}

fn get<'a>(t: &'a toml::Table, path: &str) -> &'a toml::Value {
    let mut v: Option<&toml::Value> = None;
    let mut cur = t;
    for (i, key) in path.split('.').enumerate() {
        let next = match key.parse::<usize>() {
            Ok(k) => v.and_then(|x| x.get(k)),
            Err(_) if i == 0 => cur.get(key),
            Err(_) => v.and_then(|x| x.get(key)),
        };
        v = Some(next.unwrap_or_else(|| panic!("no {path} in {t:#?}")));
        if let Some(tt) = v.unwrap().as_table() {
            cur = tt;
        }
    }
    v.unwrap()
}

fn f(v: &toml::Value) -> f64 {
    v.as_float().or(v.as_integer().map(|i| i as f64)).unwrap()
}

fn v3(v: &toml::Value) -> DVec3 {
    let a = v.as_array().unwrap();
    DVec3::new(f(&a[0]), f(&a[1]), f(&a[2]))
}

#[test]
fn the_cornell_box_as_mitsuba_xml_renders_the_pixels_of_heron_s_own_file() {
    let xml = load_scene(&repo().join("scenes/mitsuba/cornell-box.xml")).unwrap();
    let toml = load_scene(&repo().join("scenes/cornell-box.toml")).unwrap();
    // Mitsuba's max_depth 8 counts the emitter's vertex: heron's 7, as the TOML says.
    assert_eq!(xml.settings.max_depth, toml.settings.max_depth);
    assert_eq!(xml.settings.integrator, IntegratorKind::Path);
    assert_eq!((xml.camera.width, xml.camera.height), (256, 256));
    assert!(
        (xml.camera.d - toml.camera.d).abs() < 1e-6,
        "{} {}",
        xml.camera.d,
        toml.camera.d
    );
    let mut a = xml;
    let mut b = toml;
    a.camera = a.camera.resized(24, 24).unwrap();
    b.camera = b.camera.resized(24, 24).unwrap();
    let fa = run(&a, IntegratorKind::Path, 8, 3);
    let fb = run(&b, IntegratorKind::Path, 8, 3);
    // The same quads to f32 rounding, the same materials and light: the same samples.
    assert_eq!(fa.xyz, fb.xyz);
}

#[test]
fn sensor_film_sampler_and_integrator_convert_with_mitsuba_s_conventions() {
    let text = r#"<scene version="3.0.0">
    <default name="spp" value="32"/>
    <integrator type="volpath"><integer name="max_depth" value="-1"/><integer name="rr_depth" value="5"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world">
            <lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/><integer name="seed" value="7"/></sampler>
        <film type="hdrfilm"><integer name="width" value="300"/><integer name="height" value="200"/><rfilter type="box"/></film>
    </sensor>
</scene>"#;
    let (_d, r) = import_text(text);
    let t = r.unwrap().table();
    assert_eq!(v3(get(&t, "camera.eye")), DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(v3(get(&t, "camera.look_at")), DVec3::new(1.0, 2.0, 2.0));
    assert_eq!(v3(get(&t, "camera.up")), DVec3::Y);
    // fov_axis x (Mitsuba's default): the horizontal field is 60°, heron's d is the
    // distance to an image plane of height 1, width 1.5.
    let d = f(get(&t, "camera.d"));
    let fov_x = 2.0 * (0.75 / d).atan();
    assert!(
        (fov_x.to_degrees() - 60.0).abs() < 1e-9,
        "{}",
        fov_x.to_degrees()
    );
    assert_eq!(get(&t, "render.spp").as_integer(), Some(32));
    assert_eq!(get(&t, "render.seed").as_integer(), Some(7));
    assert_eq!(get(&t, "render.integrator").as_str(), Some("path"));
    assert_eq!(
        get(&t, "render.max_depth").as_integer(),
        Some(heron::scene::import::UNBOUNDED_DEPTH)
    );
    assert_eq!(get(&t, "render.rr_depth").as_integer(), Some(4));

    // fov_axis y, and a focal length (36 mm along the longer side of the image, as
    // Mitsuba 3.9 computes its x_fov), and -D overriding a default.
    for (fov, axis, want_tan_y) in [
        (
            "<float name=\"fov\" value=\"30\"/>",
            "y",
            (15f64).to_radians().tan(),
        ),
        (
            "<string name=\"focal_length\" value=\"50mm\"/>",
            "x",
            18.0 / 50.0 / 1.5,
        ),
    ] {
        let text = text.replace(
            "<float name=\"fov\" value=\"60\"/>",
            &format!("{fov}<string name=\"fov_axis\" value=\"{axis}\"/>"),
        );
        let mut o = ImportOptions::default();
        o.defines.insert("spp".into(), "9".into());
        let (_d, r) = import_with(&text, &o);
        let t = r.unwrap().table();
        let tan_y = 0.5 / f(get(&t, "camera.d"));
        assert!(
            (tan_y - want_tan_y).abs() < 1e-12,
            "{fov}: {tan_y} vs {want_tan_y}"
        );
        assert_eq!(get(&t, "render.spp").as_integer(), Some(9));
    }
}

/// Mitsuba measures a focal length's field of view on the diagonal of 36 × 24 mm film,
/// whatever the image's aspect ratio (src/render/sensor.cpp, `parse_fov`): the image's
/// half-diagonal on a plane at distance 1 is half of 43.27 mm over the focal length.
/// heron once took 36 mm along the longer side, which agrees only at 3:2 (issue 38 #7).
#[test]
fn a_focal_length_spans_the_film_diagonal_at_every_aspect_ratio() {
    for (w, h) in [(128, 128), (400, 300), (320, 180), (180, 320), (300, 200)] {
        for (focal, mm) in [
            ("", 50.0),
            ("<string name=\"focal_length\" value=\"35mm\"/>", 35.0),
        ] {
            let text = format!(
                r#"<scene version="3.0.0"><sensor type="perspective">{focal}
                <film type="hdrfilm"><integer name="width" value="{w}"/><integer name="height" value="{h}"/><rfilter type="box"/></film>
                </sensor></scene>"#
            );
            let (_d, r) = import_text(&text);
            let t = r.unwrap().table();
            let d = f(get(&t, "camera.d"));
            // heron's image plane is 1 high and w/h wide at distance d.
            let half_diag = 0.5 * (1.0 + (w as f64 / h as f64).powi(2)).sqrt() / d;
            let want = (36f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm);
            // d is written with 12 significant digits.
            assert!(
                (half_diag - want).abs() < 1e-10,
                "{w}×{h}, {mm} mm: tan of half the diagonal field {half_diag}, want {want}"
            );
        }
    }
    // fov_axis is read in any case, "smaller" of a square image is x (as Mitsuba), and
    // both fov and focal_length is refused as Mitsuba refuses it.
    let sensor = |inner: &str| {
        format!(
            r#"<scene version="3.0.0"><sensor type="perspective">{inner}
            <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/><rfilter type="box"/></film>
            </sensor></scene>"#
        )
    };
    let tan_y = |inner: &str| {
        let (_d, r) = import_text(&sensor(inner));
        0.5 / f(get(&r.unwrap().table(), "camera.d"))
    };
    let t30 = (15f64).to_radians().tan();
    let y = tan_y(r#"<float name="fov" value="30"/><string name="fov_axis" value="Y"/>"#);
    assert!((y - t30).abs() < 1e-12, "{y}");
    let y = tan_y(r#"<float name="fov" value="30"/><string name="fov_axis" value="smaller"/>"#);
    assert!((y - t30).abs() < 1e-12, "{y}");
    let y = tan_y(r#"<float name="fov" value="30"/><string name="fov_axis" value="larger"/>"#);
    assert!((y - t30 / 2.0).abs() < 1e-12, "{y}");
    let (_d, r) = import_text(&sensor(
        r#"<float name="fov" value="30"/><string name="focal_length" value="35mm"/>"#,
    ));
    let e = r
        .expect_err("fov and focal_length together are refused")
        .to_string();
    assert!(e.contains("expected fov or focal_length, not both"), "{e}");
}

#[test]
fn bsdfs_convert_to_heron_materials_and_say_what_changes() {
    let body = r#"
    <bsdf type="twosided" id="wall"><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf></bsdf>
    <bsdf type="dielectric" id="glass"><string name="int_ior" value="bk7"/></bsdf>
    <bsdf type="dielectric" id="resin"><float name="int_ior" value="1.55"/><float name="ext_ior" value="1.33"/></bsdf>
    <bsdf type="roughdielectric" id="frosted"><float name="alpha" value="0.2"/><string name="distribution" value="ggx"/><string name="int_ior" value="acrylic glass"/></bsdf>
    <bsdf type="conductor" id="gold"><string name="material" value="Au"/></bsdf>
    <bsdf type="conductor" id="mirror"/>
    <bsdf type="roughconductor" id="brushed"><string name="material" value="Al"/><float name="alpha" value="0.3"/></bsdf>
    <bsdf type="conductor" id="custom"><float name="eta" value="0.2"/><float name="k" value="3.1"/></bsdf>
    <bsdf type="roughplastic" id="plastic"><rgb name="diffuse_reflectance" value="0.5, 0.5, 0.5"/><float name="alpha" value="0.1"/></bsdf>
    <shape type="sphere"><ref id="wall"/></shape>
    <shape type="sphere"><ref id="glass"/></shape>
    <shape type="sphere"><ref id="resin"/></shape>
    <shape type="sphere"><ref id="frosted"/></shape>
    <shape type="sphere"><ref id="gold"/></shape>
    <shape type="sphere"><ref id="mirror"/></shape>
    <shape type="sphere"><ref id="brushed"/></shape>
    <shape type="sphere"><ref id="custom"/></shape>
    <shape type="sphere"><ref id="plastic"/></shape>
    <shape type="sphere"/>
"#;
    let (_d, r) = import_text(&scene(body));
    let imp = r.unwrap();
    let t = &imp.table();
    assert_eq!(get(t, "materials.wall.type").as_str(), Some("lambertian"));
    assert_eq!(
        v3(get(t, "materials.wall.rho_d")),
        DVec3::new(0.2, 0.4, 0.6)
    );
    // Named Mitsuba glasses heron has in its catalogue keep their dispersion.
    assert_eq!(get(t, "materials.glass.ior").as_str(), Some("N-BK7"));
    assert_eq!(f(get(t, "materials.glass.outside_ior")), 1.000277);
    assert_eq!(f(get(t, "materials.resin.ior")), 1.55);
    assert_eq!(f(get(t, "materials.resin.outside_ior")), 1.33);
    assert_eq!(f(get(t, "materials.frosted.ior")), 1.49);
    assert_eq!(f(get(t, "materials.frosted.roughness")), 0.2);
    assert_eq!(get(t, "materials.gold.metal").as_str(), Some("Au"));
    assert_eq!(get(t, "materials.mirror.type").as_str(), Some("mirror"));
    assert_eq!(f(get(t, "materials.brushed.roughness")), 0.3);
    assert_eq!(f(get(t, "materials.custom.metal.k")), 3.1);
    // Plastic → coated: polypropylene's 1.49 relative to air, Mitsuba's α, and its
    // default nonlinear = false.
    assert_eq!(get(t, "materials.plastic.type").as_str(), Some("coated"));
    assert!((f(get(t, "materials.plastic.ior")) - 1.49 / 1.000277).abs() < 1e-9);
    assert_eq!(f(get(t, "materials.plastic.roughness")), 0.1);
    assert_eq!(get(t, "materials.plastic.nonlinear").as_bool(), Some(false));
    assert_eq!(
        v3(get(t, "materials.plastic.reflectance")),
        DVec3::splat(0.5)
    );
    // A shape without a BSDF gets Mitsuba's default, diffuse 0.5.
    assert_eq!(
        get(t, "shapes.9.material").as_str(),
        Some("mitsuba-default-diffuse")
    );
    assert_eq!(f(get(t, "materials.mitsuba-default-diffuse.rho_d")), 0.5);
    // What changes is said, with the line: bk7's dispersion, Beckmann read as GGX on the
    // rough conductor and the rough plastic (Mitsuba's default distribution).
    let w: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    let has = |s: &str, line: u32| {
        imp.warnings
            .iter()
            .any(|d| d.message.contains(s) && d.line == line)
    };
    assert!(has("\"N-BK7\", with its dispersion", 9), "{w:#?}");
    assert!(
        has("distribution \"beckmann\" (Mitsuba's default)", 14),
        "{w:#?}"
    );
    assert!(
        has("distribution \"beckmann\" (Mitsuba's default)", 16),
        "{w:#?}"
    );
    assert!(!w.iter().any(|m| m.contains("glossy")), "{w:#?}");
    // The scene loads: every table is one heron renders.
    load_imported(&imp).unwrap();
}

#[test]
fn shapes_and_emitters_land_where_their_transforms_put_them() {
    let body = r#"
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="3"/><rotate x="1" angle="90"/><translate y="4"/></transform>
        <emitter type="area"><rgb name="radiance" value="5, 6, 7"/></emitter>
    </shape>
    <shape type="cube"><transform name="to_world"><translate x="10"/></transform></shape>
    <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/>
        <transform name="to_world"><scale value="2"/><translate z="1"/></transform></shape>
    <shape type="disk"><transform name="to_world"><translate z="-3"/></transform></shape>
    <emitter type="point"><point name="position" value="0, 5, 0"/><rgb name="intensity" value="10"/></emitter>
    <emitter type="directional"><vector name="direction" value="0, -1, 0"/><spectrum name="irradiance" value="2"/></emitter>
    <emitter type="constant"><rgb name="radiance" value="0.1, 0.2, 0.3"/></emitter>
"#;
    let (_d, r) = import_text(&scene(body));
    let imp = r.unwrap();
    let t = &imp.table();
    // The rectangle [-1, 1]² scaled, turned so its normal (+z) points down (−y), lifted.
    let o = v3(get(t, "shapes.0.origin"));
    let (e1, e2) = (v3(get(t, "shapes.0.edge1")), v3(get(t, "shapes.0.edge2")));
    assert_eq!(o, DVec3::new(-2.0, 4.0, -3.0));
    assert_eq!(e1, DVec3::new(4.0, 0.0, 0.0));
    assert_eq!(e2, DVec3::new(0.0, 0.0, 6.0));
    assert!(e1.cross(e2).normalize().abs_diff_eq(-DVec3::Y, 1e-12));
    assert_eq!(v3(get(t, "shapes.0.emission")), DVec3::new(5.0, 6.0, 7.0));
    // Six outward faces of the cube around x = 10.
    for k in 1..=6 {
        let s = get(t, &format!("shapes.{k}")).as_table().unwrap();
        let (o, e1, e2) = (v3(&s["origin"]), v3(&s["edge1"]), v3(&s["edge2"]));
        let centre = o + 0.5 * (e1 + e2);
        let n = e1.cross(e2).normalize();
        assert!(
            (centre - DVec3::new(10.0, 0.0, 0.0)).dot(n) > 0.99,
            "face {k} faces inward"
        );
    }
    // The sphere: centre and radius through the uniform scale, then the translation.
    assert_eq!(v3(get(t, "shapes.7.center")), DVec3::new(2.0, 0.0, 1.0));
    assert_eq!(f(get(t, "shapes.7.radius")), 1.0);
    // The disk: a fan of DISK_SEGMENTS triangles at z = −3, facing +z.
    let n = heron::scene::import::DISK_SEGMENTS;
    let fan: Vec<_> = (8..8 + n).map(|k| get(t, &format!("shapes.{k}"))).collect();
    assert!(fan.iter().all(|s| s["type"].as_str() == Some("triangle")));
    let tri = fan[0]["vertices"].as_array().unwrap();
    let (a, b, c) = (v3(&tri[0]), v3(&tri[1]), v3(&tri[2]));
    assert_eq!(a, DVec3::new(0.0, 0.0, -3.0));
    assert!((b - a).cross(c - a).z > 0.0);
    let area: f64 = fan
        .iter()
        .map(|s| {
            let v = s["vertices"].as_array().unwrap();
            let (a, b, c) = (v3(&v[0]), v3(&v[1]), v3(&v[2]));
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    assert!((area / std::f64::consts::PI - 1.0).abs() < 5e-4, "{area}");
    assert_eq!(get(t, "lights.0.type").as_str(), Some("point"));
    assert_eq!(v3(get(t, "lights.0.position")), DVec3::new(0.0, 5.0, 0.0));
    assert_eq!(f(get(t, "lights.0.intensity")), 10.0);
    assert_eq!(get(t, "lights.1.type").as_str(), Some("directional"));
    assert_eq!(f(get(t, "lights.1.radiance")), 2.0);
    assert_eq!(v3(get(t, "background")), DVec3::new(0.1, 0.2, 0.3));
    let scene = load_imported(&imp).unwrap();
    assert_eq!(scene.shapes.len(), 8 + n);
}

/// A tetrahedron as OBJ and as binary PLY: the same mesh through the same `to_world`.
#[test]
fn obj_and_ply_meshes_take_the_transform() {
    let dir = tempfile::tempdir().unwrap();
    let v = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let faces = [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut obj = String::new();
    for p in v {
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    for t in faces {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    std::fs::create_dir(dir.path().join("meshes")).unwrap();
    std::fs::write(dir.path().join("meshes/tet.obj"), obj).unwrap();
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
    for p in v {
        for c in p {
            ply.extend(c.to_le_bytes());
        }
    }
    for t in faces {
        ply.push(3);
        for i in t {
            ply.extend((i as i32).to_le_bytes());
        }
    }
    std::fs::write(dir.path().join("meshes/tet.ply"), ply).unwrap();
    let tf = r#"<transform name="to_world"><scale value="2"/><rotate z="1" angle="30"/><translate x="1" y="2" z="3"/></transform>"#;
    let xml = scene(&format!(
        r#"<shape type="obj"><string name="filename" value="meshes/tet.obj"/>{tf}</shape>
    <shape type="ply"><string name="filename" value="meshes/tet.ply"/>{tf}</shape>"#
    ));
    let p = write(dir.path(), "scene.xml", &xml);
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    assert_eq!(
        get(&imp.table(), "shapes.0.file").as_str(),
        Some("meshes/tet.obj")
    );
    let scene = load_imported(&imp).unwrap();
    let want = DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0))
        * DMat4::from_rotation_z(30f64.to_radians())
        * DMat4::from_scale(DVec3::splat(2.0));
    let mut meshes = scene.shapes.iter().map(|s| match &s.kind {
        ShapeKind::Mesh(m) => m.clone(),
        other => panic!("{other:?}"),
    });
    let (a, b) = (meshes.next().unwrap(), meshes.next().unwrap());
    assert_eq!(a.positions, b.positions);
    assert_eq!(a.indices, b.indices);
    // Every vertex is the transform of one of the file's vertices, and each is there.
    assert_eq!(a.positions.len(), v.len());
    for q in v {
        let w = want.transform_point3(DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64));
        assert!(
            a.positions
                .iter()
                .any(|p| (p.as_dvec3() - w).length() < 1e-5),
            "{w} not among {:?}",
            a.positions
        );
    }
    // heron convert writes the mesh path relative to the TOML's folder, and the TOML
    // loads to the same meshes.
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let text = imp.to_toml(&out);
    assert!(text.contains("file = \"../meshes/tet.obj\""), "{text}");
    let toml_path = write(&out, "scene.toml", &text);
    let again = load_scene(&toml_path).unwrap();
    match &again.shapes[1].kind {
        ShapeKind::Mesh(m) => assert_eq!(m.positions, b.positions),
        other => panic!("{other:?}"),
    }
    // A transform that is not an affine 4×4 matrix is an error at its key.
    for (rows, want) in [
        (
            "[[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
            "shapes[0].transform: expected four rows of four finite numbers",
        ),
        (
            "[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]",
            "the last [0, 0, 0, 1]",
        ),
        (
            "[[0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]",
            "expected an invertible matrix",
        ),
    ] {
        let text = format!(
            "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n[materials.m]\ntype = \"lambertian\"\nrho_d = 0.5\n[[shapes]]\ntype = \"mesh\"\nfile = \"../meshes/tet.ply\"\nmaterial = \"m\"\ntransform = {rows}\n"
        );
        let p = write(&out, "bad.toml", &text);
        let e = load_scene(&p).unwrap_err().to_string();
        assert!(e.contains(want) && e.contains("bad.toml"), "{e}");
    }
}

#[test]
fn unsupported_input_is_named_with_its_line_and_strict_makes_it_an_error() {
    let body = r#"
    <shape type="sphere">
        <bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance"/></bsdf>
    </shape>
    <emitter type="sunsky"/>
    <shape type="bsplinecurve"/>
    <shape type="sphere"><float name="nonsense" value="1"/></shape>
"#;
    let (_d, r) = import_text(&scene(body));
    let imp = r.unwrap();
    let lines: Vec<(u32, &str)> = imp
        .warnings
        .iter()
        .map(|w| (w.line, w.message.as_str()))
        .collect();
    let has = |line: u32, s: &str| lines.iter().any(|(l, m)| *l == line && m.contains(s));
    assert!(
        has(
            9,
            "texture \"mesh_attribute\" is not supported (bitmap and checkerboard are)"
        ),
        "{lines:#?}"
    );
    assert!(has(11, "emitter \"sunsky\" is not supported"), "{lines:#?}");
    assert!(
        has(12, "shape \"bsplinecurve\" is not supported"),
        "{lines:#?}"
    );
    assert!(has(13, "parameter \"nonsense\""), "{lines:#?}");
    assert!(imp.warnings[0]
        .to_string()
        .starts_with(&format!("{}: line 9: ", imp.source.display())));
    let strict = ImportOptions {
        strict: true,
        ..Default::default()
    };
    let (_d, r) = import_with(&scene(body), &strict);
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("scene.xml: line 9: ") && e.contains("mesh_attribute"),
        "{e}"
    );
}

#[test]
fn malformed_files_are_one_line_errors_with_file_and_line() {
    let cases: &[(&str, &str)] = &[
        ("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>\n", "line 3: malformed XML"),
        (&scene("<shape type=\"sphere\"><ref id=\"nowhere\"/></shape>"), "line 7: <ref id=\"nowhere\">: no element has the id \"nowhere\""),
        (&scene("<shape type=\"sphere\"><float name=\"radius\" value=\"one\"/></shape>"), "line 7: <float name=\"radius\">: value: expected a finite number, got \"one\""),
        (&scene("<shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>"), "$r is not defined"),
        (&scene("<shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"1\" y=\"2\"/></transform></shape>"), "heron's spheres take a uniform scale only"),
        (&scene("<shape type=\"serialized\"/>"), "line 7: <shape type=\"serialized\">: expected <string name=\"filename\""),
        (&scene("<shape type=\"serialized\"><string name=\"filename\" value=\"missing.serialized\"/><integer name=\"shape_index\" value=\"-1\"/></shape>"), "shape_index: expected an integer ≥ 0, got -1"),
        (&scene("<shape type=\"serialized\"><string name=\"filename\" value=\"missing.serialized\"/></shape>"), "cannot read the mesh file"),
        (&scene("<bsdf type=\"conductor\" id=\"m\"><string name=\"material\" value=\"Unobtainium\"/></bsdf><shape type=\"sphere\"><ref id=\"m\"/></shape>"), "expected one of the metals heron tabulates (Ag, Al, Au, Cu)"),
        (&scene("<bsdf type=\"dielectric\" id=\"g\"><string name=\"int_ior\" value=\"glass\"/></bsdf><shape type=\"sphere\"><ref id=\"g\"/></shape>"), "int_ior: expected a number or one of Mitsuba's named indices"),
        ("<scene version=\"3.0.0\"><shape type=\"sphere\"/></scene>", "expected a <sensor type=\"perspective\">"),
        ("<mitsuba/>", "expected the root element <scene>"),
        (&scene("<shape type=\"obj\"><string name=\"filename\" value=\"missing.obj\"/></shape>"), "cannot read the mesh file"),
        (&scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:0.2, 380:0.5\"/></bsdf></shape>"), "line 7: <spectrum name=\"reflectance\">: value: expected increasing wavelengths, got 380 nm after 400 nm"),
        (&scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:0.2, 500\"/></bsdf></shape>"), "value: expected wavelength:value pairs, got \"500\""),
        (&scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" filename=\"missing.spd\"/></bsdf></shape>"), "cannot read the spectrum file"),
        (&scene("<shape type=\"sphere\"><emitter type=\"area\"><spectrum type=\"blackbody\" name=\"radiance\"><float name=\"temperature\" value=\"-5\"/></spectrum></emitter></shape>"), "temperature: expected kelvin within [100, 1000000], got -5"),
        (&scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum type=\"blackbody\" name=\"reflectance\"><float name=\"temperature\" value=\"3000\"/></spectrum></bsdf></shape>"), "a blackbody is an emission spectrum"),
    ];
    for (text, want) in cases {
        let (_d, r) = import_text(text);
        let e = match r {
            Err(e) => e.to_string(),
            Ok(imp) => load_imported(&imp)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default(),
        };
        assert!(e.contains(want), "want {want:?}, got {e:?}\nfor {text}");
        assert!(!e.contains('\n'), "{e}");
        assert!(
            e.contains("scene.xml")
                || e.contains("missing.obj")
                || e.contains("missing.serialized"),
            "{e}"
        );
    }
}

#[test]
fn includes_are_spliced_and_a_cycle_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "materials.xml",
        r#"<scene version="3.0.0"><bsdf type="diffuse" id="grey"><float name="reflectance" value="0.25"/></bsdf></scene>"#,
    );
    let p = write(
        dir.path(),
        "scene.xml",
        &scene("<include filename=\"materials.xml\"/><shape type=\"sphere\"><ref id=\"grey\"/></shape>"),
    );
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    assert_eq!(f(get(&imp.table(), "materials.grey.rho_d")), 0.25);
    let p = write(
        dir.path(),
        "loop.xml",
        &scene("<include filename=\"loop.xml\"/>"),
    );
    let e = import_scene(&p, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("includes nested more than"), "{e}");
}

/// Files are looked up as Mitsuba 3's resolver does (issue 38, #2): in the `<path>`
/// folders (the last declared first), then the main scene's folder, and only then the
/// folder of an included file that names them; an include is looked for in the
/// including file's folder, then the same way.
#[test]
fn files_are_found_through_path_folders_and_the_main_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("assets/meshes")).unwrap();
    std::fs::create_dir_all(d.join("parts")).unwrap();
    std::fs::create_dir_all(d.join("other")).unwrap();
    let tri = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    write(&d.join("assets/meshes"), "tri.ply", tri);
    // The same name in the included file's own folder loses to the <path> folder.
    write(
        &d.join("parts"),
        "tri.ply",
        &tri.replace("0 1 0\n3", "0 2 0\n3"),
    );
    write(d, "grey.spd", "400 0.25\n700 0.25\n");
    // The included file names a mesh through <path> and a spectrum in the main folder;
    // it is itself found through <path>.
    write(
        &d.join("other"),
        "shapes.xml",
        r#"<scene version="3.0.0"><shape type="ply"><string name="filename" value="tri.ply"/>
        <bsdf type="diffuse"><spectrum name="reflectance" filename="grey.spd"/></bsdf></shape></scene>"#,
    );
    let p = write(
        d,
        "scene.xml",
        &scene(
            r#"<path value="other"/><path value="assets/meshes"/><include filename="shapes.xml"/>"#,
        ),
    );
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    let t = imp.table();
    assert_eq!(
        get(&t, "shapes.0.file").as_str(),
        Some("assets/meshes/tri.ply")
    );
    assert_eq!(load_imported(&imp).unwrap().shapes.len(), 1);
    // A <path> that is not a folder, or not at the top: one-line errors at its line.
    for (body, want) in [
        (
            r#"<path value="missing"/>"#,
            "<path>: folder \"missing\" not found",
        ),
        (
            r#"<shape type="sphere"><path value="assets"/></shape>"#,
            "<path> must be a child of the root",
        ),
    ] {
        let p = write(d, "bad.xml", &scene(body));
        let e = import_scene(&p, &ImportOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(want) && e.contains("bad.xml") && e.lines().count() == 1,
            "{e}"
        );
    }
}

#[test]
fn heron_convert_writes_a_scene_that_renders_like_the_xml() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cornell.toml");
    let bin = env!("CARGO_BIN_EXE_heron");
    let r = Command::new(bin)
        .args(["convert", "scenes/mitsuba/cornell-box.xml", "-o"])
        .arg(&out)
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("# Converted by heron"), "{text}");
    let converted = load_scene(&out).unwrap();
    let direct = load_scene(&repo().join("scenes/mitsuba/cornell-box.xml")).unwrap();
    assert_eq!(converted.shapes.len(), direct.shapes.len());
    let (mut a, mut b) = (converted, direct);
    a.camera = a.camera.resized(16, 16).unwrap();
    b.camera = b.camera.resized(16, 16).unwrap();
    assert_eq!(
        run(&a, IntegratorKind::Path, 4, 1).xyz,
        run(&b, IntegratorKind::Path, 4, 1).xyz
    );
    // Bad flags and inputs: one-line errors, nothing written.
    let toml_scene = repo().join("scenes/cornell-box.toml");
    let xml_scene = repo().join("scenes/mitsuba/cornell-box.xml");
    let (t, x) = (toml_scene.to_str().unwrap(), xml_scene.to_str().unwrap());
    for (args, want) in [
        (vec!["convert", t, "-o", "x.toml"], "needs no conversion"),
        (
            vec!["render", t, "-o", "x.exr", "--strict"],
            "apply to scenes in another renderer's format",
        ),
        (
            vec!["convert", x, "-o", "x.toml", "-D", "novalue"],
            "expected NAME=VALUE",
        ),
    ] {
        let r = Command::new(bin)
            .args(&args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(
            !r.status.success() && err.trim().lines().count() == 1,
            "{args:?}: {err}"
        );
        assert!(err.contains(want), "{args:?}: {err}");
    }
    assert!(!dir.path().join("x.toml").exists());
}

#[test]
fn the_cornell_box_as_pbrt_v4_renders_the_pixels_of_the_mitsuba_xml() {
    let pbrt = load_scene(&repo().join("scenes/pbrt/cornell-box.pbrt")).unwrap();
    let xml = load_scene(&repo().join("scenes/mitsuba/cornell-box.xml")).unwrap();
    assert_eq!(pbrt.settings.max_depth, xml.settings.max_depth);
    assert_eq!(pbrt.shapes.len(), xml.shapes.len());
    let (mut a, mut b) = (pbrt, xml);
    // The pbrt file names no filter: pbrt-v4's default Gaussian (radius 1.5, σ 0.5);
    // the XML asks for Mitsuba's box. The pixels are compared under one of them.
    use heron::settings::PixelFilter;
    assert_eq!(
        (a.settings.filter, b.settings.filter),
        (
            PixelFilter::Gaussian {
                radius: 1.5,
                stddev: 0.5
            },
            PixelFilter::BOX
        )
    );
    b.settings.filter = a.settings.filter;
    a.camera = a.camera.resized(24, 24).unwrap();
    b.camera = b.camera.resized(24, 24).unwrap();
    assert_eq!(
        run(&a, IntegratorKind::Path, 8, 3).xyz,
        run(&b, IntegratorKind::Path, 8, 3).xyz
    );
}

fn import_pbrt(text: &str) -> (tempfile::TempDir, heron::error::Result<Imported>) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "scene.pbrt", text);
    let r = import_scene(&p, &ImportOptions::default());
    (dir, r)
}

const PBRT_CAMERA: &str = "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [ 30 ]\nFilm \"rgb\" \"integer xresolution\" [ 40 ] \"integer yresolution\" [ 20 ]\nWorldBegin\n";

/// X / Z of the image's mean: 0.87 for a grey metal under heron's white (D65) sky.
fn x_over_z(scene: &heron::scene::Scene) -> f64 {
    let film = run(scene, IntegratorKind::Path, 4, 1);
    let (x, z) = film
        .xyz
        .iter()
        .fold((0.0, 0.0), |(x, z), p| (x + p[0] as f64, z + p[2] as f64));
    x / z
}

/// pbrt's `rgb eta`/`rgb k` and Mitsuba's `<rgb>`/`<spectrum>` eta and k keep every
/// channel (issue 38, #8 and #12: pbrt's rgb once kept only its first number, a grey
/// metal; Mitsuba's were refused). Gold's RGB index (pbrt-v4's and Mitsuba's own
/// example values) fills the view as a smooth metal under a white sky: it reflects red
/// far more than blue, X / Z ≈ 1.7 against 0.87 for any grey metal.
#[test]
fn rgb_and_spectral_metal_indices_keep_their_colour() {
    let quad = "Shape \"trianglemesh\" \"point3 P\" [ -4 -4 0  4 -4 0  4 4 0  -4 4 0 ] \"integer indices\" [ 0 1 2  0 2 3 ]\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n";
    for (eta, k, n_toml) in [
        (
            "\"rgb eta\" [ 0.143 0.374 1.442 ]",
            "\"rgb k\" [ 3.983 2.385 1.603 ]",
            "[0.143, 0.374, 1.442]",
        ),
        (
            "\"spectrum eta\" [ 300 1.442 450 1.442 550 0.374 650 0.143 900 0.143 ]",
            "\"spectrum k\" [ 300 1.603 450 1.603 550 2.385 650 3.983 900 3.983 ]",
            "samples",
        ),
    ] {
        let text = format!("{PBRT_CAMERA}Material \"conductor\" {eta} {k}\n{quad}");
        let (_d, r) = import_pbrt(&text);
        let imp = r.unwrap();
        let n = get(&imp.table(), "materials.conductor-1.metal.n").to_string();
        assert!(
            n.replace(' ', "").contains(&n_toml.replace(' ', "")),
            "{eta}: n = {n}"
        );
        let ratio = x_over_z(&load_imported(&imp).unwrap());
        assert!(ratio > 1.4, "{eta}: X/Z {ratio}");
    }
    // Numbers stay a constant index (a grey metal), as before.
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Material \"conductor\" \"float eta\" 0.143 \"float k\" 3.983\n{quad}"
    ));
    let ratio = x_over_z(&load_imported(&r.unwrap()).unwrap());
    assert!((ratio - 0.87).abs() < 0.02, "grey metal X/Z {ratio}");

    // Mitsuba: <rgb> and <spectrum> eta and k.
    let xml = |eta: &str, k: &str| {
        format!(
            r#"<scene version="3.0.0">
            <sensor type="perspective"><float name="fov" value="30"/>
                <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="20"/><rfilter type="box"/></film>
            </sensor>
            <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
            <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform>
                <bsdf type="conductor">{eta}{k}</bsdf></shape>
            </scene>"#
        )
    };
    for (eta, k) in [
        (
            r#"<rgb name="eta" value="0.143, 0.374, 1.442"/>"#,
            r#"<rgb name="k" value="3.983, 2.385, 1.603"/>"#,
        ),
        (
            r#"<spectrum name="eta" value="300:1.442, 450:1.442, 550:0.374, 650:0.143, 900:0.143"/>"#,
            r#"<spectrum name="k" value="300:1.603, 450:1.603, 550:2.385, 650:3.983, 900:3.983"/>"#,
        ),
    ] {
        let (_d, r) = import_text(&xml(eta, k));
        let ratio = x_over_z(&load_imported(&r.unwrap()).unwrap());
        assert!(ratio > 1.4, "{eta}: X/Z {ratio}");
    }
    // An index that is not one: one-line errors naming the parameter.
    for (eta, k, want) in [
        (
            r#"<float name="eta" value="0"/>"#,
            "",
            "eta: expected finite values > 0",
        ),
        ("", r#"<float name="k" value="2"/>"#, "k without eta"),
        (
            r#"<rgb name="eta" value="0.2, 0.3, 0.4"/><string name="material" value="Au"/>"#,
            "",
            "not both",
        ),
    ] {
        let (_d, r) = import_text(&xml(eta, k));
        let e = r.expect_err(want).to_string();
        assert!(e.contains(want) && e.lines().count() == 1, "{e}");
    }
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Material \"conductor\" \"rgb eta\" [ 0 0 0 ] \"rgb k\" [ 1 1 1 ]\n{quad}"
    ));
    let e = r.expect_err("a zero rgb eta").to_string();
    assert!(e.contains("rgb eta") && e.contains("> 0"), "{e}");
    // In heron's own format, the same forms.
    let toml = |metal: &str| {
        format!("[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n[materials.m]\ntype = \"conductor\"\nmetal = {metal}\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n")
    };
    let dir = tempfile::tempdir().unwrap();
    let good = "{ n = [0.143, 0.374, 1.442], k = { samples = [[400, 1.6], [700, 4.0]] } }";
    load_scene(&write(dir.path(), "s.toml", &toml(good))).unwrap();
    for bad in [
        "{ n = [0.2, 0.3, -0.4], k = 1 }",
        "{ n = 0, k = [1, 2, 3] }",
        "{ n = { spectrum = \"D65\" }, k = 1 }",
    ] {
        let e = load_scene(&write(dir.path(), "s.toml", &toml(bad)))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("metal") && e.lines().count() == 1, "{bad}: {e}");
    }
}

#[test]
fn pbrt_materials_lights_and_shapes_convert_with_pbrt_s_conventions() {
    let text = format!(
        "{PBRT_CAMERA}Material \"dielectric\" \"spectrum eta\" \"glass-BK7\" \"float roughness\" [ 0.04 ]\nShape \"sphere\" \"float radius\" 0.5\nMaterial \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\"\nTranslate 2 0 0\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 2 ]\nLightSource \"point\" \"rgb I\" [ 1 2 3 ] \"point3 from\" [ 0 1 0 ]\nLightSource \"infinite\" \"rgb L\" [ 0.1 0.1 0.1 ]\n"
    );
    let (_d, r) = import_pbrt(&text);
    let imp = r.unwrap();
    let t = &imp.table();
    // fov spans the shorter axis (here the height): tan(15°) = 0.5 / d.
    assert!((0.5 / f(get(t, "camera.d")) - 15f64.to_radians().tan()).abs() < 1e-9);
    assert_eq!(get(t, "materials.dielectric-1.ior").as_str(), Some("N-BK7"));
    // pbrt remaps roughness to α = √r.
    assert!((f(get(t, "materials.dielectric-1.roughness")) - 0.2).abs() < 1e-12);
    assert_eq!(get(t, "materials.conductor-2.metal").as_str(), Some("Au"));
    // The CTM moves the triangle and the light's `from` alike.
    assert_eq!(
        v3(&get(t, "shapes.1.vertices").as_array().unwrap()[1]),
        DVec3::new(3.0, 0.0, 0.0)
    );
    assert_eq!(v3(get(t, "lights.0.position")), DVec3::new(2.0, 1.0, 0.0));
    assert_eq!(v3(get(t, "background")), DVec3::splat(0.1));
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    load_imported(&imp).unwrap();

    // Without the Scale -1 1 1, pbrt's left-handed camera mirrors the image: said.
    let (_d, r) = import_pbrt(&format!("{}Shape \"sphere\"\n", &PBRT_CAMERA[13..]));
    let imp = r.unwrap();
    assert!(
        imp.warnings
            .iter()
            .any(|w| w.line == 2 && w.message.contains("left-handed")),
        "{:?}",
        imp.warnings
    );
}

#[test]
fn pbrt_errors_and_warnings_name_the_line() {
    for (body, line, want) in [
        ("Shape \"sphere\"\nFrobnicate 1\n", 7, "unknown directive \"Frobnicate\""),
        ("NamedMaterial \"nope\"\n", 6, "no material named \"nope\""),
        ("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0\n", 6, "a [ is not closed"),
        ("Translate 1 2\n", 6, "Translate: expected 3 numbers, got 2"),
        ("Shape \"plymesh\" \"string filename\" \"a\rb.ply\"\n", 6, "a string holds the control character U+000D"),
        ("Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 5 ]\n", 6, "index 5 is not one of the 3 vertices"),
    ] {
        let (_d, r) = import_pbrt(&format!("{PBRT_CAMERA}{body}"));
        let e = r.unwrap_err().to_string();
        assert!(e.contains(&format!("scene.pbrt: line {line}: ")) && e.contains(want), "{e}");
    }
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Texture \"wood\" \"spectrum\" \"fbm\"\nShape \"curve\"\nShape \"sphere\" \"float radius\" 1 \"float zmin\" -0.5\n"
    ));
    let imp = r.unwrap();
    let has = |line: u32, s: &str| {
        imp.warnings
            .iter()
            .any(|w| w.line == line && w.message.contains(s))
    };
    assert!(
        has(6, "Texture \"wood\": class \"fbm\" is not supported"),
        "{:?}",
        imp.warnings
    );
    assert!(
        has(7, "Shape \"curve\" is not supported"),
        "{:?}",
        imp.warnings
    );
    assert!(has(8, "zmin"), "{:?}", imp.warnings);
}

/// pbrt-v4's `disk` (issue 38, #10: a staircase scene lost five area lights to it): a
/// fan, a ring with `innerradius`, a sector with `phimax`, at `height`, facing its
/// object's +z (turned by Rotate, flipped by ReverseOrientation), emitting as an area
/// light; and Mitsuba's top-level `<emitter type="area" id>` referenced from a shape
/// (#9, Mitsuba's own cbox-rgb.xml) emits as the same emitter written inside it.
#[test]
fn pbrt_disks_and_referenced_mitsuba_area_emitters_import_as_lights() {
    let n = heron::scene::import::DISK_SEGMENTS;
    let pi = std::f64::consts::PI;
    let fan = n as f64 / (2.0 * pi) * (2.0 * pi / n as f64).sin(); // polygon / circle
    for (params, extra, want_area, want_tris) in [
        ("\"float radius\" 0.5", "", 0.25 * pi * fan, n),
        (
            "\"float radius\" 0.5 \"float innerradius\" 0.2",
            "",
            (0.25 - 0.04) * pi * fan,
            2 * n,
        ),
        (
            "\"float radius\" 0.5 \"float phimax\" 180",
            "",
            0.125 * pi * fan,
            n / 2,
        ),
        (
            "\"float radius\" 0.5 \"float height\" 0.25",
            "ReverseOrientation\n",
            0.25 * pi * fan,
            n,
        ),
    ] {
        let text = format!(
            "{PBRT_CAMERA}AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 4 4 4 ]\n{extra}Translate 0 1 0\nRotate 90 1 0 0\nShape \"disk\" {params}\nAttributeEnd\n"
        );
        let (_d, r) = import_pbrt(&text);
        let imp = r.unwrap();
        assert!(imp.warnings.is_empty(), "{params}: {:?}", imp.warnings);
        let t = imp.table();
        let tris = shapes(&t);
        assert_eq!(tris.len(), want_tris, "{params}");
        let mut area = 0.0;
        for s in tris {
            assert_eq!(v3(&s["emission"]), DVec3::splat(4.0));
            let v = vertices(s);
            let c = (v[1] - v[0]).cross(v[2] - v[0]);
            area += 0.5 * c.length();
            // Rotate 90 about x turns +z to −y; the height moves the disk along it.
            let y = if extra.is_empty() { -1.0 } else { 1.0 };
            assert!(
                c.normalize().abs_diff_eq(DVec3::new(0.0, y, 0.0), 1e-9),
                "{params}: {c}"
            );
            let h = if params.contains("height") { 0.75 } else { 1.0 };
            assert!(v.iter().all(|p| (p.y - h).abs() < 1e-9), "{params}: {v:?}");
        }
        assert!(
            (area / want_area - 1.0).abs() < 1e-9,
            "{params}: area {area}, want {want_area}"
        );
        load_imported(&imp).unwrap();
    }
    for bad in [
        "\"float radius\" 0.5 \"float innerradius\" 0.5",
        "\"float phimax\" 0",
        "\"float radius\" -1",
    ] {
        let (_d, r) = import_pbrt(&format!("{PBRT_CAMERA}Shape \"disk\" {bad}\n"));
        let e = r.expect_err(bad).to_string();
        assert!(
            e.contains("line 6") && e.contains("Shape \"disk\": expected"),
            "{e}"
        );
    }

    // Mitsuba: an area emitter by reference, as written inline.
    let light = r#"<rgb name="radiance" value="3, 2, 1"/>"#;
    let referenced = scene(&format!(
        r#"<emitter type="area" id="lamp">{light}</emitter>
        <shape type="rectangle"><ref id="lamp"/><transform name="to_world"><translate y="1"/></transform></shape>
        <shape type="sphere"><ref id="lamp"/></shape>"#
    ));
    let inline = scene(&format!(
        r#"<shape type="rectangle"><emitter type="area">{light}</emitter><transform name="to_world"><translate y="1"/></transform></shape>
        <shape type="sphere"><emitter type="area">{light}</emitter></shape>"#
    ));
    let (_d, a) = import_text(&referenced);
    let (_d2, b) = import_text(&inline);
    let (a, b) = (a.unwrap(), b.unwrap());
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
    assert_eq!(a.table(), b.table());
    // Declared and never used: said, not an error.
    let (_d, r) = import_text(&scene(&format!(
        r#"<emitter type="area" id="lamp">{light}</emitter><shape type="sphere"/>"#
    )));
    let imp = r.unwrap();
    assert!(
        imp.warnings
            .iter()
            .any(|w| w.message.contains("no shape references")),
        "{:?}",
        imp.warnings
    );
}

/// pbrt's dielectric `eta` is a relative index and may be below 1 (issue 38, #13): a
/// bubble of air in water, eta 0.75, becomes index 1 inside 1.3333 outside, the same
/// relative index; 0 or less is an error at its line.
#[test]
fn a_pbrt_relative_index_below_one_keeps_its_ratio() {
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Material \"dielectric\" \"float eta\" 0.75\nShape \"sphere\"\n"
    ));
    let imp = r.unwrap();
    let t = imp.table();
    let inside = f(get(&t, "materials.dielectric-1.ior"));
    let outside = f(get(&t, "materials.dielectric-1.outside_ior"));
    // Written with 12 significant digits.
    assert!(
        (inside / outside - 0.75).abs() < 1e-10,
        "{inside} / {outside}"
    );
    assert!(inside >= 1.0 && outside >= 1.0);
    load_imported(&imp).unwrap();
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Material \"dielectric\"\n  \"float eta\" -1\nShape \"sphere\"\n"
    ));
    let e = r.expect_err("a negative eta").to_string();
    assert!(
        e.contains("line 7") && e.contains("expected a relative index > 0"),
        "{e}"
    );
}

/// Mitsuba's `moment` renders its nested integrator, pbrt's `simplepath` and
/// `randomwalk` are path tracers of the same expectation (issue 38, #5): none falls back
/// to the Whitted tracer any more.
#[test]
fn wrapping_and_simpler_integrators_become_the_path_tracer() {
    let (_d, r) = import_text(&scene(
        r#"<integrator type="moment"><integrator type="path"><integer name="max_depth" value="5"/></integrator></integrator><shape type="sphere"/>"#,
    ));
    let imp = r.unwrap();
    let t = imp.table();
    assert_eq!(get(&t, "render.integrator").as_str(), Some("path"));
    assert_eq!(get(&t, "render.max_depth").as_integer(), Some(4));
    assert!(
        imp.warnings.iter().any(|w| w
            .message
            .contains("moment: the nested integrator is rendered")),
        "{:?}",
        imp.warnings
    );
    let (_d, r) = import_text(&scene(
        r#"<integrator type="moment"/><shape type="sphere"/>"#,
    ));
    let e = r
        .expect_err("moment without a nested integrator")
        .to_string();
    assert!(e.contains("expected a nested <integrator>"), "{e}");
    for kind in ["simplepath", "randomwalk"] {
        let (_d, r) = import_pbrt(&format!(
            "Integrator \"{kind}\" \"integer maxdepth\" 3 \"bool samplelights\" true\n{PBRT_CAMERA}Shape \"sphere\"\n"
        ));
        let imp = r.unwrap();
        let t = imp.table();
        assert_eq!(
            get(&t, "render.integrator").as_str(),
            Some("path"),
            "{kind}"
        );
        assert_eq!(get(&t, "render.max_depth").as_integer(), Some(3), "{kind}");
        assert!(imp.warnings.is_empty(), "{kind}: {:?}", imp.warnings);
    }
}

/// A pbrt mesh with zero-area triangles among good ones keeps the good ones, with one
/// warning at its line; a mesh of none is dropped with a warning, not an error that
/// rejects the scene (issue 38, #13).
#[test]
fn zero_area_pbrt_triangles_are_dropped_with_a_warning() {
    let good = "0 0 0  1 0 0  0 1 0";
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Shape \"trianglemesh\" \"point3 P\" [ {good}  2 2 2  3 3 3 ] \"integer indices\" [ 0 1 2  0 3 4  1 1 2 ]\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 1 1  2 2 2 ] \"integer indices\" [ 0 1 2 ]\nShape \"sphere\"\n"
    ));
    let imp = r.unwrap();
    let t = imp.table();
    let kinds: Vec<_> = shapes(&t)
        .iter()
        .map(|s| s["type"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["triangle", "sphere"]);
    let said = |line: u32, s: &str| {
        imp.warnings
            .iter()
            .any(|w| w.line == line && w.message.contains(s))
    };
    assert!(
        said(6, "2 triangle(s) of zero area dropped (1 kept)"),
        "{:?}",
        imp.warnings
    );
    assert!(
        said(
            7,
            "1 triangle(s) of zero area dropped (the shape is dropped)"
        ),
        "{:?}",
        imp.warnings
    );
    load_imported(&imp).unwrap();
}

/// Mitsuba's `shapegroup` and `instance` (issue 38, #13), flattened: each instance
/// copies the group's shapes with its `to_world` after theirs; what Mitsuba refuses
/// (emitters in a group, nesting, an instance of anything else) is an error here too.
#[test]
fn mitsuba_instances_copy_their_shapegroup() {
    let group = r#"<shape type="shapegroup" id="pair">
        <shape type="sphere"><transform name="to_world"><translate x="1"/></transform><bsdf type="diffuse"/></shape>
        <shape type="rectangle"/>
    </shape>"#;
    let body = format!(
        r#"{group}
        <shape type="instance"><ref id="pair"/><transform name="to_world"><scale value="2"/></transform></shape>
        <shape type="instance"><ref id="pair"/><transform name="to_world"><translate y="5"/></transform></shape>"#
    );
    let (_d, r) = import_text(&scene(&body));
    let imp = r.unwrap();
    let t = imp.table();
    let s = shapes(&t);
    let kinds: Vec<_> = s.iter().map(|x| x["type"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["sphere", "quad", "sphere", "quad"]);
    // The instance's scale after the sphere's translation: centre (2, 0, 0), radius 2.
    assert_eq!(v3(&s[0]["center"]), DVec3::new(2.0, 0.0, 0.0));
    assert_eq!(f(&s[0]["radius"]), 2.0);
    assert_eq!(v3(&s[2]["center"]), DVec3::new(1.0, 5.0, 0.0));
    assert_eq!(v3(&s[3]["origin"]), DVec3::new(-1.0, 4.0, 0.0));
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    load_imported(&imp).unwrap();
    for (body, want) in [
        (
            r#"<shape type="shapegroup" id="g"><shape type="sphere"><emitter type="area"/></shape></shape><shape type="instance"><ref id="g"/></shape>"#,
            "instancing of emitters is not supported",
        ),
        (
            r#"<shape type="shapegroup" id="g"><shape type="shapegroup"/></shape><shape type="instance"><ref id="g"/></shape>"#,
            "Mitsuba forbids nesting",
        ),
        (
            r#"<shape type="sphere" id="s"/><shape type="instance"><ref id="s"/></shape>"#,
            "expected a reference to a shapegroup",
        ),
        (
            r#"<shape type="instance"/>"#,
            "expected exactly one shapegroup",
        ),
    ] {
        let (_d, r) = import_text(&scene(body));
        let e = r.expect_err(want).to_string();
        assert!(e.contains(want) && e.lines().count() == 1, "{e}");
    }
}

/// The heron shape tables of a converted scene.
fn shapes(t: &toml::Table) -> &Vec<toml::Value> {
    get(t, "shapes").as_array().unwrap()
}

fn vertices(s: &toml::Value) -> Vec<DVec3> {
    s["vertices"].as_array().unwrap().iter().map(v3).collect()
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

#[test]
fn pbrt_object_instances_are_flattened_with_pbrt_v4_s_transforms_and_materials() {
    // pbrt-v4 (src/pbrt/scene.cpp): a shape in a definition keeps the CTM at its Shape,
    // an instance the CTM at its ObjectInstance, and a copy is placed by their product;
    // the copy has the definition's material; ObjectBegin/End save and restore the state.
    let body = "AttributeBegin
Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\"
Translate 0 0 -1
ObjectBegin \"thing\"
Translate 0 1 0
Shape \"sphere\" \"float radius\" 0.5
Material \"dielectric\" \"float eta\" 1.33
Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 2 ]
ObjectEnd
Shape \"sphere\" \"float radius\" 0.25
AttributeEnd
Material \"diffuse\"
AttributeBegin
Translate 2 0 0
ObjectInstance \"thing\"
AttributeEnd
AttributeBegin
Rotate 90 0 0 1
Scale 2 2 2
ObjectInstance \"thing\"
AttributeEnd
Scale -1 1 1
ObjectInstance \"thing\"
";
    let (_d, r) = import_pbrt(&format!("{PBRT_CAMERA}{body}"));
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let t = imp.table();
    let sh = shapes(&t);
    // The definition itself gives no shape; the world's sphere after it has the CTM
    // and material of before ObjectBegin (the definition's Translate and Material end
    // at ObjectEnd); then two shapes per instance, in the instances' order.
    assert_eq!(sh.len(), 7, "{sh:#?}");
    let material = |i: usize| sh[i]["material"].as_str().unwrap();
    let sphere = |i: usize| (v3(&sh[i]["center"]), f(&sh[i]["radius"]));
    assert_eq!(sphere(0), (DVec3::new(0.0, 0.0, -1.0), 0.25));
    assert_eq!(material(0), "conductor-1");
    // The copies keep the material current at their Shape, not the instance's diffuse.
    for i in [1, 3, 5] {
        assert_eq!(material(i), "conductor-1");
        assert_eq!(sh[i]["type"].as_str(), Some("sphere"));
    }
    for i in [2, 4, 6] {
        assert_eq!(material(i), "dielectric-2");
        assert_eq!(sh[i]["type"].as_str(), Some("triangle"));
    }
    assert!(sh.iter().all(|s| s.get("emission").is_none()));
    // Instance 1: T(2,0,0) · T(0,0,-1) · T(0,1,0).
    let (c, r) = sphere(1);
    assert!(close(c, DVec3::new(2.0, 1.0, -1.0)) && r == 0.5, "{c} {r}");
    let want = [
        DVec3::new(2.0, 1.0, -1.0),
        DVec3::new(3.0, 1.0, -1.0),
        DVec3::new(2.0, 2.0, -1.0),
    ];
    assert!(
        vertices(&sh[2]).iter().zip(want).all(|(a, b)| close(*a, b)),
        "{:?}",
        vertices(&sh[2])
    );
    // Instance 2: Rz(90°) · S(2) · T(0,0,-1) · T(0,1,0): (x, y, z) → (−2y, 2x, 2z).
    let (c, r) = sphere(3);
    assert!(
        close(c, DVec3::new(-2.0, 0.0, -2.0)) && (r - 1.0).abs() < 1e-12,
        "{c} {r}"
    );
    let want = [
        DVec3::new(-2.0, 0.0, -2.0),
        DVec3::new(-2.0, 2.0, -2.0),
        DVec3::new(-4.0, 0.0, -2.0),
    ];
    assert!(
        vertices(&sh[4]).iter().zip(want).all(|(a, b)| close(*a, b)),
        "{:?}",
        vertices(&sh[4])
    );
    // Instance 3 mirrors (Scale −1 1 1): the winding is reversed so the normal is the
    // mirrored one, as pbrt-v4's transformed normal.
    let (c, r) = sphere(5);
    assert!(close(c, DVec3::new(0.0, 1.0, -1.0)) && r == 0.5, "{c} {r}");
    let want = [
        DVec3::new(0.0, 1.0, -1.0),
        DVec3::new(0.0, 2.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
    ];
    assert!(
        vertices(&sh[6]).iter().zip(want).all(|(a, b)| close(*a, b)),
        "{:?}",
        vertices(&sh[6])
    );
    let scene = load_imported(&imp).unwrap();
    assert_eq!(scene.shapes.len(), 7);

    // An instance may come before its definition (pbrt-v4 resolves the names after
    // parsing); an empty object gives nothing; a mesh's copies take the product as
    // their `transform`.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("scenes/meshes/prism60.ply"),
        dir.path().join("prism60.ply"),
    )
    .unwrap();
    let body = "Translate 1 2 3
ObjectInstance \"prism\"
Identity
ObjectBegin \"empty\"
ObjectEnd
ObjectInstance \"empty\"
ObjectBegin \"prism\"
Scale 2 2 2
Shape \"plymesh\" \"string filename\" \"prism60.ply\"
ObjectEnd
";
    let p = write(dir.path(), "scene.pbrt", &format!("{PBRT_CAMERA}{body}"));
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    let t = imp.table();
    let sh = shapes(&t);
    assert_eq!(sh.len(), 1, "{sh:#?}");
    assert_eq!(sh[0]["file"].as_str(), Some("prism60.ply"));
    let rows: Vec<Vec<f64>> = sh[0]["transform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_array().unwrap().iter().map(f).collect())
        .collect();
    assert_eq!(
        rows,
        vec![
            vec![2.0, 0.0, 0.0, 1.0],
            vec![0.0, 2.0, 0.0, 2.0],
            vec![0.0, 0.0, 2.0, 3.0],
            vec![0.0, 0.0, 0.0, 1.0],
        ]
    );
    load_imported(&imp).unwrap();
}

#[test]
fn a_pbrt_object_instanced_once_in_place_converts_to_the_shapes_written_inline() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("scenes/meshes/prism60.ply"),
        dir.path().join("prism60.ply"),
    )
    .unwrap();
    let shapes = "Material \"diffuse\" \"rgb reflectance\" [ 0.2 0.5 0.8 ]
Translate 0 -0.5 0
Shape \"sphere\" \"float radius\" 0.5
Shape \"bilinearmesh\" \"point3 P\" [ -2 -1 -2  2 -1 -2  -2 -1 2  2 -1 2 ]
Rotate 20 0 1 0
Shape \"plymesh\" \"string filename\" \"prism60.ply\"
ReverseOrientation
Shape \"trianglemesh\" \"point3 P\" [ -1 0 -1  1 0 -1  0 1 -1 ] \"integer indices\" [ 0 1 2 ]
";
    let lights = "LightSource \"point\" \"rgb I\" [ 4 4 4 ] \"point3 from\" [ 1 2 3 ]\n";
    let inline = write(
        dir.path(),
        "inline.pbrt",
        &format!("{PBRT_CAMERA}{lights}AttributeBegin\n{shapes}AttributeEnd\n"),
    );
    let instanced = write(
        dir.path(),
        "instanced.pbrt",
        &format!(
            "{PBRT_CAMERA}{lights}ObjectBegin \"o\"\n{shapes}ObjectEnd\nObjectInstance \"o\"\n"
        ),
    );
    let a = import_scene(&inline, &ImportOptions::default()).unwrap();
    let b = import_scene(&instanced, &ImportOptions::default()).unwrap();
    assert!(
        a.warnings.is_empty() && b.warnings.is_empty(),
        "{:?} {:?}",
        a.warnings,
        b.warnings
    );
    assert_eq!(shapes_len(&a), 4);
    assert_eq!(a.table(), b.table());
    // The TOML `heron convert` writes is the same but for the comment naming the source.
    let body = |i: &Imported| {
        i.to_toml(dir.path())
            .split_once('\n')
            .unwrap()
            .1
            .to_string()
    };
    assert_eq!(body(&a), body(&b));
    // And so are the pixels.
    let (mut sa, mut sb) = (load_imported(&a).unwrap(), load_imported(&b).unwrap());
    sa.camera = sa.camera.resized(16, 8).unwrap();
    sb.camera = sb.camera.resized(16, 8).unwrap();
    let (fa, fb) = (
        run(&sa, IntegratorKind::Path, 4, 1),
        run(&sb, IntegratorKind::Path, 4, 1),
    );
    assert!(fa.xyz.iter().filter(|p| p[1] > 0.0).count() > 16);
    assert_eq!(fa.xyz, fb.xyz);
}

fn shapes_len(i: &Imported) -> usize {
    shapes(&i.table()).len()
}

#[test]
fn pbrt_object_errors_name_the_file_and_line() {
    for (body, line, want) in [
        ("ObjectInstance \"nope\"\n", 6, "ObjectInstance: no object named \"nope\" was defined"),
        ("ObjectBegin \"a\"\nAttributeBegin\nObjectBegin \"b\"\n", 8, "ObjectBegin \"b\": inside the definition of ObjectBegin \"a\" (line 6); object definitions do not nest"),
        ("ObjectEnd\n", 6, "ObjectEnd without a matching ObjectBegin"),
        ("ObjectBegin \"a\"\nAttributeBegin\nAttributeEnd\n", 6, "ObjectBegin \"a\" is not closed by an ObjectEnd before the end of the file"),
        ("ObjectBegin \"a\"\nShape \"sphere\"\n", 6, "ObjectBegin \"a\" is not closed by an ObjectEnd before the end of the file"),
        ("ObjectBegin \"a\"\nObjectInstance \"a\"\n", 7, "ObjectInstance \"a\": inside the definition of ObjectBegin \"a\" (line 6)"),
        ("ObjectBegin \"a\"\nObjectEnd\nObjectBegin \"a\"\n", 8, "ObjectBegin \"a\": an object of that name was defined before (line 6)"),
        ("ObjectBegin \"a\"\nAttributeBegin\nObjectEnd\n", 8, "ObjectEnd: AttributeBegin (line 7) is still open"),
        ("ObjectBegin \"a\"\nShape \"sphere\"\nObjectEnd\nScale 1 2 1\nObjectInstance \"a\"\n", 10, "ObjectInstance \"a\", the shape of line 7: Shape \"sphere\": heron's spheres take a uniform scale only"),
    ] {
        let (_d, r) = import_pbrt(&format!("{PBRT_CAMERA}{body}"));
        let e = r.unwrap_err().to_string();
        assert!(!e.contains('\n'), "{e}");
        assert!(e.contains(&format!("scene.pbrt: line {line}: ")) && e.contains(want), "{body}: {e}");
    }
    // The AttributeEnd case reports the block it meets first: the open definition.
    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}AttributeBegin\nObjectBegin \"a\"\nAttributeEnd\n"
    ));
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("scene.pbrt: line 8: AttributeEnd: ObjectBegin \"a\" (line 7) is still open"),
        "{e}"
    );

    // A definition may span an Include (spliced as text) but not an Import (pbrt-v4
    // parses an imported file with a builder of its own).
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "part.pbrt", "Shape \"sphere\"\nObjectEnd\n");
    write(
        dir.path(),
        "open.pbrt",
        "ObjectBegin \"b\"\nShape \"sphere\"\n",
    );
    let main = |how: &str| {
        format!("{PBRT_CAMERA}ObjectBegin \"a\"\n{how} \"part.pbrt\"\nObjectInstance \"a\"\n")
    };
    let p = write(dir.path(), "scene.pbrt", &main("Include"));
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    assert_eq!(shapes_len(&imp), 1);
    let p = write(dir.path(), "scene.pbrt", &main("Import"));
    let e = import_scene(&p, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("part.pbrt: line 2: ObjectEnd: ObjectBegin \"a\" (line 6 of ")
            && e.contains("was opened outside this imported file"),
        "{e}"
    );
    let p = write(
        dir.path(),
        "scene.pbrt",
        &format!("{PBRT_CAMERA}Import \"open.pbrt\"\n"),
    );
    let e = import_scene(&p, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("open.pbrt: line 1: ObjectBegin \"b\" is not closed by an ObjectEnd before the end of the imported file"), "{e}");
}

#[test]
fn pbrt_area_lights_in_an_object_warn_and_do_not_emit() {
    let body = "AreaLightSource \"diffuse\" \"rgb L\" [ 4 4 4 ]
ObjectBegin \"lamp\"
Shape \"sphere\" \"float radius\" 0.1
ObjectEnd
ObjectInstance \"lamp\"
Shape \"sphere\" \"float radius\" 0.2
";
    let text = format!("{PBRT_CAMERA}{body}");
    let (_d, r) = import_pbrt(&text);
    let imp = r.unwrap();
    assert_eq!(imp.warnings.len(), 1, "{:?}", imp.warnings);
    let w = imp.warnings[0].to_string();
    assert!(
        w.contains("scene.pbrt")
            && w.contains("line 8")
            && w.contains("area lights are not supported in object instances")
            && !w.contains('\n'),
        "{w}"
    );
    let t = imp.table();
    let sh = shapes(&t);
    assert_eq!(sh.len(), 2);
    assert!(sh[0].get("emission").is_none());
    // The area light still applies outside the definition.
    assert!(sh[1].get("emission").is_some());
    // --strict makes it an error.
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "scene.pbrt", &text);
    let strict = ImportOptions {
        strict: true,
        ..Default::default()
    };
    let e = import_scene(&p, &strict).unwrap_err().to_string();
    assert!(
        e.contains("scene.pbrt: line 8: ") && e.contains("area lights"),
        "{e}"
    );
}

/// Mitsuba's spectra: a blackbody (absolute W m⁻² sr⁻¹ nm⁻¹) becomes heron's
/// unit-luminance blackbody times its luminance, so the loaded spectrum is Planck's law
/// itself; `λ:v` pairs and `.spd` files become `samples`, zero beyond their ends as
/// Mitsuba's irregular spectra are.
#[test]
fn blackbody_tabulated_and_file_spectra_convert_to_the_same_spectra() {
    use heron::spectrum::blackbody::planck;
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "leaf.spd",
        "# a leaf\n450 0.1\n550\t0.4\n650 0.2\n",
    );
    let body = r#"
    <shape type="sphere"><float name="radius" value="0.1"/><point name="center" x="0" y="3" z="0"/>
        <emitter type="area"><spectrum type="blackbody" name="radiance"><float name="temperature" value="4000"/></spectrum></emitter>
    </shape>
    <shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" filename="leaf.spd"/></bsdf></shape>
    <shape type="sphere"><point name="center" x="2" y="0" z="0"/><bsdf type="diffuse"><spectrum name="reflectance" value="400:0.3, 700:0.9"/></bsdf></shape>"#;
    let p = write(dir.path(), "scene.xml", &scene(body));
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    assert_eq!(f(get(&imp.table(), "shapes.0.emission.blackbody")), 4000.0);
    let s = load_imported(&imp).unwrap();
    let heron::light::Light::Area(light) = &s.lights[0] else {
        panic!("{:?}", s.lights[0]);
    };
    let wl = heron::spectrum::SampledWavelengths::<4>::new([420.0, 500.0, 600.0, 780.0], [1.0; 4]);
    let l = wl.eval(&light.emission);
    for (k, &lambda) in wl.lambda.iter().enumerate() {
        let want = planck(lambda as f64, 4000.0) as f32;
        assert!(
            (l.0[k] / want - 1.0).abs() < 2e-3,
            "{lambda}: {} vs {want}",
            l.0[k]
        );
    }
    let rho = |i: usize| match &s.materials[i] {
        heron::bsdf::Material::Lambertian(m) => m.rho_d.clone(),
        other => panic!("{other:?}"),
    };
    // Materials are sorted by name; find each by its values.
    let (a, b) = (rho(0), rho(1));
    let (file, inline) = if (a.eval(550.0) - 0.4).abs() < 1e-6 {
        (a, b)
    } else {
        (b, a)
    };
    for (l, want) in [
        (450.0, 0.1),
        (500.0, 0.25),
        (550.0, 0.4),
        (650.0, 0.2),
        (440.0, 0.0),
        (700.0, 0.0),
    ] {
        assert!(
            (file.eval(l) - want).abs() < 1e-5,
            "file {l}: {}",
            file.eval(l)
        );
    }
    for (l, want) in [
        (400.0, 0.3),
        (550.0, 0.6),
        (700.0, 0.9),
        (380.0, 0.0),
        (720.0, 0.0),
    ] {
        assert!(
            (inline.eval(l) - want).abs() < 1e-5,
            "inline {l}: {}",
            inline.eval(l)
        );
    }
}

/// pbrt-v4's spectra: lights are scaled to luminance 1 (`SpectrumToPhotometric`), so a
/// blackbody or a table as `L` is heron's unit-luminance spectrum times `scale`;
/// reflectances are used as given, zero beyond their ends; a blackbody reflectance is
/// an error.
#[test]
fn pbrt_spectra_convert_as_pbrt_normalises_them() {
    use heron::spectrum::cie::spectrum_to_xyz;
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "warm.spd",
        "400 0.2\n500 0.6\n600 1.0\n700 1.2\n",
    );
    let text = format!(
        "{PBRT_CAMERA}AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" [ 3000 ] \"float scale\" [ 2 ]\nShape \"sphere\" \"float radius\" 0.1\nAttributeEnd\n\
         AttributeBegin\nTranslate 1 0 0\nAreaLightSource \"diffuse\" \"spectrum L\" \"warm.spd\"\nShape \"sphere\" \"float radius\" 0.1\nAttributeEnd\n\
         Material \"diffuse\" \"spectrum reflectance\" [ 400 0.1 700 0.7 ]\nTranslate 0 2 0\nShape \"sphere\" \"float radius\" 0.5\n"
    );
    let p = write(dir.path(), "scene.pbrt", &text);
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let t = &imp.table();
    assert_eq!(f(get(t, "shapes.0.emission.blackbody")), 3000.0);
    assert_eq!(f(get(t, "shapes.0.emission.scale")), 2.0);
    let s = load_imported(&imp).unwrap();
    let emission = |i: usize| match &s.lights[i] {
        heron::light::Light::Area(a) => a.emission.clone(),
        other => panic!("{other:?}"),
    };
    let y = |d: &heron::spectrum::DenseSpectrum| spectrum_to_xyz(d)[1];
    assert!((y(&emission(0)) - 2.0).abs() < 1e-4, "{}", y(&emission(0)));
    assert!((y(&emission(1)) - 1.0).abs() < 1e-4, "{}", y(&emission(1)));
    // The table keeps its shape: 600 nm is 5 × 400 nm.
    let e = emission(1);
    assert!((e.eval(600.0) / e.eval(400.0) - 5.0).abs() < 1e-4);
    let heron::bsdf::Material::Lambertian(m) = &s.materials[0] else {
        panic!("{:?}", s.materials);
    };
    for (l, want) in [
        (400.0, 0.1),
        (550.0, 0.4),
        (700.0, 0.7),
        (380.0, 0.0),
        (720.0, 0.0),
    ] {
        assert!(
            (m.rho_d.eval(l) - want).abs() < 1e-5,
            "{l}: {}",
            m.rho_d.eval(l)
        );
    }
    for (body, want) in [
        (
            "Material \"diffuse\" \"blackbody reflectance\" [ 3000 ]\n",
            "a blackbody is an emission spectrum",
        ),
        (
            "Material \"diffuse\" \"spectrum reflectance\" [ 500 0.1 400 0.7 ]\n",
            "wavelengths increasing",
        ),
        (
            "AreaLightSource \"diffuse\" \"spectrum L\" \"missing.spd\"\n",
            "cannot read the spectrum file",
        ),
        (
            "LightSource \"infinite\" \"string filename\" \"sky.exr\" \"rgb L\" [ 1 1 1 ]\n",
            "both \"L\" and \"filename\"",
        ),
    ] {
        let (_d, r) = import_pbrt(&format!("{PBRT_CAMERA}{body}"));
        let e = r.unwrap_err().to_string();
        assert!(
            e.contains("scene.pbrt: line 6: ") && e.contains(want),
            "{e}"
        );
    }
}

/// pbrt-v4's spectral film becomes heron's spectral bins (`[render] spectral_bins`): its
/// 16 buckets over 360–830 nm by default are heron's bins exactly; another range warns.
#[test]
fn a_pbrt_spectral_film_sets_heron_s_spectral_bins() {
    let cam = PBRT_CAMERA.replace("Film \"rgb\"", "Film \"spectral\"");
    let (_d, r) = import_pbrt(&format!("{cam}Shape \"sphere\"\n"));
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    assert_eq!(
        get(&imp.table(), "render.spectral_bins").as_integer(),
        Some(16)
    );
    assert_eq!(load_imported(&imp).unwrap().settings.spectral_bins, 16);
    let cam = PBRT_CAMERA.replace(
        "Film \"rgb\"",
        "Film \"spectral\" \"integer nbuckets\" [ 8 ] \"float lambdamin\" [ 400 ]",
    );
    let (_d, r) = import_pbrt(&format!("{cam}Shape \"sphere\"\n"));
    let imp = r.unwrap();
    assert_eq!(
        get(&imp.table(), "render.spectral_bins").as_integer(),
        Some(8)
    );
    assert!(
        imp.warnings
            .iter()
            .any(|w| w.message.contains("not 400–830 nm")),
        "{:?}",
        imp.warnings
    );
    let cam = PBRT_CAMERA.replace(
        "Film \"rgb\"",
        "Film \"spectral\" \"integer nbuckets\" [ 0 ]",
    );
    let (_d, r) = import_pbrt(&format!("{cam}Shape \"sphere\"\n"));
    assert!(r
        .unwrap_err()
        .to_string()
        .contains("nbuckets: expected a whole number from 1 to 470, got 0"));
}

/// Mitsuba's `bitmap` as a diffuse reflectance (nested or by `ref`) becomes a textured
/// `lambertian`, its file relative to the converted TOML (a bitmap with `to_uv`, a
/// `[textures]` table with the transform); settings heron does not share warn.
#[test]
fn a_mitsuba_bitmap_reflectance_converts_to_a_texture() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("tex")).unwrap();
    image::RgbImage::from_pixel(4, 2, image::Rgb([128, 64, 32]))
        .save(dir.path().join("tex/wood.png"))
        .unwrap();
    let body = r#"
    <texture type="bitmap" id="wood"><string name="filename" value="tex/wood.png"/><string name="wrap_mode" value="mirror"/></texture>
    <shape type="rectangle"><bsdf type="diffuse"><ref id="wood" name="reflectance"/></bsdf></shape>
    <shape type="sphere"><bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="tex/wood.png"/>
        <transform name="to_uv"><scale x="2"/></transform></texture></bsdf></shape>"#;
    let p = write(dir.path(), "scene.xml", &scene(body));
    let imp = import_scene(&p, &ImportOptions::default()).unwrap();
    let t = imp.table();
    let textured: Vec<&str> = get(&t, "materials")
        .as_table()
        .unwrap()
        .values()
        .filter_map(|m| m.get("texture").and_then(|t| t.as_str()))
        .collect();
    assert_eq!(textured, ["tex/wood.png"]);
    assert_eq!(
        get(&t, "textures.texture.to_uv").to_string(),
        "[[2.0, 0.0, 0.0], [0.0, 1.0, 0.0]]"
    );
    let has = |s: &str| imp.warnings.iter().any(|w| w.message.contains(s));
    assert!(
        has("wrap_mode \"mirror\": heron's textures are repeat"),
        "{:?}",
        imp.warnings
    );
    assert!(!has("to_uv"), "{:?}", imp.warnings);
    let s = load_imported(&imp).unwrap();
    assert!(s.materials.iter().all(|m| m.is_textured()));
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let t = imp.to_toml(&out);
    assert!(t.contains("texture = \"../tex/wood.png\""), "{t}");
    assert!(t.contains("file = \"../tex/wood.png\""), "{t}");
}

/// Mitsuba's `checkerboard` (colours or nested textures, `to_uv`) and pbrt-v4's
/// `Texture` directives of each kind become `[textures]` tables, their uv mappings
/// rewritten as heron's `to_uv` (pbrt's image v flipped, its checkerboard halved).
#[test]
fn checkerboards_and_pbrt_textures_convert_to_texture_tables() {
    let body = r#"
    <shape type="sphere"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
        <rgb name="color0" value="0.9, 0.1, 0.1"/>
        <texture type="checkerboard" name="color1"/>
        <transform name="to_uv"><scale x="4" y="2"/><translate x="0.5" y="0.25"/></transform>
    </texture></bsdf></shape>"#;
    let (_d, r) = import_text(&scene(body));
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let t = imp.table();
    // The nested texture is converted first: "texture", its parent "texture-2".
    assert_eq!(
        get(&t, "textures.texture-2.to_uv").to_string(),
        "[[4.0, 0.0, 0.5], [0.0, 2.0, 0.25]]"
    );
    assert_eq!(
        get(&t, "textures.texture-2.color1.texture").as_str(),
        Some("texture")
    );
    // Mitsuba's defaults, 0.4 and 0.2.
    assert_eq!(get(&t, "textures.texture.color0").as_float(), Some(0.4));
    assert_eq!(get(&t, "textures.texture.color1").as_float(), Some(0.2));
    load_imported(&imp).unwrap();

    let (_d, r) = import_pbrt(&format!(
        "{PBRT_CAMERA}Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"w.png\" \"float uscale\" 2 \"float vdelta\" 0.25 \"string encoding\" \"gamma 2.2\" \"float scale\" 0.5 \"bool invert\" \"true\"
Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 4 \"rgb tex2\" [ 0.1 0.2 0.3 ] \"texture tex1\" \"img\"
Texture \"amt\" \"float\" \"checkerboard\" \"float tex1\" 0.25
Texture \"s\" \"spectrum\" \"scale\" \"texture tex\" \"c\" \"float scale\" 2
Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"s\" \"rgb tex2\" [ 1 1 1 ] \"texture amount\" \"amt\"
Material \"diffuse\" \"texture reflectance\" \"m\"
Shape \"sphere\"
"
    ));
    let imp = r.unwrap();
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let t = imp.table();
    let s = |k: &str| get(&t, k).to_string();
    assert_eq!(
        s("textures.img.to_uv"),
        "[[2.0, 0.0, 0.0], [0.0, -1.0, 0.75]]"
    );
    assert_eq!(s("textures.img.encoding"), "\"gamma 2.2\"");
    assert_eq!(s("textures.img.scale"), "0.5");
    assert_eq!(s("textures.img.invert"), "true");
    assert_eq!(s("textures.c.to_uv"), "[[4.0, 0.0, 0.0], [0.0, 2.0, 0.0]]");
    assert_eq!(s("textures.c.color0.texture"), "\"img\"");
    assert_eq!(s("textures.c.color1"), "[0.1, 0.2, 0.3]");
    let amt = get(&t, "textures").get("amt (float)").unwrap();
    assert_eq!(amt["color0"].to_string(), "0.25");
    assert_eq!(amt["color1"].to_string(), "0.0");
    assert_eq!(s("textures.s.scale"), "2.0");
    assert_eq!(s("textures.m.amount.texture"), "\"amt (float)\"");
    let m = get(&t, "materials")
        .as_table()
        .unwrap()
        .values()
        .next()
        .unwrap();
    assert_eq!(m.get("rho_d").unwrap().to_string(), "{ texture = \"m\" }");
}

/// Mitsuba 3's `thindielectric` and pbrt-v4's `thindielectric` and
/// `diffusetransmission` become heron's thin sheet and diffuse transmission, with the
/// importers' defaults and warnings.
#[test]
fn thin_dielectrics_and_diffuse_transmission_import_as_heron_s_sheets() {
    let body = r#"
    <bsdf type="thindielectric" id="pane"/>
    <bsdf type="thindielectric" id="film"><float name="int_ior" value="1.33"/><float name="ext_ior" value="1.0"/><float name="specular_transmittance" value="1"/></bsdf>
    <bsdf type="thindielectric" id="tinted"><rgb name="specular_transmittance" value="0.5, 0.6, 0.7"/></bsdf>
    <shape type="rectangle"><ref id="pane"/></shape>
    <shape type="rectangle"><ref id="film"/></shape>
    <shape type="rectangle"><ref id="tinted"/></shape>
"#;
    let (_d, r) = import_text(&scene(body));
    let imp = r.unwrap();
    let t = &imp.table();
    assert_eq!(
        get(t, "materials.pane.type").as_str(),
        Some("thin-dielectric")
    );
    // Mitsuba's defaults, read as the dielectric reads them.
    assert_eq!(get(t, "materials.pane.ior").as_str(), Some("N-BK7"));
    assert_eq!(f(get(t, "materials.pane.outside_ior")), 1.000277);
    assert_eq!(f(get(t, "materials.film.ior")), 1.33);
    assert_eq!(f(get(t, "materials.film.outside_ior")), 1.0);
    // A factor of 1 is Mitsuba's default and says nothing; another is ignored, said.
    let w: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(imp.warnings.len(), 1, "{w:#?}");
    assert!(
        imp.warnings[0].line == 10
            && imp.warnings[0]
                .message
                .contains("specular_transmittance: heron's thin dielectric has no such factor"),
        "{w:#?}"
    );
    load_imported(&imp).unwrap();

    let text = format!(
        "{PBRT_CAMERA}Material \"thindielectric\"\nShape \"sphere\"\nMaterial \"thindielectric\" \"spectrum eta\" \"glass-F11\"\nShape \"sphere\"\nMaterial \"diffusetransmission\"\nShape \"sphere\"\nMaterial \"diffusetransmission\" \"rgb reflectance\" [ 0.2 0.4 0.6 ] \"rgb transmittance\" [ 0.1 0.3 0.2 ] \"float scale\" 1.5\nShape \"sphere\"\nMaterial \"diffusetransmission\" \"float reflectance\" 0.7 \"float transmittance\" 0.6\nShape \"sphere\"\n"
    );
    let (_d, r) = import_pbrt(&text);
    let imp = r.unwrap();
    let t = &imp.table();
    assert_eq!(
        get(t, "materials.thindielectric-1.type").as_str(),
        Some("thin-dielectric")
    );
    assert_eq!(f(get(t, "materials.thindielectric-1.ior")), 1.5);
    assert_eq!(
        get(t, "materials.thindielectric-2.ior").as_str(),
        Some("N-SF11")
    );
    assert_eq!(
        get(t, "materials.diffusetransmission-3.type").as_str(),
        Some("diffuse-transmission")
    );
    assert_eq!(
        f(get(t, "materials.diffusetransmission-3.reflectance")),
        0.25
    );
    assert_eq!(
        f(get(t, "materials.diffusetransmission-3.transmittance")),
        0.25
    );
    // `scale` multiplies both (0.9 + 0.3 = 1.2 > 1 in green: both scaled by 1/1.2).
    let r4 = v3(get(t, "materials.diffusetransmission-4.reflectance"));
    let t4 = v3(get(t, "materials.diffusetransmission-4.transmittance"));
    assert!(
        (r4 - DVec3::new(0.25, 0.5, 0.75)).abs().max_element() < 1e-6,
        "{r4}"
    );
    assert!(
        (t4 - DVec3::new(0.125, 0.375, 0.25)).abs().max_element() < 1e-6,
        "{t4}"
    );
    let w: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(imp.warnings.len(), 2, "{w:#?}");
    assert!(imp.warnings.iter().all(|d| d.message.contains("scaled by")));
    assert_eq!(
        (imp.warnings[0].line, imp.warnings[1].line),
        (12, 14),
        "{w:#?}"
    );
    load_imported(&imp).unwrap();
}

/// pbrt-v4's `coateddiffuse` is heron's coated material: its reflectance, √-remapped
/// roughness, eta and thickness (pbrt's default 0.01), a warning for anisotropy and
/// for the scattering layer heron renders as absorbing only; the scene loads.
#[test]
fn pbrt_coateddiffuse_is_heron_coated() {
    let quad = "Shape \"trianglemesh\" \"point3 P\" [ -4 -4 0  4 -4 0  4 4 0  -4 4 0 ] \"integer indices\" [ 0 1 2  0 2 3 ]\nLightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n";
    let text = format!(
        "{PBRT_CAMERA}Material \"coateddiffuse\" \"rgb reflectance\" [ 0.6 0.2 0.1 ] \"float uroughness\" 0.04 \"float vroughness\" 0.16 \"float eta\" 1.6 \"rgb albedo\" [ 0.5 0.5 0.5 ]\n{quad}Material \"coateddiffuse\"\n{quad}"
    );
    let (_d, r) = import_pbrt(&text);
    let imp = r.unwrap();
    let t = imp.table();
    assert_eq!(
        get(&t, "materials.coateddiffuse-1.type").as_str(),
        Some("coated")
    );
    assert_eq!(
        v3(get(&t, "materials.coateddiffuse-1.reflectance")),
        DVec3::new(0.6, 0.2, 0.1)
    );
    assert_eq!(f(get(&t, "materials.coateddiffuse-1.ior")), 1.6);
    // The mean of u and v (0.1), remapped: α = √0.1.
    assert!((f(get(&t, "materials.coateddiffuse-1.roughness")) - 0.1f64.sqrt()).abs() < 1e-9);
    assert_eq!(f(get(&t, "materials.coateddiffuse-1.thickness")), 0.01);
    // pbrt's defaults: reflectance 0.5, eta 1.5, smooth.
    assert_eq!(f(get(&t, "materials.coateddiffuse-2.ior")), 1.5);
    let smooth = t
        .get("materials")
        .and_then(|m| m.get("coateddiffuse-2"))
        .and_then(|m| m.get("roughness"));
    assert!(smooth.is_none(), "{smooth:?}");
    let w: Vec<String> = imp.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        w.iter().any(|m| m.contains("anisotropic roughness")),
        "{w:#?}"
    );
    assert!(w.iter().any(|m| m.contains("scattering")), "{w:#?}");
    load_imported(&imp).unwrap();
}
