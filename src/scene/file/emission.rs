//! A shape's `emission`: a colour ([`Emission`]: a number, `[r, g, b]`, a named
//! spectrum, a blackbody, samples), or a texture over the surface,
//! `{ texture = "NAME", scale = S }`, naming a `[textures]` table.
//!
//! A textured emission is the texture's value at the point's uv times D65 at luminance
//! Y = 1 times `scale` (default 1): the texture's colours are reflectance-like (in
//! [0, 1]), each uplifted as a reflectance and lit by the sRGB white, so that a texel
//! (r, g, b) emits what `emission = [r, g, b]` emits, up to metamerism (heron's RGB
//! emission uplift, pbrt-v4's `RGBIlluminantSpectrum`; Mitsuba 3's `d65` texture around
//! a nested one), and `scale` brightens it past 1 (pbrt-v4's area light `scale`).
use super::leaves::{number, raw};
use super::*;
use serde::ser::{Serialize, SerializeMap, Serializer};

/// A shape's `emission`.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeEmission {
    Colour(Emission),
    /// `{ texture = "NAME", scale = S }`.
    Texture {
        texture: String,
        scale: f64,
    },
}

impl From<Emission> for ShapeEmission {
    fn from(e: Emission) -> Self {
        ShapeEmission::Colour(e)
    }
}

impl ShapeEmission {
    /// The colour, when the emission is one.
    pub fn colour(&self) -> Option<&Emission> {
        match self {
            ShapeEmission::Colour(e) => Some(e),
            ShapeEmission::Texture { .. } => None,
        }
    }
}

impl<'de> Deserialize<'de> for ShapeEmission {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        if let toml::Value::Table(t) = &v {
            if let Some(name) = t.get("texture") {
                let toml::Value::String(name) = name else {
                    return Err(D::Error::custom(format!(
                        "expected {{ texture = \"NAME\" }} (the name of a [textures] table) with an optional scale, got {}",
                        show(&v)
                    )));
                };
                if let Some(k) = t.keys().find(|k| *k != "texture" && *k != "scale") {
                    return Err(D::Error::custom(format!(
                        "unknown key {k:?} in a textured emission (expected texture, scale)"
                    )));
                }
                let scale = match t.get("scale") {
                    None => 1.0,
                    Some(s) => number(s)
                        .filter(|x| (*x as f32).is_finite() && *x >= 0.0)
                        .ok_or_else(|| {
                            D::Error::custom(format!(
                                "expected scale = a finite number >= 0, got {}",
                                show(s)
                            ))
                        })?,
                };
                return Ok(ShapeEmission::Texture {
                    texture: name.clone(),
                    scale,
                });
            }
        }
        Emission::deserialize(v)
            .map(ShapeEmission::Colour)
            .map_err(|e| D::Error::custom(e.message()))
    }
}

impl Serialize for ShapeEmission {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            ShapeEmission::Colour(e) => e.serialize(s),
            ShapeEmission::Texture { texture, scale } => {
                let mut m = s.serialize_map(Some(if *scale == 1.0 { 1 } else { 2 }))?;
                m.serialize_entry("texture", texture)?;
                if *scale != 1.0 {
                    m.serialize_entry("scale", scale)?;
                }
                m.end()
            }
        }
    }
}
