//! The schema's leaf types: each is read as a raw TOML value and checked, so that its
//! error message is ours ("expected …, got …") and sits at the key path of the value.
//!
//! A leaf keeps its numbers as the file wrote them (TOML's f64) and checks them in f32,
//! the precision heron renders in; `get` gives the f32 value. Kept as written, a value
//! is written back unchanged: the importers (`super::super::import`) build these types
//! from their f64 arithmetic, and `heron convert` writes the digits they computed.
use super::show::show;
use super::*;
use glam::DVec3;
use serde::ser::{Serialize, SerializeMap, Serializer};

/// A refractive index: a positive number (no dispersion), the name of a catalogue entry
/// (spectra/ior_catalogue.toml), or one of `{ sellmeier = { b = [..], c = [..] } }`
/// (λ in µm, C in µm²), `{ cauchy = [A, B] }` or `{ cauchy = [A, B, C] }` (λ in µm),
/// `{ table = "file.csv" }` (rows `wavelength_nm,n`, relative to the scene file), or
/// `{ n_d = .., v_d = .. }` (a glass known by its index and Abbe number:
/// [`crate::spectrum::ior::Ior::abbe`]).
/// The numbers are kept as written (f64) and read in f32 by the loader.
#[derive(Clone, Debug, PartialEq)]
pub enum IorSpec {
    Constant(f64),
    Named(String),
    Sellmeier { b: Vec<f64>, c: Vec<f64> },
    Cauchy([f64; 3]),
    Table(String),
    Abbe { n_d: f64, v_d: f64 },
}

/// `[x, y]`, two numbers finite in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point2(pub [f64; 2]);

impl Point2 {
    /// The point in f32.
    pub fn get(&self) -> [f32; 2] {
        self.0.map(|x| x as f32)
    }
}

/// `[x, y, z]`, three numbers finite in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point3(pub DVec3);

impl Point3 {
    /// The point in f32.
    pub fn get(&self) -> Vec3 {
        self.0.as_vec3()
    }
}

/// `[x, y, z]`, finite and not the zero vector in f32 (not normalised).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction3(pub DVec3);

impl Direction3 {
    /// The vector in f32.
    pub fn get(&self) -> Vec3 {
        self.0.as_vec3()
    }

    /// The unit vector, computed without overflow or underflow for any finite non-zero
    /// vector (scaled by its largest component first).
    pub fn unit(&self) -> Vec3 {
        let v = self.get();
        (v / v.abs().max_element()).normalize()
    }
}

/// A number > 0, finite in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositiveNumber(pub f64);

impl PositiveNumber {
    /// The number in f32.
    pub fn get(&self) -> f32 {
        self.0 as f32
    }
}

/// A number in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitNumber(pub f64);

impl UnitNumber {
    /// The number in f32.
    pub fn get(&self) -> f32 {
        self.0 as f32
    }
}

/// An integer ≥ 1 that fits in u32.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PositiveCount(pub u32);

/// `[width, height]`, each in 1..=[`MAX_RESOLUTION`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution {
    pub width: u32,
    pub height: u32,
}

/// A TOML number (integer or float) as f64.
pub(super) fn number(v: &toml::Value) -> Option<f64> {
    match *v {
        toml::Value::Integer(i) => Some(i as f64),
        toml::Value::Float(f) => Some(f),
        _ => None,
    }
}

/// A number that is finite in f32 (TOML allows nan and inf, and a finite f64 may
/// overflow f32).
pub(super) fn finite_f32(v: &toml::Value) -> Option<f32> {
    number(v).map(|x| x as f32).filter(|x| x.is_finite())
}

/// A number as written whose f32 value is finite.
pub(super) fn finite_in_f32(v: &toml::Value) -> Option<f64> {
    number(v).filter(|x| (*x as f32).is_finite())
}

pub(super) fn vec3(v: &toml::Value) -> Option<DVec3> {
    match v {
        toml::Value::Array(a) if a.len() == 3 => {
            let x = finite_in_f32(&a[0])?;
            let y = finite_in_f32(&a[1])?;
            let z = finite_in_f32(&a[2])?;
            Some(DVec3::new(x, y, z))
        }
        _ => None,
    }
}

pub(super) fn raw<'de, D: Deserializer<'de>>(d: D) -> Result<toml::Value, D::Error> {
    toml::Value::deserialize(d)
}

