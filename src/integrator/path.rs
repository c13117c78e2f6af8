//! A spectral unidirectional path tracer (Kajiya 1986) with next-event estimation and
//! multiple importance sampling (Veach & Guibas 1995; Veach 1997 ch. 9), in the shape of
//! pbrt-v4's `PathIntegrator` (§13.4).
//!
//! At every surface with a non-delta lobe, one light is chosen by the scene's light
//! sampler (by power, or uniformly) and sampled for a direction; the BSDF then samples
//! the continuation. Light found both ways (area lights, the sun's disk, the
//! environment) is weighted by the power heuristic (β = 2) between the two densities;
//! delta lights and delta lobes have one strategy each and weight 1. Russian roulette
//! starts at `rr_depth` on the throughput with the η² of refractions undone; paths stop
//! after `max_depth` scattering events (max_depth = 1 is direct lighting).
//!
//! Wavelengths: the lanes travel together until a wavelength-dependent event (a
//! refraction by a dispersive interface) ends the companions (see `bsdf`); the MIS
//! densities are the hero's throughout, and `eval` treats each (ωo, ωi) as `sample`
//! does, so both strategies stay unbiased per lane.
//!
//! Random numbers: after the camera's pixel position (2D) and wavelengths (1D), each
//! bounce reads, in this order, the light choice (1D), the point on the light (2D), the
//! lobe (1D), the direction (2D) and the roulette (1D), whether or not it uses them, so
//! that a dimension always means the same decision. A segment of a path inside a medium
//! first reads its free-flight distance (1D); scattering there reads the same five
//! decisions as a surface (the lobe's number chooses the phase table's wavelength node).
//!
//! Participating media (kernels with `MEDIA`; `medium`): the path knows the medium it is
//! in (the camera is outside every medium), entering a shape's medium when it crosses the
//! shape's surface against the outward normal and leaving it (to no medium: media do not
//! nest or overlap) the other way; a medium's index-matched boundary (a shape with a
//! medium and no material) is crossed without a bounce. In a medium the hero's σ_t
//! samples the free-flight distance t ~ σ_t e^{−σ_t t} (exact for homogeneous media: the
//! majorant is σ_t); the other lanes are weighted by their ratios, and every contribution
//! is divided by the lanes' mean of the rescaled path probabilities r_u (p_λ(path) /
//! p_hero(path)), the balance heuristic over which lane was the hero (Wilkie et al. 2014,
//! "Hero wavelength spectral sampling", §4; pbrt-v4 §14.2's `r_u`, `r_l`). At a
//! scattering event the light is sampled (next-event estimation, with the exact
//! transmittance exp(−σ_t d) of the media along the shadow ray, which continues through
//! index-matched boundaries) and the hero's tabulated phase function samples the
//! continuation; the two are combined by the balance heuristic over (technique, hero)
//! pairs: a light sample's weight has the denominator mean_λ r_u (p_light + p_λ(ω) T_λ),
//! where T_λ is the phase sample's chance of flying to the light unscattered. When a
//! dispersive refraction has ended the companions, the hero's own densities are used.
use super::toolkit::{
    lane_mean, light_pdf, next_hit, roulette, sample_light, Finish, Immediate, PathState,
    ShadowSink, TransmittanceWalk, MAX_CROSSINGS,
};
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::Material;
use crate::geometry::{Interaction, Ray, SpawnPoint};
use crate::light::SurfacePoint;
use crate::math::warp::power_heuristic;
use crate::math::Frame;
use crate::medium::{Medium, NO_MEDIUM};
use crate::sampler::Sampler;
use crate::scene::{Scene, NO_LIGHT};
use crate::settings::{on, KernelFlags, EMITTERS, ESCAPE, MEDIA, SHADOWS};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// Radiance arriving along the camera ray `ray` at the wavelengths `wl`.
///
/// `K` is the kernel ([`KernelFlags`]): without `SHADOWS` there is no next-event
/// estimation (the scene has no light to sample, or no surface to light), without
/// `EMITTERS` no emission lookup at hits, without `ESCAPE` nothing along escaping rays.
/// The random numbers read per bounce are the same in every kernel.
pub fn radiance<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    mut ray: Ray,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> SampledSpectrum<N> {
    let mut s = PathState::<N>::start(ray.origin);
    let mut pending = first_hit;
    loop {
        let hit = next_hit(ctx, &ray, &mut pending, counters);
        if !step::<N, K, _>(
            ctx,
            &mut s,
            &mut ray,
            hit,
            wl,
            sampler,
            counters,
            &mut Immediate,
        ) {
            break;
        }
    }
    s.l
}

