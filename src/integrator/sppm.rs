//! Stochastic progressive photon mapping (Hachisuka & Jensen 2009, "Stochastic
//! progressive photon mapping", ACM TOG 28(5); pbrt-v4's `SPPMIntegrator`, §15.3 of its
//! third edition): the estimator that converges on specular–diffuse–specular paths, the
//! caustic on a pool's floor seen through its wavy surface, which no camera path, light
//! path or connection of the two can sample (both ends of the diffuse vertex meet smooth
//! glass, where a connection has zero density).
//!
//! Each iteration:
//!
//! 1. **Camera pass.** One camera path per pixel follows delta lobes (mirrors, smooth
//!    glass, dispersive refractions that end the companions as everywhere in heron) to
//!    the first vertex with a diffuse or glossy lobe, the *visible point*, and stores it
//!    with its throughput β. Emission met on the way (an area light, the sky or the
//!    sun's disk seen through the glass) is added; at the visible point the direct
//!    light is estimated as the path tracer does at one bounce: a light sample and a
//!    BSDF sample combined by the power heuristic. At a material with both delta and
//!    non-delta lobes (the glossy coat over glass), one of the two is chosen with
//!    probability ½ and weighted by 2, so that each path keeps one visible point.
//! 2. **Photon pass.** Photons leave the lights as light tracing's paths do
//!    (`LightPathStart`: a light by the light sampler, `sample_le`, the sun's portal),
//!    each carrying Φ/M of the iteration's M photons, and scatter by importance-mode
//!    sampling with Russian roulette. At every diffuse or glossy vertex after the first
//!    hit (the first is the direct light, which the camera pass has), the photon adds
//!    β_photon f(ωo, ωi) β_vp / (π R²) to every visible point within its pixel's radius
//!    R: the density estimate of the reflected radiance (Jensen 2001, eq. 7.6).
//! 3. **Update.** A pixel whose visible point gathered M photons keeps the fraction α of
//!    them: N ← N + αM, R² ← R² (N + αM)/(N + M) (Hachisuka et al. 2008, eqs. 5–7).
//!
//! The image is the mean of the direct light over the iterations plus T/I, where T sums
//! each iteration's Φ/(πR²) at the radius it was gathered with. This is the usual τ
//! bookkeeping written in radiance: with τ rescaled by R'²/R² at each update, as
//! Hachisuka & Jensen do, τ/(πR²) after the update equals (τ + Φ)/(πR²) before it, so
//! T = τ/(πR²) only ever grows by Φ/(πR²). Kept so, the sums are radiance like every
//! other film's and need no rescaling, and the film adds them as splats (`render/progressive.rs`).
//!
//! **Wavelengths: one set per iteration.** Every camera path and photon of an iteration
//! carries the same hero and companions (pbrt-v4 does the same). A photon's contribution
//! multiplies its throughput with the visible point's, and the visible point's throughput
//! (through dispersive glass, its very position) is known only at the wavelengths its
//! camera path was traced with; photons with wavelengths of their own would meet no
//! visible point at theirs. The heroes of successive iterations are stratified: the
//! radical inverse of the iteration index, Owen-scrambled by the seed, so I iterations
//! hold I strata of the wavelength sampler. A contribution whose camera side and photon
//! side both ended the companions (each hero × N) is divided by N once, as BDPT's
//! connections are.
//!
//! **Determinism.** Camera paths and photons draw their numbers from (seed, pixel or
//! photon, iteration); deposits are rounded to fixed point and added with exact atomic
//! adds (`film::fixed::AtomicFixed`), photon counts are integers, and the radius update
//! is per pixel: the image is the same for any thread count.
//!
//! Random numbers: the camera path reads the pixel position (2D) and the lens (2D), then
//! at each vertex the light choice (1D), the point on the light (2D), the lobe (1D) and
//! the direction (2D). A photon reads its start as light tracing does (1D, 2D, 2D), then
//! per vertex the lobe (1D), the direction (2D) and the roulette (1D).
//!
//! Not supported: participating media (refused with the other integrators that do not
//! trace them, `scene::features`).
use super::capabilities::{Capabilities, Support};
use super::toolkit::{light_pdf, next_hit, roulette, sample_light, LightPathStart};
use super::{Context, Integrator, Pass, PassIntegrator, TraceCounters};
use crate::bsdf::{BsdfContext, LobeFlags, Material, TransportMode};
use crate::camera::CameraRay;
use crate::film::fixed::{to_fixed, to_fixed3, AtomicFixed, LIMIT};
use crate::film::state::IntegratorPlane;
use crate::film::{xyz_lane_weights, SpectralBins};
use crate::geometry::SpawnPoint;
use crate::light::SurfacePoint;
use crate::math::warp::power_heuristic;
use crate::math::Frame;
use crate::sampler::Sampler;
use crate::scene::NO_LIGHT;
use crate::settings::{Packets, WavelengthSampler};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{IVec3, Vec3};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// The lobes a visible point gathers photons with, and the lobes a camera path
/// continues through.
const NON_DELTA: LobeFlags = LobeFlags::from_bits(
    LobeFlags::DIFFUSE.bits()
        | LobeFlags::GLOSSY.bits()
        | LobeFlags::REFLECTION.bits()
        | LobeFlags::TRANSMISSION.bits()
        | LobeFlags::WAVELENGTH_DEPENDENT.bits(),
);
const DELTA: LobeFlags = LobeFlags::from_bits(
    LobeFlags::SPECULAR.bits()
        | LobeFlags::REFLECTION.bits()
        | LobeFlags::TRANSMISSION.bits()
        | LobeFlags::WAVELENGTH_DEPENDENT.bits(),
);

