//! Mitsuba 3's BSDFs as heron's materials: `diffuse`, the dielectrics, the conductors,
//! the plastics (heron's coated material) and the wrappers (`twosided`,
//! `mask`, `bumpmap`, `normalmap`), with the indices and roughnesses they name.
use super::*;
use crate::scene::file::{
    CoatedFile, Colour, ConductorFile, DielectricFile, IorSpec, LambertianFile, MetalSpec,
    MirrorFile, MixTextureFile, Textured, ThinDielectricFile, UnitNumber,
};
use crate::scene::import::props::index_samples;

impl<'a> Converter<'a> {
    /// The name of heron's material for BSDF element `n` (converted once).
    pub(super) fn bsdf(&mut self, n: &'a Node) -> Result<String, Diagnostic> {
        let n = self.resolve(n)?;
        if n.tag != "bsdf" {
            return Err(n.diag("expected a <bsdf>"));
        }
        if let Some(name) = self.material_of.get(&(n as *const Node)) {
            return Ok(name.clone());
        }
        let material = self.bsdf_material(n)?;
        let name = match material {
            Some(m) => {
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
                self.materials.insert(name.clone(), m);
                name
            }
            None => self.default_material(),
        };
        self.material_of.insert(n as *const Node, name.clone());
        Ok(name)
    }

    /// Mitsuba's default BSDF (a diffuse reflectance of 0.5), made once.
    pub(super) fn default_material(&mut self) -> String {
        if let Some(m) = &self.default_material {
            return m.clone();
        }
        let name = "mitsuba-default-diffuse".to_string();
        self.materials
            .insert(name.clone(), lambertian(ColourValue::Grey(0.5)));
        self.default_material = Some(name.clone());
        name
    }

    /// heron's material for a BSDF, or None for Mitsuba's default (after a warning).
    pub(super) fn bsdf_material(
        &mut self,
        n: &'a Node,
    ) -> Result<Option<MaterialFile>, Diagnostic> {
        let kind = Self::plugin(n)?;
        let p = self.props(n);
        let t = match kind {
            "twosided" | "mask" | "bumpmap" | "normalmap" => return self.wrapper_bsdf(n, &p, kind),
            "diffuse" => self.diffuse(&p)?,
            "thindielectric" => self.thin_dielectric(&p)?,
            "dielectric" | "roughdielectric" => self.dielectric(n, &p, kind)?,
            "conductor" | "roughconductor" => self.conductor(n, &p, kind)?,
            "plastic" | "roughplastic" => self.plastic(n, &p, kind)?,
            other => {
                self.warn(n.diag(format!(
                    "BSDF {other:?} is not supported (diffuse, dielectric, roughdielectric, thindielectric, conductor, roughconductor, plastic, roughplastic, twosided are); Mitsuba's default BSDF (diffuse 0.5) is used"
                )))?;
                return Ok(None);
            }
        };
        self.finish(&p)?;
        Ok(Some(t))
    }

    /// `twosided` (heron's surfaces are two-sided) and the modulating wrappers heron
    /// renders without their modulation: the nested BSDF's material.
    pub(super) fn wrapper_bsdf(
        &mut self,
        n: &'a Node,
        p: &Props<'a>,
        kind: &str,
    ) -> Result<Option<MaterialFile>, Diagnostic> {
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
        self.finish(p)?;
        match inner.as_slice() {
            [] => Ok(None),
            [b, ..] => {
                let b = self.resolve(b)?;
                if inner.len() > 1 {
                    self.warn(
                        n.diag("two BSDFs (front and back); heron uses the first on both sides"),
                    )?;
                }
                let name = self.bsdf(b)?;
                Ok(self.materials.get(&name).cloned())
            }
        }
    }

    pub(super) fn diffuse(&mut self, p: &Props<'a>) -> Result<MaterialFile, Diagnostic> {
        if let Some(file) = self.bitmap(p, "reflectance")? {
            return Ok(MaterialFile::Lambertian(LambertianFile {
                rho_d: None,
                texture: Some(file),
            }));
        }
        let rho = self.textured_reflectance(p, "reflectance", ColourValue::Grey(0.5))?;
        Ok(MaterialFile::Lambertian(LambertianFile {
            rho_d: Some(rho),
            texture: None,
        }))
    }

