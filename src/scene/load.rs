//! Loading and validating a scene file into a [`Scene`](super::Scene).
//!
//! Three stages, each failing with `HeronError::Scene { file, message }` and a one-line
//! message that starts with the key path (or the line and column for TOML syntax):
//!
//! 1. TOML syntax: the text is parsed into a table (`line 3, column 9: …`).
//! 2. Shape of the data: the table is deserialized into [`SceneFile`] through
//!    `serde_path_to_error`, whose leaf types check ranges (`shapes[2].radius: expected a
//!    positive finite number, got -0.3`). serde's internally tagged enums buffer the
//!    item they read, which loses the key path inside `materials.X`, `shapes[i]` and
//!    `lights[i]`; when an error lands on such an item, the item alone is deserialized
//!    again into the struct of its `type` to recover the full path.
//! 3. Cross-key checks while building the [`Scene`]: material names, ρd + ρs ≤ 1,
//!    zero-area triangles and quads, the camera, and the meshes (whose errors name the
//!    mesh file and carry the scene's key path in the message).
//!
//! Orders: `Scene::materials` is sorted by material name (a TOML table keeps no order);
//! `Scene::shapes` follows the file, and a mesh entry becomes one shape per material it
//! uses, in the order in which the materials' OBJ groups first appear in the OBJ file.
pub(crate) mod obj;

use super::file::{
    show, Colour, ConductorFile, DielectricFile, DirectionalLightFile, Emission, GlossyFile,
    IorSpec, LambertianFile, LightFile, MaterialFile, MediumFile, MeshFile, MetalSpec, MirrorFile,
    PlaneFile, PointLightFile, QuadFile, SceneFile, ShapeFile, SphereFile, SpotLightFile,
    SunLightFile, TriangleFile, LIGHT_TYPES, MATERIAL_TYPES, SHAPE_TYPES,
};
use super::Scene;
use crate::bsdf::microfacet::{TrowbridgeReitz, MIN_ALPHA};
use crate::bsdf::{
    Conductor, Dielectric, Glossy, Lambertian, Material, Mirror, RoughConductor, RoughDielectric,
};
use crate::camera::Camera;
use crate::error::{HeronError, Result};
use crate::geometry::{Mesh, Shape, ShapeKind, MIN_RELATIVE_RADIUS};
use crate::light::{DirectionalLight, Light, PointLight, SpotLight, SunLight};
use crate::settings::{IntegratorKind, LightSamplerKind, OffsetMode, RenderSettings};
use crate::spectrum::ior::Ior;
use crate::spectrum::metals::ComplexIor;
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use serde::de::DeserializeOwned;
use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Reads, parses and validates the scene file at `path` (meshes are resolved relative to
/// it). Every error names the file, the key path and what was expected.
pub fn load_scene(path: &Path) -> Result<Scene> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| scene_error(path, format!("cannot read the scene file: {e}")))?;
    load_scene_from_str(&text, path)
}

/// Like [`load_scene`] for scene text already in memory; `path` names the file in error
/// messages and its folder is where relative mesh paths start.
pub fn load_scene_from_str(text: &str, path: &Path) -> Result<Scene> {
    let file = parse_scene_file(text).map_err(|m| scene_error(path, m))?;
    let mut scene = build(path, file, SkyTables::Build)?;
    scene.source_sha256 = crate::files::sha256_hex(text.as_bytes());
    Ok(scene)
}

/// Whether [`build`] tabulates a `[sky]` model and Lorenz–Mie media. Tabulating a
/// physical sky or a medium of rain drops takes seconds (it is the model's evaluation,
/// not the file's reading), so the fuzzing harness ([`crate::fuzzing`]) checks the
/// `[sky]` table and constructs its model but leaves `Scene::sky` empty, and checks a
/// `type = "mie"` medium's keys and shape but builds no medium for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SkyTables {
    Build,
    Skip,
}

/// Stages 1 and 2: TOML text to [`SceneFile`]. The error is the one-line message.
pub fn parse_scene_file(text: &str) -> std::result::Result<SceneFile, String> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let msg = one_line(e.message());
        match e.span() {
            Some(span) => {
                let (line, col) = line_col(text, span.start);
                format!("line {line}, column {col}: TOML syntax error: {msg}")
            }
            None => format!("TOML syntax error: {msg}"),
        }
    })?;
    require_tables(&table)?;
    match serde_path_to_error::deserialize::<_, SceneFile>(toml::Value::Table(table.clone())) {
        Ok(f) => Ok(f),
        Err(e) => {
            let mut path = segments(e.path());
            let mut msg = e.inner().message().to_string();
            if let Some((p, m)) = refine(&table, &path) {
                path = p;
                msg = m;
            }
            Err(friendly(&path, &msg))
        }
    }
}

/// serde's derived structs (and internally tagged enums) also accept an array of their
/// fields in order, so `render = [1]` would quietly mean `spp = 1`. A scene file writes
/// these as tables; anything else is an error.
fn require_tables(table: &toml::Table) -> std::result::Result<(), String> {
    let need = |path: String, v: &toml::Value| {
        if v.is_table() {
            Ok(())
        } else {
            Err(format!("{path}: expected a table, got {}", show(v)))
        }
    };
    for k in ["camera", "render"] {
        if let Some(v) = table.get(k) {
            need(k.to_string(), v)?;
        }
    }
    if let Some(toml::Value::Table(m)) = table.get("materials") {
        for (name, v) in m {
            need(key("materials", name), v)?;
        }
    }
    for k in ["shapes", "lights"] {
        if let Some(toml::Value::Array(items)) = table.get(k) {
            for (i, v) in items.iter().enumerate() {
                need(format!("{k}[{i}]"), v)?;
            }
        }
    }
    Ok(())
}

fn scene_error(file: &Path, message: impl AsRef<str>) -> HeronError {
    HeronError::Scene {
        file: file.to_path_buf(),
        message: one_line(message.as_ref()),
    }
}

/// Joins the lines of a message with "; " so every error is one line.
fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

/// 1-based line and column (in characters) of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, col)
}

// ---------------------------------------------------------------------------------------
// Key paths

#[derive(Clone, Debug, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

fn segments(p: &serde_path_to_error::Path) -> Vec<Seg> {
    p.iter()
        .filter_map(|s| match s {
            serde_path_to_error::Segment::Seq { index } => Some(Seg::Index(*index)),
            serde_path_to_error::Segment::Map { key } => Some(Seg::Key(key.clone())),
            serde_path_to_error::Segment::Enum { variant } => Some(Seg::Key(variant.clone())),
            serde_path_to_error::Segment::Unknown => None,
        })
        .collect()
}

/// TOML spelling of a key path: `materials.glass.ior`, `shapes[2].radius`,
/// `materials."my glass"`.
fn fmt_path(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Index(i) => {
                let _ = write!(s, "[{i}]");
            }
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                let bare = !k.is_empty()
                    && k.chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
                if bare {
                    s.push_str(k);
                } else {
                    let _ = write!(s, "{k:?}");
                }
            }
        }
    }
    s
}

fn key(base: &str, k: &str) -> String {
    fmt_path(&[Seg::Key(base.into()), Seg::Key(k.into())])
}

/// Whether `path` is an item of a collection tagged by `type`, and the type list.
fn tagged_item(path: &[Seg]) -> Option<&'static [&'static str]> {
    match path {
        [Seg::Key(c), Seg::Key(_)] if c == "materials" => Some(MATERIAL_TYPES),
        [Seg::Key(c), Seg::Index(_)] if c == "shapes" => Some(SHAPE_TYPES),
        [Seg::Key(c), Seg::Index(_)] if c == "lights" => Some(LIGHT_TYPES),
        _ => None,
    }
}

