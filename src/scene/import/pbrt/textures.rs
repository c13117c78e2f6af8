//! pbrt-v4's `Texture "name" "spectrum"|"float" "class" …` directives as heron's
//! `[textures]` tables (pbrt-v4 `textures.cpp`): `imagemap` (`filename`, `encoding`,
//! `scale`, `invert`), `checkerboard` (2D; `tex1` default 1, `tex2` default 0), `scale`
//! (`tex` × `scale`), `mix` (`tex1` default 0, `tex2` default 1, `amount` default 0.5)
//! and `constant`, each with the `uv` mapping's `uscale`, `vscale`, `udelta`, `vdelta`;
//! and `"texture reflectance" "name"` on a material, through [`Conv::textured`].
//!
//! The mapping: pbrt looks an image up at (s, 1 − t) with (s, t) = (su u + du,
//! sv v + dv), so an imagemap's `to_uv` is [[su, 0, du], [0, −sv, 1 − dv]]; its
//! checkerboard is heron's (Mitsuba's) at (s/2, t/2) (src/texture/checkerboard.rs says
//! why that is pbrt's squares).
use super::tokens::Params;
use super::*;
use crate::scene::file::{
    CheckerboardFile, Colour, ImageTextureFile, MixTextureFile, NonNegativeNumber, Reflectance,
    ScaleTextureFile, TextureFile, Textured, UnitNumber, UvMatrix,
};

impl Conv {
    /// `Texture "name" "spectrum"|"float" "class" params` at `line` of `path`.
    pub(super) fn texture_directive(
        &mut self,
        path: &Path,
        line: u32,
        strs: &[String],
        p: &Params,
    ) -> Result<(), Diagnostic> {
        let [name, kind, class] = strs else {
            return Err(self.diag(
                path,
                line,
                "Texture: expected a name, \"spectrum\" or \"float\", and a class",
            ));
        };
        let float = match kind.as_str() {
            "spectrum" => false,
            "float" => true,
            other => {
                return Err(self.diag(
                    path,
                    line,
                    format!("Texture {name:?}: expected \"spectrum\" or \"float\", got {other:?}"),
                ))
            }
        };
        let mapping = p.string("mapping").unwrap_or("uv");
        if mapping != "uv" {
            self.warn(self.diag(path, line, format!("Texture {name:?}: mapping {mapping:?} is not supported, the uv mapping is used")))?;
        }
        let su = p.float("uscale").unwrap_or(1.0);
        let sv = p.float("vscale").unwrap_or(1.0);
        let du = p.float("udelta").unwrap_or(0.0);
        let dv = p.float("vdelta").unwrap_or(0.0);
        let t = match class.as_str() {
            "imagemap" => self.imagemap(path, line, name, float, p, [su, sv, du, dv])?,
            "checkerboard" => {
                if p.get("dimension").and_then(|q| q.nums.first().copied()) == Some(3.0) {
                    self.warn(self.diag(path, line, format!("Texture {name:?}: a 3D checkerboard is not supported; the 2D one over uv is used")))?;
                }
                let color0 = self.tex_input(path, p, "tex1", 1.0, float)?;
                let color1 = self.tex_input(path, p, "tex2", 0.0, float)?;
                let to_uv: UvMatrix = [[su / 2.0, 0.0, du / 2.0], [0.0, sv / 2.0, dv / 2.0]];
                TextureFile::Checkerboard(CheckerboardFile {
                    color0: Some(color0),
                    color1: Some(color1),
                    to_uv: Some(to_uv.map(|r| r.map(tidy))),
                })
            }
            "scale" => {
                let tex = self.tex_input(path, p, "tex", 1.0, float)?;
                let scale = match p.get("scale") {
                    Some(q) if q.ty == "texture" => match self.texture_name(q.strs.first(), true) {
                        Some(n) => Textured::Texture(n),
                        None => {
                            self.warn(self.diag(path, q.line, format!("\"texture scale\": no float texture {:?} is supported; 1 is used", q.strs.first().cloned().unwrap_or_default())))?;
                            Textured::Value(NonNegativeNumber(1.0))
                        }
                    },
                    Some(q) => Textured::Value(NonNegativeNumber(tidy(
                        q.nums.first().copied().unwrap_or(1.0).max(0.0),
                    ))),
                    None => Textured::Value(NonNegativeNumber(1.0)),
                };
                TextureFile::Scale(ScaleTextureFile { tex, scale })
            }
            "mix" => {
                let tex1 = self.tex_input(path, p, "tex1", 0.0, float)?;
                let tex2 = self.tex_input(path, p, "tex2", 1.0, float)?;
                let amount = match p.get("amount") {
                    Some(q) if q.ty == "texture" => match self.texture_name(q.strs.first(), true) {
                        Some(n) => Some(Textured::Texture(n)),
                        None => {
                            self.warn(self.diag(path, q.line, format!("\"texture amount\": no float texture {:?} is supported; 0.5 is used", q.strs.first().cloned().unwrap_or_default())))?;
                            None
                        }
                    },
                    Some(q) => Some(Textured::Value(schema::unit(
                        q.nums.first().copied().unwrap_or(0.5).clamp(0.0, 1.0),
                    ))),
                    None => None,
                };
                TextureFile::Mix(MixTextureFile { tex1, tex2, amount })
            }
            "constant" => {
                let value = self.tex_input(path, p, "value", 1.0, float)?;
                TextureFile::Scale(ScaleTextureFile {
                    tex: value,
                    scale: Textured::Value(NonNegativeNumber(1.0)),
                })
            }
            other => {
                for q in &p.0 {
                    q.used.set(true);
                }
                return self.warn(self.diag(path, line, format!("Texture {name:?}: class {other:?} is not supported (imagemap, checkerboard, scale, mix, constant are); a material naming it gets the parameter's default")));
            }
        };
        let table = if float {
            format!("{name} (float)")
        } else {
            name.clone()
        };
        self.textures.insert(table.clone(), t);
        self.texture_names.insert((float, name.clone()), table);
        Ok(())
    }

