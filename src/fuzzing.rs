//! Fuzzing harnesses: the bodies of the cargo-fuzz targets in `fuzz/fuzz_targets/` and of
//! the replay test `tests/fuzz_corpus.rs`, which feeds them every file of `fuzz/corpus/`
//! and `fuzz/regressions/` on the stable toolchain. Both call these functions, so a
//! corpus file replays exactly what the fuzzer ran.
//!
//! Each harness feeds arbitrary bytes to a reader and returns normally whether the input
//! is accepted or rejected. It panics (a finding) when the reader panics, when a rejection's
//! message is empty or spans several lines (heron's errors are one line naming the file,
//! line or key), or when an accepted input yields something the renderer cannot use
//! (non-finite vertices or spectra, out-of-range indices).
//!
//! - [`scene`]: the scene loader on TOML text, as `load_scene_from_str` runs it, with the
//!   files the scene names (meshes, index and n, k tables) read from a folder of fixtures.
//!   Two differences, both to keep a fuzzing run fast and inside that folder: a `[sky]` is
//!   checked and its model constructed but not tabulated (tabulating a physical sky takes
//!   seconds, and depends only on already-checked numbers), and a scene naming a file
//!   outside the folder (an absolute path or `..`) is parsed but not built.
//! - [`obj`]: the OBJ reader and the mesh entry's triangle gathering on OBJ text, and the
//!   area light an emitting mesh becomes.
//! - [`spectral_csv`]: the spectral CSV readers on one text: a spectral distribution
//!   (`heron color`, dielectric index tables) through the interpolation onto the 1 nm
//!   grid, a metal's `wavelength_nm,n,k` table, and the Aristotelian bow texture.
use crate::bsdf::{Dielectric, Material};
use crate::camera::Camera;
use crate::colorimetry::{colour_of, Illuminant, StandardObserver};
use crate::geometry::{Shape, ShapeKind};
use crate::light::Light;
use crate::scene::file::{
    CoatedFile, ConductorFile, DielectricFile, GlossyFile, IorSpec, MaterialFile, MeshFile,
    MetalSpec, SceneFile, ShapeFile, ThinDielectricFile,
};
use crate::scene::load::{self, SkyTables};
use crate::spectrum::csv::SpectrumCsv;
use crate::spectrum::ior::Ior;
use crate::spectrum::metals::ComplexIor;
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use std::collections::BTreeMap;
use std::path::{Component, Path};

/// What a harness made of its input (the fuzz targets ignore it; the replay test counts
/// it, so that a corpus which never gets past the first check shows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The reader accepted the input (for `spectral_csv`: at least one reader did).
    Accepted,
    /// The reader rejected it with a proper error.
    Rejected,
    /// Not fed to the reader: not UTF-8 (every reader takes text), or a scene naming a
    /// file outside the fixtures' folder.
    Skipped,
}

/// A harness: the input, and the folder the scene's files are read from.
pub type Harness = fn(&[u8], &Path) -> Outcome;

/// The fuzz targets by name (the folder names under `fuzz/corpus/`). `scene_toml` reads
/// its files from `fixtures`; the others ignore it.
pub const TARGETS: &[(&str, Harness)] = &[
    ("scene_toml", scene),
    ("obj", |d, _| obj(d)),
    ("spectral_csv", |d, _| spectral_csv(d)),
    ("ply", |d, _| ply(d)),
    ("mitsuba_xml", mitsuba_xml),
    ("pbrt", pbrt),
];

/// Panics unless `msg` is a usable error message: non-empty and on one line.
fn check_message(msg: &str) {
    assert!(!msg.trim().is_empty(), "empty error message");
    assert!(
        !msg.contains('\n') && !msg.contains('\r'),
        "error message on several lines: {msg:?}"
    );
}

fn rejected(msg: &str) -> Outcome {
    check_message(msg);
    Outcome::Rejected
}

fn check_spectrum(what: &str, s: &DenseSpectrum) {
    if let Some((i, v)) = s.values().iter().enumerate().find(|(_, v)| !v.is_finite()) {
        panic!("{what}: non-finite value {v} at {} nm", 360 + i);
    }
}

