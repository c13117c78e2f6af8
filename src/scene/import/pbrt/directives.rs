//! pbrt-v4's directives: the files and their `Include`s and `Import`s, the graphics
//! state (the current transformation matrix, `AttributeBegin`/`End`,
//! `TransformBegin`/`End`, reverse orientation, the current material and area light),
//! object instancing (`ObjectBegin`/`End`/`Instance`) and the rendering options; what
//! makes scene content is handed to `translate.rs`.
use super::tokens::{Params, Statement, Statements};
use super::*;

/// Includes nested deeper than this are taken for a cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

/// A statement in its file, at its include depth.
pub(super) struct Directive<'a> {
    path: &'a Path,
    depth: usize,
    st: &'a Statement,
}

impl Directive<'_> {
    fn line(&self) -> u32 {
        self.st.line
    }

    /// The first positional name ("" if none).
    fn name(&self) -> String {
        self.st.strs.first().cloned().unwrap_or_default()
    }

    fn nums(&self) -> &[f64] {
        &self.st.nums
    }

    fn params(&self) -> &Params {
        &self.st.params
    }

    /// The error unless the directive has `n` numbers.
    fn need(&self, n: usize) -> Result<(), Diagnostic> {
        if self.st.nums.len() != n {
            return Err(Diagnostic {
                file: self.path.to_path_buf(),
                line: self.st.line,
                message: format!(
                    "{}: expected {n} numbers, got {}",
                    self.st.name,
                    self.st.nums.len()
                ),
            });
        }
        Ok(())
    }
}

impl Conv {
    pub(super) fn file(
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
    pub(super) fn text(&mut self, text: &str, path: &Path, depth: usize) -> Result<(), Diagnostic> {
        let mut statements = Statements::new(text, path)?;
        while let Some(st) = statements.next_statement() {
            let st = st?;
            let d = Directive {
                path,
                depth,
                st: &st,
            };
            self.directive(&d)?;
            for p in &st.params.0 {
                if !p.used.get() {
                    self.warn(self.diag(
                        path,
                        p.line,
                        format!(
                            "{}: parameter \"{} {}\" is not supported by heron, ignored",
                            st.name, p.ty, p.name
                        ),
                    ))?;
                }
            }
        }
        Ok(())
    }

    fn directive(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line) = (d.path, d.line());
        match d.st.name.as_str() {
            "Identity" | "Translate" | "Scale" | "Rotate" | "LookAt" | "Transform"
            | "ConcatTransform" => self.transform(d),
            "Camera" => self.camera(d),
            "Film" => self.film(d),
            "PixelFilter" => self.pixel_filter(path, line, d.name(), d.params()),
            "Sampler" => {
                let p = d.params();
                if let Some(n) = p.float("pixelsamples") {
                    let spp = schema::positive_count("Sampler: pixelsamples", (n as i64).max(1))
                        .map_err(|m| self.diag(path, line, m))?;
                    self.render().spp = Some(spp);
                }
                if let Some(seed) = p.float("seed") {
                    self.render().seed = Some(seed.max(0.0) as i64 as u64);
                }
                Ok(())
            }
            "Integrator" => self.integrator(d),
            "WorldBegin" => {
                self.g.ctm = DMat4::IDENTITY;
                Ok(())
            }
            "AttributeBegin" => {
                self.push("AttributeBegin", path, line);
                Ok(())
            }
            "TransformBegin" => {
                self.push("TransformBegin", path, line);
                Ok(())
            }
            "AttributeEnd" | "TransformEnd" => self.pop(d),
            "ObjectBegin" => self.object_begin(path, line, &d.name()),
            "ObjectEnd" => self.object_end(path, line),
            "ObjectInstance" => self.object_instance(d),
            "ReverseOrientation" => {
                self.g.reverse = !self.g.reverse;
                Ok(())
            }
            "Material" | "MakeNamedMaterial" | "NamedMaterial" | "AreaLightSource" => {
                self.material_state(d)
            }
            "LightSource" => self.light(path, line, &d.name(), d.params()),
            "Shape" => self.shape(path, line, &d.name(), d.params()),
            "Include" => {
                let f = self.base_of(path).join(d.name());
                self.file(&f, d.depth + 1, Some((path, line)))
            }
            "Import" => self.import(d),
            "WorldEnd" | "OptionBool" | "ColorSpace" | "Option" => Ok(()),
            "MakeNamedMedium" => self.make_medium(path, line, &d.name(), d.params()),
            "MediumInterface" => {
                self.medium_interface(&d.st.strs);
                Ok(())
            }
            "Texture" => self.texture_directive(path, line, &d.st.strs, d.params()),
            "CoordinateSystem" | "CoordSysTransform" | "Attribute" | "Accelerator"
            | "ActiveTransform" | "TransformTimes" => {
                for q in &d.params().0 {
                    q.used.set(true);
                }
                let name = &d.st.name;
                self.warn(self.diag(
                    path,
                    line,
                    format!("{name} is not supported by heron's import yet, ignored"),
                ))
            }
            other => Err(self.diag(path, line, format!("unknown directive {other:?}"))),
        }
    }

