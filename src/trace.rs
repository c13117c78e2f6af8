//! `heron trace`: one ray at one wavelength through a scene, event by event, with the
//! renderer's own code (Embree queries, `Interaction`, the materials' `sample` restricted
//! to their delta lobes, the ε offset). For prism and droplet experiments.
//!
//! At a surface with a reflecting and a transmitting delta lobe (a smooth dielectric, or
//! the seed's glossy over glass) the ray refracts unless the `path` string says `R`
//! (reflect) or `T` (transmit) for that event; total internal reflection forces `R`.
//! Surfaces with only a reflecting delta lobe (mirrors, smooth metals) reflect; the
//! others (Lambertian, glossy, rough) absorb; a miss escapes.
//!
//! With a Stokes vector to start from (`heron trace --stokes`), each event also reports
//! the light's Stokes vector after it, as power: the event's Mueller matrix (the
//! material's, `BsdfModel::mueller`, scaled so that its [0][0] is the unpolarised power
//! fraction of the event, R or 1 − R) applied after rotating the vector into the
//! event's frame, and the frame's x̂ (the s direction of the plane of incidence at a
//! Fresnel event; `spectrum::stokes` has the convention). The light travels along the
//! traced ray.
//!
//! Embree finds the shape a ray hits; the hit itself (distance, and a triangle's
//! barycentrics and normal) is then recomputed in f64 from the shape's own description
//! ([`refine`]). Embree's kernels differ between instruction sets (AVX2, AVX-512) in the
//! last bits of t, which a minimum-deviation search over traced rays magnifies to the
//! fifth decimal of a degree; refined, a trace is the same on every x86 CPU, so the
//! figures of papers/ regenerate byte for byte wherever they are made.
use crate::accel::embree::{self, RayQuery};
use crate::bsdf::{BsdfContext, LobeFlags, Material};
use crate::geometry::{Interaction, Ray};
use crate::math::Frame;
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
    /// With `--stokes`: the light's Stokes vector after the event (power), in the frame
    /// whose x̂ is `stokes_x`; absent otherwise and after an absorption.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stokes: Option<[f64; 4]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stokes_x: Option<[f32; 3]>,
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
/// `hit` of `ray` recomputed in f64 from the shape hit (see the module documentation):
/// a sphere's root of |o + t d − c|² = r² nearest Embree's t, a triangle's plane
/// distance, barycentrics and normal (Möller & Trumbore 1997). A refinement that fails
/// (a grazing ray with no real root) keeps Embree's hit.
pub fn refine(scene: &Scene, ray: &Ray, hit: &embree::Hit) -> embree::Hit {
    use crate::geometry::ShapeKind;
    let o = ray.origin.as_dvec3();
    let d = ray.dir.as_dvec3();
    let mut out = *hit;
    match &scene.shapes[hit.geom_id as usize].kind {
        ShapeKind::Sphere { center, radius } => {
            let oc = o - center.as_dvec3();
            let a = d.dot(d);
            let b = oc.dot(d);
            let c = oc.dot(oc) - (*radius as f64) * (*radius as f64);
            let disc = b * b - a * c;
            if disc >= 0.0 && a > 0.0 {
                let q = disc.sqrt();
                let (t0, t1) = ((-b - q) / a, (-b + q) / a);
                let te = hit.t as f64;
                out.t = if (t0 - te).abs() <= (t1 - te).abs() {
                    t0
                } else {
                    t1
                } as f32;
            }
        }
        ShapeKind::Mesh(m) => {
            let [p0, p1, p2] = m.triangle(hit.prim_id).map(|p| p.as_dvec3());
            let (e1, e2) = (p1 - p0, p2 - p0);
            let pv = d.cross(e2);
            let det = e1.dot(pv);
            if det != 0.0 {
                let inv = 1.0 / det;
                let tv = o - p0;
                let u = tv.dot(pv) * inv;
                let qv = tv.cross(e1);
                let v = d.dot(qv) * inv;
                out.t = (e2.dot(qv) * inv) as f32;
                out.u = u as f32;
                out.v = v as f32;
                // Embree's orientation, its length recomputed.
                let n = e1.cross(e2);
                let n = if n.dot(hit.ng.as_dvec3()) < 0.0 {
                    -n
                } else {
                    n
                };
                out.ng = n.as_vec3();
            }
        }
    }
    out
}