    /// An `imagemap` texture's table; `uv` = [su, sv, du, dv].
    fn imagemap(
        &mut self,
        path: &Path,
        line: u32,
        name: &str,
        float: bool,
        p: &Params,
        uv: [f64; 4],
    ) -> Result<TextureFile, Diagnostic> {
        let [su, sv, du, dv] = uv;
        if float {
            self.warn(self.diag(path, line, format!("Texture {name:?}: a float imagemap is read as its luminance where a material wants a number (a roughness) and as a colour (a spectrum per wavelength from its RGB) elsewhere; pbrt-v4 reads its first channel, the same for a grey image")))?;
        }
        let f = p.string("filename").unwrap_or_default().to_string();
        if f.is_empty() {
            return Err(self.diag(
                path,
                line,
                format!("Texture {name:?}: imagemap: expected \"string filename\""),
            ));
        }
        let full = self.base_of(path).join(&f);
        let file = relative_to(&full, &self.base)
            .to_string_lossy()
            .replace('\\', "/");
        let encoding = match p.string("encoding") {
            None | Some("sRGB") => None,
            Some("linear") => Some("linear".to_string()),
            Some(g) if g.starts_with("gamma ") => Some(g.to_string()),
            Some(other) => return Err(self.diag(path, line, format!("Texture {name:?}: encoding: expected \"sRGB\", \"linear\" or \"gamma G\", got {other:?}"))),
        };
        for (k, default) in [("filter", "bilinear"), ("wrap", "repeat")] {
            if let Some(v) = p.string(k) {
                if v != default {
                    self.warn(self.diag(path, line, format!("Texture {name:?}: {k} {v:?}: heron's textures are {default}, which is used")))?;
                }
            }
        }
        p.get("maxanisotropy");
        let scale = p.float("scale").filter(|s| *s != 1.0);
        if scale.is_some_and(|s| s < 0.0) {
            return Err(self.diag(
                path,
                line,
                format!("Texture {name:?}: scale: expected a number ≥ 0"),
            ));
        }
        let invert = p.get("invert").map(|q| {
            q.strs.first().map(String::as_str) == Some("true") || q.nums.first() == Some(&1.0)
        });
        Ok(TextureFile::Image(ImageTextureFile {
            file,
            encoding,
            scale: scale.map(|s| NonNegativeNumber(tidy(s))),
            invert: invert.filter(|i| *i),
            to_uv: Some([[su, 0.0, du], [0.0, -sv, 1.0 - dv]].map(|r| r.map(tidy))),
        }))
    }

