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
use crate::accel::embree::{Hit, RayQuery};
use crate::bsdf::{BsdfContext, Material};
use crate::camera::{Camera, CameraRay};
use crate::film::tile::SampleValue;
use crate::film::Splats;
use crate::geometry::{Ray, SpawnPoint};
use crate::light::{LightLeSample, LightLiSample, SurfacePoint};
use crate::math::{Frame, Rng};
use crate::medium::tracking::ratio_tracking;
use crate::medium::{MediumPoint, NO_MEDIUM};
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
    /// The light's index in `Scene::lights`.
    pub index: usize,
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
        index,
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

/// The most boundaries a path or shadow ray crosses between two bounces.
pub(crate) const MAX_CROSSINGS: u32 = 256;

/// The transmittance of a shadow ray from a point in a medium toward a target: exp(−σ_t ℓ)
/// for each stretch ℓ inside a medium, continuing through index-matched medium
/// boundaries, blocked by any other surface. Walked one closest-hit query at a time (an
/// any-hit query could not tell an occluder from a boundary to cross), so that the
/// packet engine can send the queries of several paths' walks together; each query
/// counts as a shadow ray.
#[derive(Clone, Copy)]
pub(crate) struct TransmittanceWalk<const N: usize> {
    /// The next query.
    pub q: RayQuery,
    tr: SampledSpectrum<N>,
    /// The light technique's relative density of the null vertices ratio tracking made
    /// in heterogeneous media (`medium::tracking`); 1 through homogeneous ones.
    a: SampledSpectrum<N>,
    medium: u32,
    wi: Vec3,
    dist: f32,
    to: SpawnPoint,
    queries: u32,
    /// The light sample's numbers, which key ratio tracking's streams (one per
    /// stretch): the pixel sample's and decision's own, whichever engine traced the ray,
    /// and hashed only where a heterogeneous medium needs them.
    key: (f32, Vec2),
}

/// What one query of a walk found.
pub(crate) enum WalkStep<const N: usize> {
    /// A boundary crossed: the walk goes on with its next query.
    Next,
    /// The target reached, with the transmittance along the way and the light
    /// technique's relative density of its null vertices.
    Done(SampledSpectrum<N>, SampledSpectrum<N>),
    /// Another surface, too many boundaries, or points too close to tell apart.
    Blocked,
}

impl<const N: usize> TransmittanceWalk<N> {
    /// The walk from `from` (in `medium`) toward `to`; `None` when blocked at once.
    #[inline]
    pub fn start(
        ctx: &Context,
        from: &SpawnPoint,
        wi: Vec3,
        dist: f32,
        to: &SpawnPoint,
        medium: u32,
    ) -> Option<Self> {
        Some(TransmittanceWalk {
            q: ctx.offset.shadow(from, wi, dist, to)?,
            tr: SampledSpectrum::splat(1.0),
            a: SampledSpectrum::splat(1.0),
            medium,
            wi,
            dist,
            to: *to,
            queries: 0,
            key: (0.0, Vec2::ZERO),
        })
    }

    /// The walk with ratio tracking's streams keyed by the light sample's numbers.
    #[inline]
    pub fn keyed(self, u_light: f32, u_point: Vec2) -> Self {
        TransmittanceWalk {
            key: (u_light, u_point),
            ..self
        }
    }

    /// Takes the closest hit `hit` of the walk's query `q`.
    #[inline]
    pub fn advance(
        &mut self,
        ctx: &Context,
        hit: Option<Hit>,
        wl: &SampledWavelengths<N>,
    ) -> WalkStep<N> {
        let scene = ctx.scene;
        let q = self.q;
        // Robust shadow rays to a point have an unnormalised direction (t in its units).
        let scale = q.dir.length();
        self.queries += 1;
        let Some(h) = hit else {
            if self.medium != NO_MEDIUM {
                let len = q.tfar * scale;
                if !len.is_finite() {
                    return WalkStep::Blocked;
                }
                self.stretch(ctx, len, wl);
            }
            return WalkStep::Done(self.tr, self.a);
        };
        let g = h.geom_id as usize;
        if !scene.shapes[g].interface {
            return WalkStep::Blocked;
        }
        if self.medium != NO_MEDIUM {
            self.stretch(ctx, h.t * scale, wl);
        }
        let ray = Ray::new(q.origin, q.dir, q.tnear, q.tfar);
        let (it, _) = scene.interaction(&ray, &h, ctx.offset.is_robust());
        self.medium = if self.wi.dot(it.n_outward) < 0.0 {
            scene.shapes[g].medium
        } else {
            NO_MEDIUM
        };
        let rest = if self.dist.is_finite() {
            (self.to.p - it.position).length()
        } else {
            f32::INFINITY
        };
        if self.queries >= MAX_CROSSINGS {
            return WalkStep::Blocked;
        }
        match ctx
            .offset
            .shadow(&it.spawn_point(), self.wi, rest, &self.to)
        {
            Some(q) => {
                self.q = q;
                WalkStep::Next
            }
            None => WalkStep::Blocked,
        }
    }
}

