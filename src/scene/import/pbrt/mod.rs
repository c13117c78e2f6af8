//! pbrt-v4 scene files (pbrt-v4 User's Guide, "Scene Description Format") to heron's
//! scene ([`SceneFile`]): the tokens and directives with their line, the current transformation
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
use super::mitsuba::{relative_to, Converted};
use super::props::ColourValue;
use super::schema::{self, tidy};
use super::xml::Diagnostic;
use crate::scene::file::{
    CameraFile, Emission, EnvironmentFile, LightFile, MaterialFile, RenderFile, SceneFile,
    ShapeFile, TextureFile,
};
use glam::{DMat4, DVec3};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

mod directives;
mod filter;
mod media;
mod textures;
mod tokens;
mod translate;

#[derive(Clone)]
struct Graphics {
    ctm: DMat4,
    material: Option<String>,
    /// The area light's radiance and two-sidedness.
    area: Option<(crate::scene::file::ShapeEmission, bool)>,
    reverse: bool,
    /// `MediumInterface`'s inside and outside medium names ("" for none).
    inside: String,
    outside: String,
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
    /// pbrt-v4's `disk` (a partial annulus at z = height), as triangles.
    Disk {
        height: f64,
        radius: f64,
        inner: f64,
        phi_max: f64,
    },
    /// pbrt-v4's `cylinder` (the open side from z = zmin to zmax), as triangles.
    Cylinder {
        radius: f64,
        z: (f64, f64),
        phi_max: f64,
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
    area: Option<(crate::scene::file::ShapeEmission, bool)>,
    /// The medium names of the `MediumInterface` current at the shape.
    inside: String,
    outside: String,
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
    /// Boxed: a shape entry is several times an instance's size.
    Shape(Box<ShapeFile>),
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
    materials: BTreeMap<String, MaterialFile>,
    /// `[textures]` from `Texture` directives (textures.rs).
    textures: BTreeMap<String, TextureFile>,
    /// The table of each texture by (float, pbrt name): pbrt's float and spectrum
    /// textures have names of their own.
    texture_names: HashMap<(bool, String), String>,
    named: HashMap<String, String>,
    /// `MakeNamedMedium`s by name (None: a type heron does not have).
    media: HashMap<String, Option<crate::scene::file::MediumFile>>,
    /// Outside media warned about (once each).
    outside_warned: std::collections::HashSet<String>,
    shapes: Vec<Slot>,
    lights: Vec<LightFile>,
    background: Option<Emission>,
    /// `[environment]` from an image `infinite` light.
    environment: Option<EnvironmentFile>,
    camera: Option<CameraFile>,
    /// The `Camera` directive: its CTM, line and file, and its projection.
    camera_from_world: Option<(DMat4, u32, PathBuf, Projection)>,
    resolution: (u32, u32),
    /// `[render]`, made by the first key set.
    render: Option<RenderFile>,
    /// Where the `Integrator` directive is (for a warning about its filter).
    integrator_at: Option<(PathBuf, u32)>,
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
            materials: BTreeMap::new(),
            textures: BTreeMap::new(),
            texture_names: HashMap::new(),
            named: HashMap::new(),
            media: HashMap::new(),
            outside_warned: std::collections::HashSet::new(),
            shapes: Vec::new(),
            lights: Vec::new(),
            background: None,
            environment: None,
            camera: None,
            camera_from_world: None,
            resolution: (1280, 720),
            render: None,
            integrator_at: None,
            g: Graphics {
                ctm: DMat4::IDENTITY,
                material: None,
                area: None,
                reverse: false,
                inside: String::new(),
                outside: String::new(),
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
    /// shapes, and the camera and the scene are put together.
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
        self.default_filter();
        if let Some(m) = schema::box_for_light_paths(&mut self.render) {
            // A light-path integrator was named, so its directive's place is known.
            let (file, line) = self.integrator_at.clone().unwrap_or((path.into(), 1));
            self.warn(self.diag(&file, line, m))?;
        }
        let scene = SceneFile {
            background: self.background.take(),
            camera: self.camera.take().expect("finish_camera sets it"),
            render: self.render.take(),
            materials: std::mem::take(&mut self.materials),
            shapes,
            lights: std::mem::take(&mut self.lights),
            textures: std::mem::take(&mut self.textures),
            sky: None,
            environment: self.environment.take(),
        };
        Ok(Converted {
            scene,
            warnings: self.warnings,
        })
    }

    /// The shapes list with each `ObjectInstance` replaced by copies of its object's
    /// shapes, each placed by CTM(instance) · CTM(shape) (pbrt-v4 `src/pbrt/scene.cpp`:
    /// `renderFromInstance = RenderFromObject(0) * worldFromRender` applied on top of the
    /// shapes' own `renderFromObject`). An unknown name is an error at the instance, as
    /// in pbrt-v4's `CreateAggregate` ("object instance not defined"); an empty object
    /// gives nothing.
    fn instantiate(&mut self) -> Result<Vec<ShapeFile>, Diagnostic> {
        let slots = std::mem::take(&mut self.shapes);
        let objects = std::mem::take(&mut self.objects);
        let mut out = Vec::with_capacity(slots.len());
        for slot in slots {
            match slot {
                Slot::Shape(v) => out.push(*v),
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

impl Conv {
    /// The `[render]` table, made on first use.
    fn render(&mut self) -> &mut RenderFile {
        self.render.get_or_insert_with(RenderFile::default)
    }

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

/// A light's colour times its `scale` parameter, the products tidied ([`tidy`]).
fn scaled(c: ColourValue, k: f64) -> ColourValue {
    if k == 1.0 {
        return c;
    }
    match c {
        ColourValue::Grey(x) => ColourValue::Grey(tidy(x * k)),
        ColourValue::Rgb(rgb) => ColourValue::Rgb(rgb.map(|x| tidy(x * k))),
        ColourValue::Samples { samples, scale } => ColourValue::Samples {
            samples,
            scale: tidy(scale * k),
        },
        ColourValue::Blackbody { kelvin, scale } => ColourValue::Blackbody {
            kelvin,
            scale: tidy(scale * k),
        },
        ColourValue::Named { spectrum, scale } => ColourValue::Named {
            spectrum,
            scale: tidy(scale * k),
        },
    }
}

/// What a `Camera` directive projects with: pbrt-v4's `perspective` (its `fov`,
/// degrees across the shorter image axis) or `orthographic` (its `screenwindow`
/// [x0, x1, y0, y1] in camera space, or the default made from `frameaspectratio`).
#[derive(Clone, Debug)]
pub(super) enum Projection {
    Perspective {
        fov: f64,
    },
    Orthographic {
        window: Option<[f64; 4]>,
        frame: Option<f64>,
    },
}
