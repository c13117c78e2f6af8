//! What a halo sky is made of, whoever asks for it: a scene's `[sky] model = "halo"`
//! (its `crystals` tables and `rays`, with the sun light's elevation and radius), `heron
//! halo profile` (its `--crystals` flags) and the Python module. One [`HaloSpec::build`]
//! holds the rules and limits; errors name the key the way the front end gives it
//! ([`HaloKey`]).
//!
//! A population (`CrystalFile`):
//!
//! - `orientation`: random, plates, columns, parry or lowitz
//!   ([`crate::optics::ice::Orientation`]).
//! - `aspect`: c/a, the prism's half-length over the hexagon's semi-diameter, in
//!   [0.02, 50]; default 1 for random crystals, 0.2 for plates and Lowitz plates, 3 for
//!   columns and Parry columns.
//! - `tilt_deg`: the σ of the orientation's Gaussian tilt, in [0°, 90°]; default 1° (10°
//!   for Lowitz, the spread of its rotation about the a-axis); not for random crystals.
//! - `size_um`: the hexagon's semi-diameter a in µm, in [5, 1000] (geometric optics
//!   needs crystals many wavelengths across; the size sets only the diffraction), with
//!   the half-length c = a·(c/a) at most 2000 µm (the tracer neglects ice's absorption,
//!   under 1% over such paths: `crate::optics::ice::trace`); default 50.
//! - `weight`: in a sky, the population's share of the layer's geometric cross-section;
//!   in an ice medium (`crate::medium::ice`), its share of the crystals by number (the
//!   medium's `number_density` counts them all); in (0, 1e6], normalised over the
//!   populations; default 1.
use super::{HaloSky, DEFAULT_RAYS};
use crate::optics::ice::{Crystals, Orientation, Population};

/// Most populations a sky mixes.
pub const MAX_POPULATIONS: usize = 8;
/// Fewest and most rays per wavelength row.
pub const MIN_RAYS: u64 = 1000;
pub const MAX_RAYS: u64 = 1 << 28;

/// One population as a scene file or a flag gives it.
#[derive(Clone, Debug, Default, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct CrystalFile {
    pub orientation: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt_deg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size_um: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weight: Option<f64>,
}

/// The keys of `CrystalFile`, in the order a flag lists them.
pub const CRYSTAL_KEYS: [&str; 5] = ["orientation", "aspect", "tilt_deg", "size_um", "weight"];

/// A key of a halo sky, for the front end to name: `sky.crystals[1].aspect` in a scene,
/// `--crystals` on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HaloKey<'a> {
    /// The list of populations.
    Crystals,
    /// Population `i`'s key.
    Crystal(usize, &'a str),
    SunElevation,
    Rays,
}

/// A halo sky's description.
#[derive(Clone, Debug, Default)]
pub struct HaloSpec {
    /// The sun's elevation above the horizon, degrees.
    pub sun_elevation_deg: f64,
    /// The sun's angular radius, radians (checked by the caller, as for every sky).
    pub sun_radius_rad: f64,
    pub crystals: Vec<CrystalFile>,
    /// Rays per wavelength row; None: [`DEFAULT_RAYS`].
    pub rays: Option<u64>,
    /// The seed of the table's random numbers; None: 0.
    pub seed: Option<u64>,
}

impl CrystalFile {
    /// Parses a flag's `ORIENTATION[:key=value,…]`, e.g. `plates:aspect=0.2,tilt_deg=0.5`.
    pub fn parse_flag(s: &str, flag: &str) -> Result<CrystalFile, String> {
        let (orientation, rest) = s.split_once(':').unwrap_or((s, ""));
        let mut c = CrystalFile {
            orientation: orientation.trim().to_string(),
            ..Default::default()
        };
        for item in rest.split(',').map(str::trim).filter(|t| !t.is_empty()) {
            let Some((k, v)) = item.split_once('=') else {
                return Err(format!("{flag} {s}: expected key=value, got {item:?}"));
            };
            let x: f64 = v.trim().parse().map_err(|_| {
                format!(
                    "{flag} {s}: {}: expected a number, got {:?}",
                    k.trim(),
                    v.trim()
                )
            })?;
            let slot = match k.trim() {
                "aspect" => &mut c.aspect,
                "tilt_deg" => &mut c.tilt_deg,
                "size_um" => &mut c.size_um,
                "weight" => &mut c.weight,
                other => {
                    return Err(format!(
                        "{flag} {s}: unknown key {other:?}; expected aspect, tilt_deg, size_um or weight"
                    ))
                }
            };
            *slot = Some(x);
        }
        Ok(c)
    }

