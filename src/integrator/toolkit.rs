//! What every integrator needs, written once: the next hit along a ray, a light chosen
//! and sampled from a point with the choice folded into its density (Mitsuba 3's
//! `Scene::sample_emitter_direction`), the same density for a light a path reached by
//! itself (for MIS; `Scene::pdf_emitter_direction`), the start of a light path, Russian
//! roulette, the camera's pixel of a direction, and the shadow ray of a connection, with
//! the transmittance of media along it.
//!
//! Emitted radiance is the light's own (`Light::l` for surfaces, `Light::le` at
//! infinity), and whether a material's event ends the companion wavelengths is the
//! material's (`Material::eval`, `BsdfSample::ended_companions`): no integrator holds
//! either rule.
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::camera::Camera;
use crate::geometry::{Ray, SpawnPoint};
use crate::light::{LightLeSample, LightLiSample, SurfacePoint};
use crate::medium::NO_MEDIUM;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// The closest hit along `ray`: the one already traced (a camera ray's, from its
/// packet) when `pending` holds it, else a new query, counted.
#[inline(always)]
pub(crate) fn next_hit(
    ctx: &Context,
    ray: &Ray,
    pending: &mut Option<Option<Hit>>,
    counters: &mut TraceCounters,
) -> Option<Hit> {
    match pending.take() {
        Some(h) => h,
        None => {
            counters.rays += 1;
            ctx.accel.intersect1(&ray.query())
        }
    }
}

/// A light sampled from a point: the sample, and the density of choosing the light and
/// then the sample (the light sampler's pmf times the light's solid-angle density; for a
/// delta light, the pmf).
pub(crate) struct ChosenLight<const N: usize> {
    pub sample: LightLiSample<N>,
    pub pdf: f32,
}

/// Chooses a light with the scene's light sampler (`u_choice`) and samples a direction
/// toward it from `p` (`u`); None when no light emits, or the sample has no density or
/// no radiance.
#[inline(always)]
pub(crate) fn sample_light<const N: usize>(
    ctx: &Context,
    p: Vec3,
    u_choice: f32,
    u: Vec2,
    wl: &SampledWavelengths<N>,
) -> Option<ChosenLight<N>> {
    let scene = ctx.scene;
    let (index, pmf) = scene.light_sampler.sample(u_choice)?;
    let sample = scene.lights[index].sample_li(p, u, wl)?;
    if !(sample.pdf > 0.0) || sample.l.is_zero() {
        return None;
    }
    Some(ChosenLight {
        pdf: pmf * sample.pdf,
        sample,
    })
}

/// The density with which [`sample_light`] from `p` would have chosen light `index` and
/// the direction `wi` (reaching the light's surface at `hit`, for an area light): the
/// other strategy's density when a BSDF or phase sample reaches a light.
#[inline(always)]
pub(crate) fn light_pdf(
    ctx: &Context,
    index: usize,
    p: Vec3,
    wi: Vec3,
    hit: Option<&SurfacePoint>,
) -> f32 {
    let scene = ctx.scene;
    scene.light_sampler.pmf(index) * scene.lights[index].pdf_li(p, wi, hit)
}

/// Russian roulette (pbrt-v4 §13.4.2): from `rr_depth` on, a path whose throughput has
/// fallen to `rr` (< 1) of where it started survives with probability `rr` and is
/// reweighted by 1/rr; `u` decides. Returns false when the path ends.
#[inline(always)]
pub(crate) fn roulette<const N: usize>(
    beta: &mut SampledSpectrum<N>,
    rr: f32,
    depth: u32,
    rr_depth: u32,
    u: f32,
) -> bool {
    if rr < 1.0 && depth >= rr_depth {
        let q = (1.0 - rr).max(0.0);
        if u < q {
            return false;
        }
        *beta /= 1.0 - q;
    }
    true
}

/// The start of a light path: a light chosen by the scene's light sampler and a ray it
/// emits. Random numbers: the choice (1D), the position (2D), the direction (2D).
pub(crate) struct LightPathStart<const N: usize> {
    pub index: usize,
    /// The light sampler's probability of the light.
    pub pmf: f32,
    pub le: LightLeSample<N>,
}