impl<const N: usize> TransmittanceWalk<N> {
    /// The stretch of length `len` of the current query inside the walk's medium:
    /// exp(−σ_t len) in a homogeneous medium, ratio tracking in a heterogeneous one.
    #[inline(always)]
    fn stretch(&mut self, ctx: &Context, len: f32, wl: &SampledWavelengths<N>) {
        let m = &ctx.scene.media[self.medium as usize];
        let Some(density) = &m.density else {
            self.tr *= m.transmittance(len, wl);
            return;
        };
        let (o, d) = (self.q.origin, self.q.dir.normalize());
        let (u, p) = self.key;
        let key = (u.to_bits() as u64) << 32 | p.x.to_bits() as u64;
        let mut rng = Rng::keyed(key, (self.queries as u64) << 32 | p.y.to_bits() as u64);
        let k = m.majorant_sigma_t(wl);
        let (tr, a) = ratio_tracking(
            density,
            (o, d, len),
            k,
            |p| m.extinction_at(p, wl),
            &mut rng,
        );
        self.tr *= tr;
        self.a *= a;
    }
}

/// How a next-event contribution through media follows from the shadow ray's
/// transmittance `tr`, kept while the packet engine walks the ray (the same arithmetic
/// as the one-path-at-a-time code, in the same order).
#[derive(Clone, Copy)]
pub(crate) enum Finish<const N: usize> {
    /// At a surface: β (f tr) L · scale.
    Surface {
        beta: SampledSpectrum<N>,
        f: SampledSpectrum<N>,
        l: SampledSpectrum<N>,
        scale: f32,
    },
    /// At a medium vertex: β f tr L / d, where d is the balance heuristic's denominator
    /// over (technique, hero) pairs: mean_λ r_u p_light a for a delta light, else
    /// mean_λ r_u (p_light a + q tr), q_λ the density with which the phase-sampling
    /// technique reaches the vertex and leaves toward the light, relative to the light
    /// technique's density of the vertex (`integrator::path`), and a_λ the light
    /// technique's relative density of the shadow ray's null vertices (1 without
    /// heterogeneous media); nothing when d ≤ 0.
    Medium {
        beta: SampledSpectrum<N>,
        f: SampledSpectrum<N>,
        q: SampledSpectrum<N>,
        l: SampledSpectrum<N>,
        r_u: SampledSpectrum<N>,
        pdf: f32,
        delta: bool,
        alive: bool,
    },
}

impl<const N: usize> Finish<N> {
    #[inline]
    pub fn apply(
        &self,
        tr: SampledSpectrum<N>,
        a: SampledSpectrum<N>,
    ) -> Option<SampledSpectrum<N>> {
        match *self {
            Finish::Surface { beta, f, l, scale } => {
                let f = f * tr;
                Some(beta * f * l * scale)
            }
            Finish::Medium {
                beta,
                f,
                q,
                l,
                r_u,
                pdf,
                delta,
                alive,
            } => {
                let denom = if delta {
                    lane_mean(r_u * pdf * a, alive)
                } else {
                    lane_mean(r_u * (SampledSpectrum::splat(pdf) * a + q * tr), alive)
                };
                (denom > 0.0).then(|| beta * f * tr * l / denom)
            }
        }
    }
}