    pub(super) fn dielectric(
        &mut self,
        n: &'a Node,
        p: &Props<'a>,
        kind: &str,
    ) -> Result<MaterialFile, Diagnostic> {
        Ok({
            let int = self.ior(p, "int_ior", "bk7")?;
            let ext = self.ior(p, "ext_ior", "air")?;
            let roughness = match kind {
                "roughdielectric" => Some(self.roughness(n, p)?),
                _ => None,
            };
            let t = MaterialFile::Dielectric(DielectricFile {
                ior: int,
                fresnel: None,
                roughness,
                // Air's 1.000277 is kept: it is Mitsuba's own default, and heron's
                // relative index is then Mitsuba's.
                outside_ior: Some(ext),
            });
            for k in ["specular_reflectance", "specular_transmittance"] {
                if let Some(c) = p.get(k) {
                    self.warn(c.diag(format!(
                        "{k}: heron's dielectric has no such factor, ignored (1 is used)"
                    )))?;
                }
            }
            t
        })
    }

    /// `thindielectric`: heron's thin sheet of relative index int_ior / ext_ior (bk7
    /// and air by default, read as the dielectric reads them). Its
    /// `specular_reflectance` and `specular_transmittance` factors ("never to be
    /// touched" for realism, says Mitsuba) are not heron's: a value other than 1 is
    /// ignored with a warning.
    pub(super) fn thin_dielectric(&mut self, p: &Props) -> Result<MaterialFile, Diagnostic> {
        let ior = self.ior(p, "int_ior", "bk7")?;
        let ext = self.ior(p, "ext_ior", "air")?;
        for k in ["specular_reflectance", "specular_transmittance"] {
            let Some(c) = p.get(k) else { continue };
            let one = matches!(c.tag.as_str(), "float" | "spectrum" | "rgb")
                && c.attr("value").and_then(|v| {
                    let v: Vec<f64> = v
                        .split([',', ' '])
                        .filter(|x| !x.is_empty())
                        .map(|x| x.trim().parse().unwrap_or(f64::NAN))
                        .collect();
                    (!v.is_empty()).then(|| v.iter().all(|&x| x == 1.0))
                }) == Some(true);
            if !one {
                self.warn(c.diag(format!(
                    "{k}: heron's thin dielectric has no such factor, ignored (1 is used)"
                )))?;
            }
        }
        Ok(MaterialFile::ThinDielectric(ThinDielectricFile {
            ior,
            // Air's 1.000277 is kept, as for the dielectric: the relative index is
            // Mitsuba's.
            outside_ior: Some(ext),
        }))
    }

