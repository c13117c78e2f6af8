//! Colours: a number (grey), `[r, g, b]` in linear sRGB, a named spectrum, a blackbody
//! or a table of samples, as read from a scene file, and their conversion to spectra
//! (reflectances uplifted to bounded spectra, emissions to unbounded ones). As the other
//! leaves (`leaves.rs`), a colour keeps its numbers as written and is read in f32.
use super::leaves::{finite_f32, number, one_key, raw};
use super::show::show;
use super::*;
use serde::ser::{Serialize, SerializeMap, Serializer};

/// A colour as written in a file, before it is known whether it is a reflectance or an
/// emission.
#[derive(Clone, Debug, PartialEq)]
pub enum Colour {
    Grey(f64),
    Rgb([f64; 3]),
    /// One of [`NAMED_SPECTRA`] times `scale`.
    Named {
        spectrum: String,
        scale: f64,
    },
    /// Planck's law at `kelvin` scaled to luminance Y = 1, times `scale`
    /// (`{ blackbody = 5000 }`; emissions only).
    Blackbody {
        kelvin: f64,
        scale: f64,
    },
    /// A tabulated spectrum, (wavelength nm, value) pairs with increasing wavelengths,
    /// linear between them and held at the end values beyond them, times `scale`
    /// (`{ samples = [[400, 0.1], [700, 0.8]] }`).
    Samples {
        samples: Vec<(f64, f64)>,
        scale: f64,
    },
}

/// A colour that is a reflectance: every RGB component in [0, 1], or a named spectrum
/// whose maximum times `scale` is at most 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Reflectance(pub Colour);

/// A colour that is an emission: every RGB component ≥ 0, or a named spectrum with
/// `scale` ≥ 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Emission(pub Colour);

impl Colour {
    /// The colour's RGB components if it is given as RGB (grey is `[g, g, g]`).
    pub fn rgb(&self) -> Option<[f32; 3]> {
        match *self {
            Colour::Grey(g) => Some([g as f32; 3]),
            Colour::Rgb(c) => Some(c.map(|x| x as f32)),
            Colour::Named { .. } | Colour::Blackbody { .. } | Colour::Samples { .. } => None,
        }
    }

    /// The spectrum times its scale, for the colours given as spectra (a named spectrum's
    /// name was checked on load, so it exists).
    fn named_spectrum(&self) -> Option<DenseSpectrum> {
        match self {
            Colour::Named { spectrum, scale } => named(spectrum).map(|s| s.scaled(*scale as f32)),
            Colour::Blackbody { kelvin, scale } => Some(
                crate::spectrum::blackbody::blackbody_unit(*kelvin as f32 as f64)
                    .scaled(*scale as f32),
            ),
            Colour::Samples { samples, scale } => {
                Some(DenseSpectrum::from_samples(&samples_f32(samples)).scaled(*scale as f32))
            }
            _ => None,
        }
    }

    /// The colour as a scene file writes it (for messages), its numbers in f32.
    pub fn describe(&self) -> String {
        match self {
            Colour::Grey(x) => format!("{}", *x as f32),
            Colour::Rgb(c) => format!("[{}, {}, {}]", c[0] as f32, c[1] as f32, c[2] as f32),
            Colour::Named { spectrum, scale } => {
                format!("{{ spectrum = {spectrum:?}, scale = {} }}", *scale as f32)
            }
            Colour::Blackbody { kelvin, scale } => {
                format!(
                    "{{ blackbody = {}, scale = {} }}",
                    *kelvin as f32, *scale as f32
                )
            }
            Colour::Samples { samples, scale } => {
                format!(
                    "{{ samples = ({} pairs), scale = {} }}",
                    samples.len(),
                    *scale as f32
                )
            }
        }
    }

    /// Largest value the colour reaches: its largest RGB component, or the maximum of the
    /// named spectrum over wavelength.
    pub fn max_value(&self) -> f32 {
        match self.rgb() {
            Some([r, g, b]) => r.max(g).max(b),
            None => self.named_spectrum().map_or(0.0, |s| s.max_value()),
        }
    }
}

