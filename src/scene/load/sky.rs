//! The `[sky]` table: checked and its model constructed with the scene's first sun light,
//! then, for a render, tabulated.
use crate::light::Light;
use crate::scene::file::SkyFile;
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

/// The `[sky]` model, checked and constructed with the scene's first sun light, before
/// its (slow) tabulation.
pub(super) struct SkyPlan {
    model: String,
    sky: crate::sky::Sky,
    sun_dir: Vec3,
    factor: DenseSpectrum,
    replaces_background: bool,
}

impl SkyPlan {
    /// Tabulates the model over (θ, λ) for rendering.
    pub fn tabulate(self) -> crate::sky::SceneSky {
        crate::sky::SceneSky {
            table: crate::sky::table::SkyTable::build(&self.sky),
            model: self.model,
            sun_dir: self.sun_dir,
            factor: self.factor,
            replaces_background: self.replaces_background,
        }
    }
}

/// Checks `[sky]` and constructs its model with the scene's first sun light.
pub(super) fn plan_sky(
    sf: &SkyFile,
    lights: &[Light],
    background: &DenseSpectrum,
) -> Result<SkyPlan, String> {
    use crate::sky::{AirySky, AristotleSky, ConstantSky, DescartesSky, MieSky, Polarisation, Sky};
    let sun = lights.iter().find_map(|l| match l {
        Light::Sun(s) => Some(s),
        _ => None,
    });
    let Some(sun) = sun else {
        return Err("sky: expected a light of type \"sun\" (the sky takes its direction and angular radius)".into());
    };
    let alpha = sun.angular_radius as f64;
    let model = sf.model.as_str();
    let physical = matches!(model, "descartes" | "airy" | "mie");
    if sf.orders.is_some() && !matches!(model, "descartes" | "airy") {
        return Err(format!(
            "sky.orders: applies to descartes and airy, not {model}"
        ));
    }
    if sf.polarisation.is_some() && !physical {
        return Err(format!(
            "sky.polarisation: applies to descartes, airy and mie, not {model}"
        ));
    }
    if sf.droplet_radius.is_some() && !matches!(model, "airy" | "mie") {
        return Err(format!(
            "sky.droplet_radius: applies to airy and mie, not {model}"
        ));
    }
    if sf.drops.is_some() && !matches!(model, "airy" | "mie") {
        return Err(format!("sky.drops: applies to airy and mie, not {model}"));
    }
    if sf.drops.is_some() && sf.droplet_radius.is_some() {
        return Err(
            "sky.droplet_radius: one radius; with sky.drops give the radius there (distribution = \"monodisperse\", radius_mm = …)"
                .into(),
        );
    }
    if let Some(p) = sf.debye {
        if model != "mie" {
            return Err(format!("sky.debye: applies to mie, not {model}"));
        }
        if p > crate::sky::mie::MAX_DEBYE_TERM {
            return Err(format!(
                "sky.debye: expected a term p in 0..={}, got {p}",
                crate::sky::mie::MAX_DEBYE_TERM
            ));
        }
    }
    let dsd = |max_mm: f64| -> std::result::Result<
        Option<(crate::drops::DropSizeDistribution, usize)>,
        String,
    > {
        let Some(f) = &sf.drops else { return Ok(None) };
        let (d, n) = f.parse("sky.drops")?;
        let n = if model == "mie" && f.nodes.is_none() {
            crate::drops::MIE_DEFAULT_NODES
        } else {
            n
        };
        let largest = d.max_radius_mm();
        if largest > max_mm {
            return Err(format!(
                "sky.drops: the {model} sky takes radii up to {max_mm} mm; this distribution reaches {largest:.3} mm"
            ));
        }
        Ok(Some((d, n)))
    };
    let orders = match &sf.orders {
        None => vec![1, 2],
        Some(o) if !o.is_empty() && o.iter().all(|k| *k == 1 || *k == 2) => {
            let mut o = o.clone();
            o.sort_unstable();
            o.dedup();
            o
        }
        Some(o) => {
            return Err(format!(
                "sky.orders: expected a non-empty subset of [1, 2], got {o:?}"
            ))
        }
    };
    let pol = match sf.polarisation.as_deref().unwrap_or("unpolarised") {
        "unpolarised" | "unpolarized" => Polarisation::Unpolarised,
        "s" => Polarisation::S,
        "p" => Polarisation::P,
        other => {
            return Err(format!(
                "sky.polarisation: expected unpolarised, s or p, got {other:?}"
            ))
        }
    };
    let radius = || -> std::result::Result<f64, String> {
        let r = sf.droplet_radius.map(|r| r.0 as f64).ok_or_else(|| {
            format!("sky.droplet_radius: the {model} model needs a drop radius in mm")
        })?;
        if r > crate::sky::profile::MIE_MAX_RADIUS_MM {
            return Err(format!(
                "sky.droplet_radius: expected at most {} mm, got {r}",
                crate::sky::profile::MIE_MAX_RADIUS_MM
            ));
        }
        Ok(r)
    };
    let sky = match model {
        "constant" => Sky::Constant(ConstantSky::new(background.clone())),
        "aristotle" => Sky::Aristotle(AristotleSky::new(alpha, background.clone())),
        "descartes" => {
            let mut d = DescartesSky::water(alpha);
            d.orders = orders;
            d.polarisation = pol;
            Sky::Descartes(d)
        }
        "airy" => {
            let mut a = match dsd(10.0)? {
                Some((d, n)) => AirySky::water(1.0, alpha).with_distribution(&d, n),
                None => AirySky::water(radius()?, alpha),
            };
            a.orders = orders;
            a.polarisation = pol;
            Sky::Airy(a)
        }
        "mie" => {
            let mut m = match dsd(crate::sky::profile::MIE_MAX_RADIUS_MM)? {
                Some((d, n)) => MieSky::water(1.0, alpha).with_distribution(&d, n),
                None => MieSky::water(radius()?, alpha),
            };
            m.polarisation = pol;
            m.debye = sf.debye;
            if m.drops.len() > 1 {
                // One Mie series per node and wavelength: a table every 10 nm, interpolated
                // (the bows move by ≤ 0.06° over 10 nm, well inside the 0.53° disk), halves
                // the scene's 95 wavelengths of the sky table.
                m.lambda_step_nm = 10.0;
            }
            Sky::Mie(m)
        }
        other => {
            return Err(format!(
            "sky.model: expected one of constant, aristotle, descartes, airy, mie, got {other:?}"
        ))
        }
    };
    let scale = sf.scale.map_or(1.0, |s| s.0);
    Ok(SkyPlan {
        model: model.to_string(),
        sky,
        sun_dir: -sun.direction,
        factor: if physical {
            sun.irradiance.scaled(scale)
        } else {
            DenseSpectrum::constant(scale)
        },
        replaces_background: !physical,
    })
}