/// The stratified wavelengths of iteration `k`: the hero from the Owen-scrambled
/// radical inverse of k, the companions rotated from it as in every render.
pub fn iteration_wavelengths<const N: usize>(
    sampler: WavelengthSampler,
    seed: u64,
    k: u32,
) -> SampledWavelengths<N> {
    let scramble = (seed ^ (seed >> 32) ^ 0x9e37_79b9) as u32;
    let v = crate::sampler::sobol::owen_scramble(k.reverse_bits(), scramble);
    let u = (v as f32 * (1.0 / 4_294_967_296.0)).min(1.0 - f32::EPSILON / 2.0);
    SampledWavelengths::sample(sampler, u)
}

/// Where a camera path stopped to gather photons.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint<const N: usize> {
    pub p: Vec3,
    frame: Frame,
    wo: Vec3,
    material: u32,
    /// The throughput from the camera, with the factor of the lobe choice.
    beta: SampledSpectrum<N>,
    /// The BSDF context at the point (companions alive or not), radiance mode, every
    /// non-delta lobe.
    ctx: BsdfContext,
}

/// What a pixel's camera path found: the light it saw (emission on its way and the
/// direct light at its visible point), the visible point, and the length of the path
/// to it (for the radius of its first iteration).
pub struct CameraPath<const N: usize> {
    pub l: SampledSpectrum<N>,
    pub vp: Option<VisiblePoint<N>>,
    pub length: f32,
}

/// One pixel's camera path of one iteration along the camera ray `cam` (step 1 of the
/// module's documentation).
pub fn camera_path<const N: usize>(
    ctx: &Context,
    cam: CameraRay,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> CameraPath<N> {
    let scene = ctx.scene;
    let mut beta = SampledSpectrum::<N>::splat(cam.weight);
    let mut bsdf_ctx = BsdfContext::radiance::<N>();
    if cam.hero_only {
        beta.terminate_secondary();
        bsdf_ctx.companions_alive = false;
    }
    let mut out = CameraPath {
        l: SampledSpectrum::zero(),
        vp: None,
        length: 0.0,
    };
    let mut ray = cam.ray;
    for bounce in 0..ctx.settings.max_depth {
        // `[render] hide_emitters`: on the camera ray itself emitters are seen directly,
        // and give nothing; after a delta bounce they are seen through it, and kept.
        let hidden = bounce == 0 && ctx.settings.hide_emitters;
        let Some(hit) = next_hit(ctx, &ray, &mut None, counters) else {
            // Every bounce so far was a delta: what the ray sees is whole.
            if !hidden {
                out.l += beta * scene.escaped_radiance(ray.dir, wl);
            }
            return out;
        };
        let (it, material) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
        bsdf_ctx.uv = it.uv;
        out.length += hit.t * ray.dir.length();
        let emitter = scene.shapes[hit.geom_id as usize].light;
        if emitter != NO_LIGHT && !hidden {
            out.l += beta * scene.lights[emitter as usize].l(it.n_outward, -ray.dir, it.uv, wl);
        }
        let u_light = sampler.get_1d();
        let u_light_point = sampler.get_2d();
        let mut u_lobe = sampler.get_1d();
        let u_dir = sampler.get_2d();
        let frame = it.frame();
        let wo = frame.to_local(-ray.dir);
        let flags = material.flags();
        let mut gather = flags.has_non_specular();
        let mut w = 1.0;
        if gather && flags.is_specular() {
            // Both kinds of lobe: one path, one of them, each with probability ½.
            gather = u_lobe >= 0.5;
            u_lobe = if gather {
                2.0 * u_lobe - 1.0
            } else {
                2.0 * u_lobe
            };
            w = 2.0;
        }
        let sp = it.spawn_point();
        if flags.has_non_specular() {
            let v = Vertex {
                sp,
                material,
                frame,
                wo,
                beta,
                bsdf: bsdf_ctx.with_lobes(NON_DELTA),
            };
            out.l += v.direct_light(ctx, u_light, u_light_point, wl, counters);
            if gather {
                // Linear in the throughput: the lobe choice's factor applies after.
                out.l += v.emission_by_bsdf(ctx, u_lobe, u_dir, wl, counters) * w;
                out.vp = Some(VisiblePoint {
                    p: it.position,
                    frame,
                    wo,
                    material: it.material,
                    beta: beta * w,
                    ctx: v.bsdf,
                });
                return out;
            }
        }
        let Some(bs) = material.sample(wo, u_lobe, u_dir, wl, &bsdf_ctx.with_lobes(DELTA)) else {
            return out;
        };
        beta *= bs.weight() * w;
        if bs.ended_companions {
            bsdf_ctx.companions_alive = false;
        }
        if beta.is_zero() {
            return out;
        }
        ray = ctx.offset.spawn(&sp, frame.to_world(bs.wi));
    }
    out
}

/// A camera path's vertex with a diffuse or glossy lobe: where rays leave it, what
/// scatters there (only its non-delta lobes, `bsdf`), toward where, and the throughput
/// that reached it.
struct Vertex<'a, const N: usize> {
    sp: SpawnPoint,
    material: &'a Material,
    frame: Frame,
    wo: Vec3,
    beta: SampledSpectrum<N>,
    bsdf: BsdfContext,
}