/// The mean over the lanes, or the hero's value once the companions have ended (the
/// balance heuristic over heroes needs every lane alive).
#[inline]
pub(crate) fn lane_mean<const N: usize>(s: SampledSpectrum<N>, companions_alive: bool) -> f32 {
    if companions_alive {
        s.0.iter().sum::<f32>() / N as f32
    } else {
        s.0[0]
    }
}

/// What a path carries from one vertex to the next (`whitted` uses the radiance, the
/// throughput, the BSDF context and the depth).
pub struct PathState<const N: usize> {
    /// Radiance found so far.
    pub(crate) l: SampledSpectrum<N>,
    /// Throughput.
    pub(crate) beta: SampledSpectrum<N>,
    pub(crate) bsdf_ctx: BsdfContext,
    /// For MIS when a BSDF or phase sample reaches a light: whether the last vertex
    /// scattered by a delta lobe, where it was, the density of its direction, and
    /// whether it was in a medium.
    pub(crate) specular_bounce: bool,
    pub(crate) prev_p: Vec3,
    pub(crate) prev_pdf: f32,
    pub(crate) prev_medium: bool,
    /// The product of the refractions' η², undone by the roulette.
    pub(crate) eta_scale: f32,
    /// Scattering events so far.
    pub(crate) depth: u32,
    /// The medium the path is in, the rescaled path probabilities (unidirectional r_u;
    /// r_l for a light reached from the last medium vertex, before its light pdf), and
    /// the boundaries crossed without a bounce (bounded, against a ray caught between
    /// coincident boundaries).
    pub(crate) medium: u32,
    pub(crate) r_u: SampledSpectrum<N>,
    pub(crate) r_l: SampledSpectrum<N>,
    pub(crate) crossings: u32,
}

impl<const N: usize> PathState<N> {
    #[inline(always)]
    pub(crate) fn start(origin: Vec3) -> Self {
        PathState {
            l: SampledSpectrum::zero(),
            beta: SampledSpectrum::splat(1.0),
            bsdf_ctx: BsdfContext::radiance::<N>(),
            specular_bounce: true,
            prev_p: origin,
            prev_pdf: 0.0,
            prev_medium: false,
            eta_scale: 1.0,
            depth: 0,
            medium: NO_MEDIUM,
            r_u: SampledSpectrum::splat(1.0),
            r_l: SampledSpectrum::splat(1.0),
            crossings: 0,
        }
    }
}

impl<const N: usize> PathState<N> {
    /// The path at the camera ray `cam`: its throughput is the camera's weight, and
    /// only the hero's when the lens ended the companions (as at a dispersive surface).
    #[inline(always)]
    pub(crate) fn at_camera(cam: &CameraRay) -> Self {
        let mut s = PathState::start(cam.ray.origin);
        s.beta = SampledSpectrum::splat(cam.weight);
        if cam.hero_only {
            s.beta.terminate_secondary();
            s.bsdf_ctx.companions_alive = false;
        }
        s
    }

    /// The radiance the path has found.
    #[inline]
    pub fn radiance(&self) -> SampledSpectrum<N> {
        self.l
    }
}

/// Where a path scatters, as a [`Transport`](super::transport::Transport) needs to know it: a surface (its material,
/// shading frame and ωo in that frame) or a point in a medium reached along `d_in`.
#[derive(Clone, Copy)]
pub(crate) enum Vertex<'a> {
    Surface {
        material: &'a Material,
        frame: &'a Frame,
        wo_local: Vec3,
    },
    Medium {
        medium: MediumPoint<'a>,
        d_in: Vec3,
    },
}

/// Where a vertex's shadow rays go. The one-path-at-a-time engine traces each at once
/// ([`Immediate`]); the packet engine defers them ([`Deferred`]) so that the shadow rays
/// of a packet's paths go to Embree together, and adds what they carry once it knows
/// which are blocked. A contribution is computed from values the vertex has before the
/// path moves on, and added to the radiance before anything the next vertex finds, so
/// both give the same sums in the same order.
pub(crate) trait ShadowSink<const N: usize> {
    /// The contribution `c()` of the shadow ray `q` (`None`: blocked without a query,
    /// the points too close to tell apart): `Some` when it is known now to be
    /// unblocked, `None` when blocked or deferred.
    fn test(
        &mut self,
        ctx: &Context,
        q: Option<RayQuery>,
        counters: &mut TraceCounters,
        c: impl FnOnce() -> SampledSpectrum<N>,
    ) -> Option<SampledSpectrum<N>>;

