//! `[textures.NAME]` tables and the texture-valued keys that name them.
//!
//! A texture is a spectrum over a surface's uv (src/texture/): an image, a
//! checkerboard of two textures, a product of two, or a mix of two by an amount. A key
//! that takes a texture takes its plain value (a colour, a number) or
//! `{ texture = "NAME" }`, naming a table of `[textures]`.
use super::leaves::raw;
use super::*;
use serde::ser::{Serialize, Serializer};

/// A value, or `{ texture = "NAME" }`.
#[derive(Clone, Debug, PartialEq)]
pub enum Textured<T> {
    Value(T),
    Texture(String),
}

impl<'de, T: serde::de::DeserializeOwned> Deserialize<'de> for Textured<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        if let toml::Value::Table(t) = &v {
            if let Some(name) = t.get("texture") {
                return match (name, t.len()) {
                    (toml::Value::String(s), 1) => Ok(Textured::Texture(s.clone())),
                    _ => Err(D::Error::custom(format!(
                        "expected {{ texture = \"NAME\" }} (the name of a [textures] table), got {}",
                        show(&v)
                    ))),
                };
            }
        }
        T::deserialize(v)
            .map(Textured::Value)
            .map_err(|e| D::Error::custom(e.message()))
    }
}

impl<T: Serialize> Serialize for Textured<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Textured::Value(v) => v.serialize(s),
            Textured::Texture(name) => super::leaves::one_key(s, "texture", name),
        }
    }
}

/// `[textures.NAME]`, tagged by `type`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum TextureFile {
    Image(ImageTextureFile),
    Checkerboard(CheckerboardFile),
    Scale(ScaleTextureFile),
    Mix(MixTextureFile),
}

impl TextureFile {
    /// The `type` values, in declaration order (`tests::names_are_the_serde_tags`).
    pub const NAMES: &'static [&'static str] = &["image", "checkerboard", "scale", "mix"];
}

/// An affine map of uv, `to_uv = [[a, b, c], [d, e, f]]`: (u, v) → (a u + b v + c,
/// d u + e v + f) (Mitsuba 3's `to_uv` without its last row and column).
pub type UvMatrix = [[f64; 3]; 2];

/// An image of reflectance (src/texture/image.rs), looked up at `to_uv(uv)`: uv (0, 0) is
/// the image's top-left corner, v runs down the rows, bilinear, repeating.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ImageTextureFile {
    /// The image, relative to the scene file: PNG, JPEG, OpenEXR, Radiance HDR or PFM.
    pub file: String,
    /// How a PNG's or JPEG's values are decoded: `"srgb"` (default), `"linear"`, or
    /// `"gamma G"` (value^G); OpenEXR, HDR and PFM are linear whatever this says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub encoding: Option<String>,
    /// Multiplies every texel before the clamp to [0, 1]; default 1 (pbrt-v4's `scale`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<NonNegativeNumber>,
    /// 1 − texel instead of the texel (after `scale`); default false (pbrt-v4's `invert`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub invert: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to_uv: Option<UvMatrix>,
}

/// Mitsuba 3's checkerboard (src/texture/checkerboard.rs): at (s, t) = `to_uv(uv)`,
/// `color0` where frac(s) > ½ and frac(t) > ½ agree, `color1` elsewhere.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct CheckerboardFile {
    /// Default 0.4 (Mitsuba's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color0: Option<Textured<Reflectance>>,
    /// Default 0.2 (Mitsuba's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color1: Option<Textured<Reflectance>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to_uv: Option<UvMatrix>,
}

/// `tex` × `scale` (pbrt-v4's `scale` texture); a diffuse reflectance clamps the product
/// to [0, 1].
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScaleTextureFile {
    pub tex: Textured<Reflectance>,
    /// A number ≥ 0 or a texture.
    pub scale: Textured<NonNegativeNumber>,
}

/// (1 − amount)·tex1 + amount·tex2 (pbrt-v4's `mix` texture).
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MixTextureFile {
    pub tex1: Textured<Reflectance>,
    pub tex2: Textured<Reflectance>,
    /// A number in [0, 1] or a texture; default 0.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amount: Option<Textured<UnitNumber>>,
}
