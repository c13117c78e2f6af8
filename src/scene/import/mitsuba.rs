//! Mitsuba 3 scene objects to heron's scene tables (the TOML heron renders): sensor,
//! film and sampler to `[camera]` and `[render]`, integrators, BSDFs to `[materials]`,
//! shapes (with their area emitters) to `[[shapes]]`, emitters to `[[lights]]` and
//! `background`. Mitsuba's defaults are those of its plugin documentation
//! (mitsuba.readthedocs.io, "Plugin reference", 3.x); where heron has no equivalent the
//! converter says what it did in a [`Diagnostic`] (a warning, an error under `strict`).
use super::props::{ColourError, ColourValue, Props};
use super::xml::{Diagnostic, Node};
use glam::{DMat4, DVec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

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

/// What the conversion made: heron's scene table, and what it could not carry over.
pub struct Converted {
    pub table: Table,
    pub warnings: Vec<Diagnostic>,
}

struct Converter<'a> {
    /// The folder of the top-level file; mesh paths are written relative to it.
    base: PathBuf,
    strict: bool,
    ids: HashMap<&'a str, &'a Node>,
    warnings: Vec<Diagnostic>,
    materials: Table,
    /// Material name of each converted BSDF element (shared through `ref`).
    material_of: HashMap<*const Node, String>,
    default_material: Option<String>,
    shapes: Vec<Value>,
    lights: Vec<Value>,
    background: Option<Value>,
    /// `[environment]` from an `envmap` emitter.
    environment: Option<Value>,
    camera: Option<Table>,
    render: Table,
}