    /// The contribution `finish` gives for the transmittance of `walk` (`None`: blocked
    /// at once): `Some` when known now (walked with `rtcIntersect1`), `None` when
    /// blocked or deferred.
    fn transmit(
        &mut self,
        ctx: &Context,
        walk: Option<TransmittanceWalk<N>>,
        finish: Finish<N>,
        wl: &SampledWavelengths<N>,
        counters: &mut TraceCounters,
    ) -> Option<SampledSpectrum<N>>;

    /// `l += scale · sum`, where `sum` is the sum of the unblocked contributions of this
    /// vertex's tests, as known now (the seed's direct lighting, summed over the lights
    /// and then weighted by the throughput).
    fn add_scaled(
        &mut self,
        l: &mut SampledSpectrum<N>,
        scale: SampledSpectrum<N>,
        sum: SampledSpectrum<N>,
    );
}

/// Shadow rays traced as they come (`rtcOccluded1`).
pub(crate) struct Immediate;

impl<const N: usize> ShadowSink<N> for Immediate {
    #[inline(always)]
    fn test(
        &mut self,
        ctx: &Context,
        q: Option<RayQuery>,
        counters: &mut TraceCounters,
        c: impl FnOnce() -> SampledSpectrum<N>,
    ) -> Option<SampledSpectrum<N>> {
        let q = q?;
        counters.shadow_rays += 1;
        (!ctx.accel.occluded1(&q)).then(c)
    }

    #[inline(always)]
    fn transmit(
        &mut self,
        ctx: &Context,
        walk: Option<TransmittanceWalk<N>>,
        finish: Finish<N>,
        wl: &SampledWavelengths<N>,
        counters: &mut TraceCounters,
    ) -> Option<SampledSpectrum<N>> {
        let mut walk = walk?;
        loop {
            counters.shadow_rays += 1;
            let hit = ctx.accel.intersect1(&walk.q);
            match walk.advance(ctx, hit, wl) {
                WalkStep::Next => {}
                WalkStep::Done(tr, a) => return finish.apply(tr, a),
                WalkStep::Blocked => return None,
            }
        }
    }

    #[inline(always)]
    fn add_scaled(
        &mut self,
        l: &mut SampledSpectrum<N>,
        scale: SampledSpectrum<N>,
        sum: SampledSpectrum<N>,
    ) {
        *l += scale * sum;
    }
}

/// Shadow rays kept for the packet engine: one vertex's tests in order, each with its
/// contribution and, once traced, whether it is blocked.
/// The most shadow walks a step makes ([`Deferred::walks`]).
pub(crate) const WALKS: usize = 2;

pub struct Deferred<const N: usize> {
    pub(crate) tests: Vec<DeferredTest<N>>,
    /// Shadow rays through media still walking, and what their transmittances become:
    /// at most two per step (the path tracer's light sample from a segment through a
    /// medium, and the one at the surface that ends it), walked in this order.
    pub(crate) walks: [Option<(TransmittanceWalk<N>, Finish<N>)>; WALKS],
    /// `Some(scale)`: the unblocked contributions are summed and then added times
    /// `scale` ([`ShadowSink::add_scaled`]); `None`: each is added as it is.
    scale: Option<SampledSpectrum<N>>,
}

/// One deferred shadow ray: its query (`None`: blocked without one), whether it is
/// blocked (set by the engine once traced) and what it adds when not.
pub(crate) struct DeferredTest<const N: usize> {
    pub(crate) query: Option<RayQuery>,
    pub(crate) blocked: bool,
    c: SampledSpectrum<N>,
}

impl<const N: usize> Default for Deferred<N> {
    fn default() -> Self {
        Deferred {
            tests: Vec::new(),
            walks: [None; WALKS],
            scale: None,
        }
    }
}

impl<const N: usize> Deferred<N> {
    /// Forgets the last vertex's tests (keeping the memory).
    #[inline]
    pub fn clear(&mut self) {
        self.tests.clear();
        self.walks = [None; WALKS];
        self.scale = None;
    }

