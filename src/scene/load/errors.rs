//! The loader's one-line messages: TOML syntax errors with line and column, serde's
//! errors rewritten in heron's words ("expected …, got …") at the full key path (serde's
//! internally tagged enums lose the path inside an item: the item is read again as the
//! struct of its `type`), key paths in TOML's spelling, and the points and numbers that
//! messages show.
use crate::error::HeronError;
use crate::scene::file::{
    show, CheckerboardFile, CoatedFile, ConductorFile, DielectricFile, DiffuseTransmissionFile,
    DirectionalLightFile, GlossyFile, ImageTextureFile, LambertianFile, LightFile, MaterialFile,
    MeshFile, MirrorFile, MixTextureFile, PlaneFile, PointLightFile, PolarizerFile, QuadFile,
    RetarderFile, ScaleTextureFile, ShapeFile, SphereFile, SpotLightFile, SunLightFile,
    TextureFile, ThinDielectricFile, TriangleFile, WavesFile,
};
use glam::Vec3;
use serde::de::DeserializeOwned;
use std::fmt::Write as _;
use std::path::Path;

/// Stage 1's message: a TOML syntax error at its line and column in `text`.
pub(super) fn toml_syntax(text: &str, e: &toml::de::Error) -> String {
    let msg = one_line(e.message());
    match e.span() {
        Some(span) => {
            let (line, col) = line_col(text, span.start);
            format!("line {line}, column {col}: TOML syntax error: {msg}")
        }
        None => format!("TOML syntax error: {msg}"),
    }
}

/// Stage 2's message: serde's error `e` reading `table` as a [`crate::scene::file::SceneFile`], at the full
/// key path and in heron's words.
pub(super) fn data_error(
    table: &toml::Table,
    e: &serde_path_to_error::Error<toml::de::Error>,
) -> String {
    let mut path = segments(e.path());
    let mut msg = e.inner().message().to_string();
    if let Some((p, m)) = refine(table, &path) {
        path = p;
        msg = m;
    }
    friendly(&path, &msg)
}

/// serde's derived structs (and internally tagged enums) also accept an array of their
/// fields in order, so `render = [1]` would quietly mean `spp = 1`. A scene file writes
/// these as tables; anything else is an error.
pub(super) fn require_tables(table: &toml::Table) -> std::result::Result<(), String> {
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

pub(super) fn scene_error(file: &Path, message: impl AsRef<str>) -> HeronError {
    HeronError::Scene {
        file: file.to_path_buf(),
        message: one_line(message.as_ref()),
    }
}

/// Joins the lines of a message with "; " so every error is one line.
pub(super) fn one_line(s: &str) -> String {
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
pub(super) enum Seg {
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
pub(super) fn fmt_path(path: &[Seg]) -> String {
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

/// The key path `base.k`, `k` quoted when it is not a bare key.
pub(super) fn key(base: &str, k: &str) -> String {
    fmt_path(&[Seg::Key(base.into()), Seg::Key(k.into())])
}

/// Whether `path` is an item of a collection tagged by `type`, and the type list.
fn tagged_item(path: &[Seg]) -> Option<&'static [&'static str]> {
    match path {
        [Seg::Key(c), Seg::Key(_)] if c == "materials" => Some(MaterialFile::NAMES),
        [Seg::Key(c), Seg::Index(_)] if c == "shapes" => Some(ShapeFile::NAMES),
        [Seg::Key(c), Seg::Index(_)] if c == "lights" => Some(LightFile::NAMES),
        [Seg::Key(c), Seg::Key(_)] if c == "textures" => Some(TextureFile::NAMES),
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
        ("materials", "coated") => check::<CoatedFile>(t),
        ("materials", "polarizer") => check::<PolarizerFile>(t),
        ("materials", "retarder") => check::<RetarderFile>(t),
        ("materials", "thin-dielectric") => check::<ThinDielectricFile>(t),
        ("materials", "diffuse-transmission") => check::<DiffuseTransmissionFile>(t),
        ("shapes", "sphere") => check::<SphereFile>(t),
        ("shapes", "triangle") => check::<TriangleFile>(t),
        ("shapes", "plane") => check::<PlaneFile>(t),
        ("shapes", "quad") => check::<QuadFile>(t),
        ("shapes", "mesh") => check::<MeshFile>(t),
        ("shapes", "waves") => check::<WavesFile>(t),
        ("lights", "point") => check::<PointLightFile>(t),
        ("lights", "directional") => check::<DirectionalLightFile>(t),
        ("lights", "sun") => check::<SunLightFile>(t),
        ("lights", "spot") => check::<SpotLightFile>(t),
        ("textures", "image") => check::<ImageTextureFile>(t),
        ("textures", "checkerboard") => check::<CheckerboardFile>(t),
        ("textures", "scale") => check::<ScaleTextureFile>(t),
        ("textures", "mix") => check::<MixTextureFile>(t),
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

/// Points as messages show them: `[x, y, z]`, several in brackets.
pub(super) fn fmt_points(v: &[Vec3]) -> String {
    let p: Vec<String> = v
        .iter()
        .map(|p| {
            let f = crate::scene::file::fmt_f32;
            format!("[{}, {}, {}]", f(p.x), f(p.y), f(p.z))
        })
        .collect();
    if p.len() == 1 {
        p[0].clone()
    } else {
        format!("[{}]", p.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every `type` of every tagged collection has its struct in `refine`, so an error
    /// inside any item is reported at its full key path.
    #[test]
    fn every_tagged_type_is_refined() {
        for (collection, item, names) in [
            ("materials", Seg::Key("m".into()), MaterialFile::NAMES),
            ("shapes", Seg::Index(0), ShapeFile::NAMES),
            ("lights", Seg::Index(0), LightFile::NAMES),
        ] {
            for name in names {
                let mut t = toml::Table::new();
                t.insert("type".into(), toml::Value::String(name.to_string()));
                t.insert("zzz".into(), toml::Value::Integer(1));
                let items = match &item {
                    Seg::Key(k) => {
                        let mut m = toml::Table::new();
                        m.insert(k.clone(), toml::Value::Table(t));
                        toml::Value::Table(m)
                    }
                    Seg::Index(_) => toml::Value::Array(vec![toml::Value::Table(t)]),
                };
                let mut table = toml::Table::new();
                table.insert(collection.into(), items);
                let path = [Seg::Key(collection.into()), item.clone()];
                let (_, msg) = refine(&table, &path)
                    .unwrap_or_else(|| panic!("{collection}: type {name} is not refined"));
                assert!(msg.contains("zzz"), "{name}: {msg}");
            }
        }
    }
}