/// Re-reads a tagged item (whose inner key path serde's buffering lost) as the struct of
/// its `type`, returning the full path and message of the error found there.
fn refine(table: &toml::Table, path: &[Seg]) -> Option<(Vec<Seg>, String)> {
    let item_path = path.get(..2)?;
    tagged_item(item_path)?;
    let value = match item_path {
        [Seg::Key(c), Seg::Key(name)] => table.get(c)?.get(name)?,
        [Seg::Key(c), Seg::Index(i)] => table.get(c)?.get(*i)?,
        _ => return None,
    };
    let mut t = value.as_table()?.clone();
    let ty = t.remove("type")?;
    let ty = ty.as_str()?;
    fn check<T: DeserializeOwned>(t: toml::Table) -> Option<(Vec<Seg>, String)> {
        serde_path_to_error::deserialize::<_, T>(toml::Value::Table(t))
            .err()
            .map(|e| (segments(e.path()), e.inner().message().to_string()))
    }
    let Seg::Key(c) = &item_path[0] else {
        return None;
    };
    let (inner, msg) = match (c.as_str(), ty) {
        ("materials", "lambertian") => check::<LambertianFile>(t),
        ("materials", "mirror") => check::<MirrorFile>(t),
        ("materials", "dielectric") => check::<DielectricFile>(t),
        ("materials", "glossy") => check::<GlossyFile>(t),
        ("materials", "conductor") => check::<ConductorFile>(t),
        ("shapes", "sphere") => check::<SphereFile>(t),
        ("shapes", "triangle") => check::<TriangleFile>(t),
        ("shapes", "plane") => check::<PlaneFile>(t),
        ("shapes", "quad") => check::<QuadFile>(t),
        ("shapes", "mesh") => check::<MeshFile>(t),
        ("lights", "point") => check::<PointLightFile>(t),
        ("lights", "directional") => check::<DirectionalLightFile>(t),
        ("lights", "sun") => check::<SunLightFile>(t),
        ("lights", "spot") => check::<SpotLightFile>(t),
        _ => None,
    }?;
    let mut full = item_path.to_vec();
    full.extend(inner);
    Some((full, msg))
}

/// What a key holds, for "missing key" messages.
fn expectation(parent: &[Seg], field: &str) -> String {
    let s = match field {
        "type" => {
            let list = tagged_item(parent).unwrap_or(&[]);
            return format!("one of {}", list.join(", "));
        }
        "eye" | "look_at" | "center" | "position" | "point" | "origin" | "translate" => {
            "[x, y, z] with three finite numbers"
        }
        "up" | "normal" | "direction" | "edge1" | "edge2" => "a non-zero vector [x, y, z]",
        "resolution" => "[width, height] with positive integers",
        "radius" | "ior" | "shininess" | "d" | "size" | "scale" | "epsilon" => {
            "a positive finite number"
        }
        "rho_d" => "a reflectance colour",
        "rho_s" => "a number in [0, 1]",
        "intensity" | "radiance" => "an emission colour",
        "material" => "the name of a material",
        "file" => "the path of an OBJ file",
        "vertices" => "three vertices [[x, y, z], [x, y, z], [x, y, z]]",
        "camera" => "a [camera] table with eye, look_at and resolution",
        "spp" | "max_depth" => "a positive integer",
        _ => "a value",
    };
    s.to_string()
}

/// serde's wording of a type ("f32", "struct CameraFile", "a sequence") in ours.
fn plain_expected(e: &str) -> String {
    let e = e.trim();
    match e {
        "f32" | "f64" => "a number".into(),
        "u32" | "u64" | "usize" => "a non-negative integer".into(),
        "i32" | "i64" => "an integer".into(),
        "a sequence" => "an array".into(),
        "a map" | "map" => "a table".into(),
        "a string" | "a boolean" => e.into(),
        _ if e.starts_with("struct ") || e.starts_with("internally tagged enum") => {
            "a table".into()
        }
        _ if e.starts_with("an array of length") => e.into(),
        _ => e.replace('`', ""),
    }
}

/// serde's wording of a found value ("integer `3`", "map") in ours.
fn plain_found(f: &str) -> String {
    let f = f.trim();
    if let Some(rest) = f.strip_prefix("string ") {
        return rest.to_string();
    }
    for prefix in ["integer ", "floating point ", "boolean "] {
        if let Some(rest) = f.strip_prefix(prefix) {
            return rest.trim_matches('`').to_string();
        }
    }
    match f {
        "map" => "a table".into(),
        "sequence" => "an array".into(),
        _ => f.to_string(),
    }
}

/// `a`, `b` -> a, b
fn strip_ticks(s: &str) -> String {
    s.replace('`', "")
}

/// serde's list of names after "expected" (`` `a` ``, `` `a` or `b` ``,
/// `` one of `a`, `b`, `c` ``, "there are no fields") as plain names.
fn name_list(tail: &str) -> Vec<String> {
    let t = tail.trim_start_matches(", ");
    let t = t.strip_prefix("expected ").unwrap_or(t);
    let t = t.strip_prefix("one of ").unwrap_or(t);
    t.split(", ")
        .flat_map(|x| x.split(" or "))
        .map(|x| strip_ticks(x).trim().to_string())
        .filter(|x| !x.is_empty() && x != "there are no fields")
        .collect()
}

/// Turns a serde/toml error at `path` into the one-line message of heron's style.
fn friendly(path: &[Seg], msg: &str) -> String {
    let msg = one_line(msg);
    let at = |p: &[Seg]| {
        if p.is_empty() {
            "the top level".to_string()
        } else {
            fmt_path(p)
        }
    };
    // unknown field `x`, expected one of `a`, `b`  |  expected `a`  |  there are no fields
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        if let Some((name, tail)) = rest.split_once('`') {
            let parent = match path.last() {
                Some(Seg::Key(k)) if k == name => &path[..path.len() - 1],
                _ => path,
            };
            let mut fields = name_list(tail);
            if tagged_item(parent).is_some() {
                fields.insert(0, "type".into());
            }
            let expected = match fields.len() {
                0 => "no keys are allowed here".to_string(),
                1 => format!("expected {}", fields[0]),
                _ => format!("expected one of {}", fields.join(", ")),
            };
            return format!("unknown key {name:?} at {} ({expected})", at(parent));
        }
    }
    let p = at(path);
    if let Some(rest) = msg.strip_prefix("unknown variant `") {
        if let Some((name, tail)) = rest.split_once('`') {
            return format!(
                "{p}: unknown variant {name:?}, expected one of {}",
                name_list(tail).join(", ")
            );
        }
    }
    if let Some(rest) = msg.strip_prefix("missing field `") {
        let name = rest.trim_end_matches('`');
        let mut full = path.to_vec();
        full.push(Seg::Key(name.into()));
        return format!(
            "{}: missing required key (expected {})",
            fmt_path(&full),
            expectation(path, name)
        );
    }
    for prefix in ["invalid type: ", "invalid value: "] {
        if let Some(rest) = msg.strip_prefix(prefix) {
            if let Some((found, expected)) = rest.rsplit_once(", expected ") {
                let mut expected = plain_expected(expected);
                if expected == "variant identifier" || expected == "tag" {
                    expected = format!(
                        "a type name, one of {}",
                        tagged_item(&path[..path.len().saturating_sub(1)])
                            .unwrap_or(&[])
                            .join(", ")
                    );
                }
                if expected == "an array" {
                    if let [Seg::Key(c)] = path {
                        if c == "shapes" || c == "lights" {
                            expected = format!("an array of tables (write [[{c}]])");
                        }
                    }
                }
                return format!("{p}: expected {expected}, got {}", plain_found(found));
            }
        }
    }
    if let Some(rest) = msg.strip_prefix("invalid length ") {
        if let Some((n, expected)) = rest.split_once(", expected ") {
            return format!(
                "{p}: expected {}, got {n} elements",
                plain_expected(expected)
            );
        }
    }
    format!("{p}: {}", strip_ticks(&msg))
}

// ---------------------------------------------------------------------------------------
// Stage 3: building the scene