    /// Takes the closest hit of the query of walk `slot`; once the walk ends, its
    /// contribution (if any) joins the tests, unblocked. Returns whether it walks on.
    #[inline]
    pub fn advance_walk(
        &mut self,
        ctx: &Context,
        slot: usize,
        hit: Option<Hit>,
        wl: &SampledWavelengths<N>,
    ) -> bool {
        let Some((walk, finish)) = &mut self.walks[slot] else {
            return false;
        };
        let c = match walk.advance(ctx, hit, wl) {
            WalkStep::Next => return true,
            WalkStep::Done(tr, a) => finish.apply(tr, a),
            WalkStep::Blocked => None,
        };
        if let Some(c) = c {
            self.tests.push(DeferredTest {
                query: None,
                blocked: false,
                c,
            });
        }
        self.walks[slot] = None;
        false
    }

    /// Adds the unblocked contributions to `l`, as [`Immediate`] would have.
    #[inline]
    pub fn resolve(&self, l: &mut SampledSpectrum<N>) {
        match self.scale {
            None => {
                for t in &self.tests {
                    if !t.blocked {
                        *l += t.c;
                    }
                }
            }
            Some(scale) => {
                let mut sum = SampledSpectrum::<N>::zero();
                for t in &self.tests {
                    if !t.blocked {
                        sum += t.c;
                    }
                }
                *l += scale * sum;
            }
        }
    }
}

impl<const N: usize> ShadowSink<N> for Deferred<N> {
    #[inline(always)]
    fn test(
        &mut self,
        _: &Context,
        q: Option<RayQuery>,
        _: &mut TraceCounters,
        c: impl FnOnce() -> SampledSpectrum<N>,
    ) -> Option<SampledSpectrum<N>> {
        self.tests.push(DeferredTest {
            query: q,
            blocked: q.is_none(),
            c: c(),
        });
        None
    }

    #[inline(always)]
    fn transmit(
        &mut self,
        _: &Context,
        walk: Option<TransmittanceWalk<N>>,
        finish: Finish<N>,
        _: &SampledWavelengths<N>,
        _: &mut TraceCounters,
    ) -> Option<SampledSpectrum<N>> {
        // Walks and no tests beside them: `resolve` adds them in the order they were
        // made, as the engine walks slot 0 to its end before slot 1.
        debug_assert!(self.tests.is_empty());
        let slot = self
            .walks
            .iter()
            .position(|w| w.is_none())
            .expect("at most WALKS shadow walks per step");
        self.walks[slot] = walk.map(|w| (w, finish));
        None
    }

    #[inline(always)]
    fn add_scaled(
        &mut self,
        _: &mut SampledSpectrum<N>,
        scale: SampledSpectrum<N>,
        _: SampledSpectrum<N>,
    ) {
        self.scale = Some(scale);
    }
}

/// What a connection adds once its shadow ray is known to be clear: to the pixel
/// sample's own value (BDPT's s ≥ 0, t ≥ 2 strategies), or splatted into a pixel (a
/// light path's vertex seen by the camera).
#[derive(Clone, Copy)]
pub(crate) struct Connection<V> {
    pub c: V,
    pub splat: Option<u32>,
}

impl<V> Connection<V> {
    /// Adds the connection: to `own` when it is finite, or into its pixel's splats.
    #[inline]
    pub fn add<const N: usize>(&self, own: &mut V, splats: &mut Splats, wl: &SampledWavelengths<N>)
    where
        V: SampleValue<N>,
    {
        match self.splat {
            Some(p) => self.c.splat(splats, p, wl),
            None => self.c.add_to(own),
        }
    }
}

/// Whether a connection's shadow ray `q` is clear (`None`: blocked without one, the
/// points too close to tell apart), traced now (`rtcOccluded1`), so that a connection
/// found blocked costs nothing more. Light tracing's and BDPT's connections once went 8
/// at a time under `--packets paths`: that gained nothing for light tracing and cost
/// BDPT 4–5% (BENCHMARKS.md, "Packets of paths"), so it is gone.
#[inline]
pub(crate) fn unoccluded(ctx: &Context, q: Option<RayQuery>, counters: &mut TraceCounters) -> bool {
    let Some(q) = q else { return false };
    counters.shadow_rays += 1;
    !ctx.accel.occluded1(&q)
}