impl<const N: usize> Vertex<'_, N> {
    /// Next-event estimation: a light sample weighted by the power heuristic against the
    /// non-delta lobes' density.
    fn direct_light(
        &self,
        ctx: &Context,
        u_light: f32,
        u_point: glam::Vec2,
        wl: &SampledWavelengths<N>,
        counters: &mut TraceCounters,
    ) -> SampledSpectrum<N> {
        let zero = SampledSpectrum::zero();
        let Some(cl) = sample_light(ctx, self.sp.p, u_light, u_point, wl) else {
            return zero;
        };
        let ls = &cl.sample;
        let wi = self.frame.to_local(ls.wi);
        let f = self.material.eval(self.wo, wi, wl, &self.bsdf).f * wi.z.abs();
        if f.is_zero() {
            return zero;
        }
        let Some(q) = ctx.offset.shadow(&self.sp, ls.wi, ls.dist, &ls.target()) else {
            return zero;
        };
        counters.shadow_rays += 1;
        if ctx.accel.occluded1(&q) {
            return zero;
        }
        let weight = if ls.delta {
            1.0
        } else {
            power_heuristic(cl.pdf, self.material.pdf(self.wo, wi, wl, &self.bsdf))
        };
        self.beta * f * ls.l * (weight / cl.pdf)
    }

    /// The emission a BSDF sample reaches directly (an area light, or the sky and the
    /// sun's disk beyond the scene), weighted by the power heuristic against light
    /// sampling: the other half of [`Vertex::direct_light`]'s estimate.
    fn emission_by_bsdf(
        &self,
        ctx: &Context,
        u_lobe: f32,
        u_dir: glam::Vec2,
        wl: &SampledWavelengths<N>,
        counters: &mut TraceCounters,
    ) -> SampledSpectrum<N> {
        let scene = ctx.scene;
        let zero = SampledSpectrum::zero();
        if scene.lights.is_empty() {
            return zero;
        }
        let Some(bs) = self.material.sample(self.wo, u_lobe, u_dir, wl, &self.bsdf) else {
            return zero;
        };
        let b = self.beta * bs.weight();
        if b.is_zero() {
            return zero;
        }
        let (p, dir) = (self.sp.p, self.frame.to_world(bs.wi));
        let ray = ctx.offset.spawn(&self.sp, dir);
        let Some(hit) = next_hit(ctx, &ray, &mut None, counters) else {
            let mut l = zero;
            for &i in &scene.infinite_lights {
                let le = scene.lights[i as usize].le(dir, wl);
                if !le.is_zero() {
                    l += le * power_heuristic(bs.pdf, light_pdf(ctx, i as usize, p, dir, None));
                }
            }
            return b * l;
        };
        let light = scene.shapes[hit.geom_id as usize].light;
        if light == NO_LIGHT {
            return zero;
        }
        let (it, _) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
        let le = scene.lights[light as usize].l(it.n_outward, -dir, it.uv, wl);
        if le.is_zero() {
            return zero;
        }
        let hp = SurfacePoint {
            p: it.position,
            n: it.n_outward,
        };
        b * le * power_heuristic(bs.pdf, light_pdf(ctx, light as usize, p, dir, Some(&hp)))
    }
}

