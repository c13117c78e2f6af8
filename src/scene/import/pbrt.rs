//! pbrt-v4 scene files (pbrt-v4 User's Guide, "Scene Description Format") to heron's
//! scene table: the tokens and directives with their line, the current transformation
//! matrix with `AttributeBegin`/`End`, materials (named and current), area lights, and
//! the shapes heron has. Conventions: pbrt's `Transform`/`ConcatTransform` matrices are
//! given column by column (pbrt transposes them), its camera looks along local +z with
//! +x to the image's right, `fov` spans the image's shorter axis, `maxdepth` counts
//! scattering events as heron's `max_depth` does, and a roughness is remapped to
//! α = √r unless `remaproughness` is false (pbrt-v4's `TrowbridgeReitzDistribution::
//! RoughnessToAlpha`).
//!
//! Object instancing (`ObjectBegin`/`ObjectEnd`/`ObjectInstance`) is flattened: every
//! `ObjectInstance` emits a copy of the object's shapes. The composition is pbrt-v4's
//! (`src/pbrt/scene.cpp`, `BasicSceneBuilder::Shape` and `::ObjectInstance`, and
//! `BasicScene::CreateAggregate`, which wraps the definition in a `TransformedPrimitive`):
//! a shape inside a definition keeps the CTM current at its `Shape` (render-from-object),
//! the instance the CTM current at its `ObjectInstance` (render-from-instance, the world
//! transform `renderFromWorld` cancelling between the two), so a copy's world-from-shape
//! matrix is CTM(instance) · CTM(shape). Everything else a copy has (material, reverse
//! orientation) is the definition's; instances may come before their definition (pbrt-v4
//! resolves them after parsing), and area lights in a definition do not emit.
use super::mitsuba::{float, relative_to, scene_table, table, vec3, Converted};
use super::xml::Diagnostic;
use glam::{DMat4, DVec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// Includes nested deeper than this are taken for a cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    line: u32,
}

fn tokenize(text: &str, file: &Path) -> Result<Vec<Token>, Diagnostic> {
    let mut out = Vec::new();
    let b = text.as_bytes();
    let (mut i, mut line) = (0usize, 1u32);
    let err = |line: u32, m: String| Diagnostic {
        file: file.to_path_buf(),
        line,
        message: m,
    };
    while i < b.len() {
        let c = b[i];
        if c == b'\n' {
            line += 1;
            i += 1;
        } else if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'#' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'[' || c == b']' {
            out.push(Token {
                tok: if c == b'[' { Tok::Open } else { Tok::Close },
                line,
            });
            i += 1;
        } else if c == b'"' {
            let start = i + 1;
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\n' {
                    return Err(err(line, "a string runs past the end of its line".into()));
                }
                // pbrt-v4's tokenizer keeps them, but a name or file name holding a
                // carriage return or another control character is a damaged file, and
                // it would break the one-line messages that quote the name.
                if b[i].is_ascii_control() && b[i] != b'\t' {
                    return Err(err(
                        line,
                        format!(
                            "a string holds the control character U+{:04X}; names and file names cannot",
                            b[i]
                        ),
                    ));
                }
                i += 1;
            }
            if i >= b.len() {
                return Err(err(line, "a string is not closed".into()));
            }
            out.push(Token {
                tok: Tok::Str(text[start..i].to_string()),
                line,
            });
            i += 1;
        } else {
            let start = i;
            while i < b.len() && !b[i].is_ascii_whitespace() && !b"[]\"#".contains(&b[i]) {
                i += 1;
            }
            let w = &text[start..i];
            let tok = if w
                .starts_with(|ch: char| ch.is_ascii_digit() || ch == '-' || ch == '+' || ch == '.')
            {
                match w.parse::<f64>() {
                    Ok(v) if v.is_finite() => Tok::Num(v),
                    _ => {
                        return Err(err(
                            line,
                            format!("expected a number, got {:?}", w.escape_debug().to_string()),
                        ))
                    }
                }
            } else {
                Tok::Word(w.to_string())
            };
            out.push(Token { tok, line });
        }
    }
    Ok(out)
}

/// One parameter: `"type name" value` or `"type name" [values]`.
#[derive(Clone, Debug)]
struct Param {
    ty: String,
    name: String,
    nums: Vec<f64>,
    strs: Vec<String>,
    line: u32,
    used: std::cell::Cell<bool>,
}

#[derive(Clone, Debug, Default)]
struct Params(Vec<Param>);

impl Params {
    fn get(&self, name: &str) -> Option<&Param> {
        let p = self.0.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }
    fn float(&self, name: &str) -> Option<f64> {
        self.get(name).and_then(|p| p.nums.first().copied())
    }
    fn string(&self, name: &str) -> Option<&str> {
        self.get(name)
            .and_then(|p| p.strs.first().map(String::as_str))
    }
}

#[derive(Clone)]
struct Graphics {
    ctm: DMat4,
    material: Option<String>,
    area: Option<(Value, bool)>,
    reverse: bool,
}

/// A shape as its `Shape` directive gave it, in its own (object) space: what
/// [`Conv::emit`] places with a matrix, once for a shape in the world and once per
/// `ObjectInstance` for a shape in an object definition.
#[derive(Clone, Debug)]
enum Geom {
    Sphere {
        radius: f64,
    },
    /// `trianglemesh` (3 indices a face) or `bilinearmesh` (4, pbrt's p00 p10 p01 p11).
    Mesh {
        kind: &'static str,
        points: Vec<DVec3>,
        faces: Vec<Vec<usize>>,
    },
    /// A PLY file, its path relative to the scene's folder.
    Ply {
        file: String,
    },
}

/// A `Shape` with the graphics state current at it (pbrt-v4's `ShapeSceneEntity`: the
/// render-from-object transform, reverse orientation, material and area light).
#[derive(Clone, Debug)]
struct ShapeDef {
    geom: Geom,
    ctm: DMat4,
    reverse: bool,
    material: String,
    area: Option<(Value, bool)>,
    file: PathBuf,
    line: u32,
}

/// An `ObjectBegin` … `ObjectEnd` definition.
#[derive(Clone, Debug)]
struct ObjectDef {
    name: String,
    file: PathBuf,
    line: u32,
    /// How many `Import`s deep it was opened: pbrt-v4 parses an imported file with a
    /// builder of its own, so a definition does not span an `Import`'s boundary
    /// (`BasicSceneBuilder::ObjectEnd`, `::MergeImported`).
    import_depth: usize,
    shapes: Vec<ShapeDef>,
}

/// What the shapes list holds until the end of the files: shapes, and instances to be
/// resolved then (pbrt-v4 resolves `ObjectInstance` names after parsing, so an instance
/// may come first), each in file order.
#[derive(Clone, Debug)]
enum Slot {
    Shape(Value),
    Instance {
        name: String,
        ctm: DMat4,
        file: PathBuf,
        line: u32,
    },
}

/// One open `AttributeBegin`, `TransformBegin` or `ObjectBegin`: the graphics state it
/// saved, and where it was opened (pbrt-v4's `pushedGraphicsStates` and `pushStack`).
#[derive(Clone)]
struct Pushed {
    g: Graphics,
    what: &'static str,
    file: PathBuf,
    line: u32,
}