    /// The population, checked; errors start with the key `name` gives.
    fn population(&self, i: usize, name: &dyn Fn(HaloKey) -> String) -> Result<Population, String> {
        let key = |k: &'static str| name(HaloKey::Crystal(i, k));
        let tilt_default = if self.orientation == "lowitz" {
            10.0
        } else {
            1.0
        };
        let tilt = self.tilt_deg.unwrap_or(tilt_default);
        let orientation =
            Orientation::from_name(&self.orientation, tilt.to_radians()).ok_or_else(|| {
                format!(
                    "{}: expected one of {}, got {:?}",
                    key("orientation"),
                    Orientation::NAMES.join(", "),
                    self.orientation
                )
            })?;
        let aspect = self.aspect.unwrap_or(match orientation {
            Orientation::Random => 1.0,
            Orientation::Plates { .. } | Orientation::Lowitz { .. } => 0.2,
            Orientation::Columns { .. } | Orientation::Parry { .. } => 3.0,
        });
        if !(0.02..=50.0).contains(&aspect) {
            return Err(format!(
                "{}: expected c/a in [0.02, 50], got {aspect}",
                key("aspect")
            ));
        }
        if self.tilt_deg.is_some() && orientation == Orientation::Random {
            return Err(format!(
                "{}: random crystals have no tilt (it applies to plates, columns, parry and lowitz)",
                key("tilt_deg")
            ));
        }
        if !(0.0..=90.0).contains(&tilt) {
            return Err(format!(
                "{}: expected an angle in [0°, 90°], got {tilt}",
                key("tilt_deg")
            ));
        }
        let size_um = self.size_um.unwrap_or(50.0);
        if !(5.0..=1000.0).contains(&size_um) {
            return Err(format!(
                "{}: expected a semi-diameter in [5, 1000] µm, got {size_um}",
                key("size_um")
            ));
        }
        if size_um * aspect > 2000.0 {
            return Err(format!(
                "{}: the half-length size_um × aspect = {} µm is over 2000 µm (ice's absorption, which the tracer neglects, would matter)",
                key("size_um"),
                size_um * aspect
            ));
        }
        let weight = self.weight.unwrap_or(1.0);
        if !(weight > 0.0 && weight <= 1e6) {
            return Err(format!(
                "{}: expected a weight in (0, 1e6], got {weight}",
                key("weight")
            ));
        }
        Ok(Population {
            orientation,
            aspect,
            size_um,
            weight,
        })
    }
}

impl HaloSpec {
    /// Checks the spec and makes the sky (its table is traced on first use).
    pub fn build(&self, name: &dyn Fn(HaloKey) -> String) -> Result<HaloSky, String> {
        let populations = populations(&self.crystals, name)?;
        let h = self.sun_elevation_deg;
        if !(-90.0..=90.0).contains(&h) {
            return Err(format!(
                "{}: expected an elevation in [−90°, 90°], got {h}°",
                name(HaloKey::SunElevation)
            ));
        }
        Ok(HaloSky::new(
            Crystals::new(populations),
            h.to_radians(),
            self.sun_radius_rad,
            rays(self.rays, DEFAULT_RAYS, name)?,
            self.seed.unwrap_or(0),
        ))
    }
}

/// The populations of `crystals`, checked: 1 to [`MAX_POPULATIONS`], each by
/// [`CrystalFile`]'s rules (a halo sky's or an ice medium's).
pub fn populations(
    crystals: &[CrystalFile],
    name: &dyn Fn(HaloKey) -> String,
) -> Result<Vec<Population>, String> {
    if crystals.is_empty() || crystals.len() > MAX_POPULATIONS {
        return Err(format!(
            "{}: expected 1 to {MAX_POPULATIONS} populations of crystals, got {}",
            name(HaloKey::Crystals),
            crystals.len()
        ));
    }
    crystals
        .iter()
        .enumerate()
        .map(|(i, c)| c.population(i, name))
        .collect()
}

/// Rays per wavelength, `default` when not given, checked against [`MIN_RAYS`] and
/// [`MAX_RAYS`].
pub fn rays(
    rays: Option<u64>,
    default: usize,
    name: &dyn Fn(HaloKey) -> String,
) -> Result<usize, String> {
    let rays = rays.unwrap_or(default as u64);
    if !(MIN_RAYS..=MAX_RAYS).contains(&rays) {
        return Err(format!(
            "{}: expected {MIN_RAYS} to {MAX_RAYS} rays per wavelength, got {rays}",
            name(HaloKey::Rays)
        ));
    }
    Ok(rays as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(k: HaloKey) -> String {
        format!("{k:?}")
    }

    #[test]
    fn flags_parse_and_bad_values_are_named() {
        let c = CrystalFile::parse_flag("plates:aspect=0.3, tilt_deg=0.5", "--crystals").unwrap();
        assert_eq!(c.orientation, "plates");
        assert_eq!((c.aspect, c.tilt_deg), (Some(0.3), Some(0.5)));
        let e = CrystalFile::parse_flag("plates:colour=2", "--crystals").unwrap_err();
        assert!(e.contains("unknown key \"colour\""), "{e}");
        let e = CrystalFile::parse_flag("plates:aspect=x", "--crystals").unwrap_err();
        assert!(e.contains("aspect: expected a number"), "{e}");
        let spec = |c: CrystalFile| HaloSpec {
            sun_elevation_deg: 20.0,
            sun_radius_rad: 0.0046,
            crystals: vec![c],
            ..Default::default()
        };
        let bad = |c: CrystalFile| spec(c).build(&key).expect_err("refused");
        let e = bad(CrystalFile {
            orientation: "needles".into(),
            ..Default::default()
        });
        assert!(
            e.starts_with("Crystal(0, \"orientation\"): expected one of random"),
            "{e}"
        );
        let e = bad(CrystalFile {
            orientation: "plates".into(),
            aspect: Some(0.0),
            ..Default::default()
        });
        assert!(e.contains("c/a in [0.02, 50]"), "{e}");
        let e = bad(CrystalFile {
            orientation: "random".into(),
            tilt_deg: Some(1.0),
            ..Default::default()
        });
        assert!(e.contains("random crystals have no tilt"), "{e}");
        let e = bad(CrystalFile {
            orientation: "columns".into(),
            weight: Some(-1.0),
            ..Default::default()
        });
        assert!(e.contains("weight in (0, 1e6]"), "{e}");
        let e = bad(CrystalFile {
            orientation: "columns".into(),
            size_um: Some(500.0),
            aspect: Some(5.0),
            ..Default::default()
        });
        assert!(e.contains("half-length size_um × aspect = 2500 µm"), "{e}");
        let e = HaloSpec::default().build(&key).expect_err("refused");
        assert!(e.starts_with("Crystals: expected 1 to 8"), "{e}");
    }
}
