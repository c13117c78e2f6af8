//! One description of a sky, [`SkySpec`], with one [`SkySpec::build`] that checks it and
//! constructs the model: the scene files' `[sky]` table (`scene::load`), `heron sky
//! profile` (its flags, [`super::profile`]) and the Python module's `heron.sky_profile`
//! (its keyword arguments) each fill a `SkySpec` and name its keys their own way
//! ([`SkyKey`]); the rules and the limits are written here once.
use super::{AirySky, AristotleSky, ConstantSky, DescartesSky, MieSky, Polarisation, Sky};
use crate::drops::{DropSizeDistribution, DropsFile};
use crate::spectrum::DenseSpectrum;

/// Largest solar angular radius a sky takes, degrees. Every model averages its profile
/// over the disk along θ with the chord-length kernel (`super::disk_kernel`), which
/// treats the disk's edge as straight across the bow: a small-disk approximation
/// (α ≪ θ ≈ 42°; the real sun is 0.27°).
pub const MAX_SUN_RADIUS_DEG: f64 = 5.0;
/// Largest drop radius of the `airy` sky, mm (one radius, or a distribution's largest
/// quadrature node). Airy's theory is the large-drop asymptote (x = 2πa/λ ≳ 1000, see
/// `super::airy`): it only improves with the radius, and its cost does not grow with it;
/// the bound is the drop-size distributions' own (`crate::drops`), beyond any rain drop
/// (they break up above about 3 mm, Pruppacher & Klett 1997 §10.3).
pub const AIRY_MAX_RADIUS_MM: f64 = 10.0;
/// Largest drop radius of the `mie` sky, mm (one radius, or a distribution's largest
/// node): the Lorenz–Mie series has about x + 4x^{1/3} + 2 terms (Wiscombe 1980),
/// x ≈ 35 000 at 2 mm and 360 nm, seconds per wavelength.
pub const MIE_MAX_RADIUS_MM: f64 = 2.0;

/// The sky models, in the order their names are listed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkyModel {
    Constant,
    Aristotle,
    Descartes,
    Airy,
    Mie,
    /// Ice crystals ([`super::halo`]): built by [`super::halo::HaloSpec`], not by
    /// [`SkySpec::build`], which refuses it.
    Halo,
}

impl SkyModel {
    /// Every model, in the order of [`SkyModel::NAMES`].
    pub const ALL: [SkyModel; 6] = [
        SkyModel::Constant,
        SkyModel::Aristotle,
        SkyModel::Descartes,
        SkyModel::Airy,
        SkyModel::Mie,
        SkyModel::Halo,
    ];
    /// The models' names, as scene files, the CLI and Python write them.
    pub const NAMES: [&'static str; 6] =
        ["constant", "aristotle", "descartes", "airy", "mie", "halo"];

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The model named `name`, if any.
    pub fn from_name(name: &str) -> Option<SkyModel> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Whether it is the scattering of particles, radiance per unit solar irradiance
    /// (descartes, airy, mie: water drops; halo: ice crystals), rather than a radiance of
    /// its own.
    pub fn is_physical(self) -> bool {
        matches!(
            self,
            SkyModel::Descartes | SkyModel::Airy | SkyModel::Mie | SkyModel::Halo
        )
    }

    /// Whether it scatters by water drops with s- or p-polarised sunlight as an option
    /// (descartes, airy, mie).
    fn takes_polarisation(self) -> bool {
        matches!(self, SkyModel::Descartes | SkyModel::Airy | SkyModel::Mie)
    }

    /// The orders k (internal reflections) it can keep: geometric optics has the
    /// external reflection (k = 0) too; Airy's theory is written for the bows of
    /// k = 1, 2; Mie has every order in its series.
    fn orders(self) -> &'static [u32] {
        match self {
            SkyModel::Descartes => &[0, 1, 2],
            SkyModel::Airy => &[1, 2],
            _ => &[],
        }
    }