struct Conv {
    base: PathBuf,
    strict: bool,
    warnings: Vec<Diagnostic>,
    materials: Table,
    named: HashMap<String, String>,
    shapes: Vec<Slot>,
    lights: Vec<Value>,
    background: Option<Value>,
    /// `[environment]` from an image `infinite` light.
    environment: Option<Value>,
    camera: Option<Table>,
    camera_from_world: Option<(DMat4, u32, PathBuf, f64)>,
    resolution: (i64, i64),
    render: Table,
    g: Graphics,
    stack: Vec<Pushed>,
    n_material: usize,
    default_material: Option<String>,
    /// The object being defined (between `ObjectBegin` and `ObjectEnd`).
    object: Option<ObjectDef>,
    objects: HashMap<String, ObjectDef>,
    import_depth: usize,
}

/// Converts the pbrt-v4 file `path`.
pub fn convert(path: &Path, strict: bool) -> Result<Converted, Diagnostic> {
    let mut c = Conv::new(path, strict);
    c.file(path, 0, None)?;
    c.finish(path)
}

/// Converts pbrt-v4 text already in memory, read as if from `path` (its `Include`s and
/// meshes are read from `path`'s folder).
pub fn convert_str(text: &str, path: &Path, strict: bool) -> Result<Converted, Diagnostic> {
    let mut c = Conv::new(path, strict);
    c.text(text, path, 0)?;
    c.finish(path)
}

impl Conv {
    fn new(path: &Path, strict: bool) -> Conv {
        Conv {
            base: path.parent().unwrap_or(Path::new("")).to_path_buf(),
            strict,
            warnings: Vec::new(),
            materials: Table::new(),
            named: HashMap::new(),
            shapes: Vec::new(),
            lights: Vec::new(),
            background: None,
            environment: None,
            camera: None,
            camera_from_world: None,
            resolution: (1280, 720),
            render: Table::new(),
            g: Graphics {
                ctm: DMat4::IDENTITY,
                material: None,
                area: None,
                reverse: false,
            },
            stack: Vec::new(),
            n_material: 0,
            default_material: None,
            object: None,
            objects: HashMap::new(),
            import_depth: 0,
        }
    }

    /// After the last file: the open definition is an error, the instances become
    /// shapes, and the camera and tables are put together.
    fn finish(mut self, path: &Path) -> Result<Converted, Diagnostic> {
        if let Some(o) = &self.object {
            return Err(self.diag(
                &o.file,
                o.line,
                format!(
                    "ObjectBegin {:?} is not closed by an ObjectEnd before the end of the file",
                    o.name
                ),
            ));
        }
        let shapes = self.instantiate()?;
        self.finish_camera(path)?;
        let mut t = scene_table(
            self.camera.take().expect("finish_camera sets it"),
            std::mem::take(&mut self.render),
            self.background.take(),
            std::mem::take(&mut self.materials),
            shapes,
            std::mem::take(&mut self.lights),
        );
        if let Some(e) = self.environment.take() {
            t.insert("environment".into(), e);
        }
        Ok(Converted {
            table: t,
            warnings: self.warnings,
        })
    }

    /// The shapes list with each `ObjectInstance` replaced by copies of its object's
    /// shapes, each placed by CTM(instance) · CTM(shape) (pbrt-v4 `src/pbrt/scene.cpp`:
    /// `renderFromInstance = RenderFromObject(0) * worldFromRender` applied on top of the
    /// shapes' own `renderFromObject`). An unknown name is an error at the instance, as
    /// in pbrt-v4's `CreateAggregate` ("object instance not defined"); an empty object
    /// gives nothing.
    fn instantiate(&mut self) -> Result<Vec<Value>, Diagnostic> {
        let slots = std::mem::take(&mut self.shapes);
        let objects = std::mem::take(&mut self.objects);
        let mut out = Vec::with_capacity(slots.len());
        for slot in slots {
            match slot {
                Slot::Shape(v) => out.push(v),
                Slot::Instance {
                    name,
                    ctm,
                    file,
                    line,
                } => {
                    let Some(o) = objects.get(&name) else {
                        return Err(self.diag(
                            &file,
                            line,
                            format!("ObjectInstance: no object named {name:?} was defined (ObjectBegin {name:?} … ObjectEnd)"),
                        ));
                    };
                    for sd in &o.shapes {
                        out.extend(self.emit(sd, Some((&name, ctm, &file, line)))?);
                    }
                }
            }
        }
        Ok(out)
    }
}

fn s(v: &str) -> Value {
    Value::String(v.to_string())
}

impl Conv {
    fn diag(&self, file: &Path, line: u32, m: impl Into<String>) -> Diagnostic {
        Diagnostic {
            file: file.to_path_buf(),
            line,
            message: m.into(),
        }
    }

    fn warn(&mut self, d: Diagnostic) -> Result<(), Diagnostic> {
        if self.strict {
            return Err(d);
        }
        self.warnings.push(d);
        Ok(())
    }

    fn file(
        &mut self,
        path: &Path,
        depth: usize,
        from: Option<(&Path, u32)>,
    ) -> Result<(), Diagnostic> {
        let (ff, fl) = from.unwrap_or((path, 1));
        if depth > MAX_INCLUDE_DEPTH {
            return Err(self.diag(
                ff,
                fl,
                format!(
                    "includes nested more than {MAX_INCLUDE_DEPTH} deep (does {} include itself?)",
                    path.display()
                ),
            ));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| self.diag(ff, fl, format!("cannot read {}: {e}", path.display())))?;
        self.text(&text, path, depth)
    }