/// The path's state at the camera: what [`step`] starts from.
#[inline]
pub fn start<const N: usize>(origin: Vec3) -> PathState<N> {
    PathState::start(origin)
}

/// One step of the path whose ray `ray` has the closest hit `hit`: the segment through a
/// medium, a boundary crossed, the light found along an escaping ray, or a surface
/// vertex; `ray` becomes the next ray. Returns false when the path has ended. Shadow
/// rays go to `shadows` (the packet engine traces them after the step, before the next).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn step<const N: usize, const K: KernelFlags, S: ShadowSink<N>>(
    ctx: &Context,
    s: &mut PathState<N>,
    ray: &mut Ray,
    hit: Option<Hit>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut S,
) -> bool {
    let scene = ctx.scene;
    if on(K, MEDIA) && s.medium != NO_MEDIUM {
        // A closed boundary always stops a ray inside; a ray that escapes it leaked.
        let Some(h) = &hit else { return false };
        match medium_segment::<N, K, S>(ctx, s, ray, h, wl, sampler, counters, shadows) {
            Segment::Scattered => return true,
            Segment::Ended => return false,
            Segment::Crossed => {}
        }
    }
    if on(K, MEDIA) {
        if let Some(h) = &hit {
            if scene.shapes[h.geom_id as usize].interface {
                // An index-matched boundary: cross it, switching media, no bounce.
                let (it, _) = scene.interaction(ray, h, ctx.offset.is_robust());
                s.medium = if ray.dir.dot(it.n_outward) < 0.0 {
                    scene.shapes[h.geom_id as usize].medium
                } else {
                    NO_MEDIUM
                };
                s.crossings += 1;
                if s.crossings > MAX_CROSSINGS {
                    return false;
                }
                *ray = ctx.offset.spawn(&it.spawn_point(), ray.dir);
                return true;
            }
        }
    }
    // The lanes' mean of r_u (1 without media) divides every contribution found.
    let mis = if on(K, MEDIA) {
        lane_mean(s.r_u, s.bsdf_ctx.companions_alive)
    } else {
        1.0
    };
    let Some(hit) = hit else {
        if on(K, ESCAPE) {
            for &i in &scene.infinite_lights {
                let le = scene.lights[i as usize].le(ray.dir, wl);
                if !le.is_zero() {
                    let (prev_p, dir) = (s.prev_p, ray.dir);
                    s.add_found_light::<K>(le, mis, || {
                        light_pdf(ctx, i as usize, prev_p, dir, None)
                    });
                }
            }
        }
        return false;
    };
    surface_vertex::<N, K, S>(ctx, s, ray, &hit, mis, wl, sampler, counters, shadows)
}

impl<const N: usize> PathState<N> {
    /// Adds radiance `le` from a light the path reached by BSDF or phase sampling:
    /// whole after a delta lobe, else weighted against light sampling, whose density
    /// `p_light` gives (the power heuristic after a surface, the balance heuristic over
    /// the lanes after a medium vertex); `mis` is the lanes' mean r_u.
    #[inline(always)]
    fn add_found_light<const K: KernelFlags>(
        &mut self,
        le: SampledSpectrum<N>,
        mis: f32,
        p_light: impl FnOnce() -> f32,
    ) {
        if self.specular_bounce {
            self.l += self.beta * le / mis;
            return;
        }
        let p_l = p_light();
        if on(K, MEDIA) && self.prev_medium {
            let d = lane_mean(self.r_u + self.r_l * p_l, self.bsdf_ctx.companions_alive);
            self.l += self.beta * le / d;
        } else {
            self.l += self.beta * le * (power_heuristic(self.prev_pdf, p_l) / mis);
        }
    }
}

