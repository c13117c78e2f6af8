//! The properties of one Mitsuba object (`<float name=…>`, `<rgb name=…>`, nested
//! objects, `<ref>`s), each marked when the converter reads it, so that whatever it did
//! not read can be named in a warning rather than dropped silently.
use super::transform::{numbers, parse_transform, vector_attrs};
use super::xml::{Diagnostic, Node};
use crate::scene::file::{Colour, Emission, Reflectance};
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
    /// Where files are looked for ([`super::xml::find_file`]): the `<path>` folders and
    /// the main scene's folder; without them, the naming file's folder only.
    files: Option<(Vec<std::path::PathBuf>, std::path::PathBuf)>,
}

/// A colour property in the forms of heron's scene files: grey, RGB, a tabulated
/// spectrum, a blackbody or a named illuminant, its numbers in f64 as the converters
/// compute them (scaled, bounded) before the scene's [`Colour`] keeps them.
#[derive(Clone, Debug, PartialEq)]
pub enum ColourValue {
    Grey(f64),
    Rgb([f64; 3]),
    /// (nm, value) pairs, linear between them, and `scale`.
    Samples {
        samples: Vec<(f64, f64)>,
        scale: f64,
    },
    /// heron's unit-luminance blackbody at `kelvin`, times `scale`.
    Blackbody {
        kelvin: f64,
        scale: f64,
    },
    /// One of heron's named spectra (`crate::spectrum::uplift::NAMED_SPECTRA`) times
    /// `scale`.
    Named {
        spectrum: &'static str,
        scale: f64,
    },
}

impl ColourValue {
    /// The scene file's colour.
    pub fn colour(&self) -> Colour {
        match self {
            ColourValue::Grey(g) => Colour::Grey(*g),
            ColourValue::Rgb(c) => Colour::Rgb(*c),
            ColourValue::Samples { samples, scale } => Colour::Samples {
                samples: samples.clone(),
                scale: *scale,
            },
            ColourValue::Blackbody { kelvin, scale } => Colour::Blackbody {
                kelvin: *kelvin,
                scale: *scale,
            },
            ColourValue::Named { spectrum, scale } => Colour::Named {
                spectrum: spectrum.to_string(),
                scale: *scale,
            },
        }
    }

    /// The colour as a reflectance (its range is checked when the scene is read).
    pub fn reflectance(&self) -> Reflectance {
        Reflectance(self.colour())
    }

    /// The colour as an emission (its range is checked when the scene is read).
    pub fn emission(&self) -> Emission {
        Emission(self.colour())
    }

    /// The largest value over channels or wavelengths (for a blackbody or a named
    /// illuminant, its scale: the unit spectrum's own peak is not needed where this is
    /// used, for reflectances, which neither is).
    pub fn max(&self) -> f64 {
        match self {
            ColourValue::Grey(g) => *g,
            ColourValue::Rgb(c) => c[0].max(c[1]).max(c[2]),
            ColourValue::Samples { samples, scale } => {
                scale * samples.iter().fold(0.0f64, |a, (_, v)| a.max(*v))
            }
            ColourValue::Blackbody { scale, .. } | ColourValue::Named { scale, .. } => *scale,
        }
    }

    /// The colour times `k`.
    pub fn scaled(&self, k: f64) -> ColourValue {
        match self {
            ColourValue::Grey(g) => ColourValue::Grey(g * k),
            ColourValue::Rgb(c) => ColourValue::Rgb(c.map(|x| x * k)),
            ColourValue::Samples { samples, scale } => ColourValue::Samples {
                samples: samples.clone(),
                scale: scale * k,
            },
            ColourValue::Blackbody { kelvin, scale } => ColourValue::Blackbody {
                kelvin: *kelvin,
                scale: scale * k,
            },
            ColourValue::Named { spectrum, scale } => ColourValue::Named {
                spectrum,
                scale: scale * k,
            },
        }
    }
}