    /// The table of the texture `name` (float or spectrum), if one was made.
    fn texture_name(&self, name: Option<&String>, float: bool) -> Option<String> {
        let name = name?;
        self.texture_names
            .get(&(float, name.clone()))
            .or_else(|| self.texture_names.get(&(!float, name.clone())))
            .cloned()
    }

    /// A texture's own input `name`: a value (a reflectance: above 1 is clamped, with a
    /// warning) or `"texture name"`.
    fn tex_input(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
        float: bool,
    ) -> Result<Textured<Reflectance>, Diagnostic> {
        if let Some(q) = p.get(name) {
            if q.ty == "texture" {
                if let Some(n) = self.texture_name(q.strs.first(), float) {
                    return Ok(Textured::Texture(n));
                }
            }
        }
        let c = self.colour(path, p, name, default)?;
        Ok(Textured::Value(self.bounded(path, p, name, c)?))
    }

    /// A reflectance parameter of a material: `"texture name"` naming a texture made
    /// before, or a colour ([`Self::colour`]).
    pub(super) fn textured(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        default: f64,
    ) -> Result<Textured<Reflectance>, Diagnostic> {
        if let Some(q) = p.get(name) {
            if q.ty == "texture" {
                if let Some(n) = self.texture_name(q.strs.first(), false) {
                    return Ok(Textured::Texture(n));
                }
            }
        }
        Ok(Textured::Value(
            self.colour(path, p, name, default)?.reflectance(),
        ))
    }

    /// A microfacet material's (`what`'s) roughness when `roughness`, `uroughness` or
    /// `vroughness` names a texture: its table, read as a number per point (its
    /// luminance; pbrt-v4 reads a float image's first channel, the same for a grey
    /// image). Two different sides become their mean, a `mix` table, with a warning
    /// (heron's microfacets are isotropic). pbrt-v4 remaps a texture's value r to α = √r
    /// per point unless `remaproughness` is false: a tree of constants, checkerboards
    /// and scales is copied with its values' square roots ([`Self::sqrt_table`]); an
    /// image or a mix has no such copy (heron's textures have no square root), so its
    /// values are used as α, with a warning. None when no texture is named.
    pub(super) fn roughness_texture(
        &mut self,
        path: &Path,
        line: u32,
        p: &Params,
        what: &str,
    ) -> Result<Option<Textured<UnitNumber>>, Diagnostic> {
        let is_tex = |n: &str| p.get(n).is_some_and(|q| q.ty == "texture");
        if !["roughness", "uroughness", "vroughness"]
            .iter()
            .any(|n| is_tex(n))
        {
            return Ok(None);
        }
        let side =
            |this: &mut Self, n: &str| -> Result<Option<Textured<Reflectance>>, Diagnostic> {
                if p.get(n).is_none() {
                    return Ok(None);
                }
                if is_tex(n) {
                    let q = p.get(n).expect("checked");
                    // A texture heron did not make (its directive warned): the default.
                    return Ok(this
                        .texture_name(q.strs.first(), true)
                        .map(Textured::Texture));
                }
                let c = this.colour(path, p, n, 0.0)?;
                Ok(Some(this.bounded(path, p, n, c)?)).map(|r| r.map(Textured::Value))
            };
        // pbrt-v4 reads uroughness and vroughness first, roughness when both are absent.
        let (u, v) = (side(self, "uroughness")?, side(self, "vroughness")?);
        let tex = match (u, v) {
            (None, None) => side(self, "roughness")?,
            (Some(u), Some(v)) if u != v => {
                self.warn(self.diag(path, line, format!("{what}: anisotropic roughness (uroughness, vroughness, a texture); heron's microfacets are isotropic, their mean (a mix texture) is used")))?;
                let mut name = format!("{what}-roughness");
                let mut k = 1;
                while self.textures.contains_key(&name) {
                    k += 1;
                    name = format!("{what}-roughness-{k}");
                }
                let mix = MixTextureFile {
                    tex1: u,
                    tex2: v,
                    amount: None,
                };
                self.textures.insert(name.clone(), TextureFile::Mix(mix));
                Some(Textured::Texture(name))
            }
            (Some(t), _) | (None, Some(t)) => Some(t),
        };
        p.get("roughness");
        let Some(Textured::Texture(tex)) = tex else {
            // A number on the side that counts (the texture was on the other): the
            // constant path reads it.
            return Ok(None);
        };
        let mut tex = tex;
        if p.string("remaproughness") != Some("false") {
            match self.sqrt_table(&tex, 0) {
                Some(t) => tex = t,
                None => self.warn(self.diag(path, line, format!("{what}: a roughness texture's values are used as GGX α; pbrt-v4 remaps each to √value (remaproughness true, its default), which heron's textures cannot compute for an image or a mix")))?,
            }
        }
        p.get("remaproughness");
        Ok(Some(Textured::Texture(tex)))
    }