    /// Whether it depends on the drops' size (one radius or a distribution).
    fn takes_drops(self) -> bool {
        matches!(self, SkyModel::Airy | SkyModel::Mie)
    }

    /// The largest drop radius it takes, mm.
    fn max_radius_mm(self) -> f64 {
        match self {
            SkyModel::Mie => MIE_MAX_RADIUS_MM,
            _ => AIRY_MAX_RADIUS_MM,
        }
    }

    /// The names of the models for which `has` holds: "descartes and airy".
    fn names_where(has: impl Fn(SkyModel) -> bool) -> String {
        let names: Vec<&str> = Self::ALL
            .into_iter()
            .filter(|m| has(*m))
            .map(SkyModel::name)
            .collect();
        choice_list(&names, "and")
    }
}

/// "a", "a and b", "a, b and c" (with `word` for "and").
fn choice_list(names: &[&str], word: &str) -> String {
    match names.split_last() {
        None => String::new(),
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} {word} {last}", rest.join(", ")),
    }
}

/// A key of a [`SkySpec`], for the front end to name in messages: `sky.droplet_radius` in a
/// scene file, `--droplet-radius` on the command line, `droplet_radius` in Python.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkyKey<'a> {
    Model,
    SunRadius,
    DropletRadius,
    Orders,
    Polarisation,
    /// The drop-size distribution as a whole.
    Drops,
    /// One key of the distribution's table ([`DropsFile`]): `median_mm`, `nodes`, ….
    Drop(&'a str),
    /// How one radius is written as a distribution, for the message that refuses both.
    MonodisperseDrops,
    Debye,
    Background,
}

/// What a sky is made of, whoever asks for it. [`SkySpec::build`] checks it against these
/// rules and limits, the same for scene files, `heron sky profile` and
/// `heron.sky_profile` (the guide's docs/rainbows-and-media.md describes them for users):
///
/// - `model`: one of [`SkyModel::NAMES`].
/// - The sun's angular radius: in (0°, [`MAX_SUN_RADIUS_DEG`]] (the disk average is a
///   small-disk approximation).
/// - `orders` (descartes, airy): a non-empty subset of the model's orders, [0, 1, 2] for
///   descartes (0: the external reflection), [1, 2] for airy; default [1, 2].
/// - `polarisation` (descartes, airy, mie): one of [`Polarisation::NAMES`] (or
///   "unpolarized").
/// - The drops (airy, mie): one radius (`droplet_radius_mm`) or a distribution (`drops`),
///   not both; radii up to [`AIRY_MAX_RADIUS_MM`] for airy and [`MIE_MAX_RADIUS_MM`] for
///   mie, a distribution's largest quadrature node included; the distribution's own
///   parameters as [`DropsFile::parse_named`] checks them, with
///   [`crate::drops::MIE_DEFAULT_NODES`] nodes for mie when the table gives none.
/// - `debye` (mie): a Debye term p in 0..=[`super::mie::MAX_DEBYE_TERM`].
/// - `background` (constant, aristotle): a radiance ≥ 0, default 1 for constant and 0 for
///   aristotle; the physical models' profiles have none (a scene adds its background).
///
/// Where the CLI and scene files once differed (before issue 18): a single Airy radius
/// was capped at 2 mm in scenes (the Mie bound) though their Airy distributions reached
/// 10 mm, and 10 mm on the command line: now 10 mm everywhere (see
/// [`AIRY_MAX_RADIUS_MM`]). The command line refused suns over 5°, scenes only over 90°:
/// now a sky refuses them everywhere. Scenes refused order 0 for descartes: now allowed.
/// The command line ignored a drop radius given to a model without drops: now an error.
#[derive(Clone, Debug, Default)]
pub struct SkySpec {
    /// The model's name (checked by [`SkySpec::build`], so a front end passes what it
    /// was given).
    pub model: String,
    /// The sun's angular radius as the user gave it, degrees: the limit is checked on
    /// this number and messages print it.
    pub sun_radius_deg: f64,
    /// The same angle in radians, as the front end converts it (a scene's sun light keeps
    /// f32 radians; the CLI converts its flag in f64): what the model uses.
    pub sun_radius_rad: f64,
    /// One drop radius, mm.
    pub droplet_radius_mm: Option<f64>,
    /// A drop-size distribution instead of one radius.
    pub drops: Option<DropsFile>,
    /// The orders k to keep; None: [1, 2].
    pub orders: Option<Vec<u32>>,
    /// The polarisation's name; None: unpolarised.
    pub polarisation: Option<String>,
    /// Only this term p of the Debye series.
    pub debye: Option<u32>,
    /// The radiance off the bow of constant and aristotle; None: their default.
    pub background: Option<DenseSpectrum>,
}

