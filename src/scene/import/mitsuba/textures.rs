//! Mitsuba 3's textures as heron's `[textures]` tables: `bitmap` (src/textures/bitmap.cpp)
//! and `checkerboard` (src/textures/checkerboard.cpp), nested or by `ref`, with their
//! `to_uv`; a checkerboard's colours may be textures themselves. A plain bitmap used
//! directly as a diffuse reflectance stays the lambertian's `texture = "file"`, as heron
//! wrote it before it had tables.
//!
//! A float parameter (a microfacet `alpha`) reads its texture with Mitsuba's `eval_1`:
//! a bitmap's luminance, which is heron's number from a texture (src/texture/mod.rs);
//! but Mitsuba's checkerboard `eval_1` puts `color1` where its `eval` puts `color0`
//! (checkerboard.cpp tests `mask.x() != mask.y()` there), so a checkerboard read as a
//! number becomes a table with the two colours swapped, which renders what Mitsuba does.
use super::*;
use crate::scene::file::{CheckerboardFile, ImageTextureFile, Reflectance, Textured, UvMatrix};

/// A bitmap's file (relative to the top-level file's folder) and its `to_uv`.
type Bitmap = (String, Option<UvMatrix>);

/// `to_uv` as heron's 2 × 3 matrix: Mitsuba reads a 4 × 4 transform's upper-left 2 × 2
/// and its translation column (`Transform::extract`); none for the identity.
fn uv_matrix(m: DMat4) -> Option<UvMatrix> {
    if m == DMat4::IDENTITY {
        return None;
    }
    let t = |x: f64| schema::tidy(x);
    Some([
        [t(m.x_axis.x), t(m.y_axis.x), t(m.w_axis.x)],
        [t(m.x_axis.y), t(m.y_axis.y), t(m.w_axis.y)],
    ])
}