impl<const N: usize> LightPathStart<N> {
    /// Draws the start; None when no light emits or the emitted ray carries nothing.
    #[inline]
    pub fn sample(
        ctx: &Context,
        wl: &SampledWavelengths<N>,
        sampler: &mut Sampler,
    ) -> Option<LightPathStart<N>> {
        let scene = ctx.scene;
        let u_light = sampler.get_1d();
        let u_pos = sampler.get_2d();
        let u_dir = sampler.get_2d();
        let (index, pmf) = scene.light_sampler.sample(u_light)?;
        let le = scene.lights[index].sample_le(u_pos, u_dir, wl, &scene.bounds)?;
        if !(le.pdf_pos > 0.0) || !(le.pdf_dir > 0.0) || le.l.is_zero() {
            return None;
        }
        Some(LightPathStart { index, pmf, le })
    }

    /// |cos| of the emitted direction at the light's surface (1 without one).
    #[inline]
    pub fn cos(&self) -> f32 {
        self.le.normal.map_or(1.0, |n| n.dot(self.le.dir).abs())
    }

    /// The throughput of the emitted ray: L |cos| / (pmf pdf_pos pdf_dir).
    #[inline]
    pub fn beta(&self) -> SampledSpectrum<N> {
        self.le.l * (self.cos() / (self.pmf * self.le.pdf_pos * self.le.pdf_dir))
    }
}

/// The pixel index of a film position (the `raster` of a connection to the camera).
#[inline]
pub(crate) fn pixel_of(cam: &Camera, raster: (f32, f32)) -> u32 {
    let x = (raster.0 as u32).min(cam.width - 1);
    let y = (raster.1 as u32).min(cam.height - 1);
    y * cam.width + x
}

/// Whether the shadow ray from `from` toward `to`, which lies along unit `wi` at
/// distance `dist` (infinite: a light at infinity), is blocked, with the cutoffs of the
/// render's `RayOffset` (the seed's: t_min = ε, t_max = dist − ε). Points too close to
/// tell apart count as blocked.
#[inline]
pub(crate) fn occluded(
    ctx: &Context,
    from: &SpawnPoint,
    wi: Vec3,
    dist: f32,
    to: &SpawnPoint,
    counters: &mut TraceCounters,
) -> bool {
    let Some(q) = ctx.offset.shadow(from, wi, dist, to) else {
        return true;
    };
    counters.shadow_rays += 1;
    ctx.accel.occluded1(&q)
}

/// The most boundaries a path or shadow ray crosses between two bounces.
pub(crate) const MAX_CROSSINGS: u32 = 256;

/// The transmittance of the shadow ray from `from` (in `medium`) toward `to` along unit
/// `wi` at distance `dist`: exp(−σ_t ℓ) for each stretch ℓ inside a medium, continuing
/// through index-matched medium boundaries; `None` when any other surface blocks it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn transmittance<const N: usize>(
    ctx: &Context,
    from: &SpawnPoint,
    wi: Vec3,
    dist: f32,
    to: &SpawnPoint,
    mut medium: u32,
    wl: &SampledWavelengths<N>,
    counters: &mut TraceCounters,
) -> Option<SampledSpectrum<N>> {
    let scene = ctx.scene;
    let mut tr = SampledSpectrum::<N>::splat(1.0);
    let mut q = ctx.offset.shadow(from, wi, dist, to)?;
    for _ in 0..MAX_CROSSINGS {
        // Robust shadow rays to a point have an unnormalised direction (t in its units).
        let scale = q.dir.length();
        // A closest-hit query: the nearest surface is either an occluder or a boundary
        // to cross (an any-hit query could not tell which). Counted as a shadow ray.
        counters.shadow_rays += 1;
        let hit = ctx.accel.intersect1(&q);
        let Some(h) = hit else {
            if medium != NO_MEDIUM {
                let len = q.tfar * scale;
                if !len.is_finite() {
                    return None;
                }
                tr *= scene.media[medium as usize].transmittance(len, wl);
            }
            return Some(tr);
        };
        let g = h.geom_id as usize;
        if !scene.shapes[g].interface {
            return None;
        }
        if medium != NO_MEDIUM {
            tr *= scene.media[medium as usize].transmittance(h.t * scale, wl);
        }
        let ray = Ray::new(q.origin, q.dir, q.tnear, q.tfar);
        let (it, _) = scene.interaction(&ray, &h, ctx.offset.is_robust());
        medium = if wi.dot(it.n_outward) < 0.0 {
            scene.shapes[g].medium
        } else {
            NO_MEDIUM
        };
        let rest = if dist.is_finite() {
            (to.p - it.position).length()
        } else {
            f32::INFINITY
        };
        q = ctx.offset.shadow(&it.spawn_point(), wi, rest, to)?;
    }
    None
}