/// Mitsuba's tabulated spectrum (`value="λ:v, λ:v, …"` or a file's rows) as heron
/// samples: Mitsuba's irregular spectrum is linear between its rows and zero beyond
/// them, heron's holds the end values, so a zero is added 1e-3 nm beyond each end.
pub fn mitsuba_samples(pairs: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(pairs.len() + 2);
    let (first, last) = (pairs[0], pairs[pairs.len() - 1]);
    if first.1 != 0.0 {
        out.push((first.0 - 1e-3, 0.0));
    }
    out.extend_from_slice(pairs);
    if last.1 != 0.0 {
        out.push((last.0 + 1e-3, 0.0));
    }
    out
}

/// A conductor's tabulated n or k as heron uses it: the zeros [`mitsuba_samples`] put
/// beyond a table's ends (Mitsuba's and pbrt-v4's tables are zero there) are taken off,
/// so heron holds the end values, since an index of 0 is no material (it would make a
/// perfect mirror of those wavelengths). Returns the covered range when the table does
/// not span heron's 360–830 nm, for the warning that says so.
pub fn index_samples(c: Colour) -> (Colour, Option<(f64, f64)>) {
    let Colour::Samples { mut samples, scale } = c else {
        return (c, None);
    };
    let added = |a: (f64, f64), b: (f64, f64)| a.1 == 0.0 && (a.0 - b.0).abs() <= 1.001e-3;
    if samples.len() > 2 && added(samples[0], samples[1]) {
        samples.remove(0);
    }
    let n = samples.len();
    if n > 2 && added(samples[n - 1], samples[n - 2]) {
        samples.pop();
    }
    let (lo, hi) = (samples[0].0, samples[samples.len() - 1].0);
    let short = (lo > 360.0 || hi < 830.0).then_some((lo, hi));
    (Colour::Samples { samples, scale }, short)
}

/// `λ:v, λ:v, …` (Mitsuba's inline tabulated spectrum): at least two pairs, wavelengths
/// increasing, values finite and ≥ 0.
fn parse_pairs(text: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for item in text.split(',') {
        let item = item.trim();
        let (l, v) = item
            .split_once(':')
            .ok_or_else(|| format!("expected wavelength:value pairs, got {item:?}"))?;
        let (l, v) = match (l.trim().parse::<f64>(), v.trim().parse::<f64>()) {
            (Ok(l), Ok(v)) if l.is_finite() && v.is_finite() && v >= 0.0 => (l, v),
            _ => {
                return Err(format!(
                    "expected wavelength:value with finite numbers, value ≥ 0, got {item:?}"
                ))
            }
        };
        check_increasing(&out, l)?;
        out.push((l, v));
    }
    if out.len() < 2 {
        return Err("expected at least two wavelength:value pairs".into());
    }
    Ok(out)
}

fn check_increasing(out: &[(f64, f64)], l: f64) -> Result<(), String> {
    match out.last() {
        Some(&(prev, _)) if !(l > prev) => Err(format!(
            "expected increasing wavelengths, got {l} nm after {prev} nm"
        )),
        _ => Ok(()),
    }
}

/// A Mitsuba spectrum file (`.spd`): rows `wavelength value` (spaces or tabs; a comma
/// is accepted too), `#` comments and blank lines skipped. The error names the line.
pub fn read_spd(path: &std::path::Path) -> Result<Vec<(f64, f64)>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read the spectrum file {}: {e}", path.display()))?;
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let nums: Vec<f64> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                format!(
                    "{}: line {}: expected two numbers, got {line:?}",
                    path.display(),
                    i + 1
                )
            })?;
        match nums.as_slice() {
            [l, v] if l.is_finite() && v.is_finite() && *v >= 0.0 => {
                check_increasing(&out, *l)
                    .map_err(|e| format!("{}: line {}: {e}", path.display(), i + 1))?;
                out.push((*l, *v));
            }
            _ => {
                return Err(format!(
                    "{}: line {}: expected a wavelength and a value ≥ 0, got {line:?}",
                    path.display(),
                    i + 1
                ))
            }
        }
    }
    if out.len() < 2 {
        return Err(format!("{}: expected at least two rows", path.display()));
    }
    Ok(out)
}

