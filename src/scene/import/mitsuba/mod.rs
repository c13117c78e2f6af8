//! Mitsuba 3 scene objects to heron's scene ([`SceneFile`], the schema of the TOML heron
//! renders): sensor, film and sampler to `camera` and `render`, integrators, BSDFs to
//! `materials`, shapes (with their area emitters) to `shapes`, emitters to `lights`,
//! `background` and `environment`. Mitsuba's defaults are those of its plugin
//! documentation (mitsuba.readthedocs.io, "Plugin reference", 3.x); where heron has no
//! equivalent the converter says what it did in a [`Diagnostic`] (a warning, an error
//! under `strict`).
use super::props::{ColourError, ColourValue, Props};
use super::schema;
use super::xml::{Diagnostic, Node};
use crate::scene::file::{
    CameraFile, Emission, EnvironmentFile, LightFile, MaterialFile, RenderFile, SceneFile,
    ShapeFile, TextureFile,
};
use glam::{DMat4, DVec3};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

mod bsdfs;
mod media;
mod rfilter;
mod shapes;
mod textures;

/// A triangle fan of this many triangles stands for a `disk` (area 0.9996 of the disk).
pub const DISK_SEGMENTS: usize = 128;

/// Mitsuba's `max_depth = -1` (unbounded) becomes this depth; Russian roulette ends the
/// paths long before it.
pub const UNBOUNDED_DEPTH: i64 = 1000;

/// Mitsuba 3's table of named indices (`src/core/ior.h`, constants). Four are heron
/// catalogue glasses with their dispersion instead; [`CATALOGUE_IORS`] names them.
const MITSUBA_IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// Mitsuba index names that are entries of heron's catalogue (spectra/ior_catalogue.toml).
const CATALOGUE_IORS: &[(&str, &str)] = &[
    ("bk7", "N-BK7"),
    ("water", "water"),
    ("fused quartz", "fused-silica"),
    ("diamond", "diamond"),
];

/// Mitsuba's conductor `material` names heron tabulates (spectrum/metals.rs).
const METALS: &[&str] = &["Ag", "Al", "Au", "Cu"];

/// What the conversion made: heron's scene, and what it could not carry over.
pub struct Converted {
    pub scene: SceneFile,
    pub warnings: Vec<Diagnostic>,
}

struct Converter<'a> {
    /// The folder of the top-level file; mesh paths are written relative to it.
    base: PathBuf,
    strict: bool,
    /// The `<path>` folders, in declaration order (files are looked up in them).
    folders: Vec<PathBuf>,
    /// While a shapegroup is copied for an instance, the instance's `to_world`.
    placing: Option<DMat4>,
    ids: HashMap<&'a str, &'a Node>,
    warnings: Vec<Diagnostic>,
    materials: BTreeMap<String, MaterialFile>,
    /// `[textures]`, from `bitmap` and `checkerboard` elements (textures.rs).
    textures: BTreeMap<String, TextureFile>,
    /// Table name of each converted texture element (shared through `ref`).
    texture_of: HashMap<*const Node, String>,
    /// Material name of each converted BSDF element (shared through `ref`).
    material_of: HashMap<*const Node, String>,
    default_material: Option<String>,
    shapes: Vec<ShapeFile>,
    lights: Vec<LightFile>,
    background: Option<Emission>,
    /// `[environment]` from an `envmap` emitter.
    environment: Option<EnvironmentFile>,
    camera: Option<CameraFile>,
    /// `[render]`, made by the first key set.
    render: Option<RenderFile>,
}

/// Whether any `<ref id="id"/>` in the tree under `n` names `id`.
fn references(n: &Node, id: &str) -> bool {
    n.children
        .iter()
        .any(|c| (c.tag == "ref" && c.attr("id") == Some(id)) || references(c, id))
}