    pub(super) fn conductor(
        &mut self,
        n: &'a Node,
        p: &Props<'a>,
        kind: &str,
    ) -> Result<MaterialFile, Diagnostic> {
        Ok({
            let material = p.string("material")?;
            // Mitsuba's eta and k are unbounded textures: a float, an rgb (uplifted as
            // pbrt-v4's RGBUnboundedSpectrum; Mitsuba's RGB variants use it per channel,
            // its spectral ones clamp it to [0, 1] first, which heron does not copy) or a
            // spectrum. Given eta, a missing k is 1 (conductor.cpp).
            let mut short = Vec::new();
            let mut index = |name: &str, default: f64, real: bool| {
                let c = match p.colour(name) {
                    Ok(c) => c.map(|c| {
                        let (c, range) = index_samples(c.colour());
                        if let Some(r) = range {
                            short.push((name.to_string(), r));
                        }
                        c
                    }),
                    Err(ColourError::Bad(d) | ColourError::Unsupported(d)) => return Err(d),
                };
                if let Some(c) = &c {
                    if matches!(c, Colour::Named { .. } | Colour::Blackbody { .. }) {
                        return Err(n.diag(format!(
                            "{name}: expected a float, rgb or spectrum table, not an illuminant"
                        )));
                    }
                    c.check_index(real)
                        .map_err(|m| n.diag(format!("{name}: {m}")))?;
                }
                Ok(c.unwrap_or(Colour::Grey(default)))
            };
            let given = p.get("eta").is_some() || p.get("k").is_some();
            let metal = match (material, given) {
                (Some(m), true) if m != "none" => {
                    return Err(n.diag(format!(
                        "expected eta and k or material, not both (Mitsuba refuses both too), got material {m:?}"
                    )))
                }
                (_, true) => {
                    if p.get("eta").is_none() {
                        // Mitsuba's eta is then 0, outside heron's conductor (n > 0).
                        return Err(n.diag("k without eta: expected eta as well (Mitsuba's default eta 0 is not a refractive index heron takes)"));
                    }
                    let eta = index("eta", 0.0, true)?;
                    let k = index("k", 1.0, false)?;
                    Some(match (eta, k) {
                        (Colour::Grey(n_), Colour::Grey(k_)) => MetalSpec::Constant {
                            n: schema::tidy(n_),
                            k: schema::tidy(k_),
                        },
                        (n_, k_) => MetalSpec::Curves { n: n_, k: k_ },
                    })
                }
                (Some(m), false) if METALS.contains(&m) => Some(MetalSpec::Named(m.into())),
                (None | Some("none"), false) => None,
                (Some(m), false) => {
                    return Err(n.diag(format!(
                        "material: expected one of the metals heron tabulates ({}), \"none\", or eta and k, got {m:?}",
                        METALS.join(", ")
                    )))
                }
            };
            for (name, (lo, hi)) in short {
                self.warn(n.diag(format!(
                    "{name}: the table covers {lo}–{hi} nm; heron holds its end values over the rest of 360–830 nm, where Mitsuba takes 0 (a perfect mirror there)"
                )))?;
            }
            if let Some(c) = p.get("specular_reflectance") {
                self.warn(c.diag("specular_reflectance: heron's conductor has no such factor, ignored (1 is used)"))?;
            }
            match metal {
            // Mitsuba's `none`: a perfect mirror.
            None if kind == "conductor" => MaterialFile::Mirror(MirrorFile {
                rho_s: Some(Textured::Value(ColourValue::Grey(1.0).reflectance())),
            }),
            None => {
                return Err(n.diag(
                    "material \"none\" on a roughconductor: heron has no rough perfect mirror; give a metal or eta and k",
                ))
            }
            Some(metal) => {
                let roughness = match kind {
                    "roughconductor" => Some(self.roughness(n, p)?),
                    _ => None,
                };
                MaterialFile::Conductor(ConductorFile { metal, roughness })
            }
        }
        })
    }

    /// `plastic` and `roughplastic` as heron's coated material: Mitsuba's closed form
    /// is heron's (src/bsdf/coated_diffuse.rs) with no absorbing layer; its default
    /// `nonlinear = false` (ρ/(1 − F_dr) rather than ρ/(1 − ρF_dr)) is the coated
    /// material's `nonlinear = false`. Mitsuba's F_dr is a polynomial fit (within 0.1%
    /// for these indices), heron integrates it; a rough coat's transmittance is
    /// heron's 1 − E where Mitsuba tabulates the microfacet transmission.
    pub(super) fn plastic(
        &mut self,
        n: &'a Node,
        p: &Props<'a>,
        kind: &str,
    ) -> Result<MaterialFile, Diagnostic> {
        let rho = self.textured_reflectance(p, "diffuse_reflectance", ColourValue::Grey(0.5))?;
        let eta = match self.ior(p, "int_ior", "polypropylene")? {
            IorSpec::Constant(x) => x,
            IorSpec::Named(name) => mitsuba_ior(&name).unwrap_or(1.49),
            _ => 1.49,
        };
        let ext = match self.ior(p, "ext_ior", "air")? {
            IorSpec::Constant(x) => x,
            _ => 1.000277,
        };
        let eta = eta / ext;
        if !(eta >= 1.0 && eta.is_finite()) {
            return Err(n.diag(format!(
                "int_ior / ext_ior = {eta}: heron's coat needs a relative index ≥ 1"
            )));
        }
        let roughness = match kind {
            "roughplastic" => Some(self.roughness(n, p)?),
            _ => None,
        };
        if kind == "roughplastic" {
            self.warn(n.diag(
                "roughplastic: heron's rough coat lets in all it does not reflect (1 − E), Mitsuba its single-scattering microfacet transmittance; the diffuse part can be a few percent brighter (6% at α = 0.2)",
            ))?;
        }
        if let Some(c) = p.get("specular_reflectance") {
            self.warn(c.diag(
                "specular_reflectance: heron's coat has no such factor, ignored (1 is used)",
            ))?;
        }
        let nonlinear = p.boolean("nonlinear")?.unwrap_or(false);
        Ok(MaterialFile::Coated(CoatedFile {
            reflectance: rho,
            ior: Some(IorSpec::Constant(schema::tidy(eta))),
            roughness,
            thickness: None,
            // Mitsuba's default is heron's `nonlinear = false`; heron's default is true.
            nonlinear: (!nonlinear).then_some(false),
        }))
    }