pub fn trace(
    scene: &Scene,
    accel: &embree::Scene,
    origin: Vec3,
    dir: Vec3,
    lambda_nm: f32,
    reflect_at: &[bool],
    stokes: Option<[f64; 4]>,
) -> Result<TraceReport> {
    check_request(origin, dir, lambda_nm, stokes)?;
    // Offsets as a render of the scene's own integrator would make them.
    let offset = scene.settings.ray_offset(scene.settings.integrator);
    let mut ray = Ray::new(origin, dir.normalize(), 0.0, f32::INFINITY);
    // The light's state and its frame's x̂ (⊥ the ray), when asked.
    let mut pol = stokes.map(|st| (st, crate::spectrum::stokes::any_perpendicular(ray.dir)));
    let mut events = Vec::new();
    let mut dielectric_events = 0usize;
    let report = |events, truncated| TraceReport {
        lambda_nm,
        events,
        truncated,
    };
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
                outgoing: Some(arr(ray.dir)),
                stokes: pol.map(|p| p.0),
                stokes_x: pol.map(|p| arr(p.1)),
                ..TraceEvent::at(ray.origin, ray.dir)
            });
            return Ok(report(events, false));
        };
        let hit = refine(scene, &ray, &hit);
        let (it, material) = scene.interaction(&ray, &hit, offset.is_robust());
        let mut ev = TraceEvent {
            kind: EventKind::Absorb,
            normal: Some(arr(it.normal)),
            material: Some(scene.material_names[it.material as usize].clone()),
            n_i: Some(1.0),
            n_t: Some(1.0),
            distance: Some(hit.t),
            ..TraceEvent::at(it.position, ray.dir)
        };
        let surface = Surface::new(material, &it, -ray.dir, lambda_nm);
        let reflect = reflect_at.get(dielectric_events).copied().unwrap_or(false);
        let (out, dielectric) = surface.scatter(&mut ev, reflect);
        dielectric_events += usize::from(dielectric);
        ev.outgoing = out.map(arr);
        if let (Some(light), Some(d)) = (pol, out) {
            let after = surface.polarize(&ev, ray.dir, light, d);
            ev.stokes = Some(after.0);
            ev.stokes_x = Some(arr(after.1));
            pol = Some(after);
        }
        events.push(ev);
        let Some(d) = out else {
            return Ok(report(events, false));
        };
        ray = offset.spawn(&it.spawn_point(), d);
    }
    Ok(report(events, true))
}

/// The ray, the wavelength and the Stokes vector as asked, or what was expected.
fn check_request(origin: Vec3, dir: Vec3, lambda_nm: f32, stokes: Option<[f64; 4]>) -> Result<()> {
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
    if let Some(st) = stokes {
        let pol = (st[1] * st[1] + st[2] * st[2] + st[3] * st[3]).sqrt();
        if !st.iter().all(|v| v.is_finite()) || !(st[0] > 0.0) || pol > st[0] * (1.0 + 1e-9) {
            return Err(HeronError::Invalid(format!(
                "--stokes: expected S0,S1,S2,S3 with S0 > 0 and S1² + S2² + S3² ≤ S0² (a physical state), got {st:?}"
            )));
        }
    }
    Ok(())
}

impl TraceEvent {
    /// An event at `position` of a ray along `incoming`, its other fields empty.
    fn at(position: Vec3, incoming: Vec3) -> TraceEvent {
        TraceEvent {
            kind: EventKind::Absorb,
            position: arr(position),
            normal: None,
            material: None,
            n_i: None,
            n_t: None,
            incoming: arr(incoming),
            outgoing: None,
            fresnel_r: None,
            distance: None,
            stokes: None,
            stokes_x: None,
        }
    }
}

/// A hit's material in its local frame, at the traced wavelength.
struct Surface<'a> {
    material: &'a Material,
    frame: Frame,
    /// Toward where the ray came from: world and local.
    wo: Vec3,
    wo_local: Vec3,
    normal: Vec3,
    front_face: bool,
    lambda_nm: f32,
    wl: SampledWavelengths<1>,
}

impl<'a> Surface<'a> {
    fn new(material: &'a Material, it: &Interaction, wo: Vec3, lambda_nm: f32) -> Self {
        let frame = it.frame();
        Surface {
            material,
            frame,
            wo,
            wo_local: frame.to_local(wo),
            normal: it.normal,
            front_face: it.front_face,
            lambda_nm,
            wl: SampledWavelengths::<1>::new([lambda_nm], [1.0]),
        }
    }