/// Mitsuba's blackbody (absolute W m⁻² sr⁻¹ nm⁻¹) as heron's unit-luminance one times
/// its luminance.
fn blackbody(n: &Node, kelvin: f64) -> Result<ColourValue, ColourError> {
    let (lo, hi) = crate::spectrum::blackbody::KELVIN_RANGE;
    if !(lo..=hi).contains(&kelvin) {
        return Err(ColourError::Bad(n.diag(format!(
            "temperature: expected kelvin within [{lo}, {hi}], got {kelvin}"
        ))));
    }
    Ok(ColourValue::Blackbody {
        kelvin,
        scale: crate::spectrum::blackbody::blackbody_luminance(kelvin),
    })
}

impl<'a> Props<'a> {
    pub fn new(node: &'a Node) -> Self {
        Props {
            node,
            used: node.children.iter().map(|_| Cell::new(false)).collect(),
            files: None,
        }
    }

    /// These properties with Mitsuba's file lookup: `folders` (the `<path>`s, in
    /// declaration order) and the main scene's folder `main`.
    pub fn with_files(mut self, folders: &[std::path::PathBuf], main: &std::path::Path) -> Self {
        self.files = Some((folders.to_vec(), main.to_path_buf()));
        self
    }

    /// The file `name` names as Mitsuba finds it, `n` the element naming it.
    pub fn find(&self, n: &Node, name: &str) -> std::path::PathBuf {
        let own = n.file.parent().unwrap_or(std::path::Path::new(""));
        match &self.files {
            Some((folders, main)) => super::xml::find_file(name, folders, main, own),
            None => own.join(name),
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

    /// A colour: `<rgb>`, a `<spectrum>` (one value, `λ:v` pairs, a `filename`, or
    /// `type="blackbody"` with its `temperature`), a `<blackbody>` (Mitsuba 0.6's form),
    /// or a `<float>`. Textures are unsupported input, reported as the error returned in
    /// `Err(Unsupported)` so the caller can warn and fall back to the default it
    /// documents.
    pub fn colour(&self, name: &str) -> Result<Option<ColourValue>, ColourError> {
        let Some(n) = self.get(name) else {
            return Ok(None);
        };
        let bad = |m: String| ColourError::Bad(n.diag(m));
        match n.tag.as_str() {
            "spectrum" if n.attr("type") == Some("blackbody") => {
                let t = n
                    .children
                    .iter()
                    .find(|c| c.attr("name") == Some("temperature"))
                    .ok_or_else(|| bad("expected <float name=\"temperature\" value=\"…\"/>".into()))?;
                let v = t.attr("value").unwrap_or("");
                match numbers(v).as_deref() {
                    Some([k]) => blackbody(n, *k).map(Some),
                    _ => Err(bad(format!("temperature: expected a number, got {v:?}"))),
                }
            }
            "blackbody" => {
                let v = n.attr("temperature").unwrap_or("");
                match numbers(v).as_deref() {
                    Some([k]) => blackbody(n, *k).map(Some),
                    _ => Err(bad(format!("temperature: expected a number, got {v:?}"))),
                }
            }
            "spectrum" if n.attr("filename").is_some() => {
                let f = n.attr("filename").unwrap_or("");
                let pairs = read_spd(&self.find(n, f)).map_err(bad)?;
                Ok(Some(ColourValue::Samples {
                    samples: mitsuba_samples(&pairs),
                    scale: 1.0,
                }))
            }
            "spectrum" if n.attr("type").is_some() => Err(ColourError::Unsupported(n.diag(
                "spectrum plugins other than blackbody (and inline or file tables) are not supported by heron's import",
            ))),
            "float" | "rgb" | "spectrum" => {
                let v = n
                    .attr("value")
                    .ok_or_else(|| bad("expected the attribute value".into()))?;
                if n.tag == "spectrum" && v.contains(':') {
                    let pairs = parse_pairs(v).map_err(|e| bad(format!("value: {e}")))?;
                    return Ok(Some(ColourValue::Samples {
                        samples: mitsuba_samples(&pairs),
                        scale: 1.0,
                    }));
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
                n.diag("textures other than a bitmap or checkerboard as a diffuse reflectance are not supported by heron's import yet"),
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