/// Checks a sun angular radius in degrees against (0°, [`MAX_SUN_RADIUS_DEG`]]; the
/// message names it `name`.
pub fn check_sun_radius(deg: f64, name: &str) -> Result<(), String> {
    if deg > 0.0 && deg <= MAX_SUN_RADIUS_DEG {
        Ok(())
    } else {
        Err(format!(
            "{name}: expected an angle in (0°, {MAX_SUN_RADIUS_DEG}°], got {deg}°"
        ))
    }
}

impl SkySpec {
    /// Checks the spec and constructs its model (without tabulating it). Every error is
    /// one line that starts with the key `name` gives. The order of the checks is the
    /// order of the errors reported: options that do not apply to the model, then the
    /// values of orders and polarisation, the model's name, the sun, and last the drops.
    pub fn build(&self, name: &dyn Fn(SkyKey) -> String) -> Result<Sky, String> {
        let model_name = self.model.as_str();
        let model = SkyModel::from_name(model_name);
        let applies = |key: SkyKey, given: bool, to: fn(SkyModel) -> bool| {
            if given && !model.is_some_and(to) {
                Err(format!(
                    "{}: applies to {}, not {model_name}",
                    name(key),
                    SkyModel::names_where(to)
                ))
            } else {
                Ok(())
            }
        };
        applies(SkyKey::Orders, self.orders.is_some(), |m| {
            !m.orders().is_empty()
        })?;
        applies(
            SkyKey::Polarisation,
            self.polarisation.is_some(),
            SkyModel::takes_polarisation,
        )?;
        applies(
            SkyKey::DropletRadius,
            self.droplet_radius_mm.is_some(),
            SkyModel::takes_drops,
        )?;
        applies(SkyKey::Drops, self.drops.is_some(), SkyModel::takes_drops)?;
        if self.drops.is_some() && self.droplet_radius_mm.is_some() {
            return Err(format!(
                "{}: one radius; with {} give the radius there ({})",
                name(SkyKey::DropletRadius),
                name(SkyKey::Drops),
                name(SkyKey::MonodisperseDrops)
            ));
        }
        if let Some(p) = self.debye {
            applies(SkyKey::Debye, true, |m| m == SkyModel::Mie)?;
            if p > super::mie::MAX_DEBYE_TERM {
                return Err(format!(
                    "{}: expected a term p in 0..={}, got {p}",
                    name(SkyKey::Debye),
                    super::mie::MAX_DEBYE_TERM
                ));
            }
        }
        let orders = match (&self.orders, model) {
            (None, _) => vec![1, 2],
            (Some(o), Some(m)) if !o.is_empty() && o.iter().all(|k| m.orders().contains(k)) => {
                let mut o = o.clone();
                o.sort_unstable();
                o.dedup();
                o
            }
            (Some(o), m) => {
                return Err(format!(
                    "{}: expected a non-empty subset of {:?}, got {o:?}",
                    name(SkyKey::Orders),
                    m.map_or(&[][..], SkyModel::orders)
                ))
            }
        };
        let pol = match self.polarisation.as_deref() {
            None => Polarisation::Unpolarised,
            Some(p) => Polarisation::from_name(p).ok_or_else(|| {
                format!(
                    "{}: expected {}, got {p:?}",
                    name(SkyKey::Polarisation),
                    choice_list(&Polarisation::NAMES, "or")
                )
            })?,
        };
        let Some(model) = model else {
            return Err(format!(
                "{}: expected one of {}, got {model_name:?}",
                name(SkyKey::Model),
                SkyModel::NAMES.join(", ")
            ));
        };
        check_sun_radius(self.sun_radius_deg, &name(SkyKey::SunRadius))?;
        let alpha = self.sun_radius_rad;
        Ok(match model {
            SkyModel::Constant => Sky::Constant(ConstantSky::new(self.background(1.0, name)?)),
            SkyModel::Aristotle => {
                Sky::Aristotle(AristotleSky::new(alpha, self.background(0.0, name)?))
            }
            SkyModel::Descartes => {
                let mut s = DescartesSky::water(alpha);
                s.orders = orders;
                s.polarisation = pol;
                Sky::Descartes(s)
            }
            SkyModel::Airy => {
                let mut s = match self.distribution(model, name)? {
                    Some((d, n)) => AirySky::water(1.0, alpha).with_distribution(&d, n),
                    None => AirySky::water(self.radius(model, name)?, alpha),
                };
                s.orders = orders;
                s.polarisation = pol;
                Sky::Airy(s)
            }
            SkyModel::Mie => {
                let mut s = match self.distribution(model, name)? {
                    Some((d, n)) => MieSky::water(1.0, alpha).with_distribution(&d, n),
                    None => MieSky::water(self.radius(model, name)?, alpha),
                };
                s.polarisation = pol;
                s.debye = self.debye;
                Sky::Mie(s)
            }
            SkyModel::Halo => {
                return Err(format!(
                    "{}: a halo sky is a table over the whole sky, not a profile about the antisolar point (`heron halo profile` draws its profiles)",
                    name(SkyKey::Model)
                ))
            }
        })
    }