impl Reflectance {
    /// Spectral reflectance: a single number g is the neutral reflectance, exactly g at
    /// every wavelength; `[r, g, b]` is uplifted after Jakob & Hanika (2019)
    /// (`rgb_to_reflectance`; `[g, g, g]` comes out as the constant spectrum g, within
    /// 1e-6); a named spectrum is itself times its scale.
    pub fn spectrum(&self) -> DenseSpectrum {
        match &self.0 {
            Colour::Grey(g) => DenseSpectrum::constant(*g as f32),
            Colour::Rgb(rgb) => rgb_to_reflectance(rgb.map(|x| x as f32)),
            Colour::Named { .. } | Colour::Blackbody { .. } | Colour::Samples { .. } => self
                .0
                .named_spectrum()
                .unwrap_or_else(|| DenseSpectrum::constant(0.0)),
        }
    }
}

impl Emission {
    /// Emission spectrum: a single number g is g times the sRGB white point, D65 scaled
    /// to luminance Y = 1 (exactly, as `rgb_to_illuminant([g, g, g])` gives it too: its
    /// grey uplifts to the constant 1); `[r, g, b]` is uplifted with `rgb_to_illuminant`;
    /// a named spectrum is itself times its scale.
    pub fn spectrum(&self) -> DenseSpectrum {
        match &self.0 {
            Colour::Grey(g) => {
                let g = *g as f32;
                named("D65").map_or_else(|| rgb_to_illuminant([g; 3]), |d65| d65.scaled(g))
            }
            Colour::Rgb(rgb) => rgb_to_illuminant(rgb.map(|x| x as f32)),
            Colour::Named { .. } | Colour::Blackbody { .. } | Colour::Samples { .. } => self
                .0
                .named_spectrum()
                .unwrap_or_else(|| DenseSpectrum::constant(0.0)),
        }
    }
}

impl Colour {
    /// A conductor's n or k over wavelength ([`MetalSpec::Curves`]): a number is
    /// constant, `[r, g, b]` is uplifted unbounded (`rgb_to_unbounded`, as pbrt-v4 and
    /// Mitsuba's RGB variants mean an RGB index: a value per colour channel), samples are
    /// themselves times their scale.
    pub fn index_spectrum(&self) -> DenseSpectrum {
        match self {
            Colour::Grey(g) => DenseSpectrum::constant(*g as f32),
            Colour::Rgb(rgb) => crate::spectrum::uplift::rgb_to_unbounded(rgb.map(|x| x as f32)),
            _ => self
                .named_spectrum()
                .unwrap_or_else(|| DenseSpectrum::constant(0.0)),
        }
    }
}

/// Reads one of a conductor's n (`real_part`) or k as a number, `[r, g, b]` or
/// `{ samples = ... }`: n must be > 0 at every wavelength, k ≥ 0.
pub(super) fn index_curve(v: &toml::Value, real_part: bool) -> Result<Colour, String> {
    let c = colour(v).map_err(|_| {
        format!(
            "expected a number, [r, g, b] or {{ samples = [[nm, value], ...], scale = number }}, got {}",
            show(v)
        )
    })?;
    if matches!(c, Colour::Named { .. } | Colour::Blackbody { .. }) {
        return Err(format!(
            "expected a number, [r, g, b] or {{ samples = ... }} (an index is not an illuminant), got {}",
            show(v)
        ));
    }
    c.check_index(real_part)
        .map_err(|e| format!("{e}, got {}", show(v)))?;
    Ok(c)
}

impl Colour {
    /// An index curve's range: n > 0 at every wavelength (`real_part`), k ≥ 0, finite.
    pub fn check_index(&self, real_part: bool) -> Result<(), String> {
        if let Colour::Rgb(c) = self {
            if c.iter().any(|x| !(*x >= 0.0)) {
                return Err("expected [r, g, b] components >= 0".into());
            }
        }
        let s = self.index_spectrum();
        let (lo, hi) = (s.min_value(), s.max_value());
        if !hi.is_finite() || (real_part && !(lo > 0.0)) || (!real_part && !(lo >= 0.0)) {
            let want = if real_part { "> 0" } else { ">= 0" };
            return Err(format!(
                "expected finite values {want} at every wavelength (the spectrum reaches {lo})"
            ));
        }
        Ok(())
    }
}