/// Converts the document `root` (from [`super::xml::read_document`]) read from `path`.
pub fn convert(root: &Node, path: &Path, strict: bool) -> Result<Converted, Diagnostic> {
    let mut ids = HashMap::new();
    collect_ids(root, &mut ids)?;
    let mut c = Converter {
        base: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        strict,
        folders: super::xml::path_folders(root),
        placing: None,
        ids,
        warnings: Vec::new(),
        materials: BTreeMap::new(),
        textures: BTreeMap::new(),
        texture_of: HashMap::new(),
        material_of: HashMap::new(),
        default_material: None,
        shapes: Vec::new(),
        lights: Vec::new(),
        background: None,
        environment: None,
        camera: None,
        render: None,
    };
    for child in &root.children {
        match child.tag.as_str() {
            "integrator" => c.integrator(child)?,
            "sensor" => c.sensor(child)?,
            // A shapegroup with an id is copied where instances reference it.
            "shape" if child.attr("type") == Some("shapegroup") && child.attr("id").is_some() => {}
            "shape" => c.shape(child)?,
            // An area emitter with an id is converted in the shapes that reference it
            // (Mitsuba's own cbox-rgb.xml declares its light so).
            "emitter" if child.attr("type") == Some("area") && child.attr("id").is_some() => {
                let id = child.attr("id").unwrap_or_default();
                if !references(root, id) {
                    c.warn(child.diag(format!(
                        "an area emitter that no shape references (<ref id=\"{id}\"/>), ignored"
                    )))?;
                }
            }
            "emitter" => {
                c.emitter(child, None)?;
            }
            // Read with the document (xml.rs): the folders files are looked up in.
            "path" => {}
            // Named objects at the top level are converted where they are referenced.
            "bsdf" | "texture" | "spectrum" | "rgb" | "float" | "medium" | "phase"
                if child.attr("id").is_some() => {}
            "bsdf" => {
                c.warn(child.diag("a BSDF that no shape uses (it has no id), ignored"))?;
            }
            "medium" | "phase" | "volume" | "texture" => {
                c.unsupported(child, "not supported by heron's import yet, ignored")?
            }
            _ => c.unsupported(child, "not supported by heron's import, ignored")?,
        }
    }
    let Some(camera) = c.camera.take() else {
        return Err(Diagnostic {
            file: path.to_path_buf(),
            line: root.line,
            message: "expected a <sensor type=\"perspective\"> (heron renders through one camera)"
                .into(),
        });
    };
    if let Some(m) = schema::box_for_light_paths(&mut c.render) {
        c.warn(Diagnostic {
            file: path.to_path_buf(),
            line: root.line,
            message: m,
        })?;
    }
    let scene = SceneFile {
        background: c.background,
        camera,
        render: c.render,
        materials: c.materials,
        shapes: c.shapes,
        lights: c.lights,
        textures: c.textures,
        sky: None,
        environment: c.environment,
    };
    Ok(Converted {
        scene,
        warnings: c.warnings,
    })
}