    /// The distribution and its node count, checked against `model`'s largest radius.
    fn distribution(
        &self,
        model: SkyModel,
        name: &dyn Fn(SkyKey) -> String,
    ) -> Result<Option<(DropSizeDistribution, usize)>, String> {
        let Some(f) = &self.drops else {
            return Ok(None);
        };
        let (d, n) = f.parse_named(&|k| name(SkyKey::Drop(k)))?;
        // Each node costs the Mie sky one series per wavelength: fewer by default.
        let n = if model == SkyModel::Mie && f.nodes.is_none() {
            crate::drops::MIE_DEFAULT_NODES
        } else {
            n
        };
        let (max, largest) = (model.max_radius_mm(), d.max_radius_mm());
        if largest > max {
            return Err(format!(
                "{}: the {} sky takes radii up to {max} mm; this distribution reaches {largest:.3} mm",
                name(SkyKey::Drops),
                model.name()
            ));
        }
        Ok(Some((d, n)))
    }

    /// The one drop radius, checked against `model`'s largest.
    fn radius(&self, model: SkyModel, name: &dyn Fn(SkyKey) -> String) -> Result<f64, String> {
        let key = name(SkyKey::DropletRadius);
        let r = self.droplet_radius_mm.ok_or_else(|| {
            format!(
                "{key}: the {} model needs a drop radius in mm",
                model.name()
            )
        })?;
        let max = model.max_radius_mm();
        if r > max {
            return Err(format!("{key}: expected at most {max} mm, got {r}"));
        }
        if !(r > 0.0) {
            return Err(format!(
                "{key}: expected a radius in (0, {max}] mm for {}, got {r}",
                model.name()
            ));
        }
        Ok(r)
    }