/// The renderer's assumptions about a loaded shape.
fn check_shape(s: &Shape, materials: usize) {
    assert!(
        (s.material as usize) < materials,
        "material index out of range"
    );
    match &s.kind {
        ShapeKind::Sphere { center, radius } => {
            assert!(center.is_finite() && radius.is_finite() && *radius > 0.0);
        }
        ShapeKind::Mesh(m) => {
            assert!(!m.indices.is_empty(), "a mesh without triangles");
            assert!(
                m.positions.iter().all(|p| p.is_finite()),
                "non-finite vertex"
            );
            let n = m.positions.len();
            assert!(
                m.indices.iter().flatten().all(|&i| (i as usize) < n),
                "vertex index out of range"
            );
        }
    }
}

fn check_ior(what: &str, ior: &Ior) {
    if let Err(e) = ior.validate() {
        panic!("{what}: {e}");
    }
}

/// The renderer's assumptions about a loaded material: finite spectra and parameters,
/// reflectances in [0, 1], indices ≥ 1 (dielectrics) or n > 0, k ≥ 0 (metals).
fn check_material(m: &Material) {
    let reflectance = |what: &str, s: &DenseSpectrum| {
        check_spectrum(what, s);
        assert!(
            s.min_value() >= 0.0 && s.max_value() <= 1.0,
            "{what} outside [0, 1]"
        );
    };
    let dielectric = |d: &Dielectric| {
        check_ior("ior", &d.ior);
        check_ior("outside ior", &d.outside);
    };
    let metal = |c: &ComplexIor| {
        check_spectrum("n", &c.n);
        check_spectrum("k", &c.k);
        assert!(c.n.min_value() > 0.0 && c.k.min_value() >= 0.0);
    };
    match m {
        Material::Lambertian(l) => reflectance("rho_d", &l.rho_d),
        Material::TexturedDiffuse(t) => {
            for n in t.texture().nodes() {
                if let crate::texture::Node::Image { image, .. } = n {
                    let (w, h) = image.size();
                    assert!(w >= 1 && h >= 1);
                }
            }
        }
        Material::Mirror(mi) => reflectance("rho_s", &mi.rho_s),
        Material::Dielectric(d) => dielectric(d),
        Material::RoughDielectric(d) => {
            dielectric(&d.interface);
            assert!(d.distribution.alpha.is_finite());
        }
        Material::Glossy(g) => {
            reflectance("rho_d", &g.rho_d);
            assert!((0.0..=1.0).contains(&g.rho_s) && g.shininess.is_finite());
            if let Some(b) = &g.base {
                dielectric(b);
            }
        }
        Material::Conductor(c) => metal(&c.ior),
        Material::CoatedDiffuse(c) => {
            reflectance("reflectance", &c.rho);
            check_ior("ior", &c.ior);
            assert!(c.thickness >= 0.0 && c.thickness.is_finite());
            assert!(c.distribution.map_or(true, |d| d.alpha.is_finite()));
        }
        Material::RoughConductor(c) => {
            metal(&c.ior);
            assert!(c.distribution.alpha.is_finite());
        }
        Material::Polarizer(p) => {
            assert!(p.axis.is_finite() && p.angle.is_finite());
            assert!(p.t_x > 0.0 && p.t_x <= 1.0 && (0.0..=p.t_x).contains(&p.t_y));
        }
        Material::Retarder(r) => {
            assert!(r.axis.is_finite() && r.angle.is_finite() && r.retardance.is_finite());
        }
        Material::ThinDielectric(d) => {
            check_ior("ior", &d.ior);
            check_ior("outside ior", &d.outside);
        }
        Material::DiffuseTransmission(d) => {
            reflectance("reflectance", &d.reflectance);
            reflectance("transmittance", &d.transmittance);
            let sum = d.reflectance.values().iter().zip(d.transmittance.values());
            assert!(sum.map(|(r, t)| r + t).fold(0.0f32, f32::max) <= 1.0 + 1e-5);
        }
    }
}