impl<'de> Deserialize<'de> for Point2 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        let xy = match &v {
            toml::Value::Array(a) if a.len() == 2 => {
                finite_in_f32(&a[0]).and_then(|x| Some([x, finite_in_f32(&a[1])?]))
            }
            _ => None,
        };
        xy.map(Point2).ok_or_else(|| {
            D::Error::custom(format!(
                "expected [x, y] with two finite numbers, got {}",
                show(&v)
            ))
        })
    }
}

impl<'de> Deserialize<'de> for Point3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        vec3(&v).map(Point3).ok_or_else(|| {
            D::Error::custom(format!(
                "expected [x, y, z] with three finite numbers, got {}",
                show(&v)
            ))
        })
    }
}

impl<'de> Deserialize<'de> for Direction3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        match vec3(&v) {
            Some(p) if p.as_vec3().abs().max_element() > 0.0 => Ok(Direction3(p)),
            _ => Err(D::Error::custom(format!(
                "expected a non-zero vector [x, y, z] of finite numbers, got {}",
                show(&v)
            ))),
        }
    }
}

impl<'de> Deserialize<'de> for PositiveNumber {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        match finite_in_f32(&v) {
            Some(x) if x as f32 > 0.0 => Ok(PositiveNumber(x)),
            _ => Err(D::Error::custom(format!(
                "expected a positive finite number, got {}",
                show(&v)
            ))),
        }
    }
}

pub(super) fn finite_list(v: &toml::Value) -> Option<Vec<f64>> {
    match v {
        toml::Value::Array(a) => a.iter().map(finite_in_f32).collect(),
        _ => None,
    }
}

impl<'de> Deserialize<'de> for IorSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        let names = || {
            crate::spectrum::ior::catalogue()
                .keys()
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        };
        let expected = || {
            format!(
                "expected a positive number, a catalogue name ({}), {{ sellmeier = {{ b = [..], c = [..] }} }}, {{ cauchy = [A, B, C] }}, {{ n_d = .., v_d = .. }} or {{ table = \"file.csv\" }}, got {}",
                names(),
                show(&v)
            )
        };
        match &v {
            toml::Value::String(name) => {
                if crate::spectrum::ior::named(name).is_some() {
                    Ok(IorSpec::Named(name.clone()))
                } else {
                    Err(D::Error::custom(format!(
                        "unknown refractive-index model {name:?}, expected one of {}",
                        names()
                    )))
                }
            }
            toml::Value::Table(t) if t.contains_key("n_d") || t.contains_key("v_d") => {
                let n_d = t.get("n_d").and_then(finite_in_f32);
                let v_d = t.get("v_d").and_then(finite_in_f32);
                match (n_d, v_d) {
                    (Some(n_d), Some(v_d))
                        if t.len() == 2 && n_d as f32 >= 1.0 && v_d as f32 > 0.0 =>
                    {
                        Ok(IorSpec::Abbe { n_d, v_d })
                    }
                    _ => Err(D::Error::custom(format!(
                        "expected {{ n_d = .., v_d = .. }} with an index n_d ≥ 1 at 587.56 nm and an Abbe number v_d > 0, got {}",
                        show(&v)
                    ))),
                }
            }
            toml::Value::Table(t) if t.len() == 1 => {
                let (k, x) = t.iter().next().expect("one entry");
                match (k.as_str(), x) {
                    ("sellmeier", toml::Value::Table(sc)) => {
                        let b = sc.get("b").and_then(finite_list);
                        let c = sc.get("c").and_then(finite_list);
                        match (b, c) {
                            (Some(b), Some(c))
                                if sc.len() == 2 && b.len() == c.len() && (1..=4).contains(&b.len()) =>
                            {
                                Ok(IorSpec::Sellmeier { b, c })
                            }
                            _ => Err(D::Error::custom(format!(
                                "expected sellmeier = {{ b = [B1, ..], c = [C1, ..] }} with 1 to 4 finite coefficients each (C in µm²), got {}",
                                show(x)
                            ))),
                        }
                    }
                    ("cauchy", x) => match finite_list(x) {
                        Some(c) if (2..=3).contains(&c.len()) => Ok(IorSpec::Cauchy([
                            c[0],
                            c[1],
                            c.get(2).copied().unwrap_or(0.0),
                        ])),
                        _ => Err(D::Error::custom(format!(
                            "expected cauchy = [A, B] or [A, B, C] (λ in µm), got {}",
                            show(x)
                        ))),
                    },
                    ("table", toml::Value::String(f)) => Ok(IorSpec::Table(f.clone())),
                    _ => Err(D::Error::custom(expected())),
                }
            }
            _ => match (number(&v), finite_in_f32(&v)) {
                (_, Some(x)) if x as f32 > 0.0 => Ok(IorSpec::Constant(x)),
                (Some(_), _) => Err(D::Error::custom(format!(
                    "expected a positive finite number, got {}",
                    show(&v)
                ))),
                _ => Err(D::Error::custom(expected())),
            },
        }
    }
}