impl<'a> Converter<'a> {
    /// The texture element parameter `name` names (nested or by `ref`), if it names one;
    /// the parameter is marked read.
    pub(super) fn texture_node(
        &mut self,
        p: &Props<'a>,
        name: &str,
    ) -> Result<Option<&'a Node>, Diagnostic> {
        let Some(n) = p
            .node
            .children
            .iter()
            .find(|c| c.attr("name") == Some(name))
        else {
            return Ok(None);
        };
        let t = self.resolve(n)?;
        if t.tag != "texture" {
            return Ok(None);
        }
        p.get(name);
        Ok(Some(t))
    }

    /// The image file of parameter `name` when it is a `bitmap` without `to_uv`, as a
    /// lambertian's `texture` reads it (bilinear, repeating, 8-bit images sRGB-decoded:
    /// Mitsuba's defaults). Its other settings warn where heron differs.
    pub(super) fn bitmap(
        &mut self,
        p: &Props<'a>,
        name: &str,
    ) -> Result<Option<String>, Diagnostic> {
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
        let tp = self.props(t);
        if tp.transform("to_uv")?.is_some_and(|m| m != DMat4::IDENTITY) {
            return Ok(None);
        }
        p.get(name);
        Ok(Some(self.bitmap_of(t)?.0))
    }

    fn bitmap_of(&mut self, t: &'a Node) -> Result<Bitmap, Diagnostic> {
        let tp = self.props(t);
        let Some(file) = tp.string("filename")? else {
            return Err(t.diag("expected <string name=\"filename\" value=\"…\"/>"));
        };
        let rel = relative_to(&self.find(t, file), &self.base);
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
        let to_uv = tp.transform("to_uv")?.and_then(uv_matrix);
        self.finish(&tp)?;
        Ok((rel.to_string_lossy().replace('\\', "/"), to_uv))
    }

    /// A reflectance that may be a texture: a `bitmap` or `checkerboard` (nested or by
    /// `ref`) becomes a `[textures]` table; another texture warns and gives `default`.
    pub(super) fn textured_reflectance(
        &mut self,
        p: &Props<'a>,
        name: &str,
        default: ColourValue,
    ) -> Result<Textured<Reflectance>, Diagnostic> {
        if let Some(t) = self.texture_node(p, name)? {
            if let Some(table) = self.texture(t)? {
                return Ok(Textured::Texture(table));
            }
            return Ok(Textured::Value(default.reflectance()));
        }
        Ok(Textured::Value(
            self.colour(p, name, default)?.reflectance(),
        ))
    }

    /// A float parameter `name` (marked read): a number, or a texture read as a number
    /// (module doc); None when absent, or (after a warning) a texture kind heron has not.
    pub(super) fn textured_float(
        &mut self,
        p: &Props<'a>,
        name: &str,
    ) -> Result<Option<Textured<f64>>, Diagnostic> {
        if let Some(t) = self.texture_node(p, name)? {
            return Ok(self.float_texture(t)?.map(Textured::Texture));
        }
        Ok(p.float(name)?.map(Textured::Value))
    }

    /// The table of texture `t` read as a number: a checkerboard with its colours
    /// swapped (module doc; a new table for each use), any other kind as [`Self::texture`].
    fn float_texture(&mut self, t: &'a Node) -> Result<Option<String>, Diagnostic> {
        if t.attr("type") != Some("checkerboard") {
            return self.texture(t);
        }
        let tp = self.props(t);
        let grey = |v: Option<Textured<f64>>, default: f64| match v {
            Some(Textured::Texture(n)) => Textured::Texture(n),
            Some(Textured::Value(x)) => Textured::Value(ColourValue::Grey(x).reflectance()),
            None => Textured::Value(ColourValue::Grey(default).reflectance()),
        };
        let color0 = grey(self.textured_float(&tp, "color0")?, 0.4);
        let color1 = grey(self.textured_float(&tp, "color1")?, 0.2);
        let to_uv = tp.transform("to_uv")?.and_then(uv_matrix);
        self.finish(&tp)?;
        let file = TextureFile::Checkerboard(CheckerboardFile {
            color0: Some(color1),
            color1: Some(color0),
            to_uv,
        });
        Ok(Some(self.add_texture(t, file, "float")))
    }

    /// Adds table `file` under a fresh name from `t`'s id (and `suffix`).
    pub(super) fn add_texture(&mut self, t: &Node, file: TextureFile, suffix: &str) -> String {
        let base = match (t.attr("id"), suffix) {
            (Some(id), "") => id.to_string(),
            (Some(id), s) => format!("{id}-{s}"),
            (None, "") => "texture".to_string(),
            (None, s) => format!("texture-{s}"),
        };
        let mut name = base.clone();
        let mut k = 1;
        while self.textures.contains_key(&name) {
            k += 1;
            name = format!("{base}-{k}");
        }
        self.textures.insert(name.clone(), file);
        name
    }

    /// The `[textures]` table of texture element `t` (converted once), or None (with a
    /// warning) for a kind heron has not.
    pub(super) fn texture(&mut self, t: &'a Node) -> Result<Option<String>, Diagnostic> {
        if let Some(name) = self.texture_of.get(&(t as *const Node)) {
            return Ok(Some(name.clone()));
        }
        let file = match t.attr("type").unwrap_or("") {
            "bitmap" => {
                let (file, to_uv) = self.bitmap_of(t)?;
                TextureFile::Image(ImageTextureFile {
                    file,
                    encoding: None,
                    scale: None,
                    invert: None,
                    to_uv,
                })
            }
            "checkerboard" => {
                let tp = self.props(t);
                let color0 = self.textured_reflectance(&tp, "color0", ColourValue::Grey(0.4))?;
                let color1 = self.textured_reflectance(&tp, "color1", ColourValue::Grey(0.2))?;
                let to_uv = tp.transform("to_uv")?.and_then(uv_matrix);
                self.finish(&tp)?;
                TextureFile::Checkerboard(CheckerboardFile {
                    color0: Some(color0),
                    color1: Some(color1),
                    to_uv,
                })
            }
            other => {
                self.warn(t.diag(format!(
                    "texture {other:?} is not supported (bitmap and checkerboard are); the parameter's default is used"
                )))?;
                return Ok(None);
            }
        };
        let name = self.add_texture(t, file, "");
        self.texture_of.insert(t as *const Node, name.clone());
        Ok(Some(name))
    }
}