/// The renderer's assumptions about a loaded light: finite spectra, positions and unit
/// directions.
fn check_light(l: &Light) {
    let unit = |what: &str, d: Vec3| {
        assert!(
            d.is_finite() && (d.length() - 1.0).abs() < 1e-5,
            "{what}: not a unit vector: {d}"
        );
    };
    match l {
        Light::Point(p) => {
            assert!(p.position.is_finite());
            check_spectrum("point light intensity", &p.intensity);
        }
        Light::Spot(s) => {
            assert!(s.position.is_finite());
            unit("spot light direction", s.direction);
            check_spectrum("spot light intensity", &s.intensity);
            assert!(s.cos_falloff_start.is_finite() && s.cos_falloff_end.is_finite());
        }
        Light::Directional(d) => {
            unit("directional light direction", d.direction);
            check_spectrum("directional light radiance", &d.radiance);
        }
        Light::Sun(s) => {
            unit("sun direction", s.direction);
            check_spectrum("sun irradiance", &s.irradiance);
            check_spectrum("sun radiance", &s.radiance);
        }
        Light::Area(a) => check_spectrum("area light emission", &a.emission),
        Light::Environment(e) => check_spectrum("environment", &e.background),
    }
}

/// The renderer's assumptions about the camera: unit ray directions across the image and
/// a finite, positive importance (the light-tracing integrators divide by the image area).
fn check_camera(c: &Camera) {
    let unit = |d: Vec3| d.is_finite() && (d.length() - 1.0).abs() < 1e-5;
    assert!(unit(c.forward()), "camera axis not a unit vector");
    let (w, h) = (c.width as f32, c.height as f32);
    for (x, y) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h), (0.5 * w, 0.5 * h)] {
        let d = c.direction(x, y);
        assert!(unit(d), "camera ray at ({x}, {y}) not a unit vector: {d}");
    }
    let we = c.we(c.direction(0.5 * w, 0.5 * h));
    assert!(
        we.is_finite() && we > 0.0,
        "camera importance {we} at the centre"
    );
}

/// Whether every file `f` names is a relative path that stays in the scene's folder.
fn stays_in_folder(f: &SceneFile) -> bool {
    fn table(spec: Option<&IorSpec>) -> Option<&str> {
        match spec {
            Some(IorSpec::Table(t)) => Some(t),
            _ => None,
        }
    }
    let mut files: Vec<&str> = Vec::new();
    for m in f.materials.values() {
        match m {
            MaterialFile::Dielectric(DielectricFile {
                ior, outside_ior, ..
            }) => files.extend(
                table(Some(ior))
                    .into_iter()
                    .chain(table(outside_ior.as_ref())),
            ),
            MaterialFile::Glossy(GlossyFile { ior, .. }) => files.extend(table(ior.as_ref())),
            MaterialFile::ThinDielectric(ThinDielectricFile { ior, outside_ior }) => files.extend(
                table(Some(ior))
                    .into_iter()
                    .chain(table(outside_ior.as_ref())),
            ),
            MaterialFile::Coated(CoatedFile { ior, .. }) => files.extend(table(ior.as_ref())),
            MaterialFile::Conductor(ConductorFile {
                metal: MetalSpec::Table(t),
                ..
            }) => files.push(t),
            MaterialFile::Lambertian(l) => files.extend(l.texture.as_deref()),
            _ => {}
        }
    }
    if let Some(e) = &f.environment {
        files.push(&e.map);
    }
    for s in &f.shapes {
        if let ShapeFile::Mesh(m) = s {
            files.push(&m.file);
        }
    }
    files.iter().all(|f| {
        Path::new(f)
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
    })
}