/// Converts the document `root` (from [`super::xml::read_document`]) read from `path`.
pub fn convert(root: &Node, path: &Path, strict: bool) -> Result<Converted, Diagnostic> {
    let mut ids = HashMap::new();
    collect_ids(root, &mut ids)?;
    let mut c = Converter {
        base: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        strict,
        ids,
        warnings: Vec::new(),
        materials: Table::new(),
        material_of: HashMap::new(),
        default_material: None,
        shapes: Vec::new(),
        lights: Vec::new(),
        background: None,
        environment: None,
        camera: None,
        render: Table::new(),
    };
    for child in &root.children {
        match child.tag.as_str() {
            "integrator" => c.integrator(child)?,
            "sensor" => c.sensor(child)?,
            "shape" => c.shape(child)?,
            "emitter" => {
                c.emitter(child, None)?;
            }
            // Named objects at the top level are converted where they are referenced.
            "bsdf" | "texture" | "spectrum" | "rgb" | "float" if child.attr("id").is_some() => {}
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
    let mut table = scene_table(
        camera,
        std::mem::take(&mut c.render),
        c.background.take(),
        std::mem::take(&mut c.materials),
        std::mem::take(&mut c.shapes),
        std::mem::take(&mut c.lights),
    );
    if let Some(e) = c.environment.take() {
        table.insert("environment".into(), e);
    }
    Ok(Converted {
        table,
        warnings: c.warnings,
    })
}

/// heron's scene table from its parts, leaving out the empty optional ones (what both
/// converters, this one and pbrt.rs, assemble).
pub(super) fn scene_table(
    camera: Table,
    render: Table,
    background: Option<Value>,
    materials: Table,
    shapes: Vec<Value>,
    lights: Vec<Value>,
) -> Table {
    let mut t = Table::new();
    t.insert("camera".into(), Value::Table(camera));
    if !render.is_empty() {
        t.insert("render".into(), Value::Table(render));
    }
    if let Some(b) = background {
        t.insert("background".into(), b);
    }
    if !materials.is_empty() {
        t.insert("materials".into(), Value::Table(materials));
    }
    t.insert("shapes".into(), Value::Array(shapes));
    if !lights.is_empty() {
        t.insert("lights".into(), Value::Array(lights));
    }
    t
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

/// `v` to 12 significant digits (far beyond f32's 7), so that a rotation by 90° writes
/// 0 and 1 rather than 6e-17 and 0.9999999999999999.
pub(super) fn tidy(v: f64) -> f64 {
    if v.abs() < 1e-12 {
        return 0.0;
    }
    format!("{v:.11e}").parse().unwrap_or(v)
}

pub(super) fn float(v: f64) -> Value {
    Value::Float(tidy(v))
}

pub(super) fn vec3(v: DVec3) -> Value {
    Value::Array(v.to_array().iter().map(|x| float(*x)).collect())
}

pub(super) fn table(pairs: Vec<(&str, Value)>) -> Table {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

impl<'a> Converter<'a> {
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

    /// The image file of parameter `name` when it is a `bitmap` texture (nested or by
    /// `ref`), relative to the top-level file's folder, as heron's `texture` reads it
    /// (bilinear, repeating, 8-bit images sRGB-decoded: Mitsuba's defaults). Its other
    /// settings warn where heron differs.
    fn bitmap(&mut self, p: &Props<'a>, name: &str) -> Result<Option<String>, Diagnostic> {
        let Some(n) = p
            .node
            .children
            .iter()
            .find(|c| c.attr("name") == Some(name))
        else {
            return Ok(None);
        };
        let t = self.resolve(n)?;
        if t.tag != "texture" || t.attr("type") != Some("bitmap") {
            return Ok(None);
        }
        p.get(name);
        let tp = Props::new(t);
        let Some(file) = tp.string("filename")? else {
            return Err(t.diag("expected <string name=\"filename\" value=\"…\"/>"));
        };
        let folder = t.file.parent().unwrap_or(Path::new(""));
        let rel = relative_to(&folder.join(file), &self.base);
        for (key, default) in [("filter_type", "bilinear"), ("wrap_mode", "repeat")] {
            if let Some(v) = tp.string(key)? {
                if v != default {
                    self.warn(t.diag(format!(
                        "{key} {v:?}: heron's textures are {default}, which is used"
                    )))?;
                }
            }
        }
        if tp.boolean("raw")? == Some(true) {
            self.warn(t.diag(
                "raw: heron decodes an 8-bit image's sRGB curve regardless (Mitsuba's spectral variants refuse a raw reflectance)",
            ))?;
        }
        if let Some(m) = tp.transform("to_uv")? {
            if m != DMat4::IDENTITY {
                self.warn(t.diag("to_uv is not supported, ignored: the texture is not moved"))?;
            }
        }
        for w in tp.unread() {
            self.warn(w)?;
        }
        Ok(Some(rel.to_string_lossy().replace('\\', "/")))
    }

    /// A colour, or `default` when absent; unsupported forms warn and use `default`.
    fn colour(
        &mut self,
        p: &Props,
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
        let p = Props::new(n);
        let kind = Self::plugin(n)?;
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
        self.render
            .insert("integrator".into(), Value::String(integrator.into()));
        self.render
            .insert("max_depth".into(), Value::Integer(heron_depth));
        if let Some(rr) = p.integer("rr_depth")? {
            self.render
                .insert("rr_depth".into(), Value::Integer((rr - 1).max(0)));
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
        if p.boolean("hide_emitters")? == Some(true) {
            self.warn(n.diag("hide_emitters is not supported, emitters stay visible"))?;
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
        if kind != "perspective" && kind != "thinlens" {
            return Err(n.diag(format!(
                "expected a perspective sensor (or thinlens, rendered as a pinhole), got {kind:?}"
            )));
        }
        let p = Props::new(n);
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
        for k in ["near_clip", "far_clip"] {
            if p.get(k).is_some() {
                self.warn(n.diag(format!(
                    "{k}: heron's camera has no clipping planes, ignored"
                )))?;
            }
        }
        // Film first: the field of view's axis needs the aspect ratio.
        let (mut width, mut height) = (768_i64, 576_i64);
        for f in p.objects(&["film", "sampler"]) {
            let f = self.resolve(f)?;
            match f.tag.as_str() {
                "film" => (width, height) = self.film(f)?,
                "sampler" => self.sampler(f)?,
                _ => return Err(f.diag("expected a film or a sampler inside the sensor")),
            }
        }
        let aspect = width as f64 / height as f64;
        let fov_axis = p.string("fov_axis")?.unwrap_or("x");
        // tan of half the vertical field of view (heron's image plane has height 1 at d).
        let tan_y = match (p.float("fov")?, p.string("focal_length")?) {
            (Some(fov), _) => {
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(n.diag(format!("fov: expected degrees in (0, 180), got {fov}")));
                }
                let t = (0.5 * fov.to_radians()).tan();
                let axis = match fov_axis {
                    "smaller" if aspect < 1.0 => "x",
                    "smaller" => "y",
                    "larger" if aspect < 1.0 => "y",
                    "larger" => "x",
                    a => a,
                };
                match axis {
                    "x" => t / aspect,
                    "y" => t,
                    "diagonal" => t / (1.0 + aspect * aspect).sqrt(),
                    other => {
                        return Err(n.diag(format!(
                            "fov_axis: expected x, y, diagonal, smaller or larger, got {other:?}"
                        )))
                    }
                }
            }
            (None, f) => {
                // Mitsuba: the focal length of 36 × 24 mm film, 36 mm along the longer
                // image axis (checked against Mitsuba 3.9's x_fov).
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
                let t_long = 18.0 / mm;
                if aspect >= 1.0 {
                    t_long / aspect
                } else {
                    t_long
                }
            }
        };
        let eye = to_world.transform_point3(DVec3::ZERO);
        let look = to_world.transform_point3(DVec3::Z);
        let up = to_world.transform_vector3(DVec3::Y);
        let mut cam = table(vec![
            ("eye", vec3(eye)),
            ("look_at", vec3(look)),
            ("up", vec3(up)),
            ("d", float(0.5 / tan_y)),
            (
                "resolution",
                Value::Array(vec![Value::Integer(width), Value::Integer(height)]),
            ),
        ]);
        cam.retain(|_, v| !matches!(v, Value::Float(x) if !x.is_finite()));
        self.camera = Some(cam);
        self.finish(&p)
    }

    fn film(&mut self, f: &'a Node) -> Result<(i64, i64), Diagnostic> {
        let kind = Self::plugin(f)?;
        if kind != "hdrfilm" && kind != "specfilm" {
            self.unsupported(f, "heron writes an OpenEXR film like hdrfilm; read as one")?;
        }
        let p = Props::new(f);
        let width = p.integer("width")?.unwrap_or(768);
        let height = p.integer("height")?.unwrap_or(576);
        for (k, v) in [("width", width), ("height", height)] {
            if v < 1 {
                return Err(f.diag(format!("{k}: expected at least 1 pixel, got {v}")));
            }
        }
        let filters = p.objects(&["rfilter"]);
        match filters.first() {
            None => self.warn(f.diag(
                "no rfilter: Mitsuba's default is a Gaussian, heron's pixels are box-filtered",
            ))?,
            Some(r) => {
                let r = self.resolve(r)?;
                if Self::plugin(r)? != "box" {
                    self.warn(
                        r.diag("heron's pixels are box-filtered; this filter is read as box"),
                    )?;
                }
            }
        }
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
        Ok((width, height))
    }

    fn sampler(&mut self, s: &'a Node) -> Result<(), Diagnostic> {
        let p = Props::new(s);
        if let Some(spp) = p.integer("sample_count")? {
            if spp < 1 {
                return Err(s.diag(format!("sample_count: expected at least 1, got {spp}")));
            }
            self.render.insert("spp".into(), Value::Integer(spp));
        }
        if let Some(seed) = p.integer("seed")? {
            self.render
                .insert("seed".into(), Value::Integer(seed.max(0)));
        }
        // heron's sample sequence is its own (Sobol by default); the kind of sampler
        // changes noise, not the expected image.
        p.get("jitter");
        self.finish(&p)
    }

    // ---- BSDFs ----------------------------------------------------------------------

    /// The name of heron's material for BSDF element `n` (converted once).
    fn bsdf(&mut self, n: &'a Node) -> Result<String, Diagnostic> {
        let n = self.resolve(n)?;
        if n.tag != "bsdf" {
            return Err(n.diag("expected a <bsdf>"));
        }
        if let Some(name) = self.material_of.get(&(n as *const Node)) {
            return Ok(name.clone());
        }
        let table = self.bsdf_table(n)?;
        let name = match table {
            Some(t) => {
                let base = n
                    .attr("id")
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("{}-{}", n.attr("type").unwrap_or("bsdf"), n.line));
                let mut name = base.clone();
                let mut k = 2;
                while self.materials.contains_key(&name) {
                    name = format!("{base}-{k}");
                    k += 1;
                }
                self.materials.insert(name.clone(), Value::Table(t));
                name
            }
            None => self.default_material(),
        };
        self.material_of.insert(n as *const Node, name.clone());
        Ok(name)
    }

    /// Mitsuba's default BSDF (a diffuse reflectance of 0.5), made once.
    fn default_material(&mut self) -> String {
        if let Some(m) = &self.default_material {
            return m.clone();
        }
        let name = "mitsuba-default-diffuse".to_string();
        self.materials.insert(
            name.clone(),
            Value::Table(table(vec![
                ("type", Value::String("lambertian".into())),
                ("rho_d", float(0.5)),
            ])),
        );
        self.default_material = Some(name.clone());
        name
    }

    /// heron's table for a BSDF, or None for Mitsuba's default (after a warning).
    fn bsdf_table(&mut self, n: &'a Node) -> Result<Option<Table>, Diagnostic> {
        let kind = Self::plugin(n)?;
        let p = Props::new(n);
        let t = match kind {
            "twosided" | "mask" | "bumpmap" | "normalmap" => {
                // heron's surfaces are two-sided: `twosided` adds nothing. The others
                // modulate their nested BSDF, which heron renders unmodulated.
                let inner = p.objects(&["bsdf"]);
                if kind != "twosided" {
                    self.warn(n.diag(format!(
                        "{kind} is not supported: the nested BSDF is used without it"
                    )))?;
                }
                for k in ["opacity", "scale", "flip_invert"] {
                    p.get(k);
                }
                // Textures a bump or normal map names are not read.
                p.objects(&["texture"]);
                self.finish(&p)?;
                return match inner.as_slice() {
                    [] => Ok(None),
                    [b, ..] => {
                        let b = self.resolve(b)?;
                        if inner.len() > 1 {
                            self.warn(n.diag(
                                "two BSDFs (front and back); heron uses the first on both sides",
                            ))?;
                        }
                        let name = self.bsdf(b)?;
                        Ok(self
                            .materials
                            .get(&name)
                            .and_then(|v| v.as_table())
                            .cloned())
                    }
                };
            }
            "diffuse" => {
                if let Some(file) = self.bitmap(&p, "reflectance")? {
                    table(vec![
                        ("type", Value::String("lambertian".into())),
                        ("texture", Value::String(file)),
                    ])
                } else {
                    let rho = self.colour(&p, "reflectance", ColourValue::Grey(0.5))?;
                    table(vec![
                        ("type", Value::String("lambertian".into())),
                        ("rho_d", rho.to_toml()),
                    ])
                }
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                if kind == "thindielectric" {
                    self.warn(n.diag(
                        "thindielectric (a sheet with no thickness) is not supported yet; Mitsuba's default BSDF is used",
                    ))?;
                    for k in [
                        "int_ior",
                        "ext_ior",
                        "specular_reflectance",
                        "specular_transmittance",
                    ] {
                        p.get(k);
                    }
                    self.finish(&p)?;
                    return Ok(None);
                }
                let int = self.ior(&p, "int_ior", "bk7")?;
                let ext = self.ior(&p, "ext_ior", "air")?;
                let mut t = table(vec![
                    ("type", Value::String("dielectric".into())),
                    ("ior", int),
                ]);
                // Air's 1.000277 is kept: it is Mitsuba's own default, and heron's
                // relative index is then Mitsuba's.
                t.insert("outside_ior".into(), ext);
                if kind == "roughdielectric" {
                    let alpha = self.roughness(n, &p)?;
                    t.insert("roughness".into(), float(alpha));
                }
                for k in ["specular_reflectance", "specular_transmittance"] {
                    if let Some(c) = p.get(k) {
                        self.warn(c.diag(format!(
                            "{k}: heron's dielectric has no such factor, ignored (1 is used)"
                        )))?;
                    }
                }
                t
            }
            "conductor" | "roughconductor" => {
                let material = p.string("material")?;
                let eta = p.float("eta");
                let k = p.float("k");
                let (eta, k) = (eta?, k?);
                let metal = match (material, eta, k) {
                    (_, Some(n_), Some(k_)) => Some(Value::Table(table(vec![
                        ("n", float(n_)),
                        ("k", float(k_)),
                    ]))),
                    (Some(m), None, None) if METALS.contains(&m) => Some(Value::String(m.into())),
                    (None | Some("none"), None, None) => None,
                    (Some(m), None, None) => {
                        return Err(n.diag(format!(
                            "material: expected one of the metals heron tabulates ({}), \"none\", or eta and k as numbers, got {m:?}",
                            METALS.join(", ")
                        )))
                    }
                    _ => {
                        return Err(n.diag(
                            "expected both eta and k as <float> (spectral and RGB eta/k are not supported yet)",
                        ))
                    }
                };
                if let Some(c) = p.get("specular_reflectance") {
                    self.warn(c.diag("specular_reflectance: heron's conductor has no such factor, ignored (1 is used)"))?;
                }
                match metal {
                    // Mitsuba's `none`: a perfect mirror.
                    None if kind == "conductor" => table(vec![
                        ("type", Value::String("mirror".into())),
                        ("rho_s", float(1.0)),
                    ]),
                    None => {
                        return Err(n.diag(
                            "material \"none\" on a roughconductor: heron has no rough perfect mirror; give a metal or eta and k",
                        ))
                    }
                    Some(m) => {
                        let mut t = table(vec![("type", Value::String("conductor".into())), ("metal", m)]);
                        if kind == "roughconductor" {
                            let alpha = self.roughness(n, &p)?;
                            t.insert("roughness".into(), float(alpha));
                        }
                        t
                    }
                }
            }
            "plastic" | "roughplastic" => {
                let rho = self.colour(&p, "diffuse_reflectance", ColourValue::Grey(0.5))?;
                let eta = match self.ior(&p, "int_ior", "polypropylene")? {
                    Value::Float(x) => x,
                    Value::String(name) => mitsuba_ior(&name).unwrap_or(1.49),
                    _ => 1.49,
                };
                let ext = match self.ior(&p, "ext_ior", "air")? {
                    Value::Float(x) => x,
                    _ => 1.000277,
                };
                let eta = eta / ext;
                let alpha = if kind == "roughplastic" {
                    self.roughness(n, &p)?
                } else {
                    0.01
                };
                let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
                // Beckmann α ↔ Phong exponent 2/α² − 2 (Walter et al. 2007, §5.2).
                let shininess = (2.0 / (alpha * alpha) - 2.0).max(1.0);
                for k in ["specular_reflectance", "nonlinear"] {
                    p.get(k);
                }
                self.warn(n.diag(format!(
                    "{kind} is mapped to heron's glossy (modified Phong) material: ρd = diffuse_reflectance, ρs = Fresnel at normal incidence {f0:.4}, shininess {shininess:.0} from α = {alpha}; Mitsuba's coating (Fresnel-weighted, with internal reflections) differs"
                )))?;
                let scale = rho.max();
                // heron requires ρd + ρs ≤ 1 (energy).
                let rho = if scale + f0 > 1.0 {
                    rho.scaled((1.0 - f0) / scale)
                } else {
                    rho
                };
                table(vec![
                    ("type", Value::String("glossy".into())),
                    ("rho_d", rho.to_toml()),
                    ("rho_s", float(f0)),
                    ("shininess", float(shininess)),
                ])
            }
            other => {
                self.warn(n.diag(format!(
                    "BSDF {other:?} is not supported (diffuse, dielectric, roughdielectric, conductor, roughconductor, plastic, roughplastic, twosided are); Mitsuba's default BSDF (diffuse 0.5) is used"
                )))?;
                return Ok(None);
            }
        };
        self.finish(&p)?;
        Ok(Some(t))
    }

    /// A microfacet BSDF's α: `alpha`, or `alpha_u`/`alpha_v` when equal; Mitsuba's
    /// default 0.1. heron's microfacets are GGX.
    fn roughness(&mut self, n: &Node, p: &Props) -> Result<f64, Diagnostic> {
        let given = p.string("distribution")?;
        let dist = given.unwrap_or("beckmann");
        if dist != "ggx" {
            let default = if given.is_none() {
                " (Mitsuba's default)"
            } else {
                ""
            };
            let msg = format!(
                "distribution {dist:?}{default}: heron's microfacets are GGX, used with the same α"
            );
            self.warn(n.diag(msg))?;
        }
        p.get("sample_visible");
        let alpha = p.float("alpha")?;
        let (u, v) = (p.float("alpha_u")?, p.float("alpha_v")?);
        let a = match (alpha, u, v) {
            (Some(a), _, _) => a,
            (None, Some(u), Some(v)) => {
                if u != v {
                    self.warn(n.diag(format!(
                        "anisotropic roughness (alpha_u {u}, alpha_v {v}) is not supported; their mean is used"
                    )))?;
                }
                0.5 * (u + v)
            }
            _ => 0.1,
        };
        if !(0.0..=1.0).contains(&a) {
            return Err(n.diag(format!("alpha: expected a roughness in [0, 1], got {a}")));
        }
        Ok(a)
    }

    /// An index of refraction as heron writes it: a number, or a catalogue name for the
    /// Mitsuba names heron has with dispersion.
    fn ior(&mut self, p: &Props, name: &str, default: &str) -> Result<Value, Diagnostic> {
        let node = p.get(name);
        let text = match node {
            None => default.to_string(),
            Some(c) => c.attr("value").unwrap_or("").trim().to_string(),
        };
        if let Ok(x) = text.parse::<f64>() {
            if !(x.is_finite() && x > 0.0) {
                let c = node.expect("a number came from the file");
                return Err(c.diag(format!("value: expected an index > 0, got {text:?}")));
            }
            return Ok(float(x));
        }
        if let Some((_, entry)) = CATALOGUE_IORS.iter().find(|(m, _)| *m == text) {
            if let Some(c) = node {
                // Said once per element: Mitsuba's constant is not what heron renders.
                self.warn(c.diag(format!(
                    "{text:?} is heron's catalogue entry {entry:?}, with its dispersion (Mitsuba uses the constant {})",
                    mitsuba_ior(&text).unwrap_or(f64::NAN)
                )))?;
            }
            return Ok(Value::String((*entry).into()));
        }
        match mitsuba_ior(&text) {
            Some(x) => Ok(float(x)),
            None => {
                let names: Vec<&str> = MITSUBA_IORS.iter().map(|(n, _)| *n).collect();
                Err(node.unwrap_or(p.node).diag(format!(
                    "{name}: expected a number or one of Mitsuba's named indices ({}), got {text:?}",
                    names.join(", ")
                )))
            }
        }
    }

    // ---- shapes -----------------------------------------------------------------

    fn shape(&mut self, n: &'a Node) -> Result<(), Diagnostic> {
        let kind = Self::plugin(n)?;
        let p = Props::new(n);
        let to_world = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        let flip = p.boolean("flip_normals")?.unwrap_or(false);
        // The BSDF and an area emitter.
        let mut material = None;
        let mut emission = None;
        for o in p.objects(&["bsdf", "emitter", "medium"]) {
            let o = self.resolve(o)?;
            match o.tag.as_str() {
                "bsdf" => material = Some(self.bsdf(o)?),
                "emitter" => emission = self.emitter(o, Some(n))?,
                "medium" => {
                    self.unsupported(o, "media are not supported by heron's import yet, ignored")?
                }
                _ => return Err(o.diag("expected a bsdf, an emitter or a medium inside a shape")),
            }
        }
        let material = match material {
            Some(m) => m,
            None => self.default_material(),
        };
        let mut entries: Vec<Table> = Vec::new();
        match kind {
            "rectangle" => {
                let mut q = quad(&to_world, [-1.0, -1.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
                if flip {
                    q.reverse_edges();
                }
                entries.push(q.table());
            }
            "cube" => {
                // The six faces of [-1, 1]³, each (origin, edge1, edge2) with edge1 × edge2
                // outward.
                let faces = [
                    ([1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]),
                    ([-1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),
                    ([-1.0, 1.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]),
                    ([-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
                    ([-1.0, -1.0, 1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
                    ([-1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]),
                ];
                for (o, e1, e2) in faces {
                    let mut q = quad(&to_world, o, e1, e2);
                    if flip {
                        q.reverse_edges();
                    }
                    entries.push(q.table());
                }
            }
            "disk" => {
                let c = to_world.transform_point3(DVec3::ZERO);
                for i in 0..DISK_SEGMENTS {
                    let a0 = std::f64::consts::TAU * i as f64 / DISK_SEGMENTS as f64;
                    let a1 = std::f64::consts::TAU * (i + 1) as f64 / DISK_SEGMENTS as f64;
                    let v0 = to_world.transform_point3(DVec3::new(a0.cos(), a0.sin(), 0.0));
                    let v1 = to_world.transform_point3(DVec3::new(a1.cos(), a1.sin(), 0.0));
                    // Counter-clockwise about the transformed +z, as `quad` keeps it.
                    let swap = flip ^ (to_world.determinant() < 0.0);
                    let verts = if swap { [c, v1, v0] } else { [c, v0, v1] };
                    entries.push(table(vec![
                        ("type", Value::String("triangle".into())),
                        ("vertices", Value::Array(verts.into_iter().map(vec3).collect())),
                    ]));
                }
            }
            "sphere" => {
                let center = p.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = p.float("radius")?.unwrap_or(1.0);
                let m3 = glam::DMat3::from_mat4(to_world);
                let s = [m3.x_axis.length(), m3.y_axis.length(), m3.z_axis.length()];
                if (s[0] - s[1]).abs() > 1e-6 * s[0] || (s[0] - s[2]).abs() > 1e-6 * s[0] {
                    return Err(n.diag(format!(
                        "to_world scales the sphere by {:.6}, {:.6}, {:.6}: heron's spheres take a uniform scale only",
                        s[0], s[1], s[2]
                    )));
                }
                if flip {
                    self.warn(n.diag("flip_normals on a sphere is not supported, ignored"))?;
                }
                entries.push(table(vec![
                    ("type", Value::String("sphere".into())),
                    ("center", vec3(to_world.transform_point3(center))),
                    ("radius", float(radius * s[0])),
                ]));
            }
            "obj" | "ply" => {
                let Some(file) = p.string("filename")? else {
                    return Err(n.diag("expected <string name=\"filename\" value=\"…\"/>"));
                };
                let folder = n.file.parent().unwrap_or(Path::new(""));
                let full = folder.join(file);
                let rel = relative_to(&full, &self.base);
                if flip {
                    self.warn(n.diag("flip_normals on a mesh is not supported, ignored"))?;
                }
                // heron shades every mesh by its face normals (README, "Mitsuba 3 scenes").
                p.get("face_normals");
                let flip_uv = p.boolean("flip_tex_coords")?;
                let mut t = table(vec![
                    ("type", Value::String("mesh".into())),
                    ("file", Value::String(rel.to_string_lossy().replace('\\', "/"))),
                ]);
                if to_world != DMat4::IDENTITY {
                    let rows: Vec<Value> = (0..4)
                        .map(|r| vec_row(to_world.row(r).to_array()))
                        .collect();
                    t.insert("transform".into(), Value::Array(rows));
                }
                // heron's defaults are Mitsuba's (true for OBJ, false for PLY).
                if let Some(f) = flip_uv {
                    t.insert("flip_tex_coords".into(), Value::Boolean(f));
                }
                entries.push(t);
            }
            "serialized" => {
                return Err(n.diag(
                    "Mitsuba's serialized meshes are not supported; save the mesh as PLY (Mitsuba 3: mesh.write_ply) and use <shape type=\"ply\">",
                ))
            }
            other => {
                self.warn(n.diag(format!(
                    "shape {other:?} is not supported (rectangle, cube, disk, sphere, obj, ply are), ignored"
                )))?;
                return self.finish(&p);
            }
        }
        for mut e in entries {
            e.insert("material".into(), Value::String(material.clone()));
            if let Some(em) = &emission {
                e.insert("emission".into(), em.clone());
            }
            self.shapes.push(Value::Table(e));
        }
        self.finish(&p)
    }

    // ---- emitters ---------------------------------------------------------------

    /// Converts an emitter; inside a shape (`shape` given) it returns the area light's
    /// radiance for the shape's `emission`.
    fn emitter(&mut self, n: &'a Node, shape: Option<&Node>) -> Result<Option<Value>, Diagnostic> {
        let kind = Self::plugin(n)?;
        let p = Props::new(n);
        let out = match (kind, shape) {
            ("area", Some(_)) => {
                let l = self.colour(&p, "radiance", ColourValue::Grey(1.0))?;
                Some(l.to_toml())
            }
            ("area", None) => return Err(n.diag("an area emitter must be inside a <shape>")),
            (_, Some(s)) => {
                return Err(n.diag(format!(
                    "expected an area emitter inside {}, got {kind:?}",
                    s.describe()
                )))
            }
            ("point", None) => {
                let pos = match (p.point("position")?, p.transform("to_world")?) {
                    (Some(x), _) => x,
                    (None, Some(m)) => m.transform_point3(DVec3::ZERO),
                    (None, None) => DVec3::ZERO,
                };
                let i = self.colour(&p, "intensity", ColourValue::Grey(1.0))?;
                self.lights.push(Value::Table(table(vec![
                    ("type", Value::String("point".into())),
                    ("position", vec3(pos)),
                    ("intensity", i.to_toml()),
                ])));
                None
            }
            ("spot", None) => {
                let m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
                let cutoff = p.float("cutoff_angle")?.unwrap_or(20.0);
                let beam = p.float("beam_width")?.unwrap_or(cutoff * 0.75);
                if !(cutoff > 0.0 && cutoff <= 90.0 && beam >= 0.0 && beam <= cutoff) {
                    return Err(n.diag(format!(
                        "expected 0 < cutoff_angle ≤ 90 and 0 ≤ beam_width ≤ cutoff_angle, got {cutoff} and {beam}"
                    )));
                }
                let i = self.colour(&p, "intensity", ColourValue::Grey(1.0))?;
                self.warn(n.diag(
                    "spot: heron's falloff between beam_width and cutoff_angle is pbrt's smoothstep, Mitsuba's is linear in angle",
                ))?;
                self.lights.push(Value::Table(table(vec![
                    ("type", Value::String("spot".into())),
                    ("position", vec3(m.transform_point3(DVec3::ZERO))),
                    ("direction", vec3(m.transform_vector3(DVec3::Z))),
                    ("intensity", i.to_toml()),
                    ("cone_angle", float(cutoff)),
                    ("cone_delta", float(cutoff - beam)),
                ])));
                None
            }
            ("directional", None) => {
                let dir = match (p.point("direction")?, p.transform("to_world")?) {
                    (Some(d), _) => d,
                    (None, Some(m)) => m.transform_vector3(DVec3::Z),
                    (None, None) => DVec3::Z,
                };
                if dir.length() == 0.0 {
                    return Err(n.diag("direction: expected a non-zero vector"));
                }
                let e = self.colour(&p, "irradiance", ColourValue::Grey(1.0))?;
                self.lights.push(Value::Table(table(vec![
                    ("type", Value::String("directional".into())),
                    ("direction", vec3(dir)),
                    ("radiance", e.to_toml()),
                ])));
                None
            }
            ("constant", None) => {
                let l = self.colour(&p, "radiance", ColourValue::Grey(1.0))?;
                if self.background.is_some() || self.environment.is_some() {
                    self.warn(n.diag(
                        "a second environment emitter (constant or envmap); heron's environment is the first, ignored",
                    ))?;
                } else {
                    self.background = Some(l.to_toml());
                }
                None
            }
            ("envmap", None) => {
                let Some(file) = p.string("filename")? else {
                    return Err(n.diag("expected <string name=\"filename\" value=\"…\"/>"));
                };
                let folder = n.file.parent().unwrap_or(Path::new(""));
                let rel = relative_to(&folder.join(file), &self.base);
                let scale = p.float("scale")?.unwrap_or(1.0);
                if !(scale >= 0.0) {
                    return Err(n.diag(format!("scale: expected a number ≥ 0, got {scale}")));
                }
                let to_world = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
                // Only how the map is sampled, not what it shows: heron's own sampling.
                p.get("mis_compensation");
                let mut t = table(vec![
                    (
                        "map",
                        Value::String(rel.to_string_lossy().replace('\\', "/")),
                    ),
                    ("scale", float(scale)),
                ]);
                if to_world != DMat4::IDENTITY {
                    // The map is at infinity: its translation does not matter.
                    let mut m = to_world;
                    m.w_axis = glam::DVec4::W;
                    let rows: Vec<Value> = (0..4).map(|r| vec_row(m.row(r).to_array())).collect();
                    t.insert("transform".into(), Value::Array(rows));
                }
                if self.environment.is_some() || self.background.is_some() {
                    self.warn(n.diag(
                        "a second environment emitter (envmap or constant); heron's environment is the first, ignored",
                    ))?;
                } else {
                    self.environment = Some(Value::Table(t));
                }
                None
            }
            (other, None) => {
                self.warn(n.diag(format!(
                    "emitter {other:?} is not supported yet (area, point, spot, directional, constant, envmap are), ignored: the image lacks its light"
                )))?;
                return Ok(None);
            }
        };
        self.finish(&p)?;
        Ok(out)
    }
}

pub(super) fn vec_row(r: [f64; 4]) -> Value {
    Value::Array(r.iter().map(|x| float(*x)).collect())
}

/// Mitsuba's constant for a named index.
fn mitsuba_ior(name: &str) -> Option<f64> {
    MITSUBA_IORS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, x)| *x)
}

/// A parallelogram after a transform: origin and edges in world space.
struct Quad {
    origin: DVec3,
    edge1: DVec3,
    edge2: DVec3,
}

impl Quad {
    fn reverse_edges(&mut self) {
        std::mem::swap(&mut self.edge1, &mut self.edge2);
    }

    fn table(&self) -> Table {
        table(vec![
            ("type", Value::String("quad".into())),
            ("origin", vec3(self.origin)),
            ("edge1", vec3(self.edge1)),
            ("edge2", vec3(self.edge2)),
        ])
    }
}

fn quad(m: &DMat4, o: [f64; 3], e1: [f64; 3], e2: [f64; 3]) -> Quad {
    let o = DVec3::from_array(o);
    let (e1, e2) = (DVec3::from_array(e1), DVec3::from_array(e2));
    let origin = m.transform_point3(o);
    let mut q = Quad {
        origin,
        edge1: m.transform_point3(o + e1) - origin,
        edge2: m.transform_point3(o + e2) - origin,
    };
    // A mirroring transform turns the normal inward; Mitsuba's normal follows the
    // transformed geometry's orientation, so the edges are swapped back.
    if m.determinant() < 0.0 {
        q.reverse_edges();
    }
    q
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
