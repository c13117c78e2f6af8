//! `heron trace`: one ray at one wavelength through a scene, event by event, with the
//! renderer's own code (Embree queries, `Interaction`, the materials' `sample` restricted
//! to their delta lobes, the ε offset). For prism and droplet experiments.
//!
//! At a surface with a reflecting and a transmitting delta lobe (a smooth dielectric, or
//! the seed's glossy over glass) the ray refracts unless the `path` string says `R`
//! (reflect) or `T` (transmit) for that event; total internal reflection forces `R`.
//! Surfaces with only a reflecting delta lobe (mirrors, smooth metals) reflect; the
//! others (Lambertian, glossy, rough) absorb; a miss escapes.
use crate::accel::embree::{self, RayQuery};
use crate::bsdf::{BsdfContext, LobeFlags};
use crate::geometry::Ray;
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;
use crate::{HeronError, Result};
use glam::Vec2;
use glam::Vec3;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EventKind {
    Reflect,
    Refract,
    TotalInternalReflection,
    Absorb,
    Escape,
}

/// One event along the traced ray. Directions are unit vectors of travel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceEvent {
    pub kind: EventKind,
    /// Where the event happens; for `escape`, the origin of the escaping ray.
    pub position: [f32; 3],
    /// Unit surface normal on the incident side (absent for `escape`).
    pub normal: Option<[f32; 3]>,
    /// Material name (absent for `escape`).
    pub material: Option<String>,
    /// Refractive index on the incident side and on the far side.
    pub n_i: Option<f32>,
    pub n_t: Option<f32>,
    pub incoming: [f32; 3],
    /// Direction after the event (absent for `absorb`).
    pub outgoing: Option<[f32; 3]>,
    /// Unpolarised Fresnel reflectance at this event (dielectrics only).
    pub fresnel_r: Option<f32>,
    /// Distance travelled from the previous event (absent for `escape`).
    pub distance: Option<f32>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceReport {
    pub lambda_nm: f32,
    pub events: Vec<TraceEvent>,
    /// True when the ray was still going after the scene's max_depth continuations.
    pub truncated: bool,
}

/// Parses a `--path` string of `R` and `T` letters.
pub fn parse_path(path: &str) -> Result<Vec<bool>> {
    path.chars()
        .map(|c| match c {
            'R' | 'r' => Ok(true),
            'T' | 't' => Ok(false),
            _ => Err(HeronError::Invalid(format!(
                "--path: expected only the letters R (reflect) and T (transmit), got {c:?} in {path:?}"
            ))),
        })
        .collect()
}

fn arr(v: Vec3) -> [f32; 3] {
    v.to_array()
}

/// Traces from `origin` along `dir` (normalised here) at `lambda_nm`. `reflect_at[k]`
/// says whether the k-th dielectric event reflects (true) or transmits; past its end,
/// rays transmit.
pub fn trace(
    scene: &Scene,
    accel: &embree::Scene,
    origin: Vec3,
    dir: Vec3,
    lambda_nm: f32,
    reflect_at: &[bool],
) -> Result<TraceReport> {
    if !origin.is_finite() || !dir.is_finite() || dir.length_squared() == 0.0 {
        return Err(HeronError::Invalid(
            "--origin and --dir: expected finite vectors, --dir not zero".into(),
        ));
    }
    if !(crate::spectrum::LAMBDA_MIN..=crate::spectrum::LAMBDA_MAX).contains(&lambda_nm) {
        return Err(HeronError::Invalid(format!(
            "--lambda: expected a wavelength in 360–830 nm, got {lambda_nm}"
        )));
    }
    // Offsets as a render of the scene's own integrator would make them.
    let offset = scene.settings.ray_offset(scene.settings.integrator);
    let mut ray = Ray::new(origin, dir.normalize(), 0.0, f32::INFINITY);
    let mut events = Vec::new();
    let mut dielectric_events = 0usize;
    for _ in 0..=scene.settings.max_depth {
        let q = RayQuery {
            origin: ray.origin,
            dir: ray.dir,
            tnear: ray.t_min,
            tfar: ray.t_max,
        };
        let Some(hit) = accel.intersect1(&q) else {
            events.push(TraceEvent {
                kind: EventKind::Escape,
                position: arr(ray.origin),
                normal: None,
                material: None,
                n_i: None,
                n_t: None,
                incoming: arr(ray.dir),
                outgoing: Some(arr(ray.dir)),
                fresnel_r: None,
                distance: None,
            });
            return Ok(TraceReport {
                lambda_nm,
                events,
                truncated: false,
            });
        };
        let (it, material) = scene.interaction(&ray, &hit, offset.is_robust());
        let wo = -ray.dir;
        let mut ev = TraceEvent {
            kind: EventKind::Absorb,
            position: arr(it.position),
            normal: Some(arr(it.normal)),
            material: Some(scene.material_names[it.material as usize].clone()),
            n_i: Some(1.0),
            n_t: Some(1.0),
            incoming: arr(ray.dir),
            outgoing: None,
            fresnel_r: None,
            distance: Some(hit.t),
        };
        let flags = material.flags();
        let frame = it.frame();
        let wo_local = frame.to_local(wo);
        let wl = SampledWavelengths::<1>::new([lambda_nm], [1.0]);
        let spec = |side: LobeFlags| {
            let ctx = BsdfContext::radiance::<1>().with_lobes(LobeFlags::SPECULAR | side);
            material
                .sample(wo_local, 0.5, Vec2::ZERO, &wl, &ctx)
                .map(|b| frame.to_world(b.wi))
        };
        let two_sided_delta =
            flags.contains(LobeFlags::SPECULAR | LobeFlags::REFLECTION | LobeFlags::TRANSMISSION);
        let out = if two_sided_delta {
            if let Some(d) = material.interface() {
                let (ni, nt) = d.indices(lambda_nm, it.front_face);
                ev.n_i = Some(ni);
                ev.n_t = Some(nt);
                ev.fresnel_r = Some(d.fresnel_r(wo_local, lambda_nm));
            }
            let want_reflect = reflect_at.get(dielectric_events).copied().unwrap_or(false);
            dielectric_events += 1;
            match spec(LobeFlags::TRANSMISSION) {
                None => {
                    ev.kind = EventKind::TotalInternalReflection;
                    spec(LobeFlags::REFLECTION)
                }
                Some(_) if want_reflect => {
                    ev.kind = EventKind::Reflect;
                    // The lecture's pure refraction gives reflection no weight outside
                    // total internal reflection; the law of reflection still says where
                    // an R event goes.
                    spec(LobeFlags::REFLECTION).or(Some(crate::bsdf::reflect(wo, it.normal)))
                }
                Some(t) => {
                    ev.kind = EventKind::Refract;
                    Some(t)
                }
            }
        } else if flags.contains(LobeFlags::SPECULAR | LobeFlags::REFLECTION) {
            ev.kind = EventKind::Reflect;
            spec(LobeFlags::REFLECTION)
        } else {
            None
        };
        ev.outgoing = out.map(arr);
        events.push(ev);
        let Some(d) = out else {
            return Ok(TraceReport {
                lambda_nm,
                events,
                truncated: false,
            });
        };
        ray = offset.spawn(&it.spawn_point(), d);
    }
    Ok(TraceReport {
        lambda_nm,
        events,
        truncated: true,
    })
}