fn collect_ids<'a>(n: &'a Node, ids: &mut HashMap<&'a str, &'a Node>) -> Result<(), Diagnostic> {
    for c in &n.children {
        if let Some(id) = c.attr("id") {
            if c.tag != "ref" && ids.insert(id, c).is_some() {
                return Err(c.diag(format!("the id {id:?} is used twice")));
            }
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

impl<'a> Converter<'a> {
    /// The `[render]` table, made on first use.
    fn render(&mut self) -> &mut RenderFile {
        self.render.get_or_insert_with(RenderFile::default)
    }

    fn warn(&mut self, d: Diagnostic) -> Result<(), Diagnostic> {
        if self.strict {
            Err(d)
        } else {
            self.warnings.push(d);
            Ok(())
        }
    }

    fn unsupported(&mut self, n: &Node, what: &str) -> Result<(), Diagnostic> {
        self.warn(n.diag(what))
    }

    /// Warnings for what `p`'s object held that nothing read.
    /// The properties of `n`, looking files up as Mitsuba does.
    fn props(&self, n: &'a Node) -> Props<'a> {
        Props::new(n).with_files(&self.folders, &self.base)
    }

    /// The file `name` that element `n` names, as Mitsuba looks it up.
    fn find(&self, n: &Node, name: &str) -> PathBuf {
        let own = n.file.parent().unwrap_or(Path::new(""));
        super::xml::find_file(name, &self.folders, &self.base, own)
    }

    fn finish(&mut self, p: &Props) -> Result<(), Diagnostic> {
        for d in p.unread() {
            self.warn(d)?;
        }
        Ok(())
    }

    fn plugin(n: &Node) -> Result<&str, Diagnostic> {
        n.attr("type")
            .ok_or_else(|| n.diag("expected the attribute type"))
    }

    fn resolve(&self, n: &'a Node) -> Result<&'a Node, Diagnostic> {
        if n.tag != "ref" {
            return Ok(n);
        }
        let Some(id) = n.attr("id") else {
            return Err(n.diag("expected the attribute id"));
        };
        self.ids
            .get(id)
            .copied()
            .ok_or_else(|| n.diag(format!("no element has the id {id:?}")))
    }

    /// A colour, or `default` when absent; unsupported forms warn and use `default`.
    fn colour(
        &mut self,
        p: &Props<'a>,
        name: &str,
        default: ColourValue,
    ) -> Result<ColourValue, Diagnostic> {
        match p.colour(name) {
            Ok(Some(c)) => Ok(c),
            Ok(None) => Ok(default),
            Err(ColourError::Bad(d)) => Err(d),
            Err(ColourError::Unsupported(d)) => {
                let msg = format!("{}; the default {:?} is used", d.message, default);
                self.warn(Diagnostic { message: msg, ..d })?;
                Ok(default)
            }
        }
    }

    // ---- integrator, sensor, film, sampler ---------------------------------------

    fn integrator(&mut self, n: &'a Node) -> Result<(), Diagnostic> {
        let p = self.props(n);
        let kind = Self::plugin(n)?;
        if kind == "moment" {
            // Mitsuba's moment integrator renders its nested integrators and adds their
            // second moments as extra channels: heron renders the first, and its
            // variance channels (--variance) are the per-pixel second moment's use.
            let nested = p.objects(&["integrator"]);
            let Some(first) = nested.first() else {
                return Err(n.diag("moment: expected a nested <integrator>"));
            };
            let first = self.resolve(first)?;
            self.warn(n.diag(format!(
                "moment: the nested integrator is rendered{}; its second-moment channels are not written (heron's --variance writes per-pixel variance)",
                if nested.len() > 1 { " (the first of them)" } else { "" }
            )))?;
            self.integrator(first)?;
            return self.finish(&p);
        }
        let (integrator, depth) = match kind {
            "path" | "volpath" | "volpathmis" => ("path", p.integer("max_depth")?.unwrap_or(-1)),
            // Mitsuba's `direct` is emitters seen directly plus one bounce of direct
            // light: heron's path tracer at one scattering event.
            "direct" => ("path", 2),
            "ptracer" => ("lighttrace", p.integer("max_depth")?.unwrap_or(-1)),
            other => {
                return self.unsupported(
                    n,
                    &format!("integrator {other:?} is not supported (path, volpath, volpathmis, direct, ptracer are), heron's default is used"),
                );
            }
        };
        // Mitsuba counts path vertices up to and including the emitter, heron counts
        // scattering events: Mitsuba's max_depth = d is heron's d − 1.
        let heron_depth = if depth < 0 {
            UNBOUNDED_DEPTH
        } else {
            depth - 1
        };
        if heron_depth < 1 {
            return Err(n.diag(format!(
                "max_depth: expected -1 or at least 2 (heron renders at least one scattering event), got {depth}"
            )));
        }
        let max_depth = schema::positive_count("max_depth", heron_depth).map_err(|m| n.diag(m))?;
        self.render().integrator = Some(integrator.into());
        self.render().max_depth = Some(max_depth);
        if let Some(rr) = p.integer("rr_depth")? {
            let rr = schema::count("rr_depth", (rr - 1).max(0)).map_err(|m| n.diag(m))?;
            self.render().rr_depth = Some(rr);
        }
        if kind == "direct" {
            for k in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                if p.get(k).is_some() {
                    self.warn(n.diag(format!(
                        "{k}: heron takes one light sample and one BSDF sample per vertex (MIS), ignored"
                    )))?;
                }
            }
        }
        if let Some(hide) = p.boolean("hide_emitters")? {
            self.render().hide_emitters = Some(hide);
            if hide {
                // Mitsuba 3.7.1+'s path and volpath continue a camera ray through a
                // hidden area light (`skip_area_emitters`); heron's integrators all keep
                // it opaque, black, as Mitsuba's ptracer and older versions do.
                self.warn(n.diag(
                    "hide_emitters: an area light the camera sees is black and opaque in heron; Mitsuba 3.7+'s path and volpath show what is behind it",
                ))?;
            }
        }
        self.finish(&p)
    }

    fn sensor(&mut self, n: &'a Node) -> Result<(), Diagnostic> {
        if self.camera.is_some() {
            return self.unsupported(
                n,
                "a second sensor; heron renders through the first, ignored",
            );
        }
        let kind = Self::plugin(n)?;
        if !matches!(kind, "perspective" | "thinlens" | "orthographic") {
            return Err(n.diag(format!(
                "expected a perspective or orthographic sensor (or thinlens, rendered as a pinhole), got {kind:?}"
            )));
        }
        let orthographic = kind == "orthographic";
        let p = self.props(n);
        let to_world = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        if to_world.determinant() < 0.0 {
            self.warn(n.diag(
                "to_world mirrors the image (negative determinant); heron's camera cannot mirror, the image is rendered unmirrored",
            ))?;
        }
        if kind == "thinlens" {
            for k in ["aperture_radius", "focus_distance"] {
                p.get(k);
            }
            self.warn(n.diag("thinlens is rendered as a pinhole: depth of field is lost"))?;
        }
        // The orthographic camera's rays start on the near plane, which heron keeps.
        let clips: &[&str] = if orthographic {
            &["far_clip"]
        } else {
            &["near_clip", "far_clip"]
        };
        for &k in clips {
            if p.get(k).is_some() {
                self.warn(n.diag(format!(
                    "{k}: heron's camera has no clipping planes, ignored"
                )))?;
            }
        }
        // Film first: the field of view's axis needs the aspect ratio.
        let (mut width, mut height) = (768, 576);
        for f in p.objects(&["film", "sampler"]) {
            let f = self.resolve(f)?;
            match f.tag.as_str() {
                "film" => (width, height) = self.film(f)?,
                "sampler" => self.sampler(f)?,
                _ => return Err(f.diag("expected a film or a sampler inside the sensor")),
            }
        }
        let aspect = width as f64 / height as f64;
        if orthographic {
            self.camera = Some(self.orthographic(n, &p, &to_world, (width, height))?);
            return self.finish(&p);
        }
        let tan_y = self.tan_half_fov_y(n, &p, aspect)?;
        let eye = to_world.transform_point3(DVec3::ZERO);
        let look = to_world.transform_point3(DVec3::Z);
        let up = to_world.transform_vector3(DVec3::Y);
        let mut cam = schema::pinhole(eye, look, up, 0.5 / tan_y, (width, height));
        // A camera constant beyond f64 is left to heron's default.
        cam.d = cam.d.filter(|d| d.0.is_finite());
        self.camera = Some(cam);
        self.finish(&p)
    }

    /// Mitsuba 3's `orthographic` sensor (src/sensors/orthographic.cpp): camera space
    /// x ∈ [-1, 1] across the image's width and y ∈ [-1/aspect, 1/aspect] across its
    /// height (`orthographic_projection`, include/mitsuba/render/sensor.h), mapped by
    /// `to_world`, whose scale thus sets the image plane's size; rays leave the near
    /// plane (z = `near_clip`, default 0.01) along +z. heron's pixels are square: when
    /// `to_world` scales x and y differently the height is kept, with a warning.
    fn orthographic(
        &mut self,
        n: &Node,
        p: &Props,
        to_world: &DMat4,
        (width, height): (u32, u32),
    ) -> Result<CameraFile, Diagnostic> {
        let near = p.float("near_clip")?.unwrap_or(1e-2);
        if !(near >= 0.0 && near.is_finite()) {
            return Err(n.diag(format!(
                "near_clip: expected a finite distance >= 0, got {near}"
            )));
        }
        let aspect = width as f64 / height as f64;
        let sx = to_world.transform_vector3(DVec3::X).length();
        let sy = to_world.transform_vector3(DVec3::Y).length();
        if !(sy > 0.0 && sx > 0.0 && (sx * sy).is_finite()) {
            return Err(n.diag(
                "to_world: expected a finite transform that keeps the image plane's size positive",
            ));
        }
        if (sx - sy).abs() > 1e-6 * sx.max(sy) {
            self.warn(n.diag(format!(
                "to_world scales the image plane's x by {sx} and y by {sy}; heron's pixels are square, so the plane keeps its height and its width is {sy} x 2 (Mitsuba's is {sx} x 2)"
            )))?;
        }
        let eye = to_world.transform_point3(DVec3::new(0.0, 0.0, near));
        let look = eye + to_world.transform_vector3(DVec3::Z);
        let up = to_world.transform_vector3(DVec3::Y);
        let mut cam = schema::pinhole(eye, look, up, 1.0, (width, height));
        cam.d = None;
        cam.kind = Some("orthographic".into());
        cam.height = Some(schema::positive(2.0 * sy / aspect));
        Ok(cam)
    }

    /// tan of half the vertical field of view (heron's image plane has height 1 at d),
    /// as Mitsuba 3's `parse_fov` (src/render/sensor.cpp) reads `fov`, `fov_axis` and
    /// `focal_length`: without `fov`, the focal length (default 50 mm) is that of 36 × 24
    /// mm film measured on the film's diagonal, whatever the image's aspect ratio.
    fn tan_half_fov_y(&mut self, n: &Node, p: &Props, aspect: f64) -> Result<f64, Diagnostic> {
        let fov = p.float("fov")?;
        let focal = p.string("focal_length")?;
        let (tan_half, axis) = match (fov, focal) {
            (Some(_), Some(_)) => {
                return Err(
                    n.diag("expected fov or focal_length, not both (Mitsuba refuses both too)")
                )
            }
            (Some(fov), None) => {
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(n.diag(format!("fov: expected degrees in (0, 180), got {fov}")));
                }
                let axis = p.string("fov_axis")?.unwrap_or("x").to_ascii_lowercase();
                ((0.5 * fov.to_radians()).tan(), axis)
            }
            (None, f) => {
                let text = f.unwrap_or("50mm");
                let mm = text
                    .trim()
                    .trim_end_matches("mm")
                    .parse::<f64>()
                    .ok()
                    .filter(|v| *v > 0.0 && v.is_finite())
                    .ok_or_else(|| {
                        n.diag(format!(
                            "focal_length: expected e.g. \"50mm\", got {text:?}"
                        ))
                    })?;
                // Half the 36 × 24 mm film's diagonal over the focal length.
                ((36.0f64.hypot(24.0) * 0.5) / mm, "diagonal".to_string())
            }
        };
        // Mitsuba resolves smaller and larger with `aspect > 1` (a square image takes x).
        let axis = match axis.as_str() {
            "smaller" if aspect > 1.0 => "y",
            "smaller" => "x",
            "larger" if aspect > 1.0 => "x",
            "larger" => "y",
            a => a,
        };
        Ok(match axis {
            "x" => tan_half / aspect,
            "y" => tan_half,
            "diagonal" => tan_half / (1.0 + aspect * aspect).sqrt(),
            other => {
                return Err(n.diag(format!(
                    "fov_axis: expected x, y, diagonal, smaller or larger, got {other:?}"
                )))
            }
        })
    }

    fn film(&mut self, f: &'a Node) -> Result<(u32, u32), Diagnostic> {
        let kind = Self::plugin(f)?;
        if kind != "hdrfilm" && kind != "specfilm" {
            self.unsupported(f, "heron writes an OpenEXR film like hdrfilm; read as one")?;
        }
        let p = self.props(f);
        let width = p.integer("width")?.unwrap_or(768);
        let height = p.integer("height")?.unwrap_or(576);
        for (k, v) in [("width", width), ("height", height)] {
            if v < 1 {
                return Err(f.diag(format!("{k}: expected at least 1 pixel, got {v}")));
            }
            schema::count(k, v).map_err(|m| f.diag(m))?;
        }
        let filters = p.objects(&["rfilter"]);
        self.rfilter(filters.first().copied())?;
        // What only changes the file's encoding is accepted as is.
        for k in ["pixel_format", "component_format", "file_format", "banner"] {
            p.get(k);
        }
        for k in [
            "crop_width",
            "crop_height",
            "crop_offset_x",
            "crop_offset_y",
        ] {
            if p.get(k).is_some() {
                self.warn(f.diag(format!(
                    "{k}: crops are not supported, the full film is rendered"
                )))?;
            }
        }
        self.finish(&p)?;
        Ok((width as u32, height as u32))
    }

    fn sampler(&mut self, s: &'a Node) -> Result<(), Diagnostic> {
        let p = self.props(s);
        if let Some(spp) = p.integer("sample_count")? {
            if spp < 1 {
                return Err(s.diag(format!("sample_count: expected at least 1, got {spp}")));
            }
            let spp = schema::positive_count("sample_count", spp).map_err(|m| s.diag(m))?;
            self.render().spp = Some(spp);
        }
        if let Some(seed) = p.integer("seed")? {
            self.render().seed = Some(seed.max(0) as u64);
        }
        // heron's sample sequence is its own (Sobol by default); the kind of sampler
        // changes noise, not the expected image.
        p.get("jitter");
        self.finish(&p)
    }

    // ---- BSDFs ----------------------------------------------------------------------
}

/// `path` relative to the folder `base` when one contains the other's ancestors;
/// otherwise `path` as given.
pub fn relative_to(path: &Path, base: &Path) -> PathBuf {
    let (Ok(p), Ok(b)) = (absolute(path), absolute(base)) else {
        return path.to_path_buf();
    };
    let pc: Vec<_> = p.components().collect();
    let bc: Vec<_> = b.components().collect();
    let common = pc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return p;
    }
    let mut out = PathBuf::new();
    for _ in common..bc.len() {
        out.push("..");
    }
    for c in &pc[common..] {
        out.push(c);
    }
    out
}

/// The absolute, `.`-free form of `p` (without touching the file system's links).
fn absolute(p: &Path) -> std::io::Result<PathBuf> {
    let abs = std::path::absolute(p)?;
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    Ok(out)
}