/// How a segment through a medium ended.
enum Segment {
    /// It scattered in the medium; the ray now leaves that vertex.
    Scattered,
    /// The path ended there.
    Ended,
    /// It reached the surface it was traced to, unscattered.
    Crossed,
}

/// The segment of `ray` inside the current medium up to `h`: a free flight sampled by
/// the hero's σ_t, then either scattering (next-event estimation and a phase sample) or
/// the surface, with the lanes' weights and rescaled probabilities updated.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn medium_segment<const N: usize, const K: KernelFlags, S: ShadowSink<N>>(
    ctx: &Context,
    s: &mut PathState<N>,
    ray: &mut Ray,
    h: &Hit,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut S,
) -> Segment {
    let m = &ctx.scene.media[s.medium as usize];
    let sigma_t = m.sigma_t(wl);
    let u_dist = sampler.get_1d();
    let s0 = sigma_t.0[0];
    let t = if s0 > 0.0 {
        -(1.0 - u_dist).ln() / s0
    } else {
        f32::INFINITY
    };
    if t >= h.t {
        // Flew to the boundary (or a surface inside) unscattered.
        let tr = exp_neg(sigma_t, h.t);
        let pdf = tr.0[0];
        if !(pdf > 0.0) {
            return Segment::Ended;
        }
        s.beta *= tr / pdf;
        s.r_u *= tr / pdf;
        s.r_l /= pdf;
        return Segment::Crossed;
    }
    // A collision: scattering with probability σ_s/σ_t per lane, in the weight.
    let tr = exp_neg(sigma_t, t);
    let pdf = tr.0[0] * s0;
    s.beta *= m.sigma_s(wl) * tr / pdf;
    s.r_u *= sigma_t * tr / pdf;
    if s.depth == ctx.settings.max_depth || s.beta.is_zero() {
        return Segment::Ended;
    }
    s.depth += 1;
    let p = ray.at(t);
    let u_light = sampler.get_1d();
    let u_light_point = sampler.get_2d();
    let u_node = sampler.get_1d();
    let u_dir = sampler.get_2d();
    let u_rr = sampler.get_1d();
    let alive = s.bsdf_ctx.companions_alive;
    if on(K, SHADOWS) {
        if let Some(ld) = medium_direct_light(
            ctx,
            s,
            m,
            ray.dir,
            p,
            u_light,
            u_light_point,
            wl,
            counters,
            shadows,
        ) {
            s.l += ld;
        }
    }
    let (wi, pv) = m.sample_phase(ray.dir, u_node, u_dir, wl);
    let pdf = pv.0[0];
    if !(pdf > 0.0) {
        return Segment::Ended;
    }
    s.beta *= pv / pdf;
    s.r_l = s.r_u / pdf;
    s.r_u *= pv / pdf;
    s.specular_bounce = false;
    s.prev_medium = true;
    s.prev_p = p;
    s.prev_pdf = pdf;
    *ray = Ray::new(p, wi, 0.0, f32::INFINITY);
    if s.beta.is_zero() {
        return Segment::Ended;
    }
    let rr = s.beta.max_value() * s.eta_scale / lane_mean(s.r_u, alive);
    if !roulette(&mut s.beta, rr, s.depth, ctx.settings.rr_depth, u_rr) {
        return Segment::Ended;
    }
    Segment::Scattered
}

