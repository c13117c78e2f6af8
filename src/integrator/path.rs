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
//! first reads its free-flight distance (1D); under `medium_nee = "forced"` then its
//! light sample's distance (1D), light choice (1D) and point on the light (2D), and
//! scattering there reads the lobe, direction and roulette; under `"collision"`
//! scattering reads the same five decisions as a surface. The lobe's number chooses
//! the sun guide's technique and then, rescaled, the phase table's wavelength node.
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
//!
//! Two estimators in media make fog and rain converge (issue 21; both unbiased, both
//! the defaults, BENCHMARKS.md "Rain and fog that converge"):
//!
//! - **Forced next-event estimation** (`MediumNee::Forced`): every segment through a
//!   medium, whether the free flight then collides in it or not, samples the light
//!   once from a point drawn with the hero's free-flight density truncated to the
//!   segment, σ e^{−σt}/(1 − e^{−σd}) (a forced collision: Kulla & Fajardo 2012,
//!   "Importance sampling techniques for path tracing in participating media", §3;
//!   Novák et al. 2018, "Monte Carlo methods for volumetric light transport
//!   simulation", §4). The free flight still decides where the path scatters, so the
//!   path continues as before; the light the continuation finds by phase sampling is
//!   the other technique of the balance heuristic. The two techniques draw the vertex
//!   with different distance densities, so each weight's denominator sums, over the
//!   lanes as heroes, the forced density times p_light and the free flight's density
//!   times q_λ(ω) T_λ, which is (1 − e^{−σ_λ d}) q_λ T_λ times the forced one.
//!   Optically thin segments, where a free flight seldom collides, are where it gains;
//!   in thick ones the two densities nearly coincide and it costs the same (one light
//!   sample per segment instead of per collision), so no per-segment switch is needed.
//! - **The sun guide** (`sun_guide` α): at a path's first two medium vertices, the new
//!   direction is drawn with probability α from the phase function about the
//!   direction toward the sun instead of about the path's direction; the density is
//!   the mixture q = (1 − α) p(d_in, ω) + α p(sun, ω) (Veach 1997, §9.2.4, one-sample
//!   MIS). Light scattered twice, a little off the sun's direction at the second
//!   vertex, then toward the camera, is where the old estimator's salt-and-pepper noise
//!   came from: the second vertex's light sample carries the phase function near its
//!   (truncated) forward peak, hundreds of times its mean, and the first vertex's phase
//!   sample seldom points there. The guide samples those directions in proportion.
//!
//! Transmittance in homogeneous media is exact (exp(−σ_t ℓ) per stretch, through
//! index-matched boundaries). In a heterogeneous medium (a `density` field,
//! `medium::tracking`) free flights are delta tracking against the density's majorant
//! grid and shadow rays ratio tracking (also through a medium whose drops vary with
//! height, `Medium::aloft`), each null collision updating the weights and
//! r_u, r_l as Miller et al. 2019 and pbrt-v4 §14.2 do, so the balance heuristic between
//! light and phase sampling holds across null vertices; there the light is sampled at
//! real collisions, since a forced collision needs the segment's transmittance in closed
//! form.
use super::capabilities::{Capabilities, Support};
use super::toolkit::{
    lane_mean, light_pdf, roulette, sample_light, Finish, PathState, ShadowSink, TransmittanceWalk,
    Vertex, MAX_CROSSINGS,
};
use super::transport::{Scatter, Tracer, Transport};
use super::{Context, Integrator, PixelIntegrator, StepIntegrator, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{LobeFlags, Material};
use crate::camera::CameraRay;
use crate::film::Splats;
use crate::geometry::{Interaction, Ray, SpawnPoint};
use crate::light::SurfacePoint;
use crate::math::warp::power_heuristic;
use crate::math::Frame;
use crate::math::Rng;
use crate::medium::tracking::{delta_tracking, Flight, Weights};
use crate::medium::{Density, Medium, MediumPoint, NO_MEDIUM};
use crate::sampler::Sampler;
use crate::scene::{Features, Scene, NO_LIGHT};
use crate::settings::{on, KernelFlags, MediumNee, Packets, EMITTERS, ESCAPE, MEDIA, SHADOWS};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// The path tracer.
pub struct PathTracer;

impl Integrator for PathTracer {
    const CAPABILITIES: Capabilities = Capabilities {
        lens: Support::Yes,
        orthographic: Support::Yes,
        media: true,
        polarization: Support::Yes,
        variance: Support::Yes,
        packets: true,
        auto_packets: Packets::Camera,
        camera_rays: true,
        steps: true,
        splats: false,
        kernel: Some(kernel_flags),
    };
}

/// The kernel flags the path tracer is specialised on: next-event estimation, emitters,
/// escaping rays and media (`scene::features`).
fn kernel_flags(f: &Features) -> KernelFlags {
    let bit = |on: bool, flag: KernelFlags| if on { flag } else { 0 };
    bit(f.nee, SHADOWS) | bit(f.emitters, EMITTERS) | bit(f.escape, ESCAPE) | bit(f.media, MEDIA)
}

impl PixelIntegrator for PathTracer {
    /// Radiance arriving along the camera ray `ray` at the wavelengths `wl`; for polarised
    /// transport `T`, the Stokes radiance in the camera's frame (`integrator::polarized`).
    ///
    /// `K` is the kernel ([`KernelFlags`]): without `SHADOWS` there is no next-event
    /// estimation (the scene has no light to sample, or no surface to light), without
    /// `EMITTERS` no emission lookup at hits, without `ESCAPE` nothing along escaping rays.
    /// The random numbers read per bounce are the same in every kernel.
    fn sample<const N: usize, const K: KernelFlags, T: Transport<N>>(
        ctx: &Context,
        cam: CameraRay,
        first_hit: Option<Option<Hit>>,
        wl: &SampledWavelengths<N>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        _: &mut Splats,
    ) -> T::Value {
        Self::sample_by_steps::<N, K, T>(ctx, cam, first_hit, wl, sampler, counters)
    }
}

impl StepIntegrator for PathTracer {
    /// The path's state at the camera: what [`StepIntegrator::step`] starts from.
    #[inline]
    fn start<const N: usize>(cam: &CameraRay) -> PathState<N> {
        PathState::at_camera(cam)
    }

    /// One step of the path whose ray `ray` has the closest hit `hit`: the segment through a
    /// medium, a boundary crossed, the light found along an escaping ray, or a surface
    /// vertex; `ray` becomes the next ray. Returns false when the path has ended. Shadow
    /// rays go to the tracer's sink (the packet engine traces them after the step, before
    /// the next); every contribution and every scattering event goes to its transport
    /// (nothing more for unpolarised transport, the Mueller product for
    /// `integrator::polarized`).
    #[inline(always)]
    fn step<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
        t: &mut Tracer<N, S, T>,
        s: &mut PathState<N>,
        ray: &mut Ray,
        hit: Option<Hit>,
    ) -> bool {
        let (ctx, wl) = (t.ctx, t.wl);
        let scene = ctx.scene;
        if on(K, MEDIA) && s.medium != NO_MEDIUM {
            // A closed boundary always stops a ray inside; a ray that escapes it leaked.
            let Some(h) = &hit else { return false };
            match medium_segment::<N, K, S, T>(t, s, ray, h) {
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
            // `[render] hide_emitters`: a camera ray that escapes before any scattering
            // event sees nothing (see `surface_vertex`).
            if on(K, ESCAPE) && !(s.depth == 0 && ctx.settings.hide_emitters) {
                for &i in &scene.infinite_lights {
                    let le = scene.lights[i as usize].le(ray.dir, wl);
                    if !le.is_zero() {
                        let (prev_p, dir) = (s.prev_p, ray.dir);
                        s.add_found_light::<K, S, T>(t, (i as usize, dir), le, mis, || {
                            light_pdf(ctx, i as usize, prev_p, dir, None)
                        });
                    }
                }
            }
            return false;
        };
        surface_vertex::<N, K, S, T>(t, s, ray, &hit, mis)
    }
}

impl<const N: usize> PathState<N> {
    /// Adds radiance `le` from a light the path reached by BSDF or phase sampling:
    /// whole after a delta lobe, else weighted against light sampling, whose density
    /// `p_light` gives (the power heuristic after a surface, the balance heuristic over
    /// the lanes after a medium vertex); `mis` is the lanes' mean r_u. `found` is the
    /// light's index and the ray's direction, for the transport.
    #[inline(always)]
    fn add_found_light<const K: KernelFlags, S, T: Transport<N>>(
        &mut self,
        t: &mut Tracer<N, S, T>,
        (light, dir): (usize, Vec3),
        le: SampledSpectrum<N>,
        mis: f32,
        p_light: impl FnOnce() -> f32,
    ) {
        if self.specular_bounce {
            t.found(&mut self.l, self.beta * le / mis, light, dir);
            return;
        }
        let p_l = p_light();
        let c = if on(K, MEDIA) && self.prev_medium {
            let d = lane_mean(self.r_u + self.r_l * p_l, self.bsdf_ctx.companions_alive);
            self.beta * le / d
        } else {
            self.beta * le * (power_heuristic(self.prev_pdf, p_l) / mis)
        };
        t.found(&mut self.l, c, light, dir);
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

/// The segment of `ray` inside the current medium up to `h`: under
/// [`MediumNee::Forced`] first a light sample from a point drawn within the segment;
/// then a free flight sampled by the hero's σ_t, and either scattering (under
/// [`MediumNee::Collision`] a light sample there, then a direction) or the surface, with
/// the lanes' weights and rescaled probabilities updated.
#[inline(always)]
fn medium_segment<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
    tc: &mut Tracer<N, S, T>,
    s: &mut PathState<N>,
    ray: &mut Ray,
    h: &Hit,
) -> Segment {
    let (ctx, wl) = (tc.ctx, tc.wl);
    let m = &ctx.scene.media[s.medium as usize];
    if let Some(density) = &m.density {
        return heterogeneous_segment::<N, K, S, T>(tc, s, ray, h, m, density);
    }
    let mp = m.at(0.0);
    let sigma_t = m.sigma_t(wl);
    let u_dist = tc.sampler.get_1d();
    let forced = on(K, SHADOWS) && ctx.settings.medium_nee == MediumNee::Forced;
    // Forced: each lane's chance 1 − e^{−σ_λ d} that a free flight collides within the
    // segment, the normalisation of its truncated distance density.
    let collide = if forced {
        SampledSpectrum(std::array::from_fn(|i| -(-sigma_t.0[i] * h.t).exp_m1()))
    } else {
        SampledSpectrum::splat(1.0)
    };
    if forced {
        let u_forced = tc.sampler.get_1d();
        let u_light = tc.sampler.get_1d();
        let u_light_point = tc.sampler.get_2d();
        if s.depth < ctx.settings.max_depth {
            let f = ForcedSample {
                dir: ray.dir,
                origin: ray.origin,
                d: h.t,
                sigma_t,
                collide,
                u: u_forced,
            };
            if let Some((ld, wi, light)) =
                forced_direct_light(tc, s, mp, &f, (u_light, u_light_point))
            {
                let v = Vertex::Medium {
                    medium: mp,
                    d_in: ray.dir,
                };
                tc.lit(&mut s.l, ld, Scatter::new(&v, wi, wi), light);
            }
        }
    }
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
    // Forced: the light technique's density of this vertex per lane, over the hero's
    // free-flight density that drew it (r_l's distance part: p_forced,λ / p_free,hero).
    let r_light = if forced {
        SampledSpectrum(std::array::from_fn(|i| {
            forced_pdf(sigma_t.0[i], tr.0[i], collide.0[i], h.t) / pdf
        }))
    } else {
        SampledSpectrum::splat(1.0)
    };
    s.beta *= m.sigma_s(wl) * tr / pdf;
    let r_before = s.r_u;
    s.r_u *= sigma_t * tr / pdf;
    medium_vertex::<N, K, S, T>(tc, s, ray, mp, t, forced.then_some((r_before, r_light)))
}

/// The segment of `ray` inside a heterogeneous medium up to `h`: delta tracking of the
/// hero's free flight through the density's majorants (`medium::tracking`), the null
/// collisions' weights and rescaled probabilities updated there, then the surface or a
/// real collision, where the light is sampled (next-event estimation at the collision:
/// [`MediumNee::Forced`]'s point drawn within the segment needs the segment's
/// transmittance in closed form, which a heterogeneous medium has not) and the
/// direction drawn as in a homogeneous medium. Reads the free flight's number (its first
/// distance; the rest come from a stream keyed by the ray) and then, at a collision, the
/// five numbers of a vertex.
#[inline(always)]
fn heterogeneous_segment<
    const N: usize,
    const K: KernelFlags,
    S: ShadowSink<N>,
    T: Transport<N>,
>(
    tc: &mut Tracer<N, S, T>,
    s: &mut PathState<N>,
    ray: &mut Ray,
    h: &Hit,
    m: &Medium,
    density: &Density,
) -> Segment {
    let wl = tc.wl;
    let k = m.majorant_sigma_t(wl);
    let mut rng = Rng::keyed(tc.sampler.stream_key(), 0);
    let u_dist = tc.sampler.get_1d();
    let (o, d) = (ray.origin, ray.dir);
    let mut w = Weights {
        beta: s.beta,
        r_u: s.r_u,
        r_l: s.r_l,
    };
    let at = |p| m.extinction_at(p, wl);
    let flight = delta_tracking(density, (o, d, h.t), k, at, u_dist, &mut rng, &mut w);
    (s.beta, s.r_u, s.r_l) = (w.beta, w.r_u, w.r_l);
    match flight {
        Flight::Escaped { tr } => {
            let pdf = tr.0[0];
            if !(pdf > 0.0) {
                return Segment::Ended;
            }
            s.beta *= tr / pdf;
            s.r_u *= tr / pdf;
            // Ratio tracking passes the last stretch with the same T̄.
            s.r_l *= tr / pdf;
            Segment::Crossed
        }
        Flight::Collided { t, sigma_t, tr } => {
            let pdf = tr.0[0] * sigma_t.0[0];
            if !(pdf > 0.0) {
                return Segment::Ended;
            }
            let (_, sigma_s, aloft) = m.coefficients_at(ray.at(t), wl);
            s.beta *= sigma_s * tr / pdf;
            s.r_u *= sigma_t * tr / pdf;
            medium_vertex::<N, K, S, T>(tc, s, ray, m.at(aloft), t, None)
        }
    }
}

/// A scattering event at distance `t` along `ray` in medium `m` (with its population of
/// drops there), the path's weight and r_u already holding the collision's density: the
/// light sample (at the collision, unless `forced` carries the forced light sample's
/// (r_u before the collision, its distance ratio), which r_l then takes), the new
/// direction and Russian roulette.
#[inline(always)]
fn medium_vertex<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
    tc: &mut Tracer<N, S, T>,
    s: &mut PathState<N>,
    ray: &mut Ray,
    m: MediumPoint,
    t: f32,
    forced: Option<(SampledSpectrum<N>, SampledSpectrum<N>)>,
) -> Segment {
    let (ctx, wl) = (tc.ctx, tc.wl);
    if s.depth == ctx.settings.max_depth || s.beta.is_zero() {
        return Segment::Ended;
    }
    s.depth += 1;
    let p = ray.at(t);
    let (u_light, u_light_point) = if forced.is_some() {
        (0.0, Vec2::ZERO)
    } else {
        (tc.sampler.get_1d(), tc.sampler.get_2d())
    };
    let u_node = tc.sampler.get_1d();
    let u_dir = tc.sampler.get_2d();
    let u_rr = tc.sampler.get_1d();
    let alive = s.bsdf_ctx.companions_alive;
    if on(K, SHADOWS) && forced.is_none() {
        let v = MediumVertex {
            p,
            dir: ray.dir,
            depth: s.depth,
            beta: s.beta,
            r_u: s.r_u,
            q_scale: SampledSpectrum::splat(1.0),
        };
        if let Some((ld, wi, light)) = light_from_medium(tc, s, m, &v, (u_light, u_light_point)) {
            let v = Vertex::Medium {
                medium: m,
                d_in: ray.dir,
            };
            tc.lit(&mut s.l, ld, Scatter::new(&v, wi, wi), light);
        }
    }
    let (wi, pv, q) = sample_direction(ctx, s.depth, m, ray.dir, u_node, u_dir, wl);
    let pdf = q.0[0];
    if !(pdf > 0.0) {
        return Segment::Ended;
    }
    s.beta *= pv / pdf;
    s.r_l = match forced {
        Some((r_before, r_light)) => r_before * r_light / pdf,
        None => s.r_u / pdf,
    };
    s.r_u *= q / pdf;
    s.specular_bounce = false;
    s.prev_medium = true;
    s.prev_p = p;
    s.prev_pdf = pdf;
    let v = Vertex::Medium {
        medium: m,
        d_in: ray.dir,
    };
    tc.scattered(Scatter::new(&v, wi, wi), LobeFlags::NONE);
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

/// The density of a free flight with extinction `sigma` truncated to [0, d] (a forced
/// collision) at the distance t where its transmittance is `tr` = e^{−σt}, given its
/// chance of colliding within the segment `collide` = 1 − e^{−σd}: σ e^{−σt} / (1 −
/// e^{−σd}); 1/d, its limit, when σ = 0.
#[inline]
fn forced_pdf(sigma: f32, tr: f32, collide: f32, d: f32) -> f32 {
    if collide > 0.0 {
        sigma * tr / collide
    } else {
        1.0 / d
    }
}

/// A segment through a medium and the number that draws its forced collision.
struct ForcedSample<const N: usize> {
    origin: Vec3,
    dir: Vec3,
    /// The segment's length.
    d: f32,
    sigma_t: SampledSpectrum<N>,
    /// 1 − e^{−σ_λ d} per lane.
    collide: SampledSpectrum<N>,
    u: f32,
}

/// The light sample of a segment through a medium under [`MediumNee::Forced`]: a point
/// at t ∈ [0, d) with the density of the hero's free flight truncated to the segment
/// (Kulla & Fajardo 2012, §3, "forced" distance sampling; Novák et al. 2018, §4.1), so
/// that a segment the path flies through unscattered still samples its in-scattered
/// light, and the light sampled there. Balance heuristic over (technique, hero) pairs
/// against phase sampling from a free-flight collision (the continuation): that
/// technique has the density σ_λ e^{−σ_λ t} q_λ(ω) T_λ(light) of reaching the same
/// vertex and leaving toward the light, which is (1 − e^{−σ_λ d}) q_λ T_λ times this
/// technique's density of the vertex.
#[inline(always)]
fn forced_direct_light<const N: usize, S: ShadowSink<N>, T: Transport<N>>(
    tc: &mut Tracer<N, S, T>,
    s: &PathState<N>,
    m: MediumPoint,
    f: &ForcedSample<N>,
    u: (f32, Vec2),
) -> Option<(SampledSpectrum<N>, Vec3, usize)> {
    let wl = tc.wl;
    let s0 = f.sigma_t.0[0];
    let c0 = f.collide.0[0];
    if !(s0 > 0.0 && c0 > 0.0) {
        return None;
    }
    // The inverse of the truncated exponential's distribution function.
    let t = (-(-f.u * c0).ln_1p() / s0).min(f.d);
    let tr = exp_neg(f.sigma_t, t);
    let p_hero = forced_pdf(s0, tr.0[0], c0, f.d);
    if !(p_hero > 0.0) {
        return None;
    }
    let beta = s.beta * m.medium.sigma_s(wl) * tr / p_hero;
    if beta.is_zero() {
        return None;
    }
    let r_u = s.r_u
        * SampledSpectrum(std::array::from_fn(|i| {
            forced_pdf(f.sigma_t.0[i], tr.0[i], f.collide.0[i], f.d) / p_hero
        }));
    let v = MediumVertex {
        p: f.origin + f.dir * t,
        dir: f.dir,
        depth: s.depth + 1,
        beta,
        r_u,
        q_scale: f.collide,
    };
    light_from_medium(tc, s, m, &v, u)
}

/// The medium vertices of a path, from its first, whose direction is drawn with the
/// sun guide. Guiding raises the variance of each vertex's weight (up to 1/(1 − α)),
/// which compounds over many scattering events: in a white furnace of optical radius 2
/// (tests/media_estimators.rs, 64 spp) guiding every vertex made the standard error
/// 4.7× that of the unguided estimator, guiding the first two 2.5×. The guide pays at the low orders of scattering, where light
/// scattered a little off the sun's direction is the bright part of the next vertex's
/// light sample; deep in a thick medium the sun is hidden and the field diffuse.
pub(crate) const GUIDED_VERTICES: u32 = 2;

/// The sun guide at a medium vertex of depth `depth` (1: the path's first scattering
/// event): the direction toward the sun and the fraction of phase samples drawn about
/// it, when the scene has a sun, the fraction is not 0 and the vertex is among the
/// first [`GUIDED_VERTICES`].
#[inline(always)]
fn sun_guide(ctx: &Context, depth: u32) -> Option<(Vec3, f32)> {
    let a = ctx.settings.sun_guide;
    if a > 0.0 && depth <= GUIDED_VERTICES {
        ctx.scene.sun_toward.map(|g| (g, a))
    } else {
        None
    }
}

/// The density per lane with which a medium vertex samples `wi`, given the phase
/// function there for the path's direction d_in, `phase`: the phase function itself, or
/// with a sun guide α the mixture (1 − α) p(d_in, wi) + α p(toward the sun, wi).
#[inline(always)]
fn direction_density<const N: usize>(
    ctx: &Context,
    depth: u32,
    m: MediumPoint,
    wi: Vec3,
    phase: SampledSpectrum<N>,
    wl: &SampledWavelengths<N>,
) -> SampledSpectrum<N> {
    match sun_guide(ctx, depth) {
        None => phase,
        Some((g, a)) => phase * (1.0 - a) + m.phase(g, wi, wl) * a,
    }
}

/// A direction from a medium vertex reached along `d_in`: with a sun guide α, with
/// probability α from the phase function about the direction toward the sun (so the
/// next vertex's light sample toward the sun, whose phase value can be hundreds of
/// times the phase function's mean, is made where it is large), else about `d_in`; one
/// sample of the mixture (Veach 1997, §9.2.4: the one-sample model with the balance
/// heuristic is the mixture density). `u_node` chooses the technique and then,
/// rescaled, the table's node. Returns the direction, the phase function there and the
/// sampling density per lane (lane 0's is the hero's).
#[inline(always)]
fn sample_direction<const N: usize>(
    ctx: &Context,
    depth: u32,
    m: MediumPoint,
    d_in: Vec3,
    u_node: f32,
    u_dir: Vec2,
    wl: &SampledWavelengths<N>,
) -> (Vec3, SampledSpectrum<N>, SampledSpectrum<N>) {
    let Some((g, a)) = sun_guide(ctx, depth) else {
        let (wi, pv) = m.sample_phase(d_in, u_node, u_dir, wl);
        return (wi, pv, pv);
    };
    let (wi, pv, pg) = if u_node < a {
        let (wi, pg) = m.sample_phase(g, u_node / a, u_dir, wl);
        (wi, m.phase(d_in, wi, wl), pg)
    } else {
        let u = ((u_node - a) / (1.0 - a)).min(1.0 - f32::EPSILON / 2.0);
        let (wi, pv) = m.sample_phase(d_in, u, u_dir, wl);
        (wi, pv, m.phase(g, wi, wl))
    };
    (wi, pv, pv * (1.0 - a) + pg * a)
}

/// A point in a medium where light is sampled: where it is, the direction the path
/// arrived along, its depth (for the sun guide), the path's throughput and rescaled
/// probabilities with the point's distance density in them, and the factor by which the
/// direction-sampling technique's density of the point differs from the light
/// technique's, per lane (1 at a free-flight collision, 1 − e^{−σ_λ d} at a forced one).
struct MediumVertex<const N: usize> {
    p: Vec3,
    dir: Vec3,
    depth: u32,
    beta: SampledSpectrum<N>,
    r_u: SampledSpectrum<N>,
    q_scale: SampledSpectrum<N>,
}

/// Next-event estimation at a medium point `v` (a free-flight collision under
/// [`MediumNee::Collision`], a forced one under [`MediumNee::Forced`]): a light sample,
/// its transmittance through the media on the way, and the balance heuristic over
/// (technique, hero) pairs against direction sampling, whose density toward the light
/// is q_λ(ω) T_λ (T_λ: the chance of flying there unscattered) times `q_scale`.
/// `u` is the light choice's number and the point on the light's. Returns the
/// contribution, the direction toward the light and the light's index.
#[inline(always)]
fn light_from_medium<const N: usize, S: ShadowSink<N>, T: Transport<N>>(
    t: &mut Tracer<N, S, T>,
    s: &PathState<N>,
    m: MediumPoint,
    v: &MediumVertex<N>,
    (u_light, u_light_point): (f32, Vec2),
) -> Option<(SampledSpectrum<N>, Vec3, usize)> {
    let (ctx, wl) = (t.ctx, t.wl);
    let cl = sample_light(ctx, v.p, u_light, u_light_point, wl)?;
    let ls = &cl.sample;
    let f = m.phase(v.dir, ls.wi, wl);
    if f.is_zero() {
        return None;
    }
    let q = v.q_scale * direction_density(ctx, v.depth, m, ls.wi, f, wl);
    let from = SpawnPoint::free(v.p);
    let walk = TransmittanceWalk::start(ctx, &from, ls.wi, ls.dist, &ls.target(), s.medium)
        .map(|w| w.keyed(u_light, u_light_point));
    let finish = Finish::Medium {
        beta: v.beta,
        f,
        q,
        l: ls.l,
        r_u: v.r_u,
        pdf: cl.pdf,
        delta: ls.delta,
        alive: s.bsdf_ctx.companions_alive,
    };
    t.shadows
        .transmit(ctx, walk, finish, wl, t.counters)
        .map(|c| (c, ls.wi, cl.index))
}

/// A surface vertex: the emission found there, next-event estimation, and the BSDF's
/// continuation with Russian roulette. Returns false when the path ends.
#[inline(always)]
fn surface_vertex<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
    t: &mut Tracer<N, S, T>,
    s: &mut PathState<N>,
    ray: &mut Ray,
    hit: &Hit,
    mis: f32,
) -> bool {
    let (ctx, wl) = (t.ctx, t.wl);
    let scene = ctx.scene;
    let (it, material) = scene.interaction(ray, hit, ctx.offset.is_robust());
    // Every query of this vertex's material sees its uv (zero unless textured).
    s.bsdf_ctx.uv = it.uv;
    let wo = -ray.dir;

    // Emission of an area light the path has reached, unless `[render] hide_emitters`
    // and the path has not scattered yet (`depth` counts scattering events, at surfaces
    // and in media, as Mitsuba 3's does: a camera ray that crossed a medium or an
    // index-matched boundary unscattered still sees the light directly, and it is
    // hidden, as in Mitsuba 3's volpath).
    let emitter = if on(K, EMITTERS) && !(s.depth == 0 && ctx.settings.hide_emitters) {
        scene.shapes[hit.geom_id as usize].light
    } else {
        NO_LIGHT
    };
    if emitter != NO_LIGHT {
        let le = scene.lights[emitter as usize].l(it.n_outward, wo, it.uv, wl);
        if !le.is_zero() {
            let (prev_p, dir) = (s.prev_p, ray.dir);
            let sp = SurfacePoint {
                p: it.position,
                n: it.n_outward,
            };
            s.add_found_light::<K, S, T>(t, (emitter as usize, dir), le, mis, || {
                light_pdf(ctx, emitter as usize, prev_p, dir, Some(&sp))
            });
        }
    }
    if s.depth == ctx.settings.max_depth {
        return false;
    }
    s.depth += 1;

    let u_light = t.sampler.get_1d();
    let u_light_point = t.sampler.get_2d();
    let u_lobe = t.sampler.get_1d();
    let u_dir = t.sampler.get_2d();
    let u_rr = t.sampler.get_1d();

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
        if let Some((ld, wi, wi_local, light)) =
            surface_direct_light::<N, K, S, T>(t, s, &v, mis, (u_light, u_light_point))
        {
            let v = Vertex::Surface {
                material,
                frame: &frame,
                wo_local,
            };
            t.lit(
                &mut s.l,
                ld,
                Scatter {
                    v: &v,
                    wi,
                    wi_local,
                },
                light,
            );
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
    let wi = frame.to_world(bs.wi);
    let v = Vertex::Surface {
        material,
        frame: &frame,
        wo_local,
    };
    let at = Scatter {
        v: &v,
        wi,
        wi_local: bs.wi,
    };
    t.scattered(at, bs.flags);
    *ray = ctx.offset.spawn(&it.spawn_point(), wi);
    if on(K, MEDIA) && bs.is_transmission() && !material.is_sheet() {
        // Through a dielectric around a medium (a glass of milk) into or out of it; a
        // sheet inside a medium leaves the path in it.
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
/// the way (kernels with `MEDIA`) or past occluders. Returns the contribution, the
/// direction toward the light (world and local) and the light's index; `u` is the light
/// choice's number and the point on the light's.
#[inline(always)]
fn surface_direct_light<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
    t: &mut Tracer<N, S, T>,
    s: &PathState<N>,
    v: &SurfaceVertex,
    mis: f32,
    (u_light, u_light_point): (f32, Vec2),
) -> Option<(SampledSpectrum<N>, Vec3, Vec3, usize)> {
    let (ctx, wl) = (t.ctx, t.wl);
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
        return t
            .shadows
            .test(ctx, q, t.counters, || {
                s.beta * f * ls.l * (weight(cl.pdf) / (cl.pdf * mis))
            })
            .map(|c| (c, ls.wi, wi_local, cl.index));
    }
    // Through media: the transmittance of the shadow ray (None: blocked).
    let from = if v.material.is_sheet() {
        // Past a sheet the light is in the medium the path is in.
        s.medium
    } else if ls.wi.dot(it.n_outward) < 0.0 {
        ctx.scene.shapes[v.geom as usize].medium
    } else {
        medium_outside(s.medium, ctx.scene, v.geom)
    };
    let walk = TransmittanceWalk::start(ctx, &it.spawn_point(), ls.wi, ls.dist, &ls.target(), from)
        .map(|w| w.keyed(u_light, u_light_point));
    let finish = Finish::Surface {
        beta: s.beta,
        f,
        l: ls.l,
        scale: weight(cl.pdf) / (cl.pdf * mis),
    };
    t.shadows
        .transmit(ctx, walk, finish, wl, t.counters)
        .map(|c| (c, ls.wi, wi_local, cl.index))
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