/// The visible points of one iteration in a hashed uniform grid (Hachisuka & Jensen
/// 2009 §4; pbrt-v4 §15.3.2): each point is listed in every cell its gather sphere
/// overlaps, so a photon looks in its own cell only. Built in pixel order, so the lists
/// do not depend on threads.
pub struct Grid {
    origin: Vec3,
    inv_cell: f32,
    mask: u32,
    /// Bucket b's points are `entries[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    entries: Vec<GridEntry>,
}

/// A visible point as its grid lists it: where it is and its squared radius beside its
/// pixel, so that a photon rejects the points out of its reach without reading them
/// (the distance test reads the bucket in order; the point itself only when it gathers).
#[derive(Clone, Copy, Debug, Default)]
pub struct GridEntry {
    pub p: Vec3,
    pub r2: f32,
    pub pixel: u32,
}

#[inline]
fn hash_cell(c: IVec3) -> u32 {
    // Teschner et al. 2003's primes.
    ((c.x as u32).wrapping_mul(73_856_093)
        ^ (c.y as u32).wrapping_mul(19_349_663)
        ^ (c.z as u32).wrapping_mul(83_492_791))
    .wrapping_mul(0x9e37_79b1)
}

/// The most cells of the grid's lists; a grid that would list more doubles its cells'
/// size (visible points of radii far apart, the largest spanning many small cells).
const MAX_ENTRIES: usize = 1 << 26;

impl Grid {
    /// The grid of the visible points `vps` (indexed by pixel) with squared radii `r2`.
    pub fn build<const N: usize>(vps: &[Option<VisiblePoint<N>>], r2: &[f32]) -> Grid {
        let present = || {
            vps.iter()
                .zip(r2)
                .enumerate()
                .filter_map(|(i, (v, &r2))| v.as_ref().map(|v| (i as u32, v.p, r2.sqrt())))
        };
        let (mut lo, mut n, mut sum_r) = (Vec3::splat(f32::INFINITY), 0usize, 0.0f64);
        for (_, p, r) in present() {
            lo = lo.min(p - Vec3::splat(r));
            n += 1;
            sum_r += r as f64;
        }
        let buckets = (2 * n).next_power_of_two().max(1) as u32;
        let mut cell = if n > 0 {
            (2.0 * sum_r / n as f64) as f32
        } else {
            1.0
        };
        if !(cell > 0.0 && cell.is_finite()) {
            cell = 1.0;
        }
        let origin = if lo.is_finite() { lo } else { Vec3::ZERO };
        let mut grid = loop {
            let inv_cell = 1.0 / cell;
            let span = |p: Vec3, r: f32| {
                let a = ((p - Vec3::splat(r) - origin) * inv_cell)
                    .floor()
                    .as_ivec3();
                let b = ((p + Vec3::splat(r) - origin) * inv_cell)
                    .floor()
                    .as_ivec3();
                (a, b)
            };
            let total: usize = present()
                .map(|(_, p, r)| {
                    let (a, b) = span(p, r);
                    let d = (b - a + IVec3::ONE).as_uvec3();
                    d.x as usize * d.y as usize * d.z as usize
                })
                .sum();
            if total > MAX_ENTRIES && cell < f32::MAX / 4.0 {
                cell *= 2.0;
                continue;
            }
            let mut count = vec![0u32; buckets as usize + 1];
            let each = |f: &mut dyn FnMut(u32, GridEntry)| {
                for (i, p, r) in present() {
                    let (a, b) = span(p, r);
                    let e = GridEntry {
                        p,
                        r2: r * r,
                        pixel: i,
                    };
                    for z in a.z..=b.z {
                        for y in a.y..=b.y {
                            for x in a.x..=b.x {
                                f(hash_cell(IVec3::new(x, y, z)) & (buckets - 1), e);
                            }
                        }
                    }
                }
            };
            each(&mut |b, _| count[b as usize + 1] += 1);
            for b in 0..buckets as usize {
                count[b + 1] += count[b];
            }
            let mut fill = count.clone();
            let mut entries = vec![GridEntry::default(); total];
            each(&mut |b, e| {
                entries[fill[b as usize] as usize] = e;
                fill[b as usize] += 1;
            });
            break Grid {
                origin,
                inv_cell,
                mask: buckets - 1,
                start: count,
                entries,
            };
        };
        grid.entries.shrink_to_fit();
        grid
    }