/// Next-event estimation at a scattering event in medium `m` at `p` (the ray arrived
/// along `dir`): a light sample, its transmittance through the media on the way, and the
/// balance heuristic over (technique, hero) pairs against phase sampling, whose density
/// toward the light is p_λ(ω) T_λ (the chance of flying there unscattered).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn medium_direct_light<const N: usize, S: ShadowSink<N>>(
    ctx: &Context,
    s: &PathState<N>,
    m: &Medium,
    dir: Vec3,
    p: Vec3,
    u_light: f32,
    u_light_point: Vec2,
    wl: &SampledWavelengths<N>,
    counters: &mut TraceCounters,
    shadows: &mut S,
) -> Option<SampledSpectrum<N>> {
    let cl = sample_light(ctx, p, u_light, u_light_point, wl)?;
    let ls = &cl.sample;
    let f = m.phase(dir, ls.wi, wl);
    if f.is_zero() {
        return None;
    }
    let from = SpawnPoint::free(p);
    let walk = TransmittanceWalk::start(ctx, &from, ls.wi, ls.dist, &ls.target(), s.medium);
    let finish = Finish::Medium {
        beta: s.beta,
        f,
        l: ls.l,
        r_u: s.r_u,
        pdf: cl.pdf,
        delta: ls.delta,
        alive: s.bsdf_ctx.companions_alive,
    };
    shadows.transmit(ctx, walk, finish, wl, counters)
}

/// A surface vertex: the emission found there, next-event estimation, and the BSDF's
/// continuation with Russian roulette. Returns false when the path ends.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn surface_vertex<const N: usize, const K: KernelFlags, S: ShadowSink<N>>(
    ctx: &Context,
    s: &mut PathState<N>,
    ray: &mut Ray,
    hit: &Hit,
    mis: f32,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut S,
) -> bool {
    let scene = ctx.scene;
    let (it, material) = scene.interaction(ray, hit, ctx.offset.is_robust());
    let wo = -ray.dir;

    // Emission of an area light the path has reached.
    let emitter = if on(K, EMITTERS) {
        scene.shapes[hit.geom_id as usize].light
    } else {
        NO_LIGHT
    };
    if emitter != NO_LIGHT {
        let le = scene.lights[emitter as usize].l(it.n_outward, wo, wl);
        if !le.is_zero() {
            let (prev_p, dir) = (s.prev_p, ray.dir);
            let sp = SurfacePoint {
                p: it.position,
                n: it.n_outward,
            };
            s.add_found_light::<K>(le, mis, || {
                light_pdf(ctx, emitter as usize, prev_p, dir, Some(&sp))
            });
        }
    }
    if s.depth == ctx.settings.max_depth {
        return false;
    }
    s.depth += 1;

    let u_light = sampler.get_1d();
    let u_light_point = sampler.get_2d();
    let u_lobe = sampler.get_1d();
    let u_dir = sampler.get_2d();
    let u_rr = sampler.get_1d();

    let frame = it.frame();
    let wo_local = frame.to_local(wo);
    if on(K, SHADOWS) && material.flags().has_non_specular() {
        let v = SurfaceVertex {
            it: &it,
            geom: hit.geom_id,
            material,
            frame: &frame,
            wo_local,
        };
        if let Some(ld) = surface_direct_light::<N, K, S>(
            ctx,
            s,
            &v,
            mis,
            u_light,
            u_light_point,
            wl,
            counters,
            shadows,
        ) {
            s.l += ld;
        }
    }

    // The continuation.
    let Some(bs) = material.sample(wo_local, u_lobe, u_dir, wl, &s.bsdf_ctx) else {
        return false;
    };
    s.beta *= bs.weight();
    s.specular_bounce = bs.is_specular();
    s.prev_medium = false;
    s.prev_pdf = bs.pdf;
    s.prev_p = it.position;
    if bs.ended_companions {
        s.bsdf_ctx.companions_alive = false;
    }
    if bs.is_transmission() {
        s.eta_scale *= bs.eta * bs.eta;
    }
    *ray = ctx.offset.spawn(&it.spawn_point(), frame.to_world(bs.wi));
    if on(K, MEDIA) && bs.is_transmission() {
        // Through a dielectric around a medium (a glass of milk) into or out of it.
        s.medium = if ray.dir.dot(it.n_outward) < 0.0 {
            scene.shapes[hit.geom_id as usize].medium
        } else {
            medium_outside(s.medium, scene, hit.geom_id)
        };
    }
    if s.beta.is_zero() {
        return false;
    }
    // Russian roulette (pbrt-v4 §13.4.2): on the throughput with refractions' η²
    // undone, so a path inside glass is not ended for having crossed into it (and,
    // with media, divided by the lanes' mean r_u, as contributions are).
    let rr = s.beta.max_value() * s.eta_scale / mis;
    roulette(&mut s.beta, rr, s.depth, ctx.settings.rr_depth, u_rr)
}