pub(crate) fn build(path: &Path, file: SceneFile, sky_tables: SkyTables) -> Result<Scene> {
    let err = |m: String| scene_error(path, m);
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    // Every file the scene reads besides itself (meshes, tables), for provenance.
    let mut inputs: Vec<String> = Vec::new();

    // Materials, sorted by name.
    let mut materials = Vec::with_capacity(file.materials.len());
    let mut material_names = Vec::with_capacity(file.materials.len());
    for (name, m) in &file.materials {
        materials
            .push(build_material(&key("materials", name), m, &base_dir, &mut inputs).map_err(err)?);
        material_names.push(name.clone());
    }
    // A shape that emits and names no material is a pure emitter: it gets a black
    // Lambertian, appended after the named materials so their indices do not move.
    let black = materials.len() as u32;
    if file.shapes.iter().any(|s| {
        let (m, e, _) = shape_emission(s);
        m.is_none() && e.is_some()
    }) {
        materials.push(Material::Lambertian(Lambertian {
            rho_d: DenseSpectrum::constant(0.0),
        }));
        material_names.push("(black emitter)".into());
    }
    // A shape with a medium and no material is the medium's index-matched boundary: it
    // gets a dielectric of index 1 (Fresnel 0, straight through), so every integrator and
    // `heron stress` see a valid material; the path tracer passes it without a bounce.
    let boundary = materials.len() as u32;
    let mut plans: Vec<Option<MediumPlan>> = Vec::with_capacity(file.shapes.len());
    for (i, s) in file.shapes.iter().enumerate() {
        let at = format!("shapes[{i}].medium");
        plans.push(match shape_medium(s) {
            Some(m) => Some(plan_medium(&at, m).map_err(err)?),
            None => None,
        });
    }
    if file.shapes.iter().any(|s| {
        let (m, e, _) = shape_emission(s);
        m.is_none() && e.is_none() && shape_medium(s).is_some()
    }) {
        materials.push(Material::Dielectric(Dielectric::new(
            Ior::Constant(1.0),
            true,
        )));
        material_names.push("(medium boundary)".into());
    }
    let index: HashMap<&str, u32> = material_names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i as u32))
        .collect();
    let lookup = |at: String, name: &str| -> Result<u32> {
        index.get(name).copied().ok_or_else(|| {
            let defined = if material_names.is_empty() {
                "no materials are defined".to_string()
            } else {
                format!("defined: {}", material_names.join(", "))
            };
            err(format!("{at}: no material named {name:?} ({defined})"))
        })
    };

    // The material of a simple shape: named, or black for a pure emitter.
    let resolve = |at: &str, s: &ShapeFile| -> Result<u32> {
        let (material, emission, two_sided) = shape_emission(s);
        if two_sided.is_some() && emission.is_none() {
            return Err(err(format!(
                "{at}.two_sided: applies to emitting shapes, but emission is not given"
            )));
        }
        match (material, emission) {
            (Some(name), _) => lookup(format!("{at}.material"), name),
            (None, Some(_)) => Ok(black),
            (None, None) if shape_medium(s).is_some() => Ok(boundary),
            (None, None) => Err(err(format!(
                "{at}.material: missing required key (expected the name of a material, or an emission)"
            ))),
        }
    };

    // Shapes, in file order; each remembers the file entry it came from.
    let mut shapes = Vec::with_capacity(file.shapes.len());
    let mut shape_entry: Vec<usize> = Vec::with_capacity(file.shapes.len());
    for (i, s) in file.shapes.iter().enumerate() {
        let at = format!("shapes[{i}]");
        match s {
            ShapeFile::Sphere(sp) => {
                // Below this a sphere spans a handful of f32 steps at its centre, less
                // than the error bound of its hit points (geometry::spawn): rays would
                // pass through it (heron stress finds leaks from 2e-7 down).
                let reach = sp.center.0.abs().max_element();
                if sp.radius.0 < MIN_RELATIVE_RADIUS * reach {
                    return Err(err(format!(
                        "{at}.radius: expected at least {MIN_RELATIVE_RADIUS:e} × the centre's largest coordinate ({}), i.e. {:e}, got {}: a smaller sphere is below float precision where it is",
                        super::file::fmt_f32(reach),
                        MIN_RELATIVE_RADIUS * reach,
                        super::file::fmt_f32(sp.radius.0)
                    )));
                }
                shapes.push(Shape {
                    kind: ShapeKind::Sphere {
                        center: sp.center.0,
                        radius: sp.radius.0,
                    },
                    material: resolve(&at, s)?,
                })
            }
            ShapeFile::Triangle(t) => {
                let material = resolve(&at, s)?;
                let v = [t.vertices[0].0, t.vertices[1].0, t.vertices[2].0];
                if cross_overflows(v[0], v[1], v[2]) {
                    return Err(err(format!(
                        "{at}.vertices: expected a triangle whose edges' cross product is finite in f32 (coordinates within about ±1e19), got {}",
                        fmt_points(&v)
                    )));
                }
                if is_degenerate(v[0], v[1], v[2]) {
                    return Err(err(format!(
                        "{at}.vertices: expected a triangle with non-zero area, got collinear vertices {}",
                        fmt_points(&v)
                    )));
                }
                shapes.push(mesh_shape(v.to_vec(), vec![[0, 1, 2]], material));
            }
            ShapeFile::Plane(p) => {
                let material = resolve(&at, s)?;
                let n = p.normal.unit();
                let size = p.size.map_or(1000.0, |s| s.0);
                // Tangents with t × b = n, so (v1 − v0) × (v2 − v0) points along n.
                let t = n.any_orthogonal_vector().normalize();
                let b = n.cross(t);
                let c = p.point.0;
                let v = vec![
                    c - size * t - size * b,
                    c + size * t - size * b,
                    c + size * t + size * b,
                    c - size * t + size * b,
                ];
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(err(format!(
                        "{at}.size: expected a size whose square has finite corners, got {size}"
                    )));
                }
                shapes.push(mesh_shape(v, vec![[0, 1, 2], [0, 2, 3]], material));
            }
            ShapeFile::Quad(q) => {
                let material = resolve(&at, s)?;
                let (o, e1, e2) = (q.origin.0, q.edge1.0, q.edge2.0);
                let v = vec![o, o + e1, o + e1 + e2, o + e2];
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(err(format!(
                        "{at}: expected a quad with finite corners, got origin + edges overflowing f32"
                    )));
                }
                if cross_overflows(v[0], v[1], v[3]) {
                    return Err(err(format!(
                        "{at}: expected edge1 and edge2 whose cross product is finite in f32 (coordinates within about ±1e19), got {} and {}",
                        fmt_points(&[e1]),
                        fmt_points(&[e2])
                    )));
                }
                if is_degenerate(v[0], v[1], v[3]) {
                    return Err(err(format!(
                        "{at}: expected edge1 and edge2 spanning a non-zero area, got parallel edges {} and {}",
                        fmt_points(&[e1]),
                        fmt_points(&[e2])
                    )));
                }
                shapes.push(mesh_shape(v, vec![[0, 1, 2], [0, 2, 3]], material));
            }
            ShapeFile::Mesh(m) => {
                if m.two_sided.is_some() && m.emission.is_none() {
                    return Err(err(format!(
                        "{at}.two_sided: applies to emitting shapes, but emission is not given"
                    )));
                }
                let fallback = match (&m.emission, &m.medium) {
                    (Some(_), _) => Some(black),
                    (None, Some(_)) => Some(boundary),
                    (None, None) => None,
                };
                shapes.extend(build_mesh(path, &base_dir, &at, m, &lookup, fallback)?);
                inputs.push(m.file.clone());
            }
        }
        shape_entry.resize(shapes.len(), i);
    }

    // Media: on closed shapes, whose surface lets light in (no material: an index-matched
    // boundary; or a smooth or rough dielectric: a glass of milk); one medium per entry,
    // tabulated once per distinct medium.
    let mut media: Vec<crate::medium::Medium> = Vec::new();
    let mut medium_plans: Vec<MediumPlan> = Vec::new();
    let mut shape_medium_of = vec![crate::medium::NO_MEDIUM; shapes.len()];
    let mut shape_interface = vec![false; shapes.len()];
    for (k, shape) in shapes.iter().enumerate() {
        let i = shape_entry[k];
        let Some(plan) = &plans[i] else { continue };
        let at = format!("shapes[{i}]");
        let entry = &file.shapes[i];
        if shape_emission(entry).1.is_some() {
            return Err(err(format!(
                "{at}.medium: a shape with a medium cannot also emit (emission is given)"
            )));
        }
        if shapes
            .iter()
            .enumerate()
            .filter(|(j, _)| shape_entry[*j] == i)
            .count()
            > 1
        {
            return Err(err(format!(
                "{at}.medium: expected a mesh of one material around the medium, got a mesh whose groups use several"
            )));
        }
        if !shape.is_closed() {
            return Err(err(format!(
                "{at}.medium: expected a closed shape (a sphere, or a mesh whose every edge is shared by two triangles) around the medium, got an open {}",
                match entry {
                    ShapeFile::Sphere(_) => "sphere",
                    ShapeFile::Triangle(_) => "triangle",
                    ShapeFile::Plane(_) => "plane",
                    ShapeFile::Quad(_) => "quad",
                    ShapeFile::Mesh(_) => "mesh",
                }
            )));
        }
        match &materials[shape.material as usize] {
            _ if shape_emission(entry).0.is_none() => shape_interface[k] = true,
            Material::Dielectric(_) | Material::RoughDielectric(_) => {}
            _ => {
                return Err(err(format!(
                    "{at}.material: a shape with a medium needs a surface light can enter: no material (an index-matched boundary) or a dielectric, got {:?}",
                    material_names[shape.material as usize]
                )))
            }
        }
        // The fuzzing harness never renders: it checks the medium's keys and shape but
        // does not spend seconds tabulating Lorenz–Mie (the shape is left without one).
        if sky_tables == SkyTables::Skip && matches!(plan, MediumPlan::Mie(_)) {
            continue;
        }
        let id = match medium_plans.iter().position(|p| p == plan) {
            Some(id) => id,
            None => {
                media.push(match plan {
                    MediumPlan::Mie(spec) => crate::medium::Medium::LorenzMie(
                        crate::medium::LorenzMieMedium::new(spec.clone()),
                    ),
                    MediumPlan::Hg {
                        sigma_a,
                        sigma_s,
                        g,
                    } => crate::medium::Medium::HenyeyGreenstein(crate::medium::HgMedium::new(
                        DenseSpectrum::constant(*sigma_a),
                        DenseSpectrum::constant(*sigma_s),
                        *g,
                    )),
                });
                medium_plans.push(plan.clone());
                media.len() - 1
            }
        };
        shape_medium_of[k] = id as u32;
    }

    // The bounding sphere (the lights at infinity start their paths on it) must be
    // finite; the first shape that makes it overflow is named.
    let mut bbox = EMPTY_BOX;
    for (k, shape) in shapes.iter().enumerate() {
        bbox = grow_box(bbox, shape);
        let b = box_sphere(bbox);
        if !(b.center.is_finite() && b.radius.is_finite()) {
            return Err(err(format!(
                "shapes[{}]: expected shapes whose bounding sphere is finite in f32 (coordinates within about ±1e19), got shapes reaching from {} to {} with this one",
                shape_entry[k],
                fmt_points(&[bbox.0]),
                fmt_points(&[bbox.1])
            )));
        }
    }

    // Lights, in file order.
    let lights = file
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| match l {
            LightFile::Point(p) => Ok(Light::Point(PointLight {
                position: p.position.0,
                intensity: p.intensity.spectrum(),
            })),
            LightFile::Directional(d) => Ok(Light::Directional(DirectionalLight {
                direction: d.direction.unit(),
                radiance: d.radiance.spectrum(),
            })),
            LightFile::Sun(s) => {
                let deg = s
                    .angular_radius
                    .map_or(crate::light::sun::SUN_ANGULAR_RADIUS_DEG, |a| a.0);
                if deg >= 90.0 {
                    return Err(err(format!(
                        "lights[{i}].angular_radius: expected degrees in (0, 90), got {deg}"
                    )));
                }
                let mut sun = SunLight::new(s.direction.unit(), s.irradiance.spectrum(), deg.to_radians());
                if !sun.radiance.values().iter().all(|v| v.is_finite()) {
                    return Err(err(format!(
                        "lights[{i}]: the sun's radiance (irradiance / solid angle of the disk) overflows f32 with angular_radius = {} degrees and irradiance up to {}; expected a larger angular_radius or a smaller irradiance",
                        super::file::fmt_f32(deg),
                        super::file::fmt_f32(sun.irradiance.max_value())
                    )));
                }
                if let Some(p) = &s.portal {
                    let (o, e1, e2) = (p.origin.0, p.edge1.0, p.edge2.0);
                    if cross_overflows(o, o + e1, o + e2) || !(o + e1 + e2).is_finite() {
                        return Err(err(format!(
                            "lights[{i}].portal: expected a portal whose corners and edges' cross product are finite in f32 (coordinates within about ±1e19), got origin {} and edges {} and {}",
                            fmt_points(&[o]),
                            fmt_points(&[e1]),
                            fmt_points(&[e2])
                        )));
                    }
                    if is_degenerate(o, o + e1, o + e2) {
                        return Err(err(format!(
                            "lights[{i}].portal: expected edge1 and edge2 spanning a non-zero area, got {} and {}",
                            fmt_points(&[e1]),
                            fmt_points(&[e2])
                        )));
                    }
                    sun.portal = Some(crate::light::Portal::new(o, e1, e2));
                }
                Ok(Light::Sun(sun))
            }
            LightFile::Spot(s) => {
                let angle = s.cone_angle.map_or(30.0, |a| a.0);
                let delta = s.cone_delta.map_or(5.0, |a| a.0);
                if angle > 90.0 {
                    return Err(err(format!(
                        "lights[{i}].cone_angle: expected degrees in (0, 90], got {angle}"
                    )));
                }
                if delta > angle {
                    return Err(err(format!(
                        "lights[{i}].cone_delta: expected degrees in [0, cone_angle = {angle}], got {delta}"
                    )));
                }
                Ok(Light::Spot(SpotLight {
                    position: s.position.0,
                    direction: s.direction.unit(),
                    intensity: s.intensity.spectrum(),
                    cos_falloff_start: (angle - delta).to_radians().cos(),
                    cos_falloff_end: angle.to_radians().cos(),
                }))
            }
        })
        .collect::<Result<Vec<_>>>()?;
    let mut lights = lights;

    // Area lights: one per emitting shape, after the file's lights.
    let mut shape_light = vec![crate::scene::NO_LIGHT; shapes.len()];
    for (k, shape) in shapes.iter().enumerate() {
        let (_, emission, two_sided) = shape_emission(&file.shapes[shape_entry[k]]);
        let Some(e) = emission else { continue };
        if e.0.max_value() <= 0.0 {
            continue;
        }
        let geometry = match &shape.kind {
            ShapeKind::Sphere { center, radius } => crate::light::AreaLight::new(
                k as u32,
                e.spectrum(),
                two_sided.unwrap_or(false),
                crate::light::AreaShape::Sphere {
                    center: *center,
                    radius: *radius,
                },
            ),
            ShapeKind::Mesh(m) => crate::light::AreaLight::triangles(
                k as u32,
                e.spectrum(),
                two_sided.unwrap_or(false),
                m.indices
                    .iter()
                    .map(|t| t.map(|v| m.positions[v as usize]))
                    .collect(),
            ),
        };
        shape_light[k] = lights.len() as u32;
        lights.push(Light::Area(geometry));
    }

    let background = file
        .background
        .as_ref()
        .map_or_else(|| DenseSpectrum::constant(0.0), |b| b.spectrum());

    let mut settings = RenderSettings::default();
    if let Some(r) = &file.render {
        if let Some(x) = r.spp {
            settings.spp = x.0;
        }
        if let Some(x) = r.max_depth {
            settings.max_depth = x.0;
        }
        if let Some(x) = r.epsilon {
            settings.epsilon = x.0;
        }
        if let Some(x) = r.seed {
            settings.seed = x;
        }
        if let Some(name) = &r.integrator {
            settings.integrator =
                IntegratorKind::parse(name).map_err(|e| err(format!("render.integrator: {e}")))?;
        }
        if let Some(x) = r.rr_depth {
            settings.rr_depth = x;
        }
        if let Some(name) = &r.offset {
            settings.offset =
                OffsetMode::parse(name).map_err(|e| err(format!("render.offset: {e}")))?;
        }
        if let Some(name) = &r.light_sampler {
            settings.light_sampler = match name.as_str() {
                "power" => LightSamplerKind::Power,
                "uniform" => LightSamplerKind::Uniform,
                other => {
                    return Err(err(format!(
                        "render.light_sampler: expected power or uniform, got {other:?}"
                    )))
                }
            };
        }
    }

    let sky = match &file.sky {
        Some(sf) => {
            let plan = plan_sky(sf, &lights, &background).map_err(err)?;
            match sky_tables {
                SkyTables::Build => Some(std::sync::Arc::new(plan.tabulate())),
                SkyTables::Skip => None,
            }
        }
        None => None,
    };

    let c = &file.camera;
    if !(c.look_at.0 - c.eye.0).length().is_finite() {
        return Err(err(format!(
            "camera: expected eye and look_at at a distance finite in f32, got eye = {} and look_at = {}",
            fmt_points(&[c.eye.0]),
            fmt_points(&[c.look_at.0])
        )));
    }
    let d = c.d.map_or(1.0, |d| d.0);
    if !(crate::camera::D_MIN..=crate::camera::D_MAX).contains(&d) {
        return Err(err(format!(
            "camera.d: expected a camera constant in [{:e}, {:e}] (a vertical field of view from about 180° down to 1e-6 rad), got {}",
            crate::camera::D_MIN,
            crate::camera::D_MAX,
            super::file::fmt_f32(d)
        )));
    }
    let camera = Camera::new(
        c.eye.0,
        c.look_at.0,
        c.up.map_or(Vec3::Y, |u| u.unit()),
        d,
        c.resolution.width,
        c.resolution.height,
    )
    .map_err(|e| err(format!("camera: {e}")))?;

    let inputs = crate::files::hash_inputs(&base_dir, inputs).map_err(err)?;
    let mut scene = Scene::from_parts(super::SceneParts {
        source: path.to_path_buf(),
        camera,
        shapes,
        materials,
        material_names,
        lights,
        shape_light,
        background,
        sky,
        settings,
    });
    scene.inputs = inputs;
    scene.media = std::sync::Arc::new(media);
    scene.shape_medium = shape_medium_of;
    scene.shape_interface = shape_interface;
    Ok(scene)
}

