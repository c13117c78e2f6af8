//! The pixel reconstruction filter a render asks for (`[render] filter`, `--filter`):
//! its name and parameters only. The filters themselves (their profiles and how camera
//! samples are drawn from them) are in `camera::filter`.

/// A pixel reconstruction filter: every filter is separable, f(x, y) = h(x) h(y) with x,
/// y in pixels from the pixel's centre, and zero beyond `radius` on either axis. The
/// defaults are pbrt-v4's (`filters.cpp`, `*Filter::Create`): box 0.5, tent 2, Gaussian
/// radius 1.5 and σ 0.5, Mitchell radius 2 and B = C = 1/3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelFilter {
    /// h(x) = 1 on [−r, r]; r = 0.5 is the uniform jitter over the pixel.
    Box { radius: f32 },
    /// h(x) = max(0, 1 − |x|/r) (pbrt-v4's `triangle`, Mitsuba 3's `tent`).
    Tent { radius: f32 },
    /// h(x) = max(0, g(x) − g(r)) with g(x) = exp(−x²/2σ²): the Gaussian less its value
    /// at the radius, so that it reaches zero there (pbrt-v4 and Mitsuba 3 alike).
    Gaussian { radius: f32, stddev: f32 },
    /// Mitchell & Netravali (1988) cubic with parameters B and C, its [−2, 2] support
    /// scaled to [−r, r] (pbrt-v4's `MitchellFilter`); B = 0, C = 1/2 is Catmull–Rom.
    Mitchell { radius: f32, b: f32, c: f32 },
}

impl Default for PixelFilter {
    fn default() -> Self {
        PixelFilter::BOX
    }
}

/// The largest filter radius accepted, in pixels (wider filters are blur, not
/// reconstruction).
pub const MAX_FILTER_RADIUS: f64 = 16.0;

/// A filter's parameters as given (scene keys or the flag's `name=value` list), each
/// `None` when absent.
#[derive(Clone, Copy, Debug, Default)]
pub struct FilterParams {
    pub radius: Option<f64>,
    pub stddev: Option<f64>,
    pub b: Option<f64>,
    pub c: Option<f64>,
}

impl PixelFilter {
    /// The default: a box of radius 0.5, the camera sample uniform over its pixel.
    pub const BOX: PixelFilter = PixelFilter::Box { radius: 0.5 };
    /// The names `filter` accepts (`triangle` is read as `tent`).
    pub const NAMES: &'static str = "box, tent (or triangle), gaussian or mitchell";