    /// `Identity`, `Translate`, `Scale`, `Rotate`, `LookAt`, `Transform` and
    /// `ConcatTransform` on the current transformation matrix.
    fn transform(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line, nums) = (d.path, d.line(), d.nums());
        match d.st.name.as_str() {
            "Identity" => self.g.ctm = DMat4::IDENTITY,
            "Translate" => {
                d.need(3)?;
                self.g.ctm *= DMat4::from_translation(DVec3::new(nums[0], nums[1], nums[2]));
            }
            "Scale" => {
                d.need(3)?;
                self.g.ctm *= DMat4::from_scale(DVec3::new(nums[0], nums[1], nums[2]));
            }
            "Rotate" => {
                d.need(4)?;
                let axis = DVec3::new(nums[1], nums[2], nums[3]);
                if axis.length() == 0.0 {
                    return Err(self.diag(path, line, "Rotate: expected a non-zero axis"));
                }
                self.g.ctm *= DMat4::from_axis_angle(axis.normalize(), nums[0].to_radians());
            }
            "LookAt" => {
                d.need(9)?;
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
            transform => {
                d.need(16)?;
                let m = DMat4::from_cols_array(&nums.try_into().expect("16 numbers"));
                if transform == "Transform" {
                    self.g.ctm = m;
                } else {
                    self.g.ctm *= m;
                }
            }
        }
        Ok(())
    }