/// Where a surface vertex is and what scatters there.
struct SurfaceVertex<'a> {
    it: &'a Interaction,
    geom: u32,
    material: &'a Material,
    frame: &'a Frame,
    wo_local: Vec3,
}

/// Next-event estimation at a surface vertex: a light sample, weighted by the power
/// heuristic against the BSDF's density (delta lights: weight 1), through the media on
/// the way (kernels with `MEDIA`) or past occluders.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn surface_direct_light<const N: usize, const K: KernelFlags, S: ShadowSink<N>>(
    ctx: &Context,
    s: &PathState<N>,
    v: &SurfaceVertex,
    mis: f32,
    u_light: f32,
    u_light_point: Vec2,
    wl: &SampledWavelengths<N>,
    counters: &mut TraceCounters,
    shadows: &mut S,
) -> Option<SampledSpectrum<N>> {
    let it = v.it;
    let cl = sample_light(ctx, it.position, u_light, u_light_point, wl)?;
    let ls = &cl.sample;
    let wi_local = v.frame.to_local(ls.wi);
    let f = v.material.eval(v.wo_local, wi_local, wl, &s.bsdf_ctx).f * wi_local.z.abs();
    if f.is_zero() {
        return None;
    }
    let weight = |cl_pdf: f32| {
        if ls.delta {
            1.0
        } else {
            power_heuristic(
                cl_pdf,
                v.material.pdf(v.wo_local, wi_local, wl, &s.bsdf_ctx),
            )
        }
    };
    if !on(K, MEDIA) {
        // Past occluders: the shadow ray, traced now or with the packet's.
        let q = ctx
            .offset
            .shadow(&it.spawn_point(), ls.wi, ls.dist, &ls.target());
        return shadows.test(ctx, q, counters, || {
            s.beta * f * ls.l * (weight(cl.pdf) / (cl.pdf * mis))
        });
    }
    // Through media: the transmittance of the shadow ray (None: blocked).
    let from = if ls.wi.dot(it.n_outward) < 0.0 {
        ctx.scene.shapes[v.geom as usize].medium
    } else {
        medium_outside(s.medium, ctx.scene, v.geom)
    };
    let walk = TransmittanceWalk::start(ctx, &it.spawn_point(), ls.wi, ls.dist, &ls.target(), from);
    let finish = Finish::Surface {
        beta: s.beta,
        f,
        l: ls.l,
        scale: weight(cl.pdf) / (cl.pdf * mis),
    };
    shadows.transmit(ctx, walk, finish, wl, counters)
}

/// exp(−σ_t d) per lane.
#[inline]
fn exp_neg<const N: usize>(sigma_t: SampledSpectrum<N>, d: f32) -> SampledSpectrum<N> {
    SampledSpectrum(std::array::from_fn(|i| (-sigma_t.0[i] * d).exp()))
}

/// The medium on the outer side of shape `geom`'s surface for a path now in `current`:
/// none when the path was in the shape's own medium (media do not nest), else `current`.
#[inline]
fn medium_outside(current: u32, scene: &Scene, geom: u32) -> u32 {
    if current == scene.shapes[geom as usize].medium {
        NO_MEDIUM
    } else {
        current
    }
}
