//! The `[sky]` table: mapped to a [`SkySpec`] (which checks it, errors named by the
//! table's keys) with the scene's first sun light, then tied to that sun and, for a
//! render, tabulated.
use crate::light::sun::SUN_ANGULAR_RADIUS_DEG;
use crate::light::Light;
use crate::scene::file::{LightFile, SkyFile};
use crate::sky::{SceneSky, Sky, SkyKey, SkyModel, SkySpec};
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

/// The `[sky]` model, checked and constructed with the scene's first sun light, before
/// its (slow) tabulation.
pub(super) struct SkyPlan {
    model: String,
    sky: Sky,
    spec: SkySpec,
    sun_dir: Vec3,
    factor: DenseSpectrum,
    replaces_background: bool,
}

impl SkyPlan {
    /// Tabulates the model over (θ, λ) for rendering.
    pub fn tabulate(self) -> SceneSky {
        SceneSky::new(
            self.model,
            self.sky,
            self.sun_dir,
            self.factor,
            self.replaces_background,
        )
        .with_spec(self.spec)
    }
}

/// The name of `key` in a scene file; the sun is `lights[sun]`.
fn scene_key(key: SkyKey, sun: usize) -> String {
    match key {
        SkyKey::Model => "sky.model".into(),
        SkyKey::SunRadius => format!("lights[{sun}].angular_radius"),
        SkyKey::DropletRadius => "sky.droplet_radius".into(),
        SkyKey::Orders => "sky.orders".into(),
        SkyKey::Polarisation => "sky.polarisation".into(),
        SkyKey::Drops => "sky.drops".into(),
        SkyKey::Drop(k) => format!("sky.drops.{k}"),
        SkyKey::MonodisperseDrops => "distribution = \"monodisperse\", radius_mm = …".into(),
        SkyKey::Debye => "sky.debye".into(),
        SkyKey::Background => "background".into(),
    }
}

/// Checks `[sky]` and constructs its model with the scene's first sun light (`entries`
/// are the file's lights, `lights` the lights built from them, in the same order).
pub(super) fn plan_sky(
    sf: &SkyFile,
    entries: &[LightFile],
    lights: &[Light],
    background: &DenseSpectrum,
) -> Result<SkyPlan, String> {
    let sun = entries
        .iter()
        .zip(lights)
        .enumerate()
        .find_map(|(i, pair)| match pair {
            (LightFile::Sun(file), Light::Sun(sun)) => Some((i, file, sun)),
            _ => None,
        });
    let Some((i, sun_file, sun)) = sun else {
        return Err("sky: expected a light of type \"sun\" (the sky takes its direction and angular radius)".into());
    };
    let deg = sun_file
        .angular_radius
        .map_or(SUN_ANGULAR_RADIUS_DEG, |a| a.get());
    let spec = SkySpec {
        model: sf.model.clone(),
        // The degrees as the file writes them (f32's shortest form, not its binary
        // value's 17 digits), which the limit is checked on and messages print.
        sun_radius_deg: deg.to_string().parse().unwrap_or(deg as f64),
        sun_radius_rad: sun.angular_radius as f64,
        droplet_radius_mm: sf.droplet_radius.map(|r| r.get() as f64),
        drops: sf.drops.clone(),
        orders: sf.orders.clone(),
        polarisation: sf.polarisation.clone(),
        debye: sf.debye,
        background: Some(background.clone()),
    };
    let sky = spec.build(&|k| scene_key(k, i))?;
    // The spec has checked the model's name.
    let physical = SkyModel::from_name(&sf.model).is_some_and(SkyModel::is_physical);
    let scale = sf.scale.map_or(1.0, |s| s.get());
    Ok(SkyPlan {
        model: sf.model.clone(),
        sky,
        spec,
        sun_dir: -sun.direction,
        factor: if physical {
            sun.irradiance.scaled(scale)
        } else {
            DenseSpectrum::constant(scale)
        },
        replaces_background: !physical,
    })
}