    /// The visible points listed in the cell of `p`.
    #[inline]
    pub fn near(&self, p: Vec3) -> &[GridEntry] {
        let c = ((p - self.origin) * self.inv_cell).floor();
        if !c.is_finite() || c.abs().max_element() > 2e9 {
            return &[];
        }
        let b = (hash_cell(c.as_ivec3()) & self.mask) as usize;
        &self.entries[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

/// One iteration's photon sums per pixel: XYZ and spectral bins of Σ Φ/(πR²) in fixed
/// point, and the photons gathered, added to by every thread at once. Every deposit of an
/// iteration has the iteration's wavelengths, so each lane's XYZ and bin weights are
/// computed once.
pub struct PhotonSums<const N: usize> {
    pub xyz: Vec<[AtomicFixed; 3]>,
    pub bins: Vec<AtomicFixed>,
    pub count: Vec<AtomicU32>,
    nb: usize,
    xyz_w: [Vec3; N],
    /// Each lane's bin and weight 1/(N p(λ) Δλ_bin) (0 for an ended lane).
    bin_of: [usize; N],
    bin_w: [f32; N],
    /// Deposits left out: not finite, or beyond the film's fixed-point range.
    pub nonfinite: std::sync::atomic::AtomicU64,
}

impl<const N: usize> PhotonSums<N> {
    pub fn new(pixels: usize, bins: usize, wl: &SampledWavelengths<N>) -> PhotonSums<N> {
        let b = SpectralBins { count: bins.max(1) };
        let w = 1.0 / (N as f32 * b.width());
        PhotonSums {
            xyz: (0..pixels).map(|_| Default::default()).collect(),
            bins: (0..pixels * bins).map(|_| Default::default()).collect(),
            count: (0..pixels).map(|_| AtomicU32::new(0)).collect(),
            nb: bins,
            xyz_w: xyz_lane_weights(wl),
            bin_of: std::array::from_fn(|i| b.index(wl.lambda[i])),
            bin_w: std::array::from_fn(|i| if wl.pdf[i] > 0.0 { w / wl.pdf[i] } else { 0.0 }),
            nonfinite: Default::default(),
        }
    }

    /// Adds the radiance `c` (at the iteration's wavelengths) to `pixel`.
    #[inline]
    fn add(&self, pixel: usize, c: &SampledSpectrum<N>) {
        self.count[pixel].fetch_add(1, Relaxed);
        let mut xyz = Vec3::ZERO;
        for i in 0..N {
            xyz += c.0[i] * self.xyz_w[i];
        }
        let lanes: [f32; N] = std::array::from_fn(|i| c.0[i] * self.bin_w[i]);
        let fixed = to_fixed3(xyz.to_array());
        let (Some(fixed), true) = (fixed, self.nb == 0 || lanes.iter().all(|v| v.abs() < LIMIT))
        else {
            self.nonfinite.fetch_add(1, Relaxed);
            return;
        };
        for (a, v) in self.xyz[pixel].iter().zip(fixed) {
            if v != 0 {
                a.add(v);
            }
        }
        if self.nb > 0 {
            for (i, &v) in lanes.iter().enumerate() {
                if v != 0.0 {
                    self.bins[pixel * self.nb + self.bin_of[i]].add(to_fixed(v).unwrap_or(0));
                }
            }
        }
    }
}

/// What a photon pass reads: the iteration's visible points, their grid, and each
/// pixel's 1/(πR²).
pub struct Gather<'a, const N: usize> {
    pub vps: &'a [Option<VisiblePoint<N>>],
    pub grid: &'a Grid,
    pub inv_area: &'a [f32],
    pub sums: &'a PhotonSums<N>,
}

/// Traces one photon of an iteration whose M photons each carry 1/M of the lights'
/// emission (`scale` = 1/M), depositing at visible points (step 2).
pub fn trace_photon<const N: usize>(
    ctx: &Context,
    gather: &Gather<N>,
    scale: f32,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) {
    let scene = ctx.scene;
    let settings = ctx.settings;
    let Some(start) = LightPathStart::sample(ctx, wl, sampler) else {
        return;
    };
    let mut beta = start.beta() * scale;
    let beta_start = beta.max_value();
    let mut ray = ctx.offset.spawn(&start.le.spawn_point(), start.le.dir);
    let mut bsdf_ctx = BsdfContext::radiance::<N>().with_mode(TransportMode::Importance);
    for depth in 0..settings.max_depth {
        let Some(hit) = next_hit(ctx, &ray, &mut None, counters) else {
            return;
        };
        let (it, material) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
        bsdf_ctx.uv = it.uv;
        let u_lobe = sampler.get_1d();
        let u_dir = sampler.get_2d();
        let u_rr = sampler.get_1d();
        let flags = material.flags();
        if depth > 0 && flags.has_non_specular() {
            deposit(
                ctx,
                gather,
                it.position,
                -ray.dir,
                beta,
                bsdf_ctx.companions_alive,
                wl,
            );
        }
        let frame = it.frame();
        let wo = frame.to_local(-ray.dir);
        let Some(bs) = material.sample(wo, u_lobe, u_dir, wl, &bsdf_ctx) else {
            return;
        };
        beta *= bs.weight();
        if bs.ended_companions {
            bsdf_ctx.companions_alive = false;
        }
        if beta.is_zero() {
            return;
        }
        ray = ctx.offset.spawn(&it.spawn_point(), frame.to_world(bs.wi));
        // As light tracing's: relative to the light's own throughput, so that a scene's
        // units do not decide when photons end.
        let rr = beta.max_value() / beta_start;
        if !roulette(&mut beta, rr, depth + 1, settings.rr_depth, u_rr) {
            return;
        }
    }
}

/// A photon arriving at `p` from direction `w_in` (pointing back along its path) adds
/// its share to every visible point whose gather sphere holds `p`.
#[inline]
fn deposit<const N: usize>(
    ctx: &Context,
    g: &Gather<N>,
    p: Vec3,
    w_in: Vec3,
    beta: SampledSpectrum<N>,
    photon_alive: bool,
    wl: &SampledWavelengths<N>,
) {
    for e in g.grid.near(p) {
        if (e.p - p).length_squared() > e.r2 {
            continue;
        }
        let i = e.pixel as usize;
        let Some(vp) = &g.vps[i] else { continue };
        let wi = vp.frame.to_local(w_in);
        let ev = ctx.scene.materials[vp.material as usize].eval(vp.wo, wi, wl, &vp.ctx);
        if ev.f.is_zero() {
            continue;
        }
        let mut c = beta * ev.f * vp.beta * g.inv_area[i];
        let vp_ended = !vp.ctx.companions_alive || ev.ended_companions;
        if N > 1 && vp_ended && !photon_alive {
            // Both sides hold hero × N (module documentation).
            c *= 1.0 / N as f32;
        }
        g.sums.add(i, &c);
    }
}

/// What photon mapping keeps per pixel from one iteration to the next: the photon
/// count N and the squared gather radius R² (0 until the pixel's first visible point
/// sets it).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SppmPixels {
    pub n: Vec<f32>,
    pub r2: Vec<f32>,
}

impl SppmPixels {
    pub fn new(pixels: usize) -> SppmPixels {
        SppmPixels {
            n: vec![0.0; pixels],
            r2: vec![0.0; pixels],
        }
    }