    /// The material's delta lobe on `side` (reflection or transmission), in world space.
    fn specular(&self, side: LobeFlags) -> Option<Vec3> {
        let ctx = BsdfContext::radiance::<1>().with_lobes(LobeFlags::SPECULAR | side);
        self.material
            .sample(self.wo_local, 0.5, Vec2::ZERO, &self.wl, &ctx)
            .map(|b| self.frame.to_world(b.wi))
    }

    /// Where the ray goes on (`None`: absorbed), with the event's kind, indices and
    /// Fresnel reflectance written into `ev`; `reflect` is the path string's choice at a
    /// dielectric event. The second value says whether this was a dielectric event (one
    /// with a reflecting and a transmitting delta lobe), which uses up a choice.
    fn scatter(&self, ev: &mut TraceEvent, reflect: bool) -> (Option<Vec3>, bool) {
        let flags = self.material.flags();
        let two_sided_delta =
            flags.contains(LobeFlags::SPECULAR | LobeFlags::REFLECTION | LobeFlags::TRANSMISSION);
        if !two_sided_delta {
            if flags.contains(LobeFlags::SPECULAR | LobeFlags::REFLECTION) {
                ev.kind = EventKind::Reflect;
                return (self.specular(LobeFlags::REFLECTION), false);
            }
            return (None, false);
        }
        if let Some(d) = self.material.interface() {
            let (ni, nt) = d.indices(self.lambda_nm, self.front_face);
            ev.n_i = Some(ni);
            ev.n_t = Some(nt);
            ev.fresnel_r = Some(d.fresnel_r(self.wo_local, self.lambda_nm));
        }
        let out = match self.specular(LobeFlags::TRANSMISSION) {
            None => {
                ev.kind = EventKind::TotalInternalReflection;
                self.specular(LobeFlags::REFLECTION)
            }
            Some(_) if reflect => {
                ev.kind = EventKind::Reflect;
                // The lecture's pure refraction gives reflection no weight outside total
                // internal reflection; the law of reflection still says where an R event
                // goes.
                self.specular(LobeFlags::REFLECTION)
                    .or(Some(crate::bsdf::reflect(self.wo, self.normal)))
            }
            Some(t) => {
                ev.kind = EventKind::Refract;
                Some(t)
            }
        };
        (out, true)
    }

    /// The light's Stokes vector and frame x̂ after the event `ev` that sends the ray
    /// arriving along `incoming` on along `d`, from `(stokes, x)` before it.
    fn polarize(
        &self,
        ev: &TraceEvent,
        incoming: Vec3,
        (st, x): ([f64; 4], Vec3),
        d: Vec3,
    ) -> ([f64; 4], Vec3) {
        let flags = self.material.flags();
        // The material's ωi is where the light comes from (−ray), ωo where it goes.
        let fraction = match ev.kind {
            EventKind::Refract => 1.0 - ev.fresnel_r.unwrap_or(0.0) as f64,
            EventKind::TotalInternalReflection => 1.0,
            _ => ev.fresnel_r.map_or_else(
                || {
                    let ctx = BsdfContext::radiance::<1>()
                        .with_lobes(LobeFlags::SPECULAR | LobeFlags::REFLECTION);
                    self.material
                        .sample(self.wo_local, 0.5, Vec2::ZERO, &self.wl, &ctx)
                        .map_or(0.0, |b| b.weight().0[0] as f64)
                },
                |r| r as f64,
            ),
        };
        let frame = &self.frame;
        let (m, x_in, x_out) =
            match self
                .material
                .mueller(frame.to_local(d), self.wo_local, flags, &self.wl, frame)
            {
                crate::bsdf::Polarizing::Mueller { m, x_in, x_out } => {
                    (m[0], frame.to_world(x_in), frame.to_world(x_out))
                }
                crate::bsdf::Polarizing::Depolarizing => (
                    glam::Mat4::from_diagonal(glam::Vec4::new(1.0, 0.0, 0.0, 0.0)),
                    x,
                    crate::spectrum::stokes::any_perpendicular(d),
                ),
            };
        let r = crate::spectrum::stokes::rotate_basis(incoming, x, x_in);
        let v = glam::Vec4::new(st[0] as f32, st[1] as f32, st[2] as f32, st[3] as f32);
        let out_st = (m * (r * v)) * fraction as f32;
        (out_st.to_array().map(f64::from), x_out)
    }
}