    fn camera(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line, p) = (d.path, d.line(), d.params());
        let projection = match d.name().as_str() {
            "perspective" => {
                for k in [
                    "lensradius",
                    "focaldistance",
                    "screenwindow",
                    "frameaspectratio",
                ] {
                    if p.get(k).is_some() {
                        self.warn(self.diag(
                            path,
                            line,
                            format!("Camera: {k} is not supported, ignored"),
                        ))?;
                    }
                }
                Projection::Perspective {
                    fov: p.float("fov").unwrap_or(90.0),
                }
            }
            "orthographic" => self.orthographic(d)?,
            other => {
                return Err(self.diag(
                    path,
                    line,
                    format!("Camera: expected \"perspective\" or \"orthographic\", got {other:?}"),
                ))
            }
        };
        for k in ["shutteropen", "shutterclose"] {
            if p.get(k).is_some() {
                self.warn(self.diag(path, line, format!("Camera: {k} is not supported, ignored")))?;
            }
        }
        if !self.g.outside.is_empty() {
            let m = format!("Camera: the camera is inside the medium {:?} (MediumInterface), which heron does not render: its camera is outside every medium", self.g.outside);
            self.warn(self.diag(path, line, m))?;
        }
        self.camera_from_world = Some((self.g.ctm, line, path.to_path_buf(), projection));
        Ok(())
    }

    /// pbrt-v4's `Camera "orthographic"` (`OrthographicCamera::Create`, cameras.cpp):
    /// `screenwindow` (four numbers) or the default window from `frameaspectratio`;
    /// a thin lens (`lensradius` > 0) is ignored with a warning.
    fn orthographic(&mut self, d: &Directive) -> Result<Projection, Diagnostic> {
        let (path, line, p) = (d.path, d.line(), d.params());
        let lens = p.float("lensradius").unwrap_or(0.0);
        p.get("focaldistance");
        if lens > 0.0 {
            self.warn(self.diag(path, line, format!("Camera \"orthographic\": lensradius {lens}: heron's orthographic camera has no lens, rendered without depth of field")))?;
        }
        let window = match p.get("screenwindow") {
            None => None,
            Some(w) => match w.nums[..] {
                [x0, x1, y0, y1] if x0 < x1 && y0 < y1 && (x1 - x0 + y1 - y0).is_finite() => {
                    Some([x0, x1, y0, y1])
                }
                _ => {
                    return Err(self.diag(path, line, format!("Camera \"orthographic\": screenwindow: expected four finite numbers x0 < x1, y0 < y1, got {:?}", w.nums)))
                }
            },
        };
        let frame = p.float("frameaspectratio");
        if let Some(f) = frame {
            if !(f > 0.0 && f.is_finite()) {
                return Err(self.diag(path, line, format!("Camera \"orthographic\": frameaspectratio: expected a positive number, got {f}")));
            }
        }
        Ok(Projection::Orthographic { window, frame })
    }

    fn film(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line, p) = (d.path, d.line(), d.params());
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
        let size = |k: &str, v: f64| {
            schema::count(&format!("Film: {k}"), v as i64).map_err(|m| self.diag(path, line, m))
        };
        self.resolution = (size("xresolution", w)?, size("yresolution", h)?);
        if d.name() == "spectral" {
            // pbrt-v4's SpectralFilm: nbuckets equal buckets over [lambdamin, lambdamax]
            // (16 over 360–830 nm by default); heron's bins span 360–830 nm.
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
            self.render().spectral_bins = Some(n as i64);
        }
        Ok(())
    }

    fn integrator(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line, p) = (d.path, d.line(), d.params());
        let kind = match d.name().as_str() {
            // simplepath (no MIS) and randomwalk (BSDF sampling only) estimate the same
            // image as path, with more noise: heron's path tracer renders it.
            "path" | "volpath" | "simplepath" | "randomwalk" => "path",
            "bdpt" => "bdpt",
            "sppm" => "sppm",
            "lightpath" => "lighttrace",
            other => {
                return self.warn(self.diag(path, line, format!("Integrator {other:?} is not supported (path, volpath, simplepath, randomwalk, bdpt, sppm, lightpath are), heron's default is used")));
            }
        };
        self.render().integrator = Some(kind.into());
        self.integrator_at = Some((path.to_path_buf(), line));
        let depth = p.float("maxdepth").unwrap_or(5.0) as i64;
        if depth < 1 {
            return Err(self.diag(
                path,
                line,
                format!("Integrator: maxdepth: expected at least 1, got {depth}"),
            ));
        }
        let depth = schema::positive_count("Integrator: maxdepth", depth)
            .map_err(|m| self.diag(path, line, m))?;
        self.render().max_depth = Some(depth);
        for k in ["regularize", "lightsampler", "samplelights", "samplebsdf"] {
            p.get(k);
        }
        Ok(())
    }

    /// `AttributeEnd` and `TransformEnd`: the graphics state (or only its matrix) its
    /// begin saved comes back.
    fn pop(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line, name) = (d.path, d.line(), d.st.name.as_str());
        let Some(top) = self.stack.last() else {
            return Err(self.diag(path, line, format!("{name} without a matching begin")));
        };
        // pbrt-v4 (`BasicSceneBuilder::AttributeEnd`, which TransformEnd calls):
        // "Mismatched nesting: open ObjectBegin … at AttributeEnd".
        if top.what == "ObjectBegin" {
            let m = format!(
                "{name}: ObjectBegin {:?} ({}) is still open; close it with ObjectEnd first",
                self.object.as_ref().map_or("", |o| o.name.as_str()),
                at(&top.file, top.line, path)
            );
            return Err(self.diag(path, line, m));
        }
        let g = self.stack.pop().expect("checked above").g;
        if name == "TransformEnd" {
            self.g.ctm = g.ctm;
        } else {
            self.g = g;
        }
        Ok(())
    }

    fn object_instance(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line) = (d.path, d.line());
        if let Some(o) = &self.object {
            let m = format!(
                "ObjectInstance {:?}: inside the definition of ObjectBegin {:?} ({}); pbrt-v4 does not allow instances in an object",
                d.name(),
                o.name,
                at(&o.file, o.line, path)
            );
            return Err(self.diag(path, line, m));
        }
        self.shapes.push(Slot::Instance {
            name: d.name(),
            ctm: self.g.ctm,
            file: path.to_path_buf(),
            line,
        });
        Ok(())
    }

    /// `Material`, `MakeNamedMaterial`, `NamedMaterial` and `AreaLightSource`: the
    /// graphics state's material and area light.
    fn material_state(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line, p) = (d.path, d.line(), d.params());
        match d.st.name.as_str() {
            "Material" => {
                let m = self.material(path, line, &d.name(), p, None)?;
                self.g.material = Some(m);
            }
            "MakeNamedMaterial" => {
                let ty = p.string("type").unwrap_or("").to_string();
                let m = self.material(path, line, &ty, p, Some(&d.name()))?;
                self.named.insert(d.name(), m);
            }
            "NamedMaterial" => {
                let Some(m) = self.named.get(&d.name()).cloned() else {
                    return Err(self.diag(
                        path,
                        line,
                        format!("NamedMaterial: no material named {:?} was made", d.name()),
                    ));
                };
                self.g.material = Some(m);
            }
            _ => {
                let scale = p.float("scale").unwrap_or(1.0);
                let two = p.string("twosided") == Some("true");
                let emission = match p.string("filename").filter(|f| !f.is_empty()) {
                    Some(f) => {
                        let f = f.to_string();
                        self.area_image(path, line, p, &f, scale)?
                    }
                    None => {
                        let l = self.emission(path, p, "L", 1.0)?;
                        scaled(l, scale).emission().into()
                    }
                };
                self.g.area = Some((emission, two));
            }
        }
        Ok(())
    }

    /// A diffuse area light's `filename`: the image as a `[textures]` table (pbrt-v4's
    /// `DiffuseAreaLight` looks it up at (u, 1 − v), bilinear, each texel's RGB an
    /// illuminant spectrum of the sRGB space, D65 at Y = 1, times `scale`), the shape's
    /// `{ texture, scale }`. heron's image texels are clamped to [0, 1] (a warning for
    /// the formats that hold more), and `power` is not applied to an image (a warning).
    fn area_image(
        &mut self,
        path: &Path,
        line: u32,
        p: &Params,
        f: &str,
        scale: f64,
    ) -> Result<crate::scene::file::ShapeEmission, Diagnostic> {
        if p.get("L").is_some() {
            return Err(self.diag(path, line, "AreaLightSource \"diffuse\": both \"L\" and \"filename\" are given (pbrt-v4 refuses that)"));
        }
        if !(scale >= 0.0 && (scale as f32).is_finite()) {
            return Err(self.diag(path, line, format!("AreaLightSource \"diffuse\": scale: expected a finite number ≥ 0 with an image, got {scale}")));
        }
        let full = self.base_of(path).join(f);
        let file = crate::scene::import::mitsuba::relative_to(&full, &self.base)
            .to_string_lossy()
            .replace('\\', "/");
        let ext = file.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
        if matches!(ext.as_str(), "exr" | "pfm" | "hdr") {
            self.warn(self.diag(path, line, format!("AreaLightSource \"diffuse\": filename {f:?}: heron's image textures hold texels in [0, 1], so brighter texels are clamped to 1 (scale still multiplies the light)")))?;
        }
        if let Some(q) = p.get("power") {
            let _ = q;
            self.warn(self.diag(path, line, "AreaLightSource \"diffuse\": power is not applied to an image light (pbrt-v4 normalises by the image's mean luminance), ignored"))?;
        }
        let mut name = "arealight-image".to_string();
        let mut k = 1;
        while self.textures.contains_key(&name) {
            k += 1;
            name = format!("arealight-image-{k}");
        }
        self.textures.insert(
            name.clone(),
            TextureFile::Image(crate::scene::file::ImageTextureFile {
                file,
                encoding: None,
                scale: None,
                invert: None,
                to_uv: Some([[1.0, 0.0, 0.0], [0.0, -1.0, 1.0]]),
            }),
        );
        Ok(crate::scene::file::ShapeEmission::Texture {
            texture: name,
            scale,
        })
    }

    fn import(&mut self, d: &Directive) -> Result<(), Diagnostic> {
        let (path, line) = (d.path, d.line());
        let f = self.base_of(path).join(d.name());
        self.import_depth += 1;
        let r = self.file(&f, d.depth + 1, Some((path, line)));
        self.import_depth -= 1;
        r?;
        // An imported file is parsed by a builder of its own in pbrt-v4, whose open
        // blocks are errors at its end (`BasicSceneBuilder::MergeImported`).
        if let Some(o) = &self.object {
            if o.import_depth > self.import_depth {
                return Err(self.diag(
                    &o.file,
                    o.line,
                    format!("ObjectBegin {:?} is not closed by an ObjectEnd before the end of the imported file", o.name),
                ));
            }
        }
        Ok(())
    }

    pub(super) fn base_of(&self, path: &Path) -> PathBuf {
        path.parent().unwrap_or(Path::new("")).to_path_buf()
    }

    pub(super) fn push(&mut self, what: &'static str, path: &Path, line: u32) {
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
}