    /// The background radiance, or `default` everywhere.
    fn background(
        &self,
        default: f32,
        name: &dyn Fn(SkyKey) -> String,
    ) -> Result<DenseSpectrum, String> {
        let Some(b) = &self.background else {
            return Ok(DenseSpectrum::constant(default));
        };
        match b.values().iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            Some(v) => Err(format!(
                "{}: expected a radiance ≥ 0, got {v}",
                name(SkyKey::Background)
            )),
            None => Ok(b.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(k: SkyKey) -> String {
        format!("{k:?}")
    }

    #[test]
    fn names_round_trip() {
        for m in SkyModel::ALL {
            assert_eq!(SkyModel::from_name(m.name()), Some(m));
        }
        assert_eq!(SkyModel::from_name("rainbow"), None);
        assert_eq!(
            SkyModel::names_where(SkyModel::is_physical),
            "descartes, airy, mie and halo"
        );
        assert_eq!(
            SkyModel::names_where(SkyModel::takes_polarisation),
            "descartes, airy and mie"
        );
        assert_eq!(SkyModel::names_where(|m| m == SkyModel::Mie), "mie");
    }

    #[test]
    fn limits_are_the_same_for_one_radius_and_a_distribution() {
        let spec = |model: &str, r: Option<f64>, drops: Option<DropsFile>| SkySpec {
            model: model.into(),
            sun_radius_deg: 0.25,
            sun_radius_rad: 0.25f64.to_radians(),
            droplet_radius_mm: r,
            drops,
            ..Default::default()
        };
        let mono = |r: f64| {
            Some(DropsFile {
                distribution: "monodisperse".into(),
                radius_mm: Some(r),
                ..Default::default()
            })
        };
        // A log-normal whose largest node (median e^{2σ² + 4σ}) is 1.5 × the median.
        let lognormal = |median_mm: f64| {
            Some(DropsFile {
                distribution: "lognormal".into(),
                median_mm: Some(median_mm),
                sigma: Some(0.1),
                nodes: Some(4),
                ..Default::default()
            })
        };
        for (model, max) in [("airy", AIRY_MAX_RADIUS_MM), ("mie", MIE_MAX_RADIUS_MM)] {
            assert!(spec(model, Some(max), None).build(&key).is_ok());
            assert!(spec(model, None, mono(max)).build(&key).is_ok());
            let e = spec(model, Some(max * 1.01), None)
                .build(&key)
                .err()
                .expect("refused");
            assert!(e.starts_with("DropletRadius: expected at most"), "{e}");
            let e = spec(model, None, lognormal(max / 1.4))
                .build(&key)
                .err()
                .expect("refused");
            let want = format!("Drops: the {model} sky takes radii up to {max} mm");
            assert!(e.starts_with(&want), "{e}");
        }
        let e = spec("airy", Some(-1.0), None)
            .build(&key)
            .err()
            .expect("refused");
        assert!(
            e.starts_with("DropletRadius: expected a radius in (0, 10]"),
            "{e}"
        );
    }

    #[test]
    fn orders_and_the_sun_follow_the_model() {
        let spec = |model: &str, orders: Vec<u32>, sun: f64| SkySpec {
            model: model.into(),
            sun_radius_deg: sun,
            sun_radius_rad: sun.to_radians(),
            droplet_radius_mm: (model == "airy").then_some(0.5),
            orders: Some(orders),
            ..Default::default()
        };
        assert!(spec("descartes", vec![0, 1, 2], 0.25).build(&key).is_ok());
        let e = spec("airy", vec![0], 0.25)
            .build(&key)
            .err()
            .expect("refused");
        assert_eq!(e, "Orders: expected a non-empty subset of [1, 2], got [0]");
        let e = spec("descartes", vec![1], 5.5)
            .build(&key)
            .err()
            .expect("refused");
        assert_eq!(e, "SunRadius: expected an angle in (0°, 5°], got 5.5°");
        let e = spec("mie", vec![1], 0.25)
            .build(&key)
            .err()
            .expect("refused");
        assert_eq!(e, "Orders: applies to descartes and airy, not mie");
    }
}