/// The sphere around the shapes' bounding box (a unit sphere at the origin for a scene
/// without shapes).
pub fn scene_bounds(shapes: &[Shape]) -> crate::light::SceneBounds {
    let mut b = EMPTY_BOX;
    for s in shapes {
        b = grow_box(b, s);
    }
    box_sphere(b)
}

/// A bounding box (lo, hi); lo > hi when empty.
type Box3 = (Vec3, Vec3);

const EMPTY_BOX: Box3 = (Vec3::INFINITY, Vec3::NEG_INFINITY);

/// `b` grown to hold shape `s`.
fn grow_box((mut lo, mut hi): Box3, s: &Shape) -> Box3 {
    match &s.kind {
        ShapeKind::Sphere { center, radius } => {
            lo = lo.min(*center - Vec3::splat(*radius));
            hi = hi.max(*center + Vec3::splat(*radius));
        }
        ShapeKind::Mesh(m) => {
            for p in &m.positions {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
    }
    (lo, hi)
}

/// The sphere around box `b` (a unit sphere at the origin for an empty box).
fn box_sphere((lo, hi): Box3) -> crate::light::SceneBounds {
    if !(lo.x <= hi.x) {
        return crate::light::SceneBounds {
            center: Vec3::ZERO,
            radius: 1.0,
        };
    }
    // Not 0.5 (lo + hi), which overflows for a shape near ±3e38 (the same value
    // elsewhere: halving is exact).
    let center = 0.5 * lo + 0.5 * hi;
    crate::light::SceneBounds {
        center,
        radius: (0.5 * (hi - lo).length()).max(1e-6),
    }
}

/// The refractive-index model a scene file's `ior` value describes (a number, a catalogue
/// name, `{ sellmeier = .. }`, `{ cauchy = .. }` or `{ table = "file.csv" }`, read
/// relative to `base_dir`), checked as the loader checks it; the error is the loader's
/// message after `at` (the key path it names). For the Python module's `heron.ior`.
pub fn ior_from_value(
    at: &str,
    value: toml::Value,
    base_dir: &Path,
) -> std::result::Result<Ior, String> {
    use serde::Deserialize as _;
    let spec = IorSpec::deserialize(value).map_err(|e| format!("{at}: {}", e.message()))?;
    build_ior(at, &spec, base_dir, &mut Vec::new())
}

/// The refractive-index model of `spec`; a table file is read relative to `base_dir`.
fn build_ior(
    at: &str,
    spec: &IorSpec,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> std::result::Result<Ior, String> {
    let ior = match spec {
        IorSpec::Constant(n) => Ior::Constant(*n),
        IorSpec::Named(name) => crate::spectrum::ior::named(name)
            .ok_or_else(|| format!("{at}: unknown refractive-index model {name:?}"))?,
        IorSpec::Sellmeier { b, c } => Ior::sellmeier(b, c).map_err(|e| format!("{at}: {e}"))?,
        IorSpec::Cauchy([a, b, c]) => Ior::Cauchy {
            a: *a,
            b: *b,
            c: *c,
        },
        IorSpec::Table(file) => {
            let p = base_dir.join(file);
            let csv =
                crate::spectrum::csv::SpectrumCsv::read(&p).map_err(|e| format!("{at}: {e}"))?;
            inputs.push(file.clone());
            Ior::Table(csv.to_dense())
        }
    };
    ior.validate().map_err(|e| format!("{at}: {e}"))?;
    Ok(ior)
}

/// The complex index of `spec`; a table is read relative to `base_dir`.
fn build_metal(
    at: &str,
    spec: &MetalSpec,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> std::result::Result<ComplexIor, String> {
    let at = format!("{at}.metal");
    match spec {
        MetalSpec::Named(name) => crate::spectrum::metals::named(name)
            .ok_or_else(|| format!("{at}: unknown metal {name:?}")),
        MetalSpec::Table(file) => {
            inputs.push(file.clone());
            crate::spectrum::metals::read_nk(&base_dir.join(file)).map_err(|e| format!("{at}: {e}"))
        }
        MetalSpec::Constant { n, k } => Ok(ComplexIor {
            n: DenseSpectrum::constant(*n),
            k: DenseSpectrum::constant(*k),
        }),
    }
}

fn build_material(
    at: &str,
    m: &MaterialFile,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> std::result::Result<Material, String> {
    Ok(match m {
        MaterialFile::Lambertian(l) => Material::Lambertian(Lambertian {
            rho_d: l.rho_d.spectrum(),
        }),
        MaterialFile::Mirror(mi) => Material::Mirror(Mirror {
            // Left out: the lecture's ideal mirror, exactly 1 at every wavelength.
            rho_s: mi
                .rho_s
                .as_ref()
                .map_or_else(|| DenseSpectrum::constant(1.0), |r| r.spectrum()),
        }),
        MaterialFile::Dielectric(d) => {
            let mut interface = Dielectric::new(
                build_ior(&format!("{at}.ior"), &d.ior, base_dir, inputs)?,
                d.fresnel.unwrap_or(true),
            );
            if let Some(o) = &d.outside_ior {
                interface.outside = build_ior(&format!("{at}.outside_ior"), o, base_dir, inputs)?;
            }
            let alpha = d.roughness.map_or(0.0, |r| r.0);
            if alpha < MIN_ALPHA {
                Material::Dielectric(interface)
            } else {
                if d.fresnel == Some(false) {
                    return Err(format!(
                        "{at}.fresnel: false applies to the smooth interface (the lecture's pure refraction), not with roughness = {alpha}"
                    ));
                }
                Material::RoughDielectric(RoughDielectric {
                    interface,
                    distribution: TrowbridgeReitz { alpha },
                })
            }
        }
        MaterialFile::Conductor(c) => {
            let ior = build_metal(at, &c.metal, base_dir, inputs)?;
            let alpha = c.roughness.map_or(0.0, |r| r.0);
            if alpha < MIN_ALPHA {
                Material::Conductor(Conductor { ior })
            } else {
                Material::RoughConductor(RoughConductor {
                    ior,
                    distribution: TrowbridgeReitz { alpha },
                })
            }
        }
        MaterialFile::Glossy(g) => {
            if g.fresnel.is_some() && g.ior.is_none() {
                return Err(format!(
                    "{at}.fresnel: expected only together with ior (fresnel weights the refractive base), but ior is not given"
                ));
            }
            // Energy conservation, seed "Glossy materials": ρd + ρs ≤ 1.
            let rho_s = g.rho_s.0;
            let sum_max = match g.rho_d.0.rgb() {
                Some(rgb) => rgb.iter().fold(f32::MIN, |a, &c| a.max(c + rho_s)),
                None => g.rho_d.0.max_value() + rho_s,
            };
            if sum_max > 1.0 + 1e-6 {
                let rho_d = match &g.rho_d.0 {
                    Colour::Grey(x) => format!("{x}"),
                    Colour::Rgb(c) => format!("[{}, {}, {}]", c[0], c[1], c[2]),
                    Colour::Named { spectrum, scale } => {
                        format!("{{ spectrum = {spectrum:?}, scale = {scale} }}")
                    }
                };
                return Err(format!(
                    "{at}: expected rho_d + rho_s <= 1 in every channel (energy conservation), got rho_d = {rho_d} and rho_s = {rho_s} (sum up to {sum_max})"
                ));
            }
            Material::Glossy(Glossy {
                rho_d: g.rho_d.spectrum(),
                rho_s,
                shininess: g.shininess.0,
                base: match &g.ior {
                    Some(spec) => Some(Dielectric::new(
                        build_ior(&format!("{at}.ior"), spec, base_dir, inputs)?,
                        g.fresnel.unwrap_or(true),
                    )),
                    None => None,
                },
            })
        }
    })
}

/// The `[sky]` model, checked and constructed with the scene's first sun light, before
/// its (slow) tabulation.
struct SkyPlan {
    model: String,
    sky: crate::sky::Sky,
    sun_dir: Vec3,
    factor: DenseSpectrum,
    replaces_background: bool,
}

impl SkyPlan {
    /// Tabulates the model over (θ, λ) for rendering.
    fn tabulate(self) -> crate::sky::SceneSky {
        crate::sky::SceneSky {
            table: crate::sky::table::SkyTable::build(&self.sky),
            model: self.model,
            sun_dir: self.sun_dir,
            factor: self.factor,
            replaces_background: self.replaces_background,
        }
    }
}

/// Checks `[sky]` and constructs its model with the scene's first sun light.
fn plan_sky(
    sf: &super::file::SkyFile,
    lights: &[Light],
    background: &DenseSpectrum,
) -> std::result::Result<SkyPlan, String> {
    use crate::sky::{AirySky, AristotleSky, ConstantSky, DescartesSky, MieSky, Polarisation, Sky};
    let sun = lights.iter().find_map(|l| match l {
        Light::Sun(s) => Some(s),
        _ => None,
    });
    let Some(sun) = sun else {
        return Err("sky: expected a light of type \"sun\" (the sky takes its direction and angular radius)".into());
    };
    let alpha = sun.angular_radius as f64;
    let model = sf.model.as_str();
    let physical = matches!(model, "descartes" | "airy" | "mie");
    if sf.orders.is_some() && !matches!(model, "descartes" | "airy") {
        return Err(format!(
            "sky.orders: applies to descartes and airy, not {model}"
        ));
    }
    if sf.polarisation.is_some() && !physical {
        return Err(format!(
            "sky.polarisation: applies to descartes, airy and mie, not {model}"
        ));
    }
    if sf.droplet_radius.is_some() && !matches!(model, "airy" | "mie") {
        return Err(format!(
            "sky.droplet_radius: applies to airy and mie, not {model}"
        ));
    }
    if sf.drops.is_some() && !matches!(model, "airy" | "mie") {
        return Err(format!("sky.drops: applies to airy and mie, not {model}"));
    }
    if sf.drops.is_some() && sf.droplet_radius.is_some() {
        return Err(
            "sky.droplet_radius: one radius; with sky.drops give the radius there (distribution = \"monodisperse\", radius_mm = …)"
                .into(),
        );
    }
    if let Some(p) = sf.debye {
        if model != "mie" {
            return Err(format!("sky.debye: applies to mie, not {model}"));
        }
        if p > crate::sky::mie::MAX_DEBYE_TERM {
            return Err(format!(
                "sky.debye: expected a term p in 0..={}, got {p}",
                crate::sky::mie::MAX_DEBYE_TERM
            ));
        }
    }
    let dsd = |max_mm: f64| -> std::result::Result<
        Option<(crate::drops::DropSizeDistribution, usize)>,
        String,
    > {
        let Some(f) = &sf.drops else { return Ok(None) };
        let (d, n) = f.parse("sky.drops")?;
        let n = if model == "mie" && f.nodes.is_none() {
            crate::drops::MIE_DEFAULT_NODES
        } else {
            n
        };
        let largest = d.max_radius_mm();
        if largest > max_mm {
            return Err(format!(
                "sky.drops: the {model} sky takes radii up to {max_mm} mm; this distribution reaches {largest:.3} mm"
            ));
        }
        Ok(Some((d, n)))
    };
    let orders = match &sf.orders {
        None => vec![1, 2],
        Some(o) if !o.is_empty() && o.iter().all(|k| *k == 1 || *k == 2) => {
            let mut o = o.clone();
            o.sort_unstable();
            o.dedup();
            o
        }
        Some(o) => {
            return Err(format!(
                "sky.orders: expected a non-empty subset of [1, 2], got {o:?}"
            ))
        }
    };
    let pol = match sf.polarisation.as_deref().unwrap_or("unpolarised") {
        "unpolarised" | "unpolarized" => Polarisation::Unpolarised,
        "s" => Polarisation::S,
        "p" => Polarisation::P,
        other => {
            return Err(format!(
                "sky.polarisation: expected unpolarised, s or p, got {other:?}"
            ))
        }
    };
    let radius = || -> std::result::Result<f64, String> {
        let r = sf.droplet_radius.map(|r| r.0 as f64).ok_or_else(|| {
            format!("sky.droplet_radius: the {model} model needs a drop radius in mm")
        })?;
        if r > crate::sky::profile::MIE_MAX_RADIUS_MM {
            return Err(format!(
                "sky.droplet_radius: expected at most {} mm, got {r}",
                crate::sky::profile::MIE_MAX_RADIUS_MM
            ));
        }
        Ok(r)
    };
    let sky = match model {
        "constant" => Sky::Constant(ConstantSky::new(background.clone())),
        "aristotle" => Sky::Aristotle(AristotleSky::new(alpha, background.clone())),
        "descartes" => {
            let mut d = DescartesSky::water(alpha);
            d.orders = orders;
            d.polarisation = pol;
            Sky::Descartes(d)
        }
        "airy" => {
            let mut a = match dsd(10.0)? {
                Some((d, n)) => AirySky::water(1.0, alpha).with_distribution(&d, n),
                None => AirySky::water(radius()?, alpha),
            };
            a.orders = orders;
            a.polarisation = pol;
            Sky::Airy(a)
        }
        "mie" => {
            let mut m = match dsd(crate::sky::profile::MIE_MAX_RADIUS_MM)? {
                Some((d, n)) => MieSky::water(1.0, alpha).with_distribution(&d, n),
                None => MieSky::water(radius()?, alpha),
            };
            m.polarisation = pol;
            m.debye = sf.debye;
            if m.drops.len() > 1 {
                // One Mie series per node and wavelength: a table every 10 nm, interpolated
                // (the bows move by ≤ 0.06° over 10 nm, well inside the 0.53° disk), halves
                // the scene's 95 wavelengths of the sky table.
                m.lambda_step_nm = 10.0;
            }
            Sky::Mie(m)
        }
        other => {
            return Err(format!(
            "sky.model: expected one of constant, aristotle, descartes, airy, mie, got {other:?}"
        ))
        }
    };
    let scale = sf.scale.map_or(1.0, |s| s.0);
    Ok(SkyPlan {
        model: model.to_string(),
        sky,
        sun_dir: -sun.direction,
        factor: if physical {
            sun.irradiance.scaled(scale)
        } else {
            DenseSpectrum::constant(scale)
        },
        replaces_background: !physical,
    })
}

/// A shape entry's material name, emission and two-sidedness.
/// A shape entry's medium.
fn shape_medium(s: &ShapeFile) -> Option<&MediumFile> {
    match s {
        ShapeFile::Sphere(x) => x.medium.as_ref(),
        ShapeFile::Triangle(x) => x.medium.as_ref(),
        ShapeFile::Plane(x) => x.medium.as_ref(),
        ShapeFile::Quad(x) => x.medium.as_ref(),
        ShapeFile::Mesh(x) => x.medium.as_ref(),
    }
}

/// Drop-size quadrature nodes of a medium's distribution when its table gives none:
/// each node is one Lorenz–Mie tabulation (about 16 s for 0.5 mm drops).
pub const MEDIUM_DEFAULT_NODES: usize = 8;

/// What a `medium` table builds: the key path is `at` (`shapes[i].medium`).
#[derive(Clone, Debug, PartialEq)]
enum MediumPlan {
    Mie(crate::medium::MieSpec),
    Hg { sigma_a: f32, sigma_s: f32, g: f32 },
}

/// Checks a `medium` table against its type. Lorenz–Mie radii are limited to
/// 0.1 µm–1 mm: the series has x + 4x^{1/3} + 2 terms per angle (x = 2πr/λ, 17 500 at
/// 1 mm and 360 nm), so larger drops would take minutes to tabulate.
fn plan_medium(at: &str, m: &MediumFile) -> std::result::Result<MediumPlan, String> {
    fn given(name: &'static str, v: bool) -> Option<&'static str> {
        if v {
            Some(name)
        } else {
            None
        }
    }
    match m.kind.as_str() {
        "mie" => {
            if let Some(k) = given("sigma_a", m.sigma_a.is_some())
                .or(given("sigma_s", m.sigma_s.is_some()))
                .or(given("g", m.g.is_some()))
            {
                return Err(format!(
                    "{at}.{k}: applies to type = \"henyey-greenstein\", not to type = \"mie\" (whose coefficients come from Lorenz-Mie theory)"
                ));
            }
            // The drops: one radius, or a distribution's quadrature nodes (number
            // fractions summing to 1).
            let (nodes, dist) = match (m.radius_mm, &m.drops) {
                (Some(r), None) => (
                    vec![crate::drops::DropNode {
                        radius_mm: r.0 as f64,
                        weight: 1.0,
                    }],
                    None,
                ),
                (None, Some(d)) => {
                    let (dist, n) = d.parse(&format!("{at}.drops"))?;
                    // Each node is a Lorenz–Mie tabulation (seconds for rain drops), so
                    // media default to fewer nodes than skies.
                    let n = if d.nodes.is_none() {
                        MEDIUM_DEFAULT_NODES
                    } else {
                        n
                    };
                    (dist.nodes(n), Some(dist))
                }
                (Some(_), Some(_)) => {
                    return Err(format!(
                        "{at}: expected one of radius_mm (one drop radius) or drops (a distribution), got both"
                    ))
                }
                (None, None) => {
                    return Err(format!(
                        "{at}.radius_mm: missing required key (expected the drop radius in mm, or a drops table)"
                    ))
                }
            };
            for n in &nodes {
                if !(1e-4..=1.0).contains(&n.radius_mm) {
                    return Err(if dist.is_some() {
                        format!(
                            "{at}.drops: expected drop radii in [0.0001, 1] mm (larger drops take minutes to tabulate), but the distribution has a quadrature node at {:.4} mm",
                            n.radius_mm
                        )
                    } else {
                        format!(
                            "{at}.radius_mm: expected a drop radius in [0.0001, 1] mm, got {}",
                            n.radius_mm
                        )
                    });
                }
            }
            // Σ wᵢ (4/3) π rᵢ³: the mean drop volume in m³.
            let mean_volume: f64 = nodes
                .iter()
                .map(|n| n.weight * 4.0 / 3.0 * std::f64::consts::PI * (n.radius_mm * 1e-3).powi(3))
                .sum();
            let density = match (m.number_density, m.liquid_water_content) {
                (Some(n), None) => n.0 as f64,
                // N = LWC / (ρ_water ⟨V⟩), ρ_water = 10⁶ g/m³.
                (None, Some(w)) => w.0 as f64 / (1e6 * mean_volume),
                (Some(_), Some(_)) => {
                    return Err(format!(
                        "{at}: expected one of number_density (drops per m³) or liquid_water_content (g/m³), got both"
                    ))
                }
                // Marshall–Palmer defines its own number density (N0/Λ).
                (None, None) => match dist.as_ref().and_then(|d| d.number_density()) {
                    Some(n) => n,
                    None => {
                        return Err(format!(
                            "{at}.number_density: missing required key (expected drops per m³, or liquid_water_content in g/m³)"
                        ))
                    }
                },
            };
            let step = m.lambda_step.map_or(10.0, |s| s.0);
            if !(1.0..=50.0).contains(&step) {
                return Err(format!(
                    "{at}.lambda_step: expected nm between wavelength nodes in [1, 50], got {step}"
                ));
            }
            let cutoff = m.forward_cutoff.map_or(0.0, |c| c.0 as f64);
            if cutoff > 10.0 {
                return Err(format!(
                    "{at}.forward_cutoff: expected degrees in [0, 10] (the diffraction peak counted as unscattered), got {cutoff}"
                ));
            }
            Ok(MediumPlan::Mie(crate::medium::MieSpec {
                population: nodes
                    .iter()
                    .map(|n| crate::medium::PopulationNode {
                        radius_m: n.radius_mm * 1e-3,
                        number_density: density * n.weight,
                    })
                    .collect(),
                absorption: m.absorption.unwrap_or(true),
                lambda_step_nm: step,
                forward_cutoff_deg: cutoff,
            }))
        }
        "henyey-greenstein" => {
            if let Some(k) = given("radius_mm", m.radius_mm.is_some())
                .or(given("drops", m.drops.is_some()))
                .or(given("number_density", m.number_density.is_some()))
                .or(given(
                    "liquid_water_content",
                    m.liquid_water_content.is_some(),
                ))
                .or(given("absorption", m.absorption.is_some()))
                .or(given("lambda_step", m.lambda_step.is_some()))
                .or(given("forward_cutoff", m.forward_cutoff.is_some()))
            {
                return Err(format!(
                    "{at}.{k}: applies to type = \"mie\", not to type = \"henyey-greenstein\""
                ));
            }
            let g = m.g.unwrap_or(0.0);
            if !(g.is_finite() && g.abs() < 1.0) {
                return Err(format!(
                    "{at}.g: expected a mean cosine in (-1, 1), got {g}"
                ));
            }
            let sigma_a = m.sigma_a.map_or(0.0, |x| x.0);
            let sigma_s = m.sigma_s.map_or(0.0, |x| x.0);
            if !(sigma_a + sigma_s).is_finite() || sigma_a + sigma_s <= 0.0 {
                return Err(format!(
                    "{at}: expected sigma_a + sigma_s finite and > 0, got {sigma_a} + {sigma_s}"
                ));
            }
            Ok(MediumPlan::Hg {
                sigma_a,
                sigma_s,
                g,
            })
        }
        other => Err(format!(
            "{at}.type: expected one of {}, got {other:?}",
            super::file::MEDIUM_TYPES.join(", ")
        )),
    }
}

fn shape_emission(s: &ShapeFile) -> (Option<&String>, Option<&Emission>, Option<bool>) {
    match s {
        ShapeFile::Sphere(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
        ShapeFile::Triangle(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
        ShapeFile::Plane(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
        ShapeFile::Quad(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
        ShapeFile::Mesh(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
    }
}

fn mesh_shape(positions: Vec<Vec3>, indices: Vec<[u32; 3]>, material: u32) -> Shape {
    Shape {
        kind: ShapeKind::Mesh(Mesh { positions, indices }),
        material,
    }
}

/// Whether the cross product of the edges b − a and c − a (twice the area, and the normal
/// Embree and the lights compute) overflows f32: coordinates beyond about ±1e19.
fn cross_overflows(a: Vec3, b: Vec3, c: Vec3) -> bool {
    !(b - a).cross(c - a).is_finite()
}

/// Zero area up to f32 rounding: |e1 × e2| ≤ ε |e1| |e2| (the angle between the edges is
/// below about 1e-7 rad), or a zero-length edge.
fn is_degenerate(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (e1, e2) = (b - a, c - a);
    let cross = e1.cross(e2).length();
    let limit = f32::EPSILON * e1.length() * e2.length();
    // Not strictly above the limit, NaN included (overflowing edges).
    cross.partial_cmp(&limit) != Some(std::cmp::Ordering::Greater)
}

fn fmt_points(v: &[Vec3]) -> String {
    let p: Vec<String> = v
        .iter()
        .map(|p| {
            let f = super::file::fmt_f32;
            format!("[{}, {}, {}]", f(p.x), f(p.y), f(p.z))
        })
        .collect();
    if p.len() == 1 {
        p[0].clone()
    } else {
        format!("[{}]", p.join(", "))
    }
}

/// A `type = "mesh"` entry: one shape per material it uses. Mesh-file problems are
/// reported with the mesh file as `file` and the scene's key path in the message.
fn build_mesh(
    scene_path: &Path,
    base_dir: &Path,
    at: &str,
    m: &MeshFile,
    lookup: &dyn Fn(String, &str) -> Result<u32>,
    emitter_material: Option<u32>,
) -> Result<Vec<Shape>> {
    // Scene-file checks first: the material names.
    let default_material = match &m.material {
        Some(name) => Some(lookup(format!("{at}.material"), name)?),
        None => emitter_material,
    };
    let mut group_material = BTreeMap::new();
    for (group, name) in &m.groups {
        let gk = fmt_path(&[Seg::Key("groups".into()), Seg::Key(group.clone())]);
        group_material.insert(group.as_str(), lookup(format!("{at}.{gk}"), name)?);
    }
    if m.file.trim().is_empty() {
        return Err(scene_error(
            scene_path,
            format!("{at}.file: expected the path of an OBJ file, got an empty string"),
        ));
    }

    let mesh_path: PathBuf = base_dir.join(&m.file);
    let text = std::fs::read_to_string(&mesh_path).map_err(|e| {
        scene_error(
            &mesh_path,
            format!("{at}.file: cannot read the mesh file: {e}"),
        )
    })?;
    mesh_shapes(
        &text,
        scene_path,
        &mesh_path,
        at,
        m,
        &group_material,
        default_material,
    )
}

/// The shapes of mesh entry `m` (at key path `at`) from the text of its OBJ file
/// `mesh_path`, with the materials of its groups already looked up.
pub(crate) fn mesh_shapes(
    text: &str,
    scene_path: &Path,
    mesh_path: &Path,
    at: &str,
    m: &MeshFile,
    group_material: &BTreeMap<&str, u32>,
    default_material: Option<u32>,
) -> Result<Vec<Shape>> {
    let merr = |msg: String| scene_error(mesh_path, format!("{at}.file: {msg}"));
    let groups = obj::parse_obj(text).map_err(merr)?;

    for g in m.groups.keys() {
        if !groups.iter().any(|x| &x.name == g) {
            let mut names: Vec<&str> = groups
                .iter()
                .filter(|x| !x.indices.is_empty())
                .map(|x| x.name.as_str())
                .collect();
            names.dedup();
            let gk = fmt_path(&[Seg::Key("groups".into()), Seg::Key(g.clone())]);
            return Err(scene_error(
                mesh_path,
                format!(
                    "{at}.{gk}: no object or group named {g:?} in the mesh (it has: {})",
                    names.join(", ")
                ),
            ));
        }
    }

    let scale = m.scale.map_or(1.0, |s| s.0);
    let translate = m.translate.map_or(Vec3::ZERO, |t| t.0);

    // Gather the triangles per material, in the order the materials first appear.
    struct Part {
        material: u32,
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        /// Vertex index by position: OBJ groups come with their own vertex arrays, so
        /// vertices are shared within a shape by their (exact) coordinates.
        remap: HashMap<[u32; 3], u32>,
    }
    let mut parts: Vec<Part> = Vec::new();
    let mut any_triangle = false;
    for g in &groups {
        if g.indices.is_empty() {
            continue;
        }
        let material = match group_material.get(g.name.as_str()).copied().or(default_material) {
            Some(mat) => mat,
            None => {
                return Err(scene_error(
                    scene_path,
                    format!(
                        "{at}.material: missing required key (expected the name of a material for the mesh's object {:?}, which groups does not list)",
                        g.name
                    ),
                ))
            }
        };
        let part = match parts.iter().position(|p| p.material == material) {
            Some(k) => &mut parts[k],
            None => {
                parts.push(Part {
                    material,
                    positions: Vec::new(),
                    indices: Vec::new(),
                    remap: HashMap::new(),
                });
                parts.last_mut().expect("just pushed")
            }
        };
        for tri in &g.indices {
            let p = tri.map(|i| g.positions[i as usize] * scale + translate);
            if p.iter().any(|x| !x.is_finite()) {
                return Err(merr(format!(
                    "a vertex of object {:?} is not finite after scale {} and translate {}",
                    g.name,
                    super::file::fmt_f32(scale),
                    fmt_points(&[translate])
                )));
            }
            if cross_overflows(p[0], p[1], p[2]) {
                return Err(merr(format!(
                    "a triangle of object {:?} is too large for f32 after scale {} and translate {}: expected its edges' cross product to be finite (coordinates within about ±1e19), got {}",
                    g.name,
                    super::file::fmt_f32(scale),
                    fmt_points(&[translate]),
                    fmt_points(&p)
                )));
            }
            // Zero-area triangles are never hit; they are dropped.
            if is_degenerate(p[0], p[1], p[2]) {
                continue;
            }
            any_triangle = true;
            let mut out = [0u32; 3];
            for (o, v) in out.iter_mut().zip(p) {
                let next = part.positions.len() as u32;
                // + 0.0 turns −0 into +0, so the two zeros share a vertex.
                let bits = (v + Vec3::ZERO).to_array().map(f32::to_bits);
                *o = *part.remap.entry(bits).or_insert_with(|| {
                    part.positions.push(v);
                    next
                });
            }
            part.indices.push(out);
        }
    }
    if !any_triangle {
        return Err(merr(
            "expected a mesh with at least one triangle of non-zero area, got none".into(),
        ));
    }
    Ok(parts
        .into_iter()
        .filter(|p| !p.indices.is_empty())
        .map(|p| mesh_shape(p.positions, p.indices, p.material))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ior_from_value_reads_a_scene_files_ior() {
        let eval = |v: toml::Value| ior_from_value("ior", v, Path::new("")).map(|i| i.eval(500.0));
        assert_eq!(eval(toml::Value::Float(1.5)), Ok(1.5));
        let named = crate::spectrum::ior::named("N-BK7").unwrap().eval(500.0);
        assert_eq!(eval(toml::Value::String("N-BK7".into())), Ok(named));
        let cauchy: toml::Value = toml::from_str::<toml::Table>("cauchy = [1.5, 0.0042]")
            .unwrap()
            .into();
        let n = eval(cauchy).unwrap();
        assert!((n - (1.5 + 0.0042 / 0.25)).abs() < 1e-6, "{n}");
        // The loader's messages, after the key path given.
        let e = eval(toml::Value::String("BK7".into())).unwrap_err();
        assert!(
            e.starts_with("ior: unknown refractive-index model \"BK7\", expected one of"),
            "{e}"
        );
        let e = eval(toml::Value::Float(-1.0)).unwrap_err();
        assert_eq!(e, "ior: expected a positive finite number, got -1");
        // A Cauchy model below 1 in the visible is refused as in a scene.
        let low: toml::Value = toml::from_str::<toml::Table>("cauchy = [0.5, 0.0]")
            .unwrap()
            .into();
        assert!(eval(low)
            .unwrap_err()
            .starts_with("ior: expected a refractive index ≥ 1"));
    }
}
