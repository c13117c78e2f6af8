//! The `[sky]` table: mapped to a [`SkySpec`] (which checks it, errors named by the
//! table's keys) with the scene's first sun light, then tied to that sun and, for a
//! render, tabulated.
use crate::light::sun::SUN_ANGULAR_RADIUS_DEG;
use crate::light::Light;
use crate::scene::file::{LightFile, SkyFile};
use crate::sky::halo::{HaloKey, HaloSky, HaloSpec, PlacedHalo};
use crate::sky::{SceneSky, Sky, SkyKey, SkyModel, SkySpec};
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

/// The `[sky]` model, checked and constructed with the scene's first sun light, before
/// its (slow) tabulation.
pub(super) struct SkyPlan {
    model: String,
    sky: PlannedSky,
    sun_dir: Vec3,
    factor: DenseSpectrum,
    replaces_background: bool,
}

/// A profile model with its spec, or a halo sky with its zenith.
enum PlannedSky {
    Profile(Box<(Sky, SkySpec)>),
    Halo(HaloSky, Vec3),
}

impl SkyPlan {
    /// Tabulates the model for rendering: over (θ, λ), or a halo's table over the sky.
    pub fn tabulate(self) -> SceneSky {
        match self.sky {
            PlannedSky::Profile(b) => {
                let (sky, spec) = *b;
                SceneSky::new(
                    self.model,
                    sky,
                    self.sun_dir,
                    self.factor,
                    self.replaces_background,
                )
                .with_spec(spec)
            }
            PlannedSky::Halo(halo, zenith) => {
                let placed = PlacedHalo::new(halo.table().clone(), self.sun_dir, zenith);
                SceneSky::halo(self.model, placed, self.factor)
            }
        }
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
    let halo_keys = [
        ("sky.crystals", sf.crystals.is_some()),
        ("sky.zenith", sf.zenith.is_some()),
        ("sky.rays", sf.rays.is_some()),
        ("sky.seed", sf.seed.is_some()),
    ];
    let sky = if sf.model == "halo" {
        plan_halo(sf, &spec, sun, i)?
    } else {
        if let Some((key, _)) = halo_keys.iter().find(|k| k.1) {
            return Err(format!("{key}: applies to halo, not {}", sf.model));
        }
        PlannedSky::Profile(Box::new((spec.build(&|k| scene_key(k, i))?, spec)))
    };
    // The spec has checked the model's name.
    let physical = SkyModel::from_name(&sf.model).is_some_and(SkyModel::is_physical);
    let scale = sf.scale.map_or(1.0, |s| s.get());
    Ok(SkyPlan {
        model: sf.model.clone(),
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

/// The halo sky of `[sky] model = "halo"`: the profile models' keys refused, the
/// zenith checked, the sun's elevation above the horizon it defines.
fn plan_halo(
    sf: &SkyFile,
    spec: &SkySpec,
    sun: &crate::light::SunLight,
    i: usize,
) -> Result<PlannedSky, String> {
    let profile_keys = [
        ("sky.droplet_radius", sf.droplet_radius.is_some()),
        ("sky.drops", sf.drops.is_some()),
        ("sky.orders", sf.orders.is_some()),
        ("sky.polarisation", sf.polarisation.is_some()),
        ("sky.debye", sf.debye.is_some()),
    ];
    if let Some((key, _)) = profile_keys.iter().find(|k| k.1) {
        return Err(format!("{key}: applies to the water-drop skies, not halo"));
    }
    crate::sky::spec::check_sun_radius(spec.sun_radius_deg, &scene_key(SkyKey::SunRadius, i))?;
    let z = sf.zenith.unwrap_or([0.0, 1.0, 0.0]);
    let zenith = Vec3::from(z);
    if !(zenith.is_finite() && zenith.length() > 1e-6) {
        return Err(format!(
            "sky.zenith: expected a non-zero direction, got {z:?}"
        ));
    }
    let zenith = zenith.normalize();
    let to_sun = -sun.direction.normalize();
    let elevation = (to_sun.dot(zenith) as f64)
        .clamp(-1.0, 1.0)
        .asin()
        .to_degrees();
    let halo = HaloSpec {
        sun_elevation_deg: elevation,
        sun_radius_rad: spec.sun_radius_rad,
        crystals: sf.crystals.clone().unwrap_or_default(),
        rays: sf.rays,
        seed: sf.seed,
    }
    .build(&|k| match k {
        HaloKey::Crystals => "sky.crystals".into(),
        HaloKey::Crystal(j, key) => format!("sky.crystals[{j}].{key}"),
        HaloKey::SunElevation => format!("lights[{i}].direction"),
        HaloKey::Rays => "sky.rays".into(),
    })?;
    Ok(PlannedSky::Halo(halo, zenith))
}