    /// A microfacet BSDF's α: `alpha`, or `alpha_u`/`alpha_v` when equal (else their
    /// mean, with a warning); Mitsuba's default 0.1. Each may be a texture, read as a
    /// number (textures.rs); two different ones become their mean as a `mix` table.
    /// heron's microfacets are GGX.
    pub(super) fn roughness(
        &mut self,
        n: &'a Node,
        p: &Props<'a>,
    ) -> Result<Textured<UnitNumber>, Diagnostic> {
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
        let alpha = self.textured_float(p, "alpha")?;
        let (u, v) = (
            self.textured_float(p, "alpha_u")?,
            self.textured_float(p, "alpha_v")?,
        );
        let a = match (alpha, u, v) {
            (Some(Textured::Value(a)), _, _) => a,
            (Some(Textured::Texture(t)), _, _) => return Ok(Textured::Texture(t)),
            (None, Some(Textured::Value(u)), Some(Textured::Value(v))) => {
                if u != v {
                    self.warn(n.diag(format!(
                        "anisotropic roughness (alpha_u {u}, alpha_v {v}) is not supported; their mean is used"
                    )))?;
                }
                0.5 * (u + v)
            }
            (None, Some(u), Some(v)) => return self.mean_roughness(n, u, v),
            _ => 0.1,
        };
        if !(0.0..=1.0).contains(&a) {
            return Err(n.diag(format!("alpha: expected a roughness in [0, 1], got {a}")));
        }
        Ok(Textured::Value(schema::unit(a)))
    }

    /// The mean of `alpha_u` and `alpha_v` when one is a texture: a `mix` table with
    /// amount ½, after a warning (heron's microfacets are isotropic).
    fn mean_roughness(
        &mut self,
        n: &Node,
        u: Textured<f64>,
        v: Textured<f64>,
    ) -> Result<Textured<UnitNumber>, Diagnostic> {
        if u == v {
            return Ok(match u {
                Textured::Texture(t) => Textured::Texture(t),
                Textured::Value(a) => Textured::Value(schema::unit(a)),
            });
        }
        self.warn(n.diag(
            "anisotropic roughness (alpha_u, alpha_v, a texture) is not supported; their mean (a mix texture) is used",
        ))?;
        let side = |x: Textured<f64>| match x {
            Textured::Texture(t) => Textured::Texture(t),
            Textured::Value(a) => Textured::Value(ColourValue::Grey(a).reflectance()),
        };
        let mix = TextureFile::Mix(MixTextureFile {
            tex1: side(u),
            tex2: side(v),
            amount: None,
        });
        Ok(Textured::Texture(self.add_texture(n, mix, "alpha")))
    }

    /// An index of refraction as heron writes it: a number, or a catalogue name for the
    /// Mitsuba names heron has with dispersion.
    pub(super) fn ior(
        &mut self,
        p: &Props,
        name: &str,
        default: &str,
    ) -> Result<IorSpec, Diagnostic> {
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
            return Ok(IorSpec::Constant(schema::tidy(x)));
        }
        if let Some((_, entry)) = CATALOGUE_IORS.iter().find(|(m, _)| *m == text) {
            if let Some(c) = node {
                // Said once per element: Mitsuba's constant is not what heron renders.
                self.warn(c.diag(format!(
                    "{text:?} is heron's catalogue entry {entry:?}, with its dispersion (Mitsuba uses the constant {})",
                    mitsuba_ior(&text).unwrap_or(f64::NAN)
                )))?;
            }
            return Ok(IorSpec::Named((*entry).into()));
        }
        match mitsuba_ior(&text) {
            Some(x) => Ok(IorSpec::Constant(schema::tidy(x))),
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
}

/// Mitsuba's constant for a named index.
pub(super) fn mitsuba_ior(name: &str) -> Option<f64> {
    MITSUBA_IORS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, x)| *x)
}

/// A diffuse material of reflectance `rho`.
fn lambertian(rho: ColourValue) -> MaterialFile {
    MaterialFile::Lambertian(LambertianFile {
        rho_d: Some(Textured::Value(rho.reflectance())),
        texture: None,
    })
}