pub(super) const COLOUR_FORMS: &str =
    "a colour: a number, [r, g, b], { spectrum = \"E\" | \"D65\" | \"A\", scale = number }, { blackbody = kelvin, scale = number } or { samples = [[nm, value], ...], scale = number }";

/// The (wavelength, value) pairs in f32.
fn samples_f32(samples: &[(f64, f64)]) -> Vec<(f32, f32)> {
    samples.iter().map(|&(l, x)| (l as f32, x as f32)).collect()
}

/// `samples = [[nm, value], ...]`: at least two pairs of finite numbers, wavelengths
/// strictly increasing, values ≥ 0 (in f32; kept as written).
pub(super) fn spectral_samples(v: &toml::Value) -> Result<Vec<(f64, f64)>, String> {
    let bad = || {
        format!(
            "expected samples = [[wavelength_nm, value], ...] (at least two pairs of finite numbers, values >= 0), got {}",
            show(v)
        )
    };
    let toml::Value::Array(rows) = v else {
        return Err(bad());
    };
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(rows.len());
    for r in rows {
        match r {
            toml::Value::Array(p) if p.len() == 2 => {
                let (l, x) = (
                    finite_f32(&p[0]).ok_or_else(bad)?,
                    finite_f32(&p[1]).ok_or_else(bad)?,
                );
                if x < 0.0 {
                    return Err(bad());
                }
                if let Some(&(prev, _)) = out.last() {
                    let prev = prev as f32;
                    if !(l > prev) {
                        return Err(format!(
                            "expected samples with strictly increasing wavelengths, got {l} nm after {prev} nm"
                        ));
                    }
                }
                // Both are numbers: finite_f32 read them.
                out.push((number(&p[0]).unwrap_or(0.0), number(&p[1]).unwrap_or(0.0)));
            }
            _ => return Err(bad()),
        }
    }
    if out.len() < 2 {
        return Err(bad());
    }
    Ok(out)
}

/// Reads the shape of a colour; ranges are checked by [`Reflectance`] and [`Emission`].
pub(super) fn colour(v: &toml::Value) -> Result<Colour, String> {
    let shape_err = || format!("expected {COLOUR_FORMS}, got {}", show(v));
    let comp = |x: &toml::Value| {
        number(x)
            .filter(|x| (*x as f32).is_finite())
            .ok_or_else(|| format!("expected a colour with finite components, got {}", show(v)))
    };
    match v {
        toml::Value::Integer(_) | toml::Value::Float(_) => Ok(Colour::Grey(comp(v)?)),
        toml::Value::Array(a) if a.len() == 3 => {
            if a.iter().any(|x| number(x).is_none()) {
                return Err(shape_err());
            }
            Ok(Colour::Rgb([comp(&a[0])?, comp(&a[1])?, comp(&a[2])?]))
        }
        toml::Value::Table(t) => {
            let scale = match t.get("scale") {
                None => 1.0,
                Some(s) => number(s)
                    .filter(|x| (*x as f32).is_finite())
                    .ok_or_else(|| format!("expected scale = a finite number, got {}", show(s)))?,
            };
            let kind = ["spectrum", "blackbody", "samples"]
                .into_iter()
                .filter(|k| t.contains_key(*k))
                .collect::<Vec<_>>();
            let kind = match kind.as_slice() {
                [k] => *k,
                [] => {
                    return Err(format!(
                        "{}; none of the keys spectrum, blackbody, samples is given",
                        shape_err()
                    ))
                }
                _ => {
                    return Err(format!(
                        "expected one of the keys spectrum, blackbody, samples in a colour, got {}",
                        kind.join(" and ")
                    ))
                }
            };
            for k in t.keys() {
                if k != kind && k != "scale" {
                    return Err(format!(
                        "unknown key {k:?} in a {kind} colour (expected one of {kind}, scale)"
                    ));
                }
            }
            match kind {
                "blackbody" => {
                    let (lo, hi) = crate::spectrum::blackbody::KELVIN_RANGE;
                    let k = number(&t["blackbody"])
                        .filter(|k| (lo..=hi).contains(k))
                        .ok_or_else(|| {
                            format!(
                                "expected blackbody = a temperature in kelvin within [{lo}, {hi}], got {}",
                                show(&t["blackbody"])
                            )
                        })?;
                    Ok(Colour::Blackbody { kelvin: k, scale })
                }
                "samples" => Ok(Colour::Samples {
                    samples: spectral_samples(&t["samples"])?,
                    scale,
                }),
                _ => {
                    let name = match &t["spectrum"] {
                        toml::Value::String(s) => s.clone(),
                        other => {
                            return Err(format!(
                                "expected spectrum = one of {}, got {}",
                                NAMED_SPECTRA.join(", "),
                                show(other)
                            ))
                        }
                    };
                    if named(&name).is_none() {
                        return Err(format!(
                            "unknown spectrum {name:?}, expected one of {}",
                            NAMED_SPECTRA.join(", ")
                        ));
                    }
                    Ok(Colour::Named {
                        spectrum: name,
                        scale,
                    })
                }
            }
        }
        _ => Err(shape_err()),
    }
}