    /// The directives of `text`, the contents of `path`.
    fn text(&mut self, text: &str, path: &Path, depth: usize) -> Result<(), Diagnostic> {
        let toks = tokenize(text, path)?;
        let mut i = 0;
        while i < toks.len() {
            let line = toks[i].line;
            let Tok::Word(d) = &toks[i].tok else {
                return Err(self.diag(
                    path,
                    line,
                    format!("expected a directive, got {:?}", toks[i].tok),
                ));
            };
            let d = d.clone();
            i += 1;
            // Positional arguments: the quoted names a directive takes, or the numbers
            // of a transform (bare or in brackets).
            let names = match d.as_str() {
                "Texture" => 3,
                "Shape" | "Material" | "MakeNamedMaterial" | "NamedMaterial" | "LightSource"
                | "AreaLightSource" | "Camera" | "Film" | "Sampler" | "Integrator" | "Include"
                | "Import" | "ObjectBegin" | "ObjectInstance" | "PixelFilter" | "Accelerator"
                | "MakeNamedMedium" | "CoordinateSystem" | "CoordSysTransform" | "ColorSpace"
                | "Attribute" | "ActiveTransform" => 1,
                "MediumInterface" => 2,
                _ => 0,
            };
            let mut nums = Vec::new();
            let mut strs = Vec::new();
            for _ in 0..names {
                match toks.get(i).map(|t| &t.tok) {
                    Some(Tok::Str(x)) => strs.push(x.clone()),
                    Some(Tok::Word(x)) if d == "ActiveTransform" => strs.push(x.clone()),
                    _ if d == "MediumInterface" && !strs.is_empty() => break,
                    _ => {
                        return Err(self.diag(
                            path,
                            line,
                            format!("{d}: expected a quoted name after it"),
                        ))
                    }
                }
                i += 1;
            }
            if names == 0 {
                let bracket = toks.get(i).map(|t| &t.tok) == Some(&Tok::Open);
                if bracket {
                    i += 1;
                }
                while let Some(Tok::Num(v)) = toks.get(i).map(|t| &t.tok) {
                    nums.push(*v);
                    i += 1;
                }
                if bracket {
                    if toks.get(i).map(|t| &t.tok) != Some(&Tok::Close) {
                        return Err(self.diag(
                            path,
                            line,
                            format!("{d}: expected numbers and a closing ]"),
                        ));
                    }
                    i += 1;
                }
            }
            // Then parameters: "type name" value(s).
            let mut params = Params::default();
            while i < toks.len() {
                let Tok::Str(decl) = &toks[i].tok else { break };
                let mut w = decl.split_whitespace();
                let (Some(ty), Some(name), None) = (w.next(), w.next(), w.next()) else {
                    break;
                };
                let pline = toks[i].line;
                let (ty, name) = (ty.to_string(), name.to_string());
                i += 1;
                let mut p = Param {
                    ty,
                    name,
                    nums: Vec::new(),
                    strs: Vec::new(),
                    line: pline,
                    used: Default::default(),
                };
                let take = |t: &Tok, p: &mut Param| -> bool {
                    match t {
                        Tok::Num(v) => p.nums.push(*v),
                        Tok::Str(x) => p.strs.push(x.clone()),
                        Tok::Word(w) if w == "true" || w == "false" => p.strs.push(w.clone()),
                        _ => return false,
                    }
                    true
                };
                match toks.get(i).map(|t| &t.tok) {
                    Some(Tok::Open) => {
                        i += 1;
                        while i < toks.len() && toks[i].tok != Tok::Close {
                            if !take(&toks[i].tok, &mut p) {
                                return Err(self.diag(
                                    path,
                                    toks[i].line,
                                    format!("parameter {:?}: expected values inside [ ]", p.name),
                                ));
                            }
                            i += 1;
                        }
                        if i >= toks.len() {
                            return Err(self.diag(path, pline, "a [ is not closed"));
                        }
                        i += 1;
                    }
                    Some(t) if take(t, &mut p) => i += 1,
                    _ => {
                        return Err(self.diag(
                            path,
                            pline,
                            format!("parameter {:?}: expected a value", p.name),
                        ))
                    }
                }
                params.0.push(p);
            }
            self.directive(path, line, &d, &nums, &strs, &params, depth)?;
            for p in &params.0 {
                if !p.used.get() {
                    self.warn(self.diag(
                        path,
                        p.line,
                        format!(
                            "{d}: parameter \"{} {}\" is not supported by heron, ignored",
                            p.ty, p.name
                        ),
                    ))?;
                }
            }
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn directive(
        &mut self,
        path: &Path,
        line: u32,
        d: &str,
        nums: &[f64],
        strs: &[String],
        p: &Params,
        depth: usize,
    ) -> Result<(), Diagnostic> {
        let need = |n: usize, c: &Conv| -> Result<(), Diagnostic> {
            if nums.len() != n {
                return Err(c.diag(
                    path,
                    line,
                    format!("{d}: expected {n} numbers, got {}", nums.len()),
                ));
            }
            Ok(())
        };
        let name = || strs.first().cloned().unwrap_or_default();
        match d {
            "Identity" => self.g.ctm = DMat4::IDENTITY,
            "Translate" => {
                need(3, self)?;
                self.g.ctm *= DMat4::from_translation(DVec3::new(nums[0], nums[1], nums[2]));
            }
            "Scale" => {
                need(3, self)?;
                self.g.ctm *= DMat4::from_scale(DVec3::new(nums[0], nums[1], nums[2]));
            }
            "Rotate" => {
                need(4, self)?;
                let axis = DVec3::new(nums[1], nums[2], nums[3]);
                if axis.length() == 0.0 {
                    return Err(self.diag(path, line, "Rotate: expected a non-zero axis"));
                }
                self.g.ctm *= DMat4::from_axis_angle(axis.normalize(), nums[0].to_radians());
            }
            "LookAt" => {
                need(9, self)?;
                let eye = DVec3::new(nums[0], nums[1], nums[2]);
                let look = DVec3::new(nums[3], nums[4], nums[5]);
                let up = DVec3::new(nums[6], nums[7], nums[8]);
                let dir = (look - eye).normalize_or_zero();
                let right = up.normalize_or_zero().cross(dir).normalize_or_zero();
                if dir == DVec3::ZERO || right == DVec3::ZERO {
                    return Err(self.diag(path, line, "LookAt: expected distinct eye and look points and an up vector not along the view"));
                }
                let new_up = dir.cross(right);
                let world_from_camera = DMat4::from_cols(
                    right.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    eye.extend(1.0),
                );
                self.g.ctm *= world_from_camera.inverse();
            }
            "Transform" | "ConcatTransform" => {
                need(16, self)?;
                let m = DMat4::from_cols_array(&nums.try_into().expect("16 numbers"));
                if d == "Transform" {
                    self.g.ctm = m;
                } else {
                    self.g.ctm *= m;
                }
            }
            "Camera" => {
                if name() != "perspective" {
                    return Err(self.diag(
                        path,
                        line,
                        format!("Camera: expected \"perspective\", got {:?}", name()),
                    ));
                }
                let fov = p.float("fov").unwrap_or(90.0);
                for k in [
                    "lensradius",
                    "focaldistance",
                    "screenwindow",
                    "frameaspectratio",
                    "shutteropen",
                    "shutterclose",
                ] {
                    if p.get(k).is_some() {
                        self.warn(self.diag(
                            path,
                            line,
                            format!("Camera: {k} is not supported, ignored"),
                        ))?;
                    }
                }
                self.camera_from_world = Some((self.g.ctm, line, path.to_path_buf(), fov));
            }
            "Film" => {
                for k in [
                    "filename",
                    "iso",
                    "whitebalance",
                    "sensor",
                    "savefp16",
                    "exposuretime",
                    "diagonal",
                ] {
                    p.get(k);
                }
                let w = p.float("xresolution").unwrap_or(1280.0);
                let h = p.float("yresolution").unwrap_or(720.0);
                if !(w >= 1.0 && h >= 1.0) {
                    return Err(self.diag(
                        path,
                        line,
                        "Film: expected xresolution and yresolution of at least 1",
                    ));
                }
                self.resolution = (w as i64, h as i64);
                if name() == "spectral" {
                    // pbrt-v4's SpectralFilm: nbuckets equal buckets over [lambdamin,
                    // lambdamax] (16 over 360–830 nm by default); heron's bins span
                    // 360–830 nm.
                    let n = p.float("nbuckets").unwrap_or(16.0);
                    let (lo, hi) = (
                        p.float("lambdamin").unwrap_or(360.0),
                        p.float("lambdamax").unwrap_or(830.0),
                    );
                    if !((1.0..=470.0).contains(&n) && n.fract() == 0.0) {
                        return Err(self.diag(path, line, format!("Film \"spectral\": nbuckets: expected a whole number from 1 to 470, got {n}")));
                    }
                    if (lo, hi) != (360.0, 830.0) {
                        self.warn(self.diag(path, line, format!("Film \"spectral\": heron's spectral bins span 360–830 nm, not {lo}–{hi} nm; {n} bins over 360–830 nm are used")))?;
                    }
                    self.render
                        .insert("spectral_bins".into(), Value::Integer(n as i64));
                }
            }
            "Sampler" => {
                if let Some(n) = p.float("pixelsamples") {
                    self.render
                        .insert("spp".into(), Value::Integer((n as i64).max(1)));
                }
                if let Some(seed) = p.float("seed") {
                    self.render
                        .insert("seed".into(), Value::Integer(seed.max(0.0) as i64));
                }
            }
            "Integrator" => {
                let kind = match name().as_str() {
                    "path" | "volpath" => "path",
                    "bdpt" => "bdpt",
                    "sppm" => "sppm",
                    "lightpath" => "lighttrace",
                    other => {
                        return self.warn(self.diag(path, line, format!("Integrator {other:?} is not supported (path, volpath, bdpt, sppm, lightpath are), heron's default is used")));
                    }
                };
                self.render.insert("integrator".into(), s(kind));
                let depth = p.float("maxdepth").unwrap_or(5.0) as i64;
                if depth < 1 {
                    return Err(self.diag(
                        path,
                        line,
                        format!("Integrator: maxdepth: expected at least 1, got {depth}"),
                    ));
                }
                self.render
                    .insert("max_depth".into(), Value::Integer(depth));
                p.get("regularize");
                p.get("lightsampler");
            }
            "WorldBegin" => {
                self.g.ctm = DMat4::IDENTITY;
            }
            "AttributeBegin" => self.push("AttributeBegin", path, line),
            "TransformBegin" => self.push("TransformBegin", path, line),
            "AttributeEnd" | "TransformEnd" => {
                let Some(top) = self.stack.last() else {
                    return Err(self.diag(path, line, format!("{d} without a matching begin")));
                };
                // pbrt-v4 (`BasicSceneBuilder::AttributeEnd`, which TransformEnd calls):
                // "Mismatched nesting: open ObjectBegin … at AttributeEnd".
                if top.what == "ObjectBegin" {
                    let m = format!(
                        "{d}: ObjectBegin {:?} ({}) is still open; close it with ObjectEnd first",
                        self.object.as_ref().map_or("", |o| o.name.as_str()),
                        at(&top.file, top.line, path)
                    );
                    return Err(self.diag(path, line, m));
                }
                let g = self.stack.pop().expect("checked above").g;
                if d == "TransformEnd" {
                    self.g.ctm = g.ctm;
                } else {
                    self.g = g;
                }
            }
            "ObjectBegin" => self.object_begin(path, line, &name())?,
            "ObjectEnd" => self.object_end(path, line)?,
            "ObjectInstance" => {
                if let Some(o) = &self.object {
                    let m = format!(
                        "ObjectInstance {:?}: inside the definition of ObjectBegin {:?} ({}); pbrt-v4 does not allow instances in an object",
                        name(),
                        o.name,
                        at(&o.file, o.line, path)
                    );
                    return Err(self.diag(path, line, m));
                }
                self.shapes.push(Slot::Instance {
                    name: name(),
                    ctm: self.g.ctm,
                    file: path.to_path_buf(),
                    line,
                });
            }
            "ReverseOrientation" => self.g.reverse = !self.g.reverse,
            "Material" => {
                let m = self.material(path, line, &name(), p, None)?;
                self.g.material = Some(m);
            }
            "MakeNamedMaterial" => {
                let ty = p.string("type").unwrap_or("").to_string();
                let m = self.material(path, line, &ty, p, Some(&name()))?;
                self.named.insert(name(), m);
            }
            "NamedMaterial" => {
                let Some(m) = self.named.get(&name()).cloned() else {
                    return Err(self.diag(
                        path,
                        line,
                        format!("NamedMaterial: no material named {:?} was made", name()),
                    ));
                };
                self.g.material = Some(m);
            }
            "AreaLightSource" => {
                let l = self.emission(path, p, "L", 1.0)?;
                let scale = p.float("scale").unwrap_or(1.0);
                let two = p.string("twosided") == Some("true");
                self.g.area = Some((scaled(l, scale), two));
            }
            "LightSource" => self.light(path, line, &name(), p)?,
            "Shape" => self.shape(path, line, &name(), p)?,
            "Include" => {
                let f = self.base_of(path).join(name());
                self.file(&f, depth + 1, Some((path, line)))?;
            }
            "Import" => {
                let f = self.base_of(path).join(name());
                self.import_depth += 1;
                let r = self.file(&f, depth + 1, Some((path, line)));
                self.import_depth -= 1;
                r?;
                // An imported file is parsed by a builder of its own in pbrt-v4, whose
                // open blocks are errors at its end (`BasicSceneBuilder::MergeImported`).
                if let Some(o) = &self.object {
                    if o.import_depth > self.import_depth {
                        return Err(self.diag(
                            &o.file,
                            o.line,
                            format!("ObjectBegin {:?} is not closed by an ObjectEnd before the end of the imported file", o.name),
                        ));
                    }
                }
            }
            "WorldEnd" | "OptionBool" | "ColorSpace" | "Option" => {}
            "Texture" | "MakeNamedMedium" | "MediumInterface" | "CoordinateSystem"
            | "CoordSysTransform" | "Attribute" | "PixelFilter" | "Accelerator"
            | "ActiveTransform" | "TransformTimes" => {
                for q in &p.0 {
                    q.used.set(true);
                }
                self.warn(self.diag(
                    path,
                    line,
                    format!("{d} is not supported by heron's import yet, ignored"),
                ))?;
            }
            other => return Err(self.diag(path, line, format!("unknown directive {other:?}"))),
        }
        Ok(())
    }

    fn base_of(&self, path: &Path) -> PathBuf {
        path.parent().unwrap_or(Path::new("")).to_path_buf()
    }

    fn push(&mut self, what: &'static str, path: &Path, line: u32) {
        self.stack.push(Pushed {
            g: self.g.clone(),
            what,
            file: path.to_path_buf(),
            line,
        });
    }

    /// pbrt-v4's `BasicSceneBuilder::ObjectBegin`: it saves the graphics state as
    /// `AttributeBegin` does (so what the definition changes ends at its `ObjectEnd`),
    /// and refuses a definition inside another and a name defined before.
    fn object_begin(&mut self, path: &Path, line: u32, name: &str) -> Result<(), Diagnostic> {
        if let Some(o) = &self.object {
            let m = format!(
                "ObjectBegin {name:?}: inside the definition of ObjectBegin {:?} ({}); object definitions do not nest",
                o.name,
                at(&o.file, o.line, path)
            );
            return Err(self.diag(path, line, m));
        }
        if let Some(o) = self.objects.get(name) {
            let m = format!(
                "ObjectBegin {name:?}: an object of that name was defined before ({}); pbrt-v4 does not redefine one",
                at(&o.file, o.line, path)
            );
            return Err(self.diag(path, line, m));
        }
        self.push("ObjectBegin", path, line);
        self.object = Some(ObjectDef {
            name: name.to_string(),
            file: path.to_path_buf(),
            line,
            import_depth: self.import_depth,
            shapes: Vec::new(),
        });
        Ok(())
    }

    /// pbrt-v4's `BasicSceneBuilder::ObjectEnd`: the graphics state saved by its
    /// `ObjectBegin` comes back; an `AttributeBegin` still open inside the definition,
    /// or a definition opened outside the `Import`ed file being read, is an error.
    fn object_end(&mut self, path: &Path, line: u32) -> Result<(), Diagnostic> {
        let Some(o) = &self.object else {
            return Err(self.diag(path, line, "ObjectEnd without a matching ObjectBegin"));
        };
        if o.import_depth != self.import_depth {
            let m = format!(
                "ObjectEnd: ObjectBegin {:?} ({}) was opened outside this imported file, and pbrt-v4 does not close it inside one",
                o.name,
                at(&o.file, o.line, path)
            );
            return Err(self.diag(path, line, m));
        }
        match self.stack.last() {
            Some(top) if top.what == "ObjectBegin" => {}
            Some(top) => {
                let m = format!(
                    "ObjectEnd: {} ({}) is still open; close it first",
                    top.what,
                    at(&top.file, top.line, path)
                );
                return Err(self.diag(path, line, m));
            }
            // ObjectBegin pushed the state and no End pops it while it is on top.
            None => return Err(self.diag(path, line, "ObjectEnd without a matching ObjectBegin")),
        }
        if let (Some(top), Some(o)) = (self.stack.pop(), self.object.take()) {
            self.g = top.g;
            self.objects.insert(o.name.clone(), o);
        }
        Ok(())
    }

    /// A reflectance parameter ([`Self::colour_as`] for a reflectance).
    fn colour(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
    ) -> Result<Value, Diagnostic> {
        self.colour_as(path, p, name, default, false)
    }

    /// A light's spectrum ([`Self::colour_as`] for an emission).
    fn emission(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
    ) -> Result<Value, Diagnostic> {
        self.colour_as(path, p, name, default, true)
    }

    /// A colour parameter: "rgb", a "spectrum" (one number, λ value pairs, a file of
    /// them, or the named illuminants stdillum-D65 and stdillum-A), a "blackbody"
    /// temperature, or a "float". For a light (`emission`), pbrt-v4 scales every
    /// spectrum to luminance 1 (`scale /= SpectrumToPhotometric(L)` in each light's
    /// `Create`; for RGB only the colour space's illuminant counts), which heron's
    /// blackbody and named illuminants already are and a table is given as a `scale`.
    /// pbrt-v4's `PiecewiseLinearSpectrum` is zero beyond its ends, as Mitsuba's is.
    fn colour_as(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
        emission: bool,
    ) -> Result<Value, Diagnostic> {
        use super::props::{mitsuba_samples, read_spd, ColourValue};
        let Some(q) = p.get(name) else {
            return Ok(float(default));
        };
        let bad =
            |this: &Self, m: String| this.diag(path, q.line, format!("\"{} {name}\": {m}", q.ty));
        let table_colour = |pairs: Vec<(f64, f64)>| {
            let samples = mitsuba_samples(&pairs);
            let scale = if emission {
                let dense = crate::spectrum::DenseSpectrum::from_samples(
                    &samples
                        .iter()
                        .map(|&(l, v)| (l as f32, v as f32))
                        .collect::<Vec<_>>(),
                );
                let y = crate::spectrum::cie::spectrum_to_xyz(&dense)[1] as f64;
                if y > 0.0 {
                    1.0 / y
                } else {
                    1.0
                }
            } else {
                1.0
            };
            ColourValue::Samples { samples, scale }.to_toml()
        };
        match (q.ty.as_str(), q.nums.as_slice(), q.strs.as_slice()) {
            ("rgb", [r, g, b], _) => Ok(Value::Array(vec![float(*r), float(*g), float(*b)])),
            ("spectrum" | "float", [v], []) => Ok(float(*v)),
            ("blackbody", [k], _) => {
                if !emission {
                    return Err(bad(self, "a blackbody is an emission spectrum".into()));
                }
                let (lo, hi) = crate::spectrum::blackbody::KELVIN_RANGE;
                if !(lo..=hi).contains(k) {
                    return Err(bad(self, format!("expected kelvin within [{lo}, {hi}], got {k}")));
                }
                Ok(ColourValue::Blackbody { kelvin: *k, scale: 1.0 }.to_toml())
            }
            ("spectrum", nums, []) if nums.len() >= 4 && nums.len() % 2 == 0 => {
                let pairs: Vec<(f64, f64)> = nums.chunks(2).map(|c| (c[0], c[1])).collect();
                if pairs.windows(2).any(|w| !(w[1].0 > w[0].0)) || pairs.iter().any(|(_, v)| !(*v >= 0.0)) {
                    return Err(bad(self, "expected wavelength value pairs, wavelengths increasing, values ≥ 0".into()));
                }
                Ok(table_colour(pairs))
            }
            ("spectrum", [], [n]) if n == "stdillum-D65" || n == "stdillum-A" => {
                let name = if n == "stdillum-A" { "A" } else { "D65" };
                let mut t = Table::new();
                t.insert("spectrum".into(), Value::String(name.into()));
                if !emission {
                    // A reflectance must stay within [0, 1]: the named illuminants are
                    // scaled to luminance 1, so only as lights.
                    return Err(bad(self, "a named illuminant is an emission spectrum".into()));
                }
                Ok(Value::Table(t))
            }
            ("spectrum", [], [f]) if !f.starts_with("metal-") && !f.starts_with("glass-") && !f.contains("illum") && !f.starts_with("canon") && !f.starts_with("nikon") && !f.starts_with("sony") => {
                let full = self.base_of(path).join(f);
                let pairs = read_spd(&full).map_err(|e| bad(self, e))?;
                Ok(table_colour(pairs))
            }
            ("spectrum", _, _) | ("texture", _, _) => {
                self.warn(self.diag(path, q.line, format!("\"{} {name}\": this named spectrum or texture is not supported yet (rgb, blackbody, λ value pairs, .spd files, stdillum-D65 and stdillum-A are); {default} is used", q.ty)))?;
                Ok(float(default))
            }
            _ => Err(self.diag(
                path,
                q.line,
                format!(
                    "\"{} {name}\": expected three rgb values, one number, wavelength value pairs, a spectrum file or a blackbody temperature",
                    q.ty
                ),
            )),
        }
    }

    fn alpha(&mut self, p: &Params) -> Option<f64> {
        let remap = p.string("remaproughness") != Some("false");
        let r = p.float("roughness").or_else(|| {
            let (u, v) = (p.float("uroughness"), p.float("vroughness"));
            match (u, v) {
                (Some(u), Some(v)) => Some(0.5 * (u + v)),
                (Some(u), None) | (None, Some(u)) => Some(u),
                _ => None,
            }
        })?;
        Some(if remap { r.max(0.0).sqrt() } else { r })
    }

    fn material(
        &mut self,
        path: &Path,
        line: u32,
        ty: &str,
        p: &Params,
        name: Option<&str>,
    ) -> Result<String, Diagnostic> {
        let t = match ty {
            "diffuse" => table(vec![
                ("type", s("lambertian")),
                ("rho_d", self.colour(path, p, "reflectance", 0.5)?),
            ]),
            "dielectric" | "thindielectric" => {
                if ty == "thindielectric" {
                    self.warn(self.diag(
                        path,
                        line,
                        "thindielectric is not supported yet; rendered as a solid dielectric",
                    ))?;
                }
                let ior = match p.get("eta") {
                    None => float(1.5),
                    Some(q) => match (q.ty.as_str(), q.nums.first(), q.strs.first()) {
                        (_, Some(v), _) => float(*v),
                        ("spectrum", None, Some(n)) => match n.as_str() {
                            "glass-BK7" => s("N-BK7"),
                            "glass-F11" | "glass-SF11" => s("N-SF11"),
                            "fused silica" | "glass-fused-silica" => s("fused-silica"),
                            other => return Err(self.diag(path, q.line, format!("\"spectrum eta\": expected a number or one of glass-BK7, glass-F11 (heron's N-SF11), got {other:?}"))),
                        },
                        _ => return Err(self.diag(path, q.line, "\"eta\": expected a number or a named spectrum")),
                    },
                };
                let mut t = table(vec![("type", s("dielectric")), ("ior", ior)]);
                if let Some(a) = self.alpha(p) {
                    if a > 0.0 {
                        t.insert("roughness".into(), float(a.min(1.0)));
                    }
                }
                p.get("remaproughness");
                t
            }
            "conductor" => {
                let metal = match (p.get("eta"), p.get("k"), p.get("reflectance")) {
                    (None, None, None) => s("Cu"),
                    (Some(e), Some(k), _) => match (e.nums.first(), k.nums.first(), e.strs.first(), k.strs.first()) {
                        (Some(n), Some(kk), _, _) => Value::Table(table(vec![("n", float(*n)), ("k", float(*kk))])),
                        (_, _, Some(a), Some(b)) => {
                            let m = a.strip_prefix("metal-").and_then(|x| x.strip_suffix("-eta"));
                            let m2 = b.strip_prefix("metal-").and_then(|x| x.strip_suffix("-k"));
                            match (m, m2) {
                                (Some(m), Some(m2)) if m == m2 && ["Ag", "Al", "Au", "Cu"].contains(&m) => s(m),
                                _ => return Err(self.diag(path, e.line, format!("conductor: expected metal-Ag/Al/Au/Cu-eta and -k spectra or numbers, got {a:?} and {b:?}"))),
                            }
                        }
                        _ => return Err(self.diag(path, e.line, "conductor: expected eta and k both as numbers or both as named spectra")),
                    },
                    (_, _, Some(q)) => return Err(self.diag(path, q.line, "conductor: \"reflectance\" (an artist's colour) is not supported; give eta and k")),
                    (Some(q), None, _) | (None, Some(q), _) => return Err(self.diag(path, q.line, "conductor: expected both eta and k")),
                };
                let mut t = table(vec![("type", s("conductor")), ("metal", metal)]);
                if let Some(a) = self.alpha(p) {
                    if a > 0.0 {
                        t.insert("roughness".into(), float(a.min(1.0)));
                    }
                }
                p.get("remaproughness");
                t
            }
            "coateddiffuse" => {
                let rho = self.colour(path, p, "reflectance", 0.5)?;
                let a = self.alpha(p).unwrap_or(0.0).max(0.01);
                let shininess = (2.0 / (a * a) - 2.0).max(1.0);
                let eta = p.float("eta").unwrap_or(1.5);
                let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
                p.get("remaproughness");
                p.get("thickness");
                self.warn(self.diag(path, line, format!("coateddiffuse is mapped to heron's glossy (modified Phong): ρd = reflectance, ρs = {f0:.4} (Fresnel at normal incidence), shininess {shininess:.0}")))?;
                table(vec![
                    ("type", s("glossy")),
                    ("rho_d", rho),
                    ("rho_s", float(f0)),
                    ("shininess", float(shininess)),
                ])
            }
            other => {
                for q in &p.0 {
                    q.used.set(true);
                }
                self.warn(self.diag(path, line, format!("material {other:?} is not supported (diffuse, dielectric, conductor, coateddiffuse are); a diffuse 0.5 is used")))?;
                return Ok(self.default_material());
            }
        };
        p.get("type");
        p.get("displacement");
        self.n_material += 1;
        let key = match name {
            Some(n) => n.to_string(),
            None => format!("{ty}-{}", self.n_material),
        };
        self.materials.insert(key.clone(), Value::Table(t));
        Ok(key)
    }

    fn default_material(&mut self) -> String {
        if let Some(m) = &self.default_material {
            return m.clone();
        }
        let k = "pbrt-default-diffuse".to_string();
        self.materials.insert(
            k.clone(),
            Value::Table(table(vec![
                ("type", s("lambertian")),
                ("rho_d", float(0.5)),
            ])),
        );
        self.default_material = Some(k.clone());
        k
    }

    fn light(&mut self, path: &Path, line: u32, kind: &str, p: &Params) -> Result<(), Diagnostic> {
        let scale = p.float("scale").unwrap_or(1.0);
        let m = self.g.ctm;
        match kind {
            "point" => {
                let from = p.get("from").map_or(DVec3::ZERO, |q| v3(&q.nums));
                let i = self.emission(path, p, "I", 1.0)?;
                self.lights.push(Value::Table(table(vec![
                    ("type", s("point")),
                    ("position", vec3(m.transform_point3(from))),
                    ("intensity", scaled(i, scale)),
                ])));
            }
            "spot" => {
                let from = p.get("from").map_or(DVec3::ZERO, |q| v3(&q.nums));
                let to = p.get("to").map_or(DVec3::Z, |q| v3(&q.nums));
                let i = self.emission(path, p, "I", 1.0)?;
                let cone = p.float("coneangle").unwrap_or(30.0);
                let delta = p.float("conedelta").unwrap_or(5.0);
                self.lights.push(Value::Table(table(vec![
                    ("type", s("spot")),
                    ("position", vec3(m.transform_point3(from))),
                    ("direction", vec3(m.transform_vector3(to - from))),
                    ("intensity", scaled(i, scale)),
                    ("cone_angle", float(cone)),
                    ("cone_delta", float(delta)),
                ])));
            }
            "distant" => {
                let from = p.get("from").map_or(DVec3::ZERO, |q| v3(&q.nums));
                let to = p.get("to").map_or(DVec3::Z, |q| v3(&q.nums));
                let l = self.emission(path, p, "L", 1.0)?;
                self.lights.push(Value::Table(table(vec![
                    ("type", s("directional")),
                    ("direction", vec3(m.transform_vector3(to - from))),
                    ("radiance", scaled(l, scale)),
                ])));
            }
            "infinite" if p.get("filename").is_none() => {
                let l = self.emission(path, p, "L", 1.0)?;
                self.background = Some(scaled(l, scale));
            }
            "infinite" => {
                // pbrt-v4's ImageInfiniteLight: a square image on the equal-area
                // octahedral map, in the light's frame (the CTM), looked up nearest.
                let f = p.string("filename").unwrap_or_default().to_string();
                if p.get("L").is_some() {
                    return Err(self.diag(path, line, "LightSource \"infinite\": both \"L\" and \"filename\" are given (pbrt-v4 refuses that too)"));
                }
                if p.get("illuminance").is_some() {
                    self.warn(self.diag(path, line, "LightSource \"infinite\": \"illuminance\" (rescaling the map to an illuminance) is not supported, ignored"))?;
                }
                if p.get("portal").is_some() {
                    for q in &p.0 {
                        q.used.set(true);
                    }
                    // PortalImageInfiniteLight lays the image out in the portal's frame,
                    // not on the equal-area square.
                    self.warn(self.diag(path, line, "LightSource \"infinite\" with a \"portal\" is not supported yet, ignored: the image lacks its light"))?;
                    return Ok(());
                }
                let full = self.base_of(path).join(&f);
                let rel = relative_to(&full, &self.base);
                // The rotation of the CTM (a uniform scale divided out: pbrt normalises
                // the direction), without its translation.
                let lin = glam::DMat3::from_mat4(m);
                let s3 = lin.determinant().abs().cbrt();
                let lin = if s3 > 0.0 { lin * (1.0 / s3) } else { lin };
                let mut rows = Vec::new();
                for r in 0..3 {
                    let row = lin.row(r);
                    rows.push(super::mitsuba::vec_row([row.x, row.y, row.z, 0.0]));
                }
                rows.push(super::mitsuba::vec_row([0.0, 0.0, 0.0, 1.0]));
                let mut t = table(vec![
                    ("map", s(&rel.to_string_lossy().replace('\\', "/"))),
                    ("mapping", s("equal-area")),
                    ("scale", float(scale)),
                ]);
                if lin != glam::DMat3::IDENTITY {
                    t.insert("transform".into(), Value::Array(rows));
                }
                if self.environment.is_some() || self.background.is_some() {
                    self.warn(self.diag(
                        path,
                        line,
                        "a second infinite light; heron's environment is the first, ignored",
                    ))?;
                } else {
                    self.environment = Some(Value::Table(t));
                }
            }
            other => {
                for q in &p.0 {
                    q.used.set(true);
                }
                self.warn(self.diag(path, line, format!("LightSource {other:?} is not supported yet (point, spot, distant, infinite are), ignored: the image lacks its light")))?;
            }
        }
        Ok(())
    }

    /// A `Shape` directive: its geometry read once, then placed now (a shape in the
    /// world) or kept with the graphics state for each `ObjectInstance` (a shape in an
    /// object definition; pbrt-v4 `BasicSceneBuilder::Shape` keeps the CTM, reverse
    /// orientation and material current here, so a copy has the definition's material).
    fn shape(&mut self, path: &Path, line: u32, kind: &str, p: &Params) -> Result<(), Diagnostic> {
        let Some(geom) = self.geometry(path, line, kind, p)? else {
            return Ok(());
        };
        let material = match self.g.material.clone() {
            Some(mm) => mm,
            None => self.default_material(),
        };
        let mut area = self.g.area.clone();
        if let Some(o) = &self.object {
            if area.is_some() {
                // pbrt-v4 warns "Area lights not supported with object instancing" and
                // makes the lights of the world's shapes only (`BasicScene::CreateLights`),
                // so an instance's copies do not emit.
                let m = format!("Shape {kind:?} inside ObjectBegin {:?}: area lights are not supported in object instances (as in pbrt-v4), so its copies do not emit", o.name);
                self.warn(self.diag(path, line, m))?;
                area = None;
            }
        }
        let sd = ShapeDef {
            geom,
            ctm: self.g.ctm,
            reverse: self.g.reverse,
            material,
            area,
            file: path.to_path_buf(),
            line,
        };
        match &mut self.object {
            Some(o) => o.shapes.push(sd),
            None => {
                for v in self.emit(&sd, None)? {
                    self.shapes.push(Slot::Shape(v));
                }
            }
        }
        Ok(())
    }

    /// A shape's geometry in its own space, its parameters checked; `None` (and a
    /// warning) for a shape heron does not have.
    fn geometry(
        &mut self,
        path: &Path,
        line: u32,
        kind: &str,
        p: &Params,
    ) -> Result<Option<Geom>, Diagnostic> {
        Ok(Some(match kind {
            "sphere" => {
                let radius = p.float("radius").unwrap_or(1.0);
                for k in ["zmin", "zmax", "phimax"] {
                    if p.get(k).is_some() {
                        self.warn(self.diag(path, line, format!("Shape \"sphere\": {k} (a partial sphere) is not supported, the whole sphere is used")))?;
                    }
                }
                Geom::Sphere { radius }
            }
            "trianglemesh" | "bilinearmesh" => {
                let kind = if kind == "trianglemesh" {
                    "trianglemesh"
                } else {
                    "bilinearmesh"
                };
                let pts = p.get("P").map(|q| q.nums.clone()).unwrap_or_default();
                let idx = p.get("indices").map(|q| q.nums.clone());
                if pts.len() % 3 != 0 || pts.is_empty() {
                    return Err(self.diag(path, line, format!("Shape {kind:?}: expected \"point3 P\" with a multiple of 3 numbers, got {}", pts.len())));
                }
                let n = pts.len() / 3;
                let points: Vec<DVec3> = pts
                    .chunks(3)
                    .map(|c| DVec3::new(c[0], c[1], c[2]))
                    .collect();
                let per = if kind == "trianglemesh" { 3 } else { 4 };
                let idx = idx.unwrap_or_else(|| {
                    if n == per {
                        (0..per).map(|i| i as f64).collect()
                    } else {
                        Vec::new()
                    }
                });
                if idx.is_empty() || idx.len() % per != 0 {
                    return Err(self.diag(
                        path,
                        line,
                        format!("Shape {kind:?}: expected \"integer indices\", {per} per face"),
                    ));
                }
                let mut faces = Vec::with_capacity(idx.len() / per);
                for f in idx.chunks(per) {
                    let mut ix = Vec::with_capacity(per);
                    for &v in f {
                        if !(v >= 0.0 && (v as usize) < n && v.fract() == 0.0) {
                            return Err(self.diag(
                                path,
                                line,
                                format!("Shape {kind:?}: index {v} is not one of the {n} vertices"),
                            ));
                        }
                        ix.push(v as usize);
                    }
                    faces.push(ix);
                }
                for k in ["N", "uv", "S", "faceIndices"] {
                    p.get(k);
                }
                Geom::Mesh {
                    kind,
                    points,
                    faces,
                }
            }
            "plymesh" => {
                let Some(f) = p.string("filename").map(str::to_string) else {
                    return Err(self.diag(
                        path,
                        line,
                        "Shape \"plymesh\": expected \"string filename\"",
                    ));
                };
                if f.ends_with(".gz") {
                    return Err(self.diag(
                        path,
                        line,
                        "Shape \"plymesh\": gzipped PLY files are not supported; unpack the file",
                    ));
                }
                let full = self.base_of(path).join(&f);
                let rel = relative_to(&full, &self.base);
                for k in ["displacement", "edgelength"] {
                    if p.get(k).is_some() {
                        self.warn(self.diag(
                            path,
                            line,
                            format!("Shape \"plymesh\": {k} is not supported, ignored"),
                        ))?;
                    }
                }
                Geom::Ply {
                    file: rel.to_string_lossy().replace('\\', "/"),
                }
            }
            other => {
                for q in &p.0 {
                    q.used.set(true);
                }
                self.warn(self.diag(path, line, format!("Shape {other:?} is not supported (sphere, trianglemesh, bilinearmesh, plymesh are), ignored")))?;
                return Ok(None);
            }
        }))
    }

    /// The heron shape tables of `sd` placed by its CTM, or for an `ObjectInstance`
    /// (`inst`: the object's name, the instance's CTM, file and line) by CTM(instance) ·
    /// CTM(shape). What depends on the whole matrix (a sphere's uniform scale, a mirror
    /// flipping the winding) is decided here, a copy's message naming the instance.
    fn emit(
        &mut self,
        sd: &ShapeDef,
        inst: Option<(&str, DMat4, &Path, u32)>,
    ) -> Result<Vec<Value>, Diagnostic> {
        let m = match inst {
            Some((_, ctm, _, _)) => ctm * sd.ctm,
            None => sd.ctm,
        };
        // Where a message about the placed shape points: the shape, or the instance
        // (whose transform is the one to fix), naming the shape's line.
        let (file, line, ctx) = match inst {
            Some((name, _, f, l)) => (
                f.to_path_buf(),
                l,
                format!(
                    "ObjectInstance {name:?}, the shape of {}: ",
                    at(&sd.file, sd.line, f)
                ),
            ),
            None => (sd.file.clone(), sd.line, String::new()),
        };
        let flip = sd.reverse ^ (m.determinant() < 0.0);
        let mut entries: Vec<Table> = Vec::new();
        match &sd.geom {
            Geom::Sphere { radius } => {
                let m3 = glam::DMat3::from_mat4(m);
                let sc = [m3.x_axis.length(), m3.y_axis.length(), m3.z_axis.length()];
                if (sc[0] - sc[1]).abs() > 1e-6 * sc[0] || (sc[0] - sc[2]).abs() > 1e-6 * sc[0] {
                    return Err(self.diag(
                        &file,
                        line,
                        format!("{ctx}Shape \"sphere\": heron's spheres take a uniform scale only"),
                    ));
                }
                entries.push(table(vec![
                    ("type", s("sphere")),
                    ("center", vec3(m.transform_point3(DVec3::ZERO))),
                    ("radius", float(radius * sc[0])),
                ]));
            }
            Geom::Mesh {
                kind,
                points,
                faces,
            } => {
                let verts: Vec<DVec3> = points.iter().map(|&q| m.transform_point3(q)).collect();
                for ix in faces {
                    // A flat parallelogram patch (p00, p10, p01, p11) is heron's quad,
                    // normal (p10 − p00) × (p01 − p00) as pbrt's; others two triangles.
                    if *kind == "bilinearmesh" {
                        let (o, a, b, c) = (verts[ix[0]], verts[ix[1]], verts[ix[2]], verts[ix[3]]);
                        let scale = (a - o).length().max((b - o).length());
                        if (c - (a + b - o)).length() <= 1e-9 * scale {
                            let (e1, e2) = if flip { (b - o, a - o) } else { (a - o, b - o) };
                            entries.push(table(vec![
                                ("type", s("quad")),
                                ("origin", vec3(o)),
                                ("edge1", vec3(e1)),
                                ("edge2", vec3(e2)),
                            ]));
                            continue;
                        }
                    }
                    // pbrt's bilinear patch (p00, p10, p01, p11) as two triangles.
                    let tris: Vec<[usize; 3]> = if *kind == "trianglemesh" {
                        vec![[ix[0], ix[1], ix[2]]]
                    } else {
                        vec![[ix[0], ix[1], ix[3]], [ix[0], ix[3], ix[2]]]
                    };
                    for t in tris {
                        let t = if flip { [t[0], t[2], t[1]] } else { t };
                        entries.push(table(vec![
                            ("type", s("triangle")),
                            (
                                "vertices",
                                Value::Array(t.iter().map(|&k| vec3(verts[k])).collect()),
                            ),
                        ]));
                    }
                }
            }
            Geom::Ply { file: f } => {
                if flip {
                    self.warn(self.diag(&file, line, format!("{ctx}Shape \"plymesh\": ReverseOrientation or a mirroring transform on a mesh is not supported, ignored")))?;
                }
                let mut t = table(vec![("type", s("mesh")), ("file", s(f))]);
                if m != DMat4::IDENTITY {
                    t.insert(
                        "transform".into(),
                        Value::Array(
                            (0..4)
                                .map(|r| {
                                    Value::Array(
                                        m.row(r).to_array().iter().map(|x| float(*x)).collect(),
                                    )
                                })
                                .collect(),
                        ),
                    );
                }
                entries.push(t);
            }
        }
        Ok(entries
            .into_iter()
            .map(|mut e| {
                e.insert("material".into(), s(&sd.material));
                if let Some((l, two)) = &sd.area {
                    e.insert("emission".into(), l.clone());
                    if *two {
                        e.insert("two_sided".into(), Value::Boolean(true));
                    }
                }
                Value::Table(e)
            })
            .collect())
    }

    fn finish_camera(&mut self, path: &Path) -> Result<(), Diagnostic> {
        let Some((cfw, line, file, fov)) = self.camera_from_world.clone() else {
            return Err(self.diag(path, 1, "expected a Camera \"perspective\" directive"));
        };
        let wfc = cfw.inverse();
        let eye = wfc.transform_point3(DVec3::ZERO);
        let look = wfc.transform_point3(DVec3::Z);
        let up = wfc.transform_vector3(DVec3::Y);
        let right = wfc.transform_vector3(DVec3::X);
        // heron's image right is forward × up; pbrt's is the camera's +x.
        if right.dot((look - eye).cross(up)) < 0.0 {
            self.warn(self.diag(&file, line, "Camera: pbrt's camera space is left-handed, so this camera shows the scene mirrored in pbrt; heron renders it unmirrored (a Scale -1 1 1 before LookAt makes the two agree)"))?;
        }
        let (w, h) = self.resolution;
        let aspect = w as f64 / h as f64;
        // pbrt's fov spans the shorter image axis.
        let t = (0.5 * fov.to_radians()).tan();
        let tan_y = if aspect >= 1.0 { t } else { t / aspect };
        self.camera = Some(table(vec![
            ("eye", vec3(eye)),
            ("look_at", vec3(look)),
            ("up", vec3(up)),
            ("d", float(0.5 / tan_y)),
            (
                "resolution",
                Value::Array(vec![Value::Integer(w), Value::Integer(h)]),
            ),
        ]));
        Ok(())
    }
}

/// "line N", or "line N of FILE" when `file` is not `here`, for a message about a place
/// that an error elsewhere refers to.
fn at(file: &Path, line: u32, here: &Path) -> String {
    if file == here {
        format!("line {line}")
    } else {
        format!("line {line} of {}", file.display())
    }
}

fn v3(n: &[f64]) -> DVec3 {
    match n {
        [x, y, z, ..] => DVec3::new(*x, *y, *z),
        _ => DVec3::ZERO,
    }
}

fn scaled(v: Value, k: f64) -> Value {
    if k == 1.0 {
        return v;
    }
    match v {
        Value::Table(mut t) => {
            let s0 = t.get("scale").and_then(Value::as_float).unwrap_or(1.0);
            t.insert("scale".into(), float(s0 * k));
            Value::Table(t)
        }
        Value::Float(x) => float(x * k),
        Value::Array(a) => Value::Array(
            a.into_iter()
                .map(|x| float(x.as_float().unwrap_or(0.0) * k))
                .collect(),
        ),
        v => v,
    }
}
