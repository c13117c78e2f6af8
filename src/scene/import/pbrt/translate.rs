//! pbrt-v4's materials, lights, shapes and camera in heron's terms: the translation
//! of what the directives (`directives.rs`) hand over, and the placement of each shape
//! with its matrix.
use super::tokens::Params;
use super::*;
use crate::scene::file::{
    CoatedFile, Colour, ConductorFile, DielectricFile, DiffuseTransmissionFile,
    DirectionalLightFile, IorSpec, LambertianFile, MetalSpec, PointLightFile, SpotLightFile,
    Textured, ThinDielectricFile, UnitNumber,
};

impl Conv {
    /// A reflectance parameter ([`Self::colour_as`] for a reflectance).
    pub(super) fn colour(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
    ) -> Result<ColourValue, Diagnostic> {
        self.colour_as(path, p, name, default, false)
    }

    /// A light's spectrum ([`Self::colour_as`] for an emission).
    pub(super) fn emission(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
    ) -> Result<ColourValue, Diagnostic> {
        self.colour_as(path, p, name, default, true)
    }

    /// A colour parameter: "rgb", a "spectrum" (one number, λ value pairs, a file of
    /// them, or the named illuminants stdillum-D65 and stdillum-A), a "blackbody"
    /// temperature, or a "float". For a light (`emission`), pbrt-v4 scales every
    /// spectrum to luminance 1 (`scale /= SpectrumToPhotometric(L)` in each light's
    /// `Create`; for RGB only the colour space's illuminant counts), which heron's
    /// blackbody and named illuminants already are and a table is given as a `scale`.
    /// pbrt-v4's `PiecewiseLinearSpectrum` is zero beyond its ends, as Mitsuba's is.
    pub(super) fn colour_as(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
        emission: bool,
    ) -> Result<ColourValue, Diagnostic> {
        use crate::scene::import::props::{mitsuba_samples, read_spd};
        let Some(q) = p.get(name) else {
            return Ok(ColourValue::Grey(tidy(default)));
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
            ColourValue::Samples { samples, scale }
        };
        match (q.ty.as_str(), q.nums.as_slice(), q.strs.as_slice()) {
            ("rgb", [r, g, b], _) => Ok(ColourValue::Rgb([tidy(*r), tidy(*g), tidy(*b)])),
            ("spectrum" | "float", [v], []) => Ok(ColourValue::Grey(tidy(*v))),
            ("blackbody", [k], _) => {
                if !emission {
                    return Err(bad(self, "a blackbody is an emission spectrum".into()));
                }
                let (lo, hi) = crate::spectrum::blackbody::KELVIN_RANGE;
                if !(lo..=hi).contains(k) {
                    return Err(bad(self, format!("expected kelvin within [{lo}, {hi}], got {k}")));
                }
                Ok(ColourValue::Blackbody { kelvin: *k, scale: 1.0 })
            }
            ("spectrum", nums, []) if nums.len() >= 4 && nums.len() % 2 == 0 => {
                let pairs: Vec<(f64, f64)> = nums.chunks(2).map(|c| (c[0], c[1])).collect();
                if pairs.windows(2).any(|w| !(w[1].0 > w[0].0)) || pairs.iter().any(|(_, v)| !(*v >= 0.0)) {
                    return Err(bad(self, "expected wavelength value pairs, wavelengths increasing, values ≥ 0".into()));
                }
                Ok(table_colour(pairs))
            }
            ("spectrum", [], [n]) if n == "stdillum-D65" || n == "stdillum-A" => {
                let spectrum = if n == "stdillum-A" { "A" } else { "D65" };
                if !emission {
                    // A reflectance must stay within [0, 1]: the named illuminants are
                    // scaled to luminance 1, so only as lights.
                    return Err(bad(self, "a named illuminant is an emission spectrum".into()));
                }
                Ok(ColourValue::Named { spectrum, scale: 1.0 })
            }
            ("spectrum", [], [f]) if !f.starts_with("metal-") && !f.starts_with("glass-") && !f.contains("illum") && !f.starts_with("canon") && !f.starts_with("nikon") && !f.starts_with("sony") => {
                let full = self.base_of(path).join(f);
                let pairs = read_spd(&full).map_err(|e| bad(self, e))?;
                Ok(table_colour(pairs))
            }
            ("spectrum", _, _) | ("texture", _, _) => {
                self.warn(self.diag(path, q.line, format!("\"{} {name}\": this named spectrum or texture is not supported yet (rgb, blackbody, λ value pairs, .spd files, stdillum-D65 and stdillum-A are); {default} is used", q.ty)))?;
                Ok(ColourValue::Grey(tidy(default)))
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

    /// pbrt-v4's `coateddiffuse` as heron's coated material: its layered BxDF's
    /// stochastic estimate becomes the closed form of src/bsdf/coated_diffuse.rs, whose
    /// layer absorbs only (a scattering medium, `albedo` > 0, is approximated, with a
    /// warning); `maxdepth` and `nsamples` steer pbrt's estimator and mean nothing here.
    fn coated_diffuse(
        &mut self,
        path: &Path,
        line: u32,
        p: &Params,
    ) -> Result<MaterialFile, Diagnostic> {
        let rho = self.textured(path, p, "reflectance", 0.5)?;
        let roughness = self.roughness(path, line, p, "coateddiffuse")?;
        let (ior, below_one) = self.eta(path, line, p)?;
        if let (IorSpec::Constant(e), None) | (_, Some(IorSpec::Constant(e))) = (&ior, &below_one) {
            let e = if below_one.is_some() { 1.0 / *e } else { *e };
            if !(e >= 1.0 && e.is_finite()) {
                let at = p.get("eta").map_or(line, |q| q.line);
                return Err(self.diag(
                    path,
                    at,
                    format!("coateddiffuse \"eta\": expected a coat index ≥ 1, got {e}"),
                ));
            }
        }
        let thickness = p.float("thickness").unwrap_or(0.01);
        if !(thickness >= 0.0 && thickness.is_finite()) {
            let at = p.get("thickness").map_or(line, |q| q.line);
            return Err(self.diag(
                path,
                at,
                format!("coateddiffuse \"thickness\": expected a number ≥ 0, got {thickness}"),
            ));
        }
        let albedo = self.colour(path, p, "albedo", 0.0)?;
        let g = p.float("g").unwrap_or(0.0);
        if albedo.max() > 0.0 || g != 0.0 {
            self.warn(self.diag(path, line, format!("coateddiffuse: the layer's scattering (albedo {}, g {g}) is not modelled; heron's layer only absorbs, with optical depth thickness = {thickness}", albedo.max())))?;
        }
        p.get("maxdepth");
        p.get("nsamples");
        Ok(MaterialFile::Coated(CoatedFile {
            reflectance: rho,
            ior: Some(ior),
            roughness,
            thickness: (thickness > 0.0).then_some(tidy(thickness)),
            nonlinear: None,
        }))
    }

    /// A microfacet material's (`what`'s) roughness: [`Self::alpha`] when above 0, at
    /// most 1; or a float texture ([`Self::roughness_texture`]). Different `uroughness`
    /// and `vroughness` warn: heron's microfacets are isotropic, their mean is used.
    fn roughness(
        &mut self,
        path: &Path,
        line: u32,
        p: &Params,
        what: &str,
    ) -> Result<Option<Textured<UnitNumber>>, Diagnostic> {
        if let Some(t) = self.roughness_texture(path, line, p, what)? {
            return Ok(Some(t));
        }
        let (u, v) = (p.float("uroughness"), p.float("vroughness"));
        if p.get("roughness").is_none() {
            if let (Some(u), Some(v)) = (u, v) {
                if u != v {
                    self.warn(self.diag(path, line, format!("{what}: anisotropic roughness (uroughness {u}, vroughness {v}); heron's microfacets are isotropic, their mean is used")))?;
                }
            }
        }
        p.get("remaproughness");
        Ok(self
            .alpha(p)
            .filter(|a| *a > 0.0)
            .map(|a| Textured::Value(schema::unit(a.min(1.0)))))
    }

    pub(super) fn alpha(&mut self, p: &Params) -> Option<f64> {
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

    pub(super) fn material(
        &mut self,
        path: &Path,
        line: u32,
        ty: &str,
        p: &Params,
        name: Option<&str>,
    ) -> Result<String, Diagnostic> {
        let t = match ty {
            // Not a material: the shape bounds a medium (`media.rs`).
            "interface" => return Ok(super::media::INTERFACE.to_string()),
            "diffuse" => MaterialFile::Lambertian(LambertianFile {
                rho_d: Some(self.textured(path, p, "reflectance", 0.5)?),
                texture: None,
            }),
            "dielectric" => {
                let (ior, outside_ior) = self.eta(path, line, p)?;
                let roughness = self.roughness(path, line, p, "dielectric")?;
                MaterialFile::Dielectric(DielectricFile {
                    ior,
                    fresnel: None,
                    roughness,
                    outside_ior,
                })
            }
            "thindielectric" => {
                // pbrt-v4's ThinDielectricMaterial: smooth, with an index only.
                let (ior, outside_ior) = self.eta(path, line, p)?;
                MaterialFile::ThinDielectric(ThinDielectricFile { ior, outside_ior })
            }
            "diffusetransmission" => self.diffuse_transmission(path, line, p)?,
            "conductor" => {
                let metal = match (p.get("eta"), p.get("k"), p.get("reflectance")) {
                    (None, None, None) => MetalSpec::Named("Cu".into()),
                    (Some(e), Some(k_param), _) => match (e.strs.first().filter(|s| s.starts_with("metal-")), k_param.strs.first().filter(|s| s.starts_with("metal-"))) {
                        (Some(a), Some(b)) => {
                            let m = a.strip_prefix("metal-").and_then(|x| x.strip_suffix("-eta"));
                            let m2 = b.strip_prefix("metal-").and_then(|x| x.strip_suffix("-k"));
                            match (m, m2) {
                                (Some(m), Some(m2)) if m == m2 && ["Ag", "Al", "Au", "Cu"].contains(&m) => MetalSpec::Named(m.into()),
                                _ => return Err(self.diag(path, e.line, format!("conductor: expected metal-Ag/Al/Au/Cu-eta and -k spectra or numbers, got {a:?} and {b:?}"))),
                            }
                        }
                        (None, None) => {
                            // rgb, λ value pairs, files and numbers: pbrt-v4 reads them as
                            // unbounded spectra (an rgb as RGBUnboundedSpectrum).
                            let curve = |this: &mut Self, name: &str, q: &crate::scene::import::pbrt::tokens::Param| -> Result<Colour, Diagnostic> {
                                let (c, short) = crate::scene::import::props::index_samples(this.colour(path, p, name, 1.0)?.colour());
                                if let Some((lo, hi)) = short {
                                    this.warn(this.diag(path, q.line, format!("conductor \"{} {name}\": the table covers {lo}–{hi} nm; heron holds its end values over the rest of 360–830 nm, where pbrt-v4 takes 0", q.ty)))?;
                                }
                                Ok(c)
                            };
                            let n = curve(self, "eta", e)?;
                            let k = curve(self, "k", k_param)?;
                            for (c, q, real) in [(&n, e, true), (&k, k_param, false)] {
                                c.check_index(real).map_err(|m| self.diag(path, q.line, format!("conductor \"{} {}\": {m}", q.ty, q.name)))?;
                            }
                            match (&n, &k) {
                                (Colour::Grey(n), Colour::Grey(k)) => MetalSpec::Constant { n: *n, k: *k },
                                _ => MetalSpec::Curves { n, k },
                            }
                        }
                        _ => return Err(self.diag(path, e.line, "conductor: expected eta and k both as named metal spectra or both as numbers, rgb or spectra")),
                    },
                    (_, _, Some(q)) => return Err(self.diag(path, q.line, "conductor: \"reflectance\" (an artist's colour) is not supported; give eta and k")),
                    (Some(q), None, _) | (None, Some(q), _) => return Err(self.diag(path, q.line, "conductor: expected both eta and k")),
                };
                let roughness = self.roughness(path, line, p, "conductor")?;
                MaterialFile::Conductor(ConductorFile { metal, roughness })
            }
            "coateddiffuse" => self.coated_diffuse(path, line, p)?,
            other => {
                for q in &p.0 {
                    q.used.set(true);
                }
                self.warn(self.diag(path, line, format!("material {other:?} is not supported (diffuse, dielectric, thindielectric, diffusetransmission, conductor, coateddiffuse are); a diffuse 0.5 is used")))?;
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
        self.materials.insert(key.clone(), t);
        Ok(key)
    }

    /// A dielectric's `eta` (default 1.5): a number, or a named glass spectrum read as
    /// heron's catalogue glass (dispersive). pbrt's eta is the relative index inside /
    /// outside; below 1 (an air bubble in water, say) heron writes it as a unit index
    /// inside 1 / eta outside, the same relative index.
    fn eta(
        &mut self,
        path: &Path,
        line: u32,
        p: &Params,
    ) -> Result<(IorSpec, Option<IorSpec>), Diagnostic> {
        let named = |n: &str| IorSpec::Named(n.into());
        let ior = match p.get("eta") {
            None => IorSpec::Constant(tidy(1.5)),
            Some(q) => match (q.ty.as_str(), q.nums.first(), q.strs.first()) {
                (_, Some(v), _) => IorSpec::Constant(tidy(*v)),
                ("spectrum", None, Some(n)) => match n.as_str() {
                    "glass-BK7" => named("N-BK7"),
                    "glass-F11" | "glass-SF11" => named("N-SF11"),
                    "fused silica" | "glass-fused-silica" => named("fused-silica"),
                    other => return Err(self.diag(path, q.line, format!("\"spectrum eta\": expected a number or one of glass-BK7, glass-F11 (heron's N-SF11), got {other:?}"))),
                },
                _ => return Err(self.diag(path, q.line, "\"eta\": expected a number or a named spectrum")),
            },
        };
        Ok(match ior {
            IorSpec::Constant(e) if e > 0.0 && e < 1.0 => (
                IorSpec::Constant(1.0),
                Some(IorSpec::Constant(tidy(1.0 / e))),
            ),
            IorSpec::Constant(e) if !(e > 0.0 && e.is_finite()) => {
                let at = p.get("eta").map_or(line, |q| q.line);
                return Err(self.diag(
                    path,
                    at,
                    format!("\"eta\": expected a relative index > 0, got {e}"),
                ));
            }
            other => (other, None),
        })
    }

    /// pbrt-v4's DiffuseTransmissionMaterial: `reflectance` and `transmittance` (0.25
    /// each by default) times `scale`, each clamped to [0, 1] as pbrt does; where their
    /// sum exceeds 1 (pbrt allows it, heron does not: energy conservation) both are
    /// scaled down to sum to 1, with a warning.
    fn diffuse_transmission(
        &mut self,
        path: &Path,
        line: u32,
        p: &Params,
    ) -> Result<MaterialFile, Diagnostic> {
        let k = p.float("scale").unwrap_or(1.0);
        if !(k >= 0.0 && k.is_finite()) {
            let at = p.get("scale").map_or(line, |q| q.line);
            return Err(self.diag(
                path,
                at,
                format!("\"scale\": expected a number ≥ 0, got {k}"),
            ));
        }
        let r = scaled(self.colour(path, p, "reflectance", 0.25)?, k);
        let t = scaled(self.colour(path, p, "transmittance", 0.25)?, k);
        let clamp = |c: ColourValue| match c {
            ColourValue::Grey(g) => ColourValue::Grey(g.clamp(0.0, 1.0)),
            ColourValue::Rgb(rgb) => ColourValue::Rgb(rgb.map(|x| x.clamp(0.0, 1.0))),
            other => {
                let m = other.colour().max_value() as f64;
                if m > 1.0 {
                    scaled(other, 1.0 / m)
                } else {
                    other
                }
            }
        };
        let (r, t) = (clamp(r), clamp(t));
        let sum = match (r.colour().rgb(), t.colour().rgb()) {
            (Some(a), Some(b)) => (0..3).map(|i| (a[i] + b[i]) as f64).fold(0.0, f64::max),
            _ => (r.colour().max_value() + t.colour().max_value()) as f64,
        };
        let (r, t) = if sum > 1.0 {
            self.warn(self.diag(path, line, format!("diffusetransmission: reflectance + transmittance reaches {sum:.4} > 1 (pbrt-v4 allows it); both are scaled by {:.4} to conserve energy", 1.0 / sum)))?;
            (scaled(r, 1.0 / sum), scaled(t, 1.0 / sum))
        } else {
            (r, t)
        };
        Ok(MaterialFile::DiffuseTransmission(DiffuseTransmissionFile {
            reflectance: r.reflectance(),
            transmittance: t.reflectance(),
        }))
    }

    pub(super) fn default_material(&mut self) -> String {
        if let Some(m) = &self.default_material {
            return m.clone();
        }
        let k = "pbrt-default-diffuse".to_string();
        self.materials
            .insert(k.clone(), lambertian(ColourValue::Grey(tidy(0.5))));
        self.default_material = Some(k.clone());
        k
    }

    pub(super) fn light(
        &mut self,
        path: &Path,
        line: u32,
        kind: &str,
        p: &Params,
    ) -> Result<(), Diagnostic> {
        let scale = p.float("scale").unwrap_or(1.0);
        let m = self.g.ctm;
        match kind {
            "point" => {
                let from = p.get("from").map_or(DVec3::ZERO, |q| v3(&q.nums));
                let i = self.emission(path, p, "I", 1.0)?;
                self.lights.push(LightFile::Point(PointLightFile {
                    position: schema::point(m.transform_point3(from)),
                    intensity: scaled(i, scale).emission(),
                    polarization: None,
                }));
            }
            "spot" => {
                let from = p.get("from").map_or(DVec3::ZERO, |q| v3(&q.nums));
                let to = p.get("to").map_or(DVec3::Z, |q| v3(&q.nums));
                let i = self.emission(path, p, "I", 1.0)?;
                let cone = p.float("coneangle").unwrap_or(30.0);
                let delta = p.float("conedelta").unwrap_or(5.0);
                self.lights.push(LightFile::Spot(SpotLightFile {
                    position: schema::point(m.transform_point3(from)),
                    direction: schema::direction(m.transform_vector3(to - from)),
                    intensity: scaled(i, scale).emission(),
                    cone_angle: Some(schema::positive(cone)),
                    cone_delta: Some(schema::non_negative(delta)),
                    polarization: None,
                }));
            }
            "distant" => {
                let from = p.get("from").map_or(DVec3::ZERO, |q| v3(&q.nums));
                let to = p.get("to").map_or(DVec3::Z, |q| v3(&q.nums));
                let l = self.emission(path, p, "L", 1.0)?;
                self.lights
                    .push(LightFile::Directional(DirectionalLightFile {
                        direction: schema::direction(m.transform_vector3(to - from)),
                        radiance: scaled(l, scale).emission(),
                        polarization: None,
                    }));
            }
            "infinite" if p.get("filename").is_none() => {
                let l = self.emission(path, p, "L", 1.0)?;
                self.background = Some(scaled(l, scale).emission());
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
                let t = EnvironmentFile {
                    map: rel.to_string_lossy().replace('\\', "/"),
                    mapping: Some("equal-area".into()),
                    scale: Some(schema::non_negative(scale)),
                    transform: (lin != glam::DMat3::IDENTITY)
                        .then(|| schema::rows(DMat4::from_mat3(lin))),
                };
                if self.environment.is_some() || self.background.is_some() {
                    self.warn(self.diag(
                        path,
                        line,
                        "a second infinite light; heron's environment is the first, ignored",
                    ))?;
                } else {
                    self.environment = Some(t);
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
    pub(super) fn shape(
        &mut self,
        path: &Path,
        line: u32,
        kind: &str,
        p: &Params,
    ) -> Result<(), Diagnostic> {
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
            inside: self.g.inside.clone(),
            outside: self.g.outside.clone(),
            file: path.to_path_buf(),
            line,
        };
        match &mut self.object {
            Some(o) => o.shapes.push(sd),
            None => {
                for v in self.emit(&sd, None)? {
                    self.shapes.push(Slot::Shape(Box::new(v)));
                }
            }
        }
        Ok(())
    }

    /// A shape's geometry in its own space, its parameters checked; `None` (and a
    /// warning) for a shape heron does not have.
    pub(super) fn geometry(
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
            "disk" => {
                let radius = p.float("radius").unwrap_or(1.0);
                let inner = p.float("innerradius").unwrap_or(0.0);
                let height = p.float("height").unwrap_or(0.0);
                let phi_max = p.float("phimax").unwrap_or(360.0);
                if !(radius > 0.0
                    && radius.is_finite()
                    && inner >= 0.0
                    && inner < radius
                    && height.is_finite())
                {
                    return Err(self.diag(path, line, format!("Shape \"disk\": expected 0 <= innerradius < radius and a finite height, got radius {radius}, innerradius {inner}, height {height}")));
                }
                if !(phi_max > 0.0 && phi_max <= 360.0) {
                    return Err(self.diag(
                        path,
                        line,
                        format!(
                            "Shape \"disk\": expected phimax in (0, 360] degrees, got {phi_max}"
                        ),
                    ));
                }
                Geom::Disk {
                    height,
                    radius,
                    inner,
                    phi_max: phi_max.to_radians(),
                }
            }
            "cylinder" => self.cylinder(path, line, p)?,
            other => {
                for q in &p.0 {
                    q.used.set(true);
                }
                self.warn(self.diag(path, line, format!("Shape {other:?} is not supported (sphere, disk, cylinder, trianglemesh, bilinearmesh, plymesh are), ignored")))?;
                return Ok(None);
            }
        }))
    }

    /// pbrt-v4's `cylinder` (`Cylinder::Create`, shapes.cpp): `radius` (default 1),
    /// `zmin` (−1), `zmax` (1), `phimax` (360 degrees); zmin and zmax in either order,
    /// as pbrt orders them.
    fn cylinder(&mut self, path: &Path, line: u32, p: &Params) -> Result<Geom, Diagnostic> {
        let radius = p.float("radius").unwrap_or(1.0);
        let (z0, z1) = (
            p.float("zmin").unwrap_or(-1.0),
            p.float("zmax").unwrap_or(1.0),
        );
        let phi_max = p.float("phimax").unwrap_or(360.0);
        if !(radius > 0.0 && radius.is_finite() && z0 != z1 && (z0 - z1).is_finite()) {
            return Err(self.diag(path, line, format!("Shape \"cylinder\": expected a positive radius and finite zmin != zmax, got radius {radius}, zmin {z0}, zmax {z1}")));
        }
        if !(phi_max > 0.0 && phi_max <= 360.0) {
            return Err(self.diag(
                path,
                line,
                format!("Shape \"cylinder\": expected phimax in (0, 360] degrees, got {phi_max}"),
            ));
        }
        Ok(Geom::Cylinder {
            radius,
            z: (z0.min(z1), z0.max(z1)),
            phi_max: phi_max.to_radians(),
        })
    }

    /// The heron shape tables of `sd` placed by its CTM, or for an `ObjectInstance`
    /// (`inst`: the object's name, the instance's CTM, file and line) by CTM(instance) ·
    /// CTM(shape). What depends on the whole matrix (a sphere's uniform scale, a mirror
    /// flipping the winding) is decided here, a copy's message naming the instance.
    pub(super) fn emit(
        &mut self,
        sd: &ShapeDef,
        inst: Option<(&str, DMat4, &Path, u32)>,
    ) -> Result<Vec<ShapeFile>, Diagnostic> {
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
        let closed = match &sd.geom {
            Geom::Sphere { .. } | Geom::Ply { .. } => true,
            Geom::Disk { .. } | Geom::Cylinder { .. } => false,
            Geom::Mesh { kind, faces, .. } => faces_closed(kind, faces),
        };
        let medium = self.interior(sd, closed, &file, line, &ctx)?;
        let interface = sd.material == super::media::INTERFACE;
        if interface && medium.is_none() {
            // Only a boundary between media, and no medium here: nothing to render.
            return Ok(Vec::new());
        }
        // A medium needs its mesh as one closed entry, not separate triangles.
        let mut one_mesh: Option<Vec<[DVec3; 3]>> = medium.is_some().then(Vec::new);
        let mut entries: Vec<ShapeFile> = Vec::new();
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
                entries.push(schema::sphere(
                    m.transform_point3(DVec3::ZERO),
                    radius * sc[0],
                ));
            }
            Geom::Mesh {
                kind,
                points,
                faces,
            } => {
                let verts: Vec<DVec3> = points.iter().map(|&q| m.transform_point3(q)).collect();
                // heron's own triangles must have an area; an imported mesh loses its
                // zero-area ones (never hit) with one warning, as pbrt renders it.
                let flat = |t: [usize; 3]| {
                    let v = t.map(|k| schema::point(verts[k]).get());
                    crate::scene::load::is_degenerate(v[0], v[1], v[2])
                };
                let (before, mut dropped) = (entries.len(), 0usize);
                for ix in faces {
                    // A flat parallelogram patch (p00, p10, p01, p11) is heron's quad,
                    // normal (p10 − p00) × (p01 − p00) as pbrt's; others two triangles.
                    if *kind == "bilinearmesh" && one_mesh.is_none() {
                        let (o, a, b, c) = (verts[ix[0]], verts[ix[1]], verts[ix[2]], verts[ix[3]]);
                        let scale = (a - o).length().max((b - o).length());
                        if (c - (a + b - o)).length() <= 1e-9 * scale {
                            let (e1, e2) = if flip { (b - o, a - o) } else { (a - o, b - o) };
                            entries.push(schema::quad(o, e1, e2));
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
                        if flat(t) {
                            dropped += 1;
                            continue;
                        }
                        let t = if flip { [t[0], t[2], t[1]] } else { t };
                        match &mut one_mesh {
                            Some(tris) => tris.push(t.map(|k| verts[k])),
                            None => entries.push(schema::triangle(t.map(|k| verts[k]))),
                        }
                    }
                }
                if let Some(tris) = one_mesh.take().filter(|t| !t.is_empty()) {
                    entries.push(schema::triangle_mesh(&tris));
                }
                if dropped > 0 {
                    let kept = entries.len() - before;
                    let what = if kept == 0 {
                        "the shape is dropped".to_string()
                    } else {
                        format!("{kept} kept")
                    };
                    self.warn(self.diag(&file, line, format!("{ctx}Shape {kind:?}: {dropped} triangle(s) of zero area dropped ({what})")))?;
                }
            }
            Geom::Disk {
                height,
                radius,
                inner,
                phi_max,
            } => {
                let segs = crate::scene::import::DISK_SEGMENTS;
                entries.extend(schema::disk(
                    &m, *radius, *inner, *height, *phi_max, flip, segs,
                ));
            }
            Geom::Cylinder { radius, z, phi_max } => {
                let segs = crate::scene::import::DISK_SEGMENTS;
                entries.push(schema::cylinder(&m, *radius, *z, *phi_max, flip, segs));
            }
            Geom::Ply { file: f } => {
                if flip {
                    self.warn(self.diag(&file, line, format!("{ctx}Shape \"plymesh\": ReverseOrientation or a mirroring transform on a mesh is not supported, ignored")))?;
                }
                entries.push(schema::mesh(f.clone(), m, None));
            }
        }
        Ok(entries
            .into_iter()
            .map(|mut e| {
                let (material, emission, two_sided) = e.surface_mut();
                *material = (!interface).then(|| sd.material.clone());
                if let Some((l, two)) = &sd.area {
                    *emission = Some(l.clone());
                    *two_sided = two.then_some(true);
                }
                *e.medium_mut() = medium.clone();
                e
            })
            .collect())
    }

    pub(super) fn finish_camera(&mut self, path: &Path) -> Result<(), Diagnostic> {
        let Some((cfw, line, file, projection)) = self.camera_from_world.clone() else {
            return Err(self.diag(
                path,
                1,
                "expected a Camera \"perspective\" or \"orthographic\" directive",
            ));
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
        let fov = match projection {
            Projection::Perspective { fov } => fov,
            Projection::Orthographic { window, frame } => {
                let cam = self.orthographic_camera(&wfc, (&file, line), window, frame)?;
                self.camera = Some(cam);
                return Ok(());
            }
        };
        // pbrt's fov spans the shorter image axis.
        let t = (0.5 * fov.to_radians()).tan();
        let tan_y = if aspect >= 1.0 { t } else { t / aspect };
        self.camera = Some(schema::pinhole(eye, look, up, 0.5 / tan_y, (w, h)));
        Ok(())
    }

    /// pbrt-v4's orthographic camera: rays along camera +z from the screen window's
    /// point at z = 0 (camera space is screen space for x and y). By default the window
    /// spans [-1, 1] on the shorter axis of `frameaspectratio` (the image's aspect
    /// ratio unless given). heron's image plane is centred at its eye and has square
    /// pixels: an off-centre window moves the eye to the window's centre; a window whose
    /// shape is not the image's keeps its height, with a warning.
    fn orthographic_camera(
        &mut self,
        wfc: &DMat4,
        (file, line): (&Path, u32),
        window: Option<[f64; 4]>,
        frame: Option<f64>,
    ) -> Result<CameraFile, Diagnostic> {
        let (w, h) = self.resolution;
        let aspect = w as f64 / h as f64;
        let [x0, x1, y0, y1] = window.unwrap_or_else(|| {
            let f = frame.unwrap_or(aspect);
            if f > 1.0 {
                [-f, f, -1.0, 1.0]
            } else {
                [-1.0, 1.0, -1.0 / f, 1.0 / f]
            }
        });
        let shape = (x1 - x0) / (y1 - y0);
        if (shape - aspect).abs() > 1e-6 * aspect {
            self.warn(self.diag(file, line, format!("Camera \"orthographic\": the screen window is {} x {} and the image's aspect ratio {aspect}; heron's pixels are square, so the window keeps its height and its width is {}", x1 - x0, y1 - y0, (y1 - y0) * aspect)))?;
        }
        let centre = DVec3::new(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0);
        // The camera-from-world transform may scale (pbrt warns and goes on): the
        // window is measured in camera space, so its height is scaled to the world's.
        let sy = wfc.transform_vector3(DVec3::Y).length();
        let eye = wfc.transform_point3(centre);
        let look = eye + wfc.transform_vector3(DVec3::Z);
        let up = wfc.transform_vector3(DVec3::Y);
        let mut cam = schema::pinhole(eye, look, up, 1.0, (w, h));
        cam.d = None;
        cam.kind = Some("orthographic".into());
        cam.height = Some(schema::positive((y1 - y0) * sy));
        Ok(cam)
    }
}

/// Whether a `trianglemesh` (3 indices a face) or `bilinearmesh` (4) is closed: every
/// edge, by vertex index, shared by exactly two triangles.
fn faces_closed(kind: &str, faces: &[Vec<usize>]) -> bool {
    let mut edges: HashMap<(usize, usize), u32> = HashMap::new();
    for f in faces {
        let tris: Vec<[usize; 3]> = if kind == "trianglemesh" {
            vec![[f[0], f[1], f[2]]]
        } else {
            vec![[f[0], f[1], f[3]], [f[0], f[3], f[2]]]
        };
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
    }
    !edges.is_empty() && edges.values().all(|&c| c == 2)
}

/// A diffuse material of reflectance `rho`.
fn lambertian(rho: ColourValue) -> MaterialFile {
    MaterialFile::Lambertian(LambertianFile {
        rho_d: Some(Textured::Value(rho.reflectance())),
        texture: None,
    })
}