impl<'de> Deserialize<'de> for Reflectance {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        let c = colour(&v).map_err(D::Error::custom)?;
        if let Colour::Blackbody { .. } = c {
            return Err(D::Error::custom(format!(
                "expected a reflectance, got {}: a blackbody is an emission spectrum",
                show(&v)
            )));
        }
        let ok = match &c {
            Colour::Named { scale, .. } | Colour::Samples { scale, .. } => {
                *scale as f32 >= 0.0 && c.max_value() <= 1.0
            }
            _ => c
                .rgb()
                .is_some_and(|x| x.iter().all(|&x| (0.0..=1.0).contains(&x))),
        };
        if ok {
            Ok(Reflectance(c))
        } else if matches!(c, Colour::Named { .. } | Colour::Samples { .. }) {
            Err(D::Error::custom(format!(
                "expected a reflectance in [0, 1] at every wavelength, got {}, whose maximum is {}",
                c.describe(),
                c.max_value()
            )))
        } else {
            Err(D::Error::custom(format!(
                "expected a reflectance with every component in [0, 1], got {}",
                show(&v)
            )))
        }
    }
}

impl<'de> Deserialize<'de> for Emission {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        let c = colour(&v).map_err(D::Error::custom)?;
        let ok = match &c {
            Colour::Named { scale, .. }
            | Colour::Blackbody { scale, .. }
            | Colour::Samples { scale, .. } => *scale as f32 >= 0.0,
            _ => c.rgb().is_some_and(|x| x.iter().all(|&x| x >= 0.0)),
        };
        if !ok {
            return Err(D::Error::custom(format!(
                "expected an emission with every component (or the scale) >= 0, got {}",
                show(&v)
            )));
        }
        // Near f32's largest number, the spectrum (the colour times D65 at Y = 1, or
        // the named spectrum times the scale) overflows.
        let e = Emission(c);
        let s = e.spectrum();
        if let Some(i) = s.values().iter().position(|x| !x.is_finite()) {
            return Err(D::Error::custom(format!(
                "expected an emission whose spectrum is finite in f32, got {}, which overflows at {} nm",
                show(&v),
                crate::spectrum::LAMBDA_MIN + i as f32
            )));
        }
        Ok(e)
    }
}

/// `{ key = value }`, with `scale` unless it is 1 (the default).
fn scaled_table<S: Serializer, T: Serialize + ?Sized>(
    s: S,
    key: &str,
    value: &T,
    scale: f64,
) -> Result<S::Ok, S::Error> {
    if scale == 1.0 {
        return one_key(s, key, value);
    }
    let mut m = s.serialize_map(Some(2))?;
    m.serialize_entry(key, value)?;
    m.serialize_entry("scale", &scale)?;
    m.end()
}

impl Serialize for Colour {
    /// The colour in the form [`colour`] reads it.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Colour::Grey(g) => s.serialize_f64(*g),
            Colour::Rgb(c) => c.serialize(s),
            Colour::Named { spectrum, scale } => scaled_table(s, "spectrum", spectrum, *scale),
            Colour::Blackbody { kelvin, scale } => scaled_table(s, "blackbody", kelvin, *scale),
            Colour::Samples { samples, scale } => scaled_table(s, "samples", samples, *scale),
        }
    }
}

impl Serialize for Reflectance {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

impl Serialize for Emission {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}