/// The scene loader on `data` as a scene file `fixtures/scene.toml`.
pub fn scene(data: &[u8], fixtures: &Path) -> Outcome {
    let Ok(text) = std::str::from_utf8(data) else {
        return Outcome::Skipped;
    };
    let file = match load::parse_scene_file(text) {
        Ok(f) => f,
        Err(msg) => return rejected(&msg),
    };
    if !stays_in_folder(&file) {
        return Outcome::Skipped;
    }
    let path = fixtures.join("scene.toml");
    match load::build(&path, file, SkyTables::Skip, String::new()) {
        Ok(scene) => {
            check_scene(&scene);
            Outcome::Accepted
        }
        Err(e) => rejected(&e.to_string()),
    }
}

/// What every loaded scene must satisfy, whatever file it came from.
fn check_scene(scene: &crate::scene::Scene) {
    assert_eq!(scene.materials.len(), scene.material_names.len());
    for s in &scene.shapes {
        check_shape(s, scene.materials.len());
        assert!(
            s.light == crate::geometry::NO_LIGHT
                || matches!(scene.lights.get(s.light as usize), Some(Light::Area(_))),
            "a shape's light is not an area light"
        );
    }
    scene.materials.iter().for_each(check_material);
    scene.lights.iter().for_each(check_light);
    check_camera(&scene.camera);
    check_spectrum("background", &scene.background);
    assert!(scene.bounds.center.is_finite() && scene.bounds.radius.is_finite());
}

/// The PLY reader on `data` as the file of a mesh entry with one material.
pub fn ply(data: &[u8]) -> Outcome {
    let groups = match load::ply::parse_ply(data, "fuzz") {
        Ok(g) => g,
        Err(msg) => return rejected(&msg),
    };
    for g in &groups {
        for t in &g.indices {
            assert!(
                t.iter().all(|&i| (i as usize) < g.positions.len()),
                "index out of range"
            );
        }
    }
    let entry = mesh_entry("fuzz.ply");
    let mut warnings = Vec::new();
    match load::shapes_of_groups(
        groups,
        Path::new("fuzz.toml"),
        Path::new("fuzz.ply"),
        "shapes[0]",
        &entry,
        &BTreeMap::new(),
        Some(0),
        &mut warnings,
    ) {
        // A mesh of zero-area triangles only is dropped with a warning.
        Ok(shapes) if shapes.is_empty() => rejected(&warnings.join("; ")),
        Ok(shapes) => {
            shapes.iter().for_each(|s| check_shape(s, 1));
            Outcome::Accepted
        }
        Err(e) => rejected(&e.to_string()),
    }
}

/// The Mitsuba 3 importer on `data` as `fixtures/scene.xml`, then the scene it becomes.
/// Files outside the fixtures folder are not read (inputs naming `..` or an absolute
/// path are skipped).
pub fn mitsuba_xml(data: &[u8], fixtures: &Path) -> Outcome {
    let Ok(text) = std::str::from_utf8(data) else {
        return Outcome::Skipped;
    };
    if text.contains("..") || text.contains("=\"/") || text.contains("='/") {
        return Outcome::Skipped;
    }
    let path = fixtures.join("scene.xml");
    let options = crate::scene::import::ImportOptions::default();
    imported_scene(crate::scene::import::import_mitsuba_str(
        text, &path, &options,
    ))
}

/// The pbrt-v4 importer on `data` as `fixtures/scene.pbrt`, then the scene it becomes.
/// Files outside the fixtures folder are not read (inputs naming `..` or an absolute
/// path are skipped).
pub fn pbrt(data: &[u8], fixtures: &Path) -> Outcome {
    let Ok(text) = std::str::from_utf8(data) else {
        return Outcome::Skipped;
    };
    if text.contains("..") || text.contains("\"/") {
        return Outcome::Skipped;
    }
    let path = fixtures.join("scene.pbrt");
    let options = crate::scene::import::ImportOptions::default();
    imported_scene(crate::scene::import::import_pbrt_str(text, &path, &options))
}

/// What an importer made of its input: its warnings checked as messages, then the scene
/// loaded and checked (both importers' harnesses).
fn imported_scene(r: crate::Result<crate::scene::import::Imported>) -> Outcome {
    let imported = match r {
        Ok(i) => i,
        Err(e) => return rejected(&e.to_string()),
    };
    for w in &imported.warnings {
        check_message(&w.to_string());
    }
    match load::load_imported(&imported) {
        Ok(scene) => {
            check_scene(&scene);
            Outcome::Accepted
        }
        Err(e) => rejected(&e.to_string()),
    }
}

