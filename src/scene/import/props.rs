//! The properties of one Mitsuba object (`<float name=…>`, `<rgb name=…>`, nested
//! objects, `<ref>`s), each marked when the converter reads it, so that whatever it did
//! not read can be named in a warning rather than dropped silently.
use super::transform::{numbers, parse_transform, vector_attrs};
use super::xml::{Diagnostic, Node};
use glam::{DMat4, DVec3};
use std::cell::Cell;

/// The tags that hold a value (Mitsuba 3's property types).
const VALUE_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "spectrum",
    "point",
    "vector",
    "transform",
    "blackbody",
];

pub struct Props<'a> {
    pub node: &'a Node,
    used: Vec<Cell<bool>>,
}

/// A colour property as heron's scene files write colours: grey, or RGB.
#[derive(Clone, Debug, PartialEq)]
pub enum ColourValue {
    Grey(f64),
    Rgb([f64; 3]),
}

impl ColourValue {
    pub fn to_toml(&self) -> toml::Value {
        match self {
            ColourValue::Grey(g) => toml::Value::Float(*g),
            ColourValue::Rgb(c) => {
                toml::Value::Array(c.iter().map(|x| toml::Value::Float(*x)).collect())
            }
        }
    }
}

impl<'a> Props<'a> {
    pub fn new(node: &'a Node) -> Self {
        Props {
            node,
            used: node.children.iter().map(|_| Cell::new(false)).collect(),
        }
    }

    /// The child named `name` (a value or a nested object), marked as read.
    pub fn get(&self, name: &str) -> Option<&'a Node> {
        let i = self
            .node
            .children
            .iter()
            .position(|c| c.attr("name") == Some(name))?;
        self.used[i].set(true);
        Some(&self.node.children[i])
    }

    /// The nested objects whose tag is one of `tags`, and every `<ref>` (which the
    /// caller resolves and checks), marked as read.
    pub fn objects(&self, tags: &[&str]) -> Vec<&'a Node> {
        let mut out = Vec::new();
        for (i, c) in self.node.children.iter().enumerate() {
            if tags.contains(&c.tag.as_str()) || c.tag == "ref" {
                self.used[i].set(true);
                out.push(c);
            }
        }
        out
    }

    fn value_of<'n>(&self, n: &'n Node) -> Result<&'n str, Diagnostic> {
        n.attr("value")
            .ok_or_else(|| n.diag("expected the attribute value"))
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>, Diagnostic> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        if n.tag != "float" && n.tag != "integer" {
            return Err(n.diag(format!("expected <float name=\"{name}\" value=\"…\"/>")));
        }
        let v = self.value_of(n)?;
        match numbers(v).as_deref() {
            Some([x]) => Ok(Some(*x)),
            _ => Err(n.diag(format!("value: expected a finite number, got {v:?}"))),
        }
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, Diagnostic> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        let v = self.value_of(n)?;
        if n.tag != "integer" {
            return Err(n.diag(format!("expected <integer name=\"{name}\" value=\"…\"/>")));
        }
        v.trim()
            .parse::<i64>()
            .map(Some)
            .map_err(|_| n.diag(format!("value: expected an integer, got {v:?}")))
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, Diagnostic> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        let v = self.value_of(n)?;
        match (n.tag.as_str(), v.trim()) {
            ("boolean", "true") => Ok(Some(true)),
            ("boolean", "false") => Ok(Some(false)),
            _ => Err(n.diag(format!(
                "expected <boolean name=\"{name}\" value=\"true\"/> or \"false\", got {v:?}"
            ))),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&'a str>, Diagnostic> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        if n.tag != "string" {
            return Err(n.diag(format!("expected <string name=\"{name}\" value=\"…\"/>")));
        }
        n.attr("value")
            .map(Some)
            .ok_or_else(|| n.diag("expected the attribute value"))
    }

    pub fn point(&self, name: &str) -> Result<Option<DVec3>, Diagnostic> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        if n.tag != "point" && n.tag != "vector" {
            return Err(n.diag(format!("expected <point name=\"{name}\" …/>")));
        }
        vector_attrs(n, 0.0).map(Some)
    }

    pub fn transform(&self, name: &str) -> Result<Option<DMat4>, Diagnostic> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        if n.tag != "transform" {
            return Err(n.diag(format!("expected <transform name=\"{name}\">")));
        }
        parse_transform(n).map(Some)
    }

    /// A colour: `<rgb>`, a constant `<spectrum>` or a `<float>`. Tabulated and file
    /// spectra, blackbodies and textures are unsupported input, reported as the error
    /// returned in `Err(Unsupported)` so the caller can warn and fall back to the
    /// default it documents.
    pub fn colour(&self, name: &str) -> Result<Option<ColourValue>, ColourError> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        let bad = |m: String| ColourError::Bad(n.diag(m));
        match n.tag.as_str() {
            "float" | "rgb" | "spectrum" => {
                if n.tag == "spectrum" && n.attr("filename").is_some() {
                    return Err(ColourError::Unsupported(n.diag(
                        "spectra read from a file are not supported by heron's import yet",
                    )));
                }
                let v = n
                    .attr("value")
                    .ok_or_else(|| bad("expected the attribute value".into()))?;
                if n.tag == "spectrum" && v.contains(':') {
                    return Err(ColourError::Unsupported(n.diag(
                        "tabulated spectra (wavelength:value pairs) are not supported by heron's import yet",
                    )));
                }
                match numbers(v).as_deref() {
                    Some([g]) if *g >= 0.0 => Ok(Some(ColourValue::Grey(*g))),
                    Some([r, g, b]) if n.tag == "rgb" && r.min(*g).min(*b) >= 0.0 => {
                        Ok(Some(ColourValue::Rgb([*r, *g, *b])))
                    }
                    _ => Err(bad(format!(
                        "value: expected {} finite numbers ≥ 0, got {v:?}",
                        if n.tag == "rgb" {
                            "one or three"
                        } else {
                            "one"
                        }
                    ))),
                }
            }
            "texture" | "ref" => Err(ColourError::Unsupported(
                n.diag("textures are not supported by heron's import yet"),
            )),
            "blackbody" => Err(ColourError::Unsupported(
                n.diag("blackbody spectra are not supported by heron's import yet"),
            )),
            _ => Err(bad(format!("expected <rgb name=\"{name}\" value=\"…\"/>"))),
        }
    }

    /// The children nobody read, as warnings: each is a parameter heron ignores.
    pub fn unread(&self) -> Vec<Diagnostic> {
        self.node
            .children
            .iter()
            .zip(&self.used)
            .filter(|(_, u)| !u.get())
            .map(|(c, _)| {
                let what = if VALUE_TAGS.contains(&c.tag.as_str()) {
                    format!("parameter {:?}", c.attr("name").unwrap_or("?"))
                } else {
                    "nested element".to_string()
                };
                c.diag(format!(
                    "{what} of {} is not supported by heron, ignored",
                    self.node.describe()
                ))
            })
            .collect()
    }
}

/// A colour that could not be read: malformed (always an error), or well formed but
/// beyond what heron imports (a warning, or an error under `--strict`).
#[derive(Debug)]
pub enum ColourError {
    Bad(Diagnostic),
    Unsupported(Diagnostic),
}