    pub fn name(&self) -> &'static str {
        match self {
            PixelFilter::Box { .. } => "box",
            PixelFilter::Tent { .. } => "tent",
            PixelFilter::Gaussian { .. } => "gaussian",
            PixelFilter::Mitchell { .. } => "mitchell",
        }
    }

    /// The radius in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            PixelFilter::Box { radius }
            | PixelFilter::Tent { radius }
            | PixelFilter::Gaussian { radius, .. }
            | PixelFilter::Mitchell { radius, .. } => radius,
        }
    }

    /// Whether this is the default box (camera samples uniform over their pixel).
    pub fn is_default(&self) -> bool {
        *self == PixelFilter::BOX
    }

    /// The filter as the EXR provenance records it (`heron.filter`), e.g. `gaussian
    /// radius=1.5 stddev=0.5`; also the flag's syntax with spaces for commas.
    pub fn describe(&self) -> String {
        match *self {
            PixelFilter::Box { radius } | PixelFilter::Tent { radius } => {
                format!("{} radius={radius}", self.name())
            }
            PixelFilter::Gaussian { radius, stddev } => {
                format!("gaussian radius={radius} stddev={stddev}")
            }
            PixelFilter::Mitchell { radius, b, c } => {
                format!("mitchell radius={radius} b={b} c={c}")
            }
        }
    }

    /// The filter `name` with parameters `p`; an error names the bad part through
    /// `key` (given "" for the name itself, else "radius", "stddev", "b" or "c").
    pub fn from_parts(
        name: &str,
        p: FilterParams,
        key: &dyn Fn(&str) -> String,
    ) -> Result<PixelFilter, String> {
        let radius = |default: f64| -> Result<f32, String> {
            match p.radius {
                None => Ok(default as f32),
                Some(r) if r > 0.0 && r <= MAX_FILTER_RADIUS => Ok(r as f32),
                Some(r) => Err(format!(
                    "{}: expected a radius in pixels in (0, {MAX_FILTER_RADIUS}], got {r}",
                    key("radius")
                )),
            }
        };
        let unused = |what: &str, v: Option<f64>| -> Result<(), String> {
            match v {
                Some(_) => Err(format!(
                    "{}: applies to filter = \"{}\" only, not {name:?}",
                    key(what),
                    if what == "stddev" {
                        "gaussian"
                    } else {
                        "mitchell"
                    }
                )),
                None => Ok(()),
            }
        };
        let finite = |what: &str, v: Option<f64>, default: f64| -> Result<f32, String> {
            match v {
                None => Ok(default as f32),
                Some(x) if x.is_finite() && x.abs() <= 1e3 => Ok(x as f32),
                Some(x) => Err(format!("{}: expected a finite number, got {x}", key(what))),
            }
        };
        match name {
            "box" | "tent" | "triangle" => {
                unused("stddev", p.stddev)?;
                unused("b", p.b)?;
                unused("c", p.c)?;
                Ok(if name == "box" {
                    PixelFilter::Box {
                        radius: radius(0.5)?,
                    }
                } else {
                    PixelFilter::Tent {
                        radius: radius(2.0)?,
                    }
                })
            }
            "gaussian" => {
                unused("b", p.b)?;
                unused("c", p.c)?;
                let stddev = match p.stddev {
                    None => 0.5,
                    Some(s) if s > 0.0 && s <= MAX_FILTER_RADIUS => s,
                    Some(s) => Err(format!(
                        "{}: expected a standard deviation in pixels in (0, {MAX_FILTER_RADIUS}], got {s}",
                        key("stddev")
                    ))?,
                };
                // Without a radius, three standard deviations (pbrt-v4's 1.5 for σ = 0.5).
                let radius = radius((3.0 * stddev).min(MAX_FILTER_RADIUS))?;
                Ok(PixelFilter::Gaussian {
                    radius,
                    stddev: stddev as f32,
                })
            }
            "mitchell" => {
                unused("stddev", p.stddev)?;
                Ok(PixelFilter::Mitchell {
                    radius: radius(2.0)?,
                    b: finite("b", p.b, 1.0 / 3.0)?,
                    c: finite("c", p.c, 1.0 / 3.0)?,
                })
            }
            other => Err(format!(
                "{}: expected {}, got {other:?}",
                key(""),
                PixelFilter::NAMES
            )),
        }
    }

    /// The flag's value: a name, optionally followed by `:` and comma-separated
    /// `radius=`, `stddev=`, `b=`, `c=` (e.g. `gaussian:radius=2,stddev=0.5`).
    pub fn parse(s: &str) -> Result<PixelFilter, String> {
        let (name, rest) = s.split_once(':').unwrap_or((s, ""));
        let mut p = FilterParams::default();
        for item in rest.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let Some((k, v)) = item.split_once('=') else {
                return Err(format!(
                    "expected name=value after the filter's name, got {item:?}"
                ));
            };
            let v: f64 = v
                .trim()
                .parse()
                .map_err(|_| format!("{}: expected a number, got {v:?}", k.trim()))?;
            let slot = match k.trim() {
                "radius" => &mut p.radius,
                "stddev" => &mut p.stddev,
                "b" | "B" => &mut p.b,
                "c" | "C" => &mut p.c,
                other => {
                    return Err(format!(
                        "unknown filter parameter {other:?} (expected radius, stddev, b or c)"
                    ))
                }
            };
            *slot = Some(v);
        }
        PixelFilter::from_parts(name.trim(), p, &|k| {
            if k.is_empty() {
                "the filter".to_string()
            } else {
                k.to_string()
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_names_defaults_and_errors() {
        assert_eq!(PixelFilter::parse("box").unwrap(), PixelFilter::BOX);
        assert_eq!(
            PixelFilter::parse("gaussian").unwrap(),
            PixelFilter::Gaussian {
                radius: 1.5,
                stddev: 0.5
            }
        );
        assert_eq!(
            PixelFilter::parse("triangle:radius=1").unwrap(),
            PixelFilter::Tent { radius: 1.0 }
        );
        assert_eq!(
            PixelFilter::parse("mitchell:b=0,c=0.5").unwrap(),
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 0.0,
                c: 0.5
            }
        );
        for (bad, says) in [
            ("lanczos", "expected box, tent"),
            ("box:stddev=1", "applies to filter = \"gaussian\" only"),
            ("gaussian:radius=0", "expected a radius in pixels"),
            ("gaussian:radius", "expected name=value"),
            ("gaussian:sigma=1", "unknown filter parameter"),
        ] {
            let e = PixelFilter::parse(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }
}
