//! A conductor's `metal`: a catalogue name, a table file, constant n and k, or n and k
//! over wavelength (each a number, `[r, g, b]` or samples), read and written with the
//! same digits. Apart from `leaves.rs` and `colour.rs` because it uses both.
use super::colour::index_curve;
use super::leaves::{finite_in_f32, one_key, raw, two_keys};
use super::show::show;
use super::*;
use serde::ser::{Serialize, SerializeMap, Serializer};

impl<'de> Deserialize<'de> for MetalSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use crate::spectrum::metals::METAL_NAMES;
        let v = raw(d)?;
        let expected = || {
            format!(
                "expected a metal of the catalogue ({}), {{ table = \"nk.csv\" }} or {{ n = .., k = .. }} (each a number, [r, g, b] or {{ samples = [[nm, value], ...] }}), got {}",
                METAL_NAMES.join(", "),
                show(&v)
            )
        };
        match &v {
            toml::Value::String(name) => {
                if METAL_NAMES.contains(&name.as_str()) {
                    Ok(MetalSpec::Named(name.clone()))
                } else {
                    Err(D::Error::custom(format!(
                        "unknown metal {name:?}, expected one of {}",
                        METAL_NAMES.join(", ")
                    )))
                }
            }
            toml::Value::Table(t) => {
                if let (1, Some(toml::Value::String(f))) = (t.len(), t.get("table")) {
                    return Ok(MetalSpec::Table(f.clone()));
                }
                let n = t.get("n").and_then(finite_in_f32);
                let k = t.get("k").and_then(finite_in_f32);
                match (t.len(), n, k) {
                    (2, Some(n), Some(k)) if n as f32 > 0.0 && k as f32 >= 0.0 => {
                        Ok(MetalSpec::Constant { n, k })
                    }
                    (2, Some(_), Some(_)) => Err(D::Error::custom(format!(
                        "expected n > 0 and k >= 0, got {}",
                        show(&v)
                    ))),
                    (2, _, _) if t.contains_key("n") && t.contains_key("k") => {
                        let curve = |key: &str| {
                            index_curve(&t[key], key == "n")
                                .map_err(|e| D::Error::custom(format!("{key}: {e}")))
                        };
                        Ok(MetalSpec::Curves {
                            n: curve("n")?,
                            k: curve("k")?,
                        })
                    }
                    _ => Err(D::Error::custom(expected())),
                }
            }
            _ => Err(D::Error::custom(expected())),
        }
    }
}

impl Serialize for MetalSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            MetalSpec::Named(name) => s.serialize_str(name),
            MetalSpec::Table(file) => one_key(s, "table", file),
            MetalSpec::Constant { n, k } => two_keys(s, ("n", *n), ("k", *k)),
            MetalSpec::Curves { n, k } => {
                let mut m = s.serialize_map(Some(2))?;
                m.serialize_entry("n", n)?;
                m.serialize_entry("k", k)?;
                m.end()
            }
        }
    }
}