/// A mesh entry of `file` with the one material "m" and nothing else set.
fn mesh_entry(file: &str) -> MeshFile {
    MeshFile {
        file: file.into(),
        vertices: None,
        triangles: None,
        shape_index: None,
        material: Some("m".into()),
        groups: BTreeMap::new(),
        scale: None,
        translate: None,
        transform: None,
        uv: None,
        flip_tex_coords: None,
        emission: None,
        two_sided: None,
        medium: None,
    }
}

/// The OBJ reader on `data` as the file of a mesh entry with one material, and the area
/// light the mesh becomes when it emits.
pub fn obj(data: &[u8]) -> Outcome {
    let Ok(text) = std::str::from_utf8(data) else {
        return Outcome::Skipped;
    };
    let entry = mesh_entry("fuzz.obj");
    let mut warnings = Vec::new();
    let shapes = match load::mesh_shapes(
        text,
        Path::new("fuzz.toml"),
        Path::new("fuzz.obj"),
        "shapes[0]",
        &entry,
        &BTreeMap::new(),
        Some(0),
        &mut warnings,
    ) {
        // A mesh of zero-area triangles only is dropped with a warning.
        Ok(s) if s.is_empty() => return rejected(&warnings.join("; ")),
        Ok(s) => s,
        Err(e) => return rejected(&e.to_string()),
    };
    assert!(!shapes.is_empty());
    for (k, s) in shapes.iter().enumerate() {
        check_shape(s, 1);
        if let ShapeKind::Mesh(m) = &s.kind {
            let tris = m
                .indices
                .iter()
                .map(|t| t.map(|v| m.positions[v as usize]))
                .collect();
            let _ = crate::light::AreaLight::triangles(
                k as u32,
                DenseSpectrum::constant(1.0),
                false,
                tris,
            );
        }
    }
    // (A scene checks that its bounding sphere is finite; a mesh alone need not be.)
    let _ = load::scene_bounds(&shapes);
    Outcome::Accepted
}

/// The spectral CSV readers on `data`.
pub fn spectral_csv(data: &[u8]) -> Outcome {
    let Ok(text) = std::str::from_utf8(data) else {
        return Outcome::Skipped;
    };
    let path = Path::new("fuzz.csv");
    let mut outcome = Outcome::Rejected;
    // A spectral distribution: `heron color`, and a dielectric's `{ table = .. }`.
    match SpectrumCsv::parse(text, path) {
        Ok(csv) => {
            assert!(csv.samples.len() >= 2);
            assert!(csv.samples.windows(2).all(|w| w[0].0 < w[1].0));
            let dense = csv.to_dense();
            check_spectrum("spectral distribution", &dense);
            let _ = colour_of(&dense, StandardObserver::Cie1931, Illuminant::D65);
            let _ = colour_of(&dense, StandardObserver::Cie1964, Illuminant::None);
            if let Err(e) = Ior::Table(dense).validate() {
                check_message(&e);
            }
            outcome = Outcome::Accepted;
        }
        Err(e) => check_message(&e.to_string()),
    }
    // A metal's n, k table.
    match crate::spectrum::metals::parse_nk(text, path) {
        Ok(c) => {
            check_spectrum("n", &c.n);
            check_spectrum("k", &c.k);
            assert!(c.n.values().iter().all(|&n| n > 0.0));
            assert!(c.k.values().iter().all(|&k| k >= 0.0));
            outcome = Outcome::Accepted;
        }
        Err(e) => check_message(&e.to_string()),
    }
    // The Aristotelian bow's texture.
    match crate::sky::aristotle::BowTexture::parse(text) {
        Ok(t) => {
            let _ = (t.coverage(0.5), t.radiance(0.5, 550.0));
            outcome = Outcome::Accepted;
        }
        Err(e) => check_message(&e),
    }
    outcome
}