    /// A copy of table `name` whose every value is the square root of the original's
    /// (pbrt-v4's roughness remap, α = √r, applied to the leaves: exact through a
    /// checkerboard, which picks a leaf, and a scale, √(ab) = √a √b), named
    /// `"NAME (alpha)"`; None when the tree holds an image or a mix (or is too deep).
    fn sqrt_table(&mut self, name: &str, depth: u32) -> Option<String> {
        let out = format!("{name} (alpha)");
        if self.textures.contains_key(&out) {
            return Some(out);
        }
        if depth > 16 {
            return None;
        }
        let leaf = |this: &mut Self, v: Option<&Textured<Reflectance>>, default: f64| match v {
            None => Some(Textured::Value(Reflectance(Colour::Grey(tidy(
                default.sqrt(),
            ))))),
            Some(Textured::Value(Reflectance(Colour::Grey(g)))) => Some(Textured::Value(
                Reflectance(Colour::Grey(tidy(g.max(0.0).sqrt()))),
            )),
            Some(Textured::Value(_)) => None,
            Some(Textured::Texture(t)) => this.sqrt_table(t, depth + 1).map(Textured::Texture),
        };
        let file = match self.textures.get(name)?.clone() {
            TextureFile::Checkerboard(c) => TextureFile::Checkerboard(CheckerboardFile {
                color0: Some(leaf(self, c.color0.as_ref(), 0.4)?),
                color1: Some(leaf(self, c.color1.as_ref(), 0.2)?),
                to_uv: c.to_uv,
            }),
            TextureFile::Scale(sc) => TextureFile::Scale(ScaleTextureFile {
                tex: leaf(self, Some(&sc.tex), 1.0)?,
                scale: match sc.scale {
                    Textured::Value(x) => Textured::Value(NonNegativeNumber(tidy(x.0.sqrt()))),
                    Textured::Texture(_) => return None,
                },
            }),
            TextureFile::Image(_) | TextureFile::Mix(_) => return None,
        };
        self.textures.insert(out.clone(), file);
        Some(out)
    }

    /// `c` as a reflectance, components above 1 clamped with a warning.
    fn bounded(
        &mut self,
        path: &Path,
        p: &Params,
        name: &str,
        c: ColourValue,
    ) -> Result<Reflectance, Diagnostic> {
        let clamp = |x: f64| x.clamp(0.0, 1.0);
        let out = match c {
            ColourValue::Grey(g) if g > 1.0 => ColourValue::Grey(clamp(g)),
            ColourValue::Rgb(v) if v.iter().any(|x| *x > 1.0) => ColourValue::Rgb(v.map(clamp)),
            c => return Ok(c.reflectance()),
        };
        let line = p.get(name).map_or(0, |q| q.line);
        self.warn(self.diag(path, line, format!("\"{name}\": a texture's value above 1 is clamped to 1 (heron's texture values are reflectances)")))?;
        Ok(out.reflectance())
    }
}