impl<'de> Deserialize<'de> for NonNegativeNumber {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        match finite_in_f32(&v) {
            Some(x) if x as f32 >= 0.0 => Ok(NonNegativeNumber(x)),
            _ => Err(D::Error::custom(format!(
                "expected a finite number >= 0, got {}",
                show(&v)
            ))),
        }
    }
}

impl<'de> Deserialize<'de> for UnitNumber {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        match number(&v) {
            Some(x) if (0.0..=1.0).contains(&x) => Ok(UnitNumber(x)),
            _ => Err(D::Error::custom(format!(
                "expected a number in [0, 1], got {}",
                show(&v)
            ))),
        }
    }
}

impl<'de> Deserialize<'de> for PositiveCount {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        match v {
            toml::Value::Integer(i) if i >= 1 && i <= u32::MAX as i64 => {
                Ok(PositiveCount(i as u32))
            }
            _ => Err(D::Error::custom(format!(
                "expected a positive integer, got {}",
                show(&v)
            ))),
        }
    }
}

impl<'de> Deserialize<'de> for Resolution {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        let ok = |x: &toml::Value| match *x {
            toml::Value::Integer(i) if i >= 1 && i <= MAX_RESOLUTION as i64 => Some(i as u32),
            _ => None,
        };
        if let toml::Value::Array(a) = &v {
            if let [w, h] = a.as_slice() {
                if let (Some(width), Some(height)) = (ok(w), ok(h)) {
                    return Ok(Resolution { width, height });
                }
            }
        }
        Err(D::Error::custom(format!(
            "expected [width, height] with positive integers (at most {MAX_RESOLUTION}), got {}",
            show(&v)
        )))
    }
}

// Writing the leaves back: each in the form its reader takes, its numbers as kept.

impl Serialize for Point2 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

impl Serialize for Point3 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.to_array().serialize(s)
    }
}

impl Serialize for Direction3 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.to_array().serialize(s)
    }
}

impl Serialize for PositiveNumber {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.0)
    }
}

impl Serialize for UnitNumber {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.0)
    }
}

impl Serialize for NonNegativeNumber {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.0)
    }
}

impl Serialize for PositiveCount {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u32(self.0)
    }
}

impl Serialize for Resolution {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        [self.width, self.height].serialize(s)
    }
}

/// `{ key = value }`, the one-key tables of the leaves' table forms.
pub(crate) fn one_key<S: Serializer, T: Serialize + ?Sized>(
    s: S,
    key: &str,
    value: &T,
) -> Result<S::Ok, S::Error> {
    let mut m = s.serialize_map(Some(1))?;
    m.serialize_entry(key, value)?;
    m.end()
}

/// `{ a = x, b = y }`, the two-number tables (`n_d`/`v_d`, `n`/`k`).
pub(super) fn two_keys<S: Serializer>(
    s: S,
    a: (&str, f64),
    b: (&str, f64),
) -> Result<S::Ok, S::Error> {
    let mut m = s.serialize_map(Some(2))?;
    m.serialize_entry(a.0, &a.1)?;
    m.serialize_entry(b.0, &b.1)?;
    m.end()
}

impl Serialize for IorSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(serde::Serialize)]
        struct Sellmeier<'a> {
            b: &'a [f64],
            c: &'a [f64],
        }
        match self {
            IorSpec::Constant(x) => s.serialize_f64(*x),
            IorSpec::Named(name) => s.serialize_str(name),
            IorSpec::Sellmeier { b, c } => one_key(s, "sellmeier", &Sellmeier { b, c }),
            IorSpec::Cauchy(abc) => one_key(s, "cauchy", abc),
            IorSpec::Table(file) => one_key(s, "table", file),
            IorSpec::Abbe { n_d, v_d } => two_keys(s, ("n_d", *n_d), ("v_d", *v_d)),
        }
    }
}