    /// The name of the film's plane that keeps this state for a resume.
    pub const PLANE: &'static str = "sppm";

    /// The state as the film's integrator plane: every pixel's N, then every R².
    pub fn into_plane(self) -> IntegratorPlane {
        let mut values = self.n;
        values.extend(self.r2);
        IntegratorPlane {
            name: Self::PLANE.into(),
            values,
        }
    }

    /// The state [`SppmPixels::into_plane`] kept (2 values per pixel: the resume checked).
    pub fn from_plane(plane: IntegratorPlane) -> SppmPixels {
        let mut n = plane.values;
        let r2 = n.split_off(n.len() / 2);
        SppmPixels { n, r2 }
    }
}

/// What one iteration found: its wavelengths, each pixel's camera-path light, the
/// photons' sums per pixel, and the rays it traced.
pub struct Iteration<const N: usize> {
    pub wl: SampledWavelengths<N>,
    pub l: Vec<SampledSpectrum<N>>,
    pub photons: PhotonSums<N>,
    pub counters: TraceCounters,
}

/// Photons traced per task of the photon pass.
const PHOTON_CHUNK: u32 = 1024;

/// Iteration `k` of a render (the module's three steps), on the current rayon pool;
/// `pixels` is updated. `cancelled` is polled per row and per chunk of photons: once it
/// says so the iteration returns early, and its result must be thrown away.
pub fn iteration<const N: usize>(
    ctx: &Context,
    pixels: &mut SppmPixels,
    k: u32,
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Iteration<N> {
    use rayon::prelude::*;
    let settings = ctx.settings;
    let cam = &ctx.scene.camera;
    let (w, h) = (cam.width, cam.height);
    let npix = (w * h) as usize;
    let wl = iteration_wavelengths::<N>(settings.wavelengths, settings.seed, k);
    let sum = |a: TraceCounters, b: TraceCounters| TraceCounters {
        rays: a.rays + b.rays,
        shadow_rays: a.shadow_rays + b.shadow_rays,
    };

    // 1. Camera pass, a row per task.
    let mut l = vec![SampledSpectrum::<N>::zero(); npix];
    let mut vps: Vec<Option<VisiblePoint<N>>> = vec![None; npix];
    let mut length = vec![0.0f32; npix];
    let base = Sampler::new(settings.sampler, settings.seed, w, h, settings.spp);
    let filter = crate::camera::filter::Filter::new(&settings.filter);
    let camera_counters = l
        .par_chunks_mut(w as usize)
        .zip(vps.par_chunks_mut(w as usize))
        .zip(length.par_chunks_mut(w as usize))
        .enumerate()
        .map(|(y, ((l_row, vp_row), len_row))| {
            let mut counters = TraceCounters::default();
            if cancelled() {
                return counters;
            }
            let mut sampler = base.clone();
            for x in 0..w as usize {
                sampler.start_pixel_sample(x as u32, y as u32, k);
                let j = sampler.get_pixel_2d();
                let (fx, fy, weight) = filter.film_point(x as u32, y as u32, j);
                let ray = cam.ray(fx, fy, || sampler.get_2d(), wl.lambda[0]);
                if let Some(ray) = ray {
                    let mut p = camera_path(ctx, ray, &wl, &mut sampler, &mut counters);
                    // The filter's weight f/(p ∫f) scales all the pixel's light: what
                    // the camera path saw and what its visible point gathers (the
                    // photons' flux is linear in the point's throughput).
                    if weight != 1.0 {
                        p.l *= weight;
                        if let Some(vp) = &mut p.vp {
                            vp.beta *= weight;
                        }
                    }
                    (l_row[x], vp_row[x], len_row[x]) = (p.l, p.vp, p.length);
                }
            }
            counters
        })
        .reduce(TraceCounters::default, sum);

    // A pixel's first visible point sets its radius: the scene's, or a few pixel
    // footprints at the distance the camera path travelled (an orthographic pixel's
    // footprint is the same at every distance).
    let footprint = cam.pixel_angle();
    let pixel_size = cam.pixel_size();
    for i in 0..npix {
        if vps[i].is_some() && pixels.r2[i] == 0.0 {
            let r = if settings.sppm.radius > 0.0 {
                settings.sppm.radius
            } else if let Some(s) = pixel_size {
                crate::settings::SppmSettings::RADIUS_PIXELS * s
            } else {
                crate::settings::SppmSettings::RADIUS_PIXELS * footprint * length[i]
            };
            pixels.r2[i] = (r * r).max(f32::MIN_POSITIVE);
        }
    }
    let inv_area: Vec<f32> = pixels
        .r2
        .iter()
        .map(|&r2| {
            if r2 > 0.0 {
                1.0 / (std::f32::consts::PI * r2)
            } else {
                0.0
            }
        })
        .collect();

    // 2. Photon pass, a chunk of photons per task.
    let grid = Grid::build(&vps, &pixels.r2);
    let photons = PhotonSums::new(npix, settings.spectral_bins, &wl);
    let m = settings.sppm.photons_for(w * h);
    let gather = Gather {
        vps: &vps,
        grid: &grid,
        inv_area: &inv_area,
        sums: &photons,
    };
    // Photons draw from their own sampler (another seed), photon j as the "pixel"
    // (j mod pw, j div pw) of a pw-wide grid, at sample index k.
    let pw = (m as f64).sqrt().ceil().max(1.0) as u32;
    let photon_base = Sampler::new(
        settings.sampler,
        settings.seed ^ 0x5050_4d50_686f_746f,
        pw,
        m.div_ceil(pw),
        settings.spp,
    );
    let scale = 1.0 / m as f32;
    let photon_counters = (0..m.div_ceil(PHOTON_CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut counters = TraceCounters::default();
            if cancelled() {
                return counters;
            }
            let mut sampler = photon_base.clone();
            for j in c * PHOTON_CHUNK..((c + 1) * PHOTON_CHUNK).min(m) {
                sampler.start_pixel_sample(j % pw, j / pw, k);
                trace_photon(ctx, &gather, scale, &wl, &mut sampler, &mut counters);
            }
            counters
        })
        .reduce(TraceCounters::default, sum);

    // 3. The radii.
    for i in 0..npix {
        let got = photons.count[i].load(Relaxed);
        (pixels.n[i], pixels.r2[i]) =
            update_radius(pixels.n[i], pixels.r2[i], got, settings.sppm.alpha);
    }
    Iteration {
        wl,
        l,
        photons,
        counters: sum(camera_counters, photon_counters),
    }
}

/// The progressive radius update of one pixel that gathered `m` photons (step 3):
/// returns the new (N, R²).
#[inline]
pub fn update_radius(n: f32, r2: f32, m: u32, alpha: f32) -> (f32, f32) {
    if m == 0 {
        return (n, r2);
    }
    let m = m as f32;
    let n_new = n + alpha * m;
    (n_new, r2 * n_new / (n + m))
}

/// Stochastic progressive photon mapping.
pub struct PhotonMapping;

impl Integrator for PhotonMapping {
    const CAPABILITIES: Capabilities = Capabilities {
        lens: Support::Yes,
        orthographic: Support::Yes,
        media: false,
        polarization: Support::No(
            "polarised transport (polarization = true) is implemented for integrator = \"path\", \"whitted\", \"lighttrace\" and \"bdpt\"; photon mapping's photons carry no Stokes vectors",
        ),
        variance: Support::No(
            "photon mapping's pixels are not means of independent samples (each iteration's radii depend on the ones before), so it has no per-pixel variance; use integrator path or bdpt for --variance",
        ),
        // Rays one at a time: the camera pass follows specular chains and the photons
        // scatter from wherever the lights put them, so neither has packets.
        packets: false,
        auto_packets: Packets::Off,
        camera_rays: true,
        steps: false,
        splats: true,
        kernel: None,
    };
}

impl PassIntegrator for PhotonMapping {
    const PLANE: (&'static str, usize) = (SppmPixels::PLANE, 2);

    fn initial_plane(pixels: usize) -> IntegratorPlane {
        SppmPixels::new(pixels).into_plane()
    }

    /// An [`iteration`]; its photons' sums go to the film's splat planes.
    fn pass<const N: usize>(
        ctx: &Context,
        plane: &mut IntegratorPlane,
        k: u32,
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> Pass<N> {
        let mut pixels = SppmPixels::from_plane(std::mem::take(plane));
        let it = iteration::<N>(ctx, &mut pixels, k, cancelled);
        *plane = pixels.into_plane();
        Pass {
            wl: it.wl,
            l: it.l,
            splat: it.photons.xyz.iter().flatten().map(|a| a.load()).collect(),
            splat_bins: it.photons.bins.iter().map(|a| a.load()).collect(),
            nonfinite: it.photons.nonfinite.load(Relaxed),
            counters: it.counters,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radius_shrinks_as_hachisuka_and_jensen_write() {
        // N = 0, M = 30, α = 2/3: N' = 20, R'² = R² · 20/30.
        let (n, r2) = update_radius(0.0, 9.0, 30, 2.0 / 3.0);
        assert!((n - 20.0).abs() < 1e-5 && (r2 - 6.0).abs() < 1e-5);
        // No photons: unchanged.
        assert_eq!(update_radius(5.0, 2.0, 0, 0.5), (5.0, 2.0));
        // Over many iterations with the same M the radius keeps shrinking, ever slower.
        let (mut n, mut r2) = (0.0f32, 1.0f32);
        let mut last = f32::INFINITY;
        for _ in 0..100 {
            let before = r2;
            (n, r2) = update_radius(n, r2, 10, 2.0 / 3.0);
            assert!(r2 < before && before - r2 <= last);
            last = before - r2;
        }
    }

    #[test]
    fn iteration_wavelengths_are_stratified() {
        // 64 iterations put one hero in each of 64 equal strata of u; the visible
        // sampler maps u monotonically to λ, so the heroes are 64 distinct wavelengths,
        // and sorted, one per stratum of the sampler's CDF.
        let mut u: Vec<f32> = (0..64)
            .map(|k| {
                let wl = iteration_wavelengths::<1>(WavelengthSampler::Uniform, 3, k);
                (wl.lambda[0] - crate::spectrum::LAMBDA_MIN)
                    / (crate::spectrum::LAMBDA_MAX - crate::spectrum::LAMBDA_MIN)
            })
            .collect();
        u.sort_by(f32::total_cmp);
        for (i, x) in u.iter().enumerate() {
            assert!(
                (*x * 64.0).floor() as usize == i,
                "stratum {i} holds {x} (all: {u:?})"
            );
        }
    }
}
