//! The seed lecture's Whitted-style tracer, spectral.
//!
//! Per the seed: shadow rays start at t_min = ε and stop at ‖p − x‖ − ε (directional
//! lights and the sun: no cutoff); mirrors reflect, dielectrics refract with n_i/n_t and
//! reflect on total internal reflection; glossy surfaces add the modified Phong
//! highlight. A shader that continues the path overwrites the ray and increments the
//! depth ("Exercises").
//!
//! In terms of the materials' methods: at a surface with diffuse or glossy lobes, every
//! light (but the environment, which the seed's tracer sees only along escaping rays)
//! is sampled once and weighted by `eval`; at a surface with delta lobes, the path
//! continues by `sample` restricted to them (a Fresnel dielectric picks reflection with
//! probability R, so one ray per path stays unbiased for R·L_r + (1 − R)·L_t). A
//! surface with both (the course's glossy over glass) does both, each at full weight.
//! Light reaching a diffuse surface through glass or off other diffuse surfaces is
//! missing: that is the `path` integrator's job.
use super::capabilities::{Capabilities, Support};
use super::toolkit::{PathState, ShadowSink, Vertex};
use super::transport::{Scatter, Tracer, Transport};
use super::{Context, Integrator, PixelIntegrator, StepIntegrator, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::LobeFlags;
use crate::camera::CameraRay;
use crate::film::Splats;
use crate::geometry::{Interaction, Ray};
use crate::light::Light;
use crate::sampler::Sampler;
use crate::scene::{Features, NO_LIGHT};
use crate::settings::{on, KernelFlags, Packets, EMITTERS, ESCAPE, SHADOWS, SPECULAR};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// The delta lobes the seed's tracer continues through.
const DELTA: LobeFlags = LobeFlags::SPECULAR
    .union(LobeFlags::REFLECTION)
    .union(LobeFlags::TRANSMISSION);

/// The seed's Whitted tracer.
pub struct Whitted;

impl Integrator for Whitted {
    const CAPABILITIES: Capabilities = Capabilities {
        lens: Support::Yes,
        orthographic: Support::Yes,
        media: false,
        polarization: Support::Yes,
        variance: Support::Yes,
        packets: true,
        // Most of its paths end at their first hit: packets of paths keep Embree's
        // packets full (BENCHMARKS.md, "Packets of paths").
        auto_packets: Packets::Paths,
        camera_rays: true,
        steps: true,
        splats: false,
        kernel: Some(kernel_flags),
    };
}

/// The kernel flags the Whitted tracer is specialised on: shadow rays, specular
/// continuation, emitters and escaping rays (`scene::features`).
fn kernel_flags(f: &Features) -> KernelFlags {
    let bit = |on: bool, flag: KernelFlags| if on { flag } else { 0 };
    bit(f.shadows, SHADOWS)
        | bit(f.specular, SPECULAR)
        | bit(f.emitters, EMITTERS)
        | bit(f.escape, ESCAPE)
}

impl PixelIntegrator for Whitted {
    /// Radiance arriving along `ray` at the wavelengths `wl` (Stokes radiance, in the
    /// camera's frame, for polarised transport `T`: the direct lighting light by light
    /// through the surface's non-delta lobes and the delta continuations, each with its
    /// Mueller matrix).
    ///
    /// Random numbers, in order: per non-delta light at a diffuse or glossy hit, a 2D point
    /// on the light; per continuation through a surface with both a reflecting and a
    /// transmitting delta lobe, one number for the choice between them.
    ///
    /// `K` is the kernel ([`KernelFlags`]): code for a feature whose flag is off is not
    /// compiled into this instance (shadow rays, specular continuation, area-light
    /// emission, radiance along escaping rays).
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

impl StepIntegrator for Whitted {
    /// The path's state at the camera: what [`StepIntegrator::step`] starts from (the seed's tracer samples
    /// delta lobes only).
    #[inline]
    fn start<const N: usize>(cam: &CameraRay) -> PathState<N> {
        let mut s = PathState::at_camera(cam);
        s.bsdf_ctx = s.bsdf_ctx.with_lobes(DELTA);
        s
    }

    /// One shader call of the seed's loop for the ray `ray` with closest hit `hit`: the
    /// radiance along an escaping ray, or the emission, direct lighting and specular
    /// continuation at a hit; `ray` becomes the next ray. Returns false when the path ends.
    /// Shadow rays go to the tracer's sink; polarised, each light's contribution goes to
    /// the transport on its own.
    #[inline(always)]
    fn step<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
        t: &mut Tracer<N, S, T>,
        s: &mut PathState<N>,
        ray: &mut Ray,
        hit: Option<Hit>,
    ) -> bool {
        let (ctx, wl) = (t.ctx, t.wl);
        let scene = ctx.scene;
        // `[render] hide_emitters`: before the first continuation (`depth` counts the
        // seed's specular continuations) the camera sees emitters directly, and they
        // give nothing; what a later segment finds is light through a mirror or a
        // refraction, kept (Mitsuba 3's `depth == 0 && hide_emitters`).
        let hidden = s.depth == 0 && ctx.settings.hide_emitters;
        let Some(hit) = hit else {
            if on(K, ESCAPE) && !hidden {
                if T::POLARIZED {
                    for &i in &scene.infinite_lights {
                        let le = scene.lights[i as usize].le(ray.dir, wl);
                        t.found(&mut s.l, s.beta * le, i as usize, ray.dir);
                    }
                } else {
                    s.l += s.beta * scene.escaped_radiance(ray.dir, wl);
                }
            }
            return false;
        };
        let (it, material) = scene.interaction(ray, &hit, ctx.offset.is_robust());
        s.bsdf_ctx.uv = it.uv;
        let wo = -ray.dir;
        if on(K, EMITTERS) {
            let emitter = scene.shapes[hit.geom_id as usize].light;
            if emitter != NO_LIGHT && !hidden {
                let c = s.beta * scene.lights[emitter as usize].l(it.n_outward, wo, it.uv, wl);
                t.found(&mut s.l, c, emitter as usize, ray.dir);
            }
        }
        let flags = material.flags();
        let frame = it.frame();
        let wo_local = frame.to_local(wo);
        if on(K, SHADOWS) && flags.has_non_specular() {
            let bsdf_ctx = &s.bsdf_ctx;
            let f = |wi| material.eval(wo_local, frame.to_local(wi), wl, bsdf_ctx).f;
            if T::POLARIZED {
                let v = Vertex::Surface {
                    material,
                    frame: &frame,
                    wo_local,
                };
                let (beta, l) = (s.beta, &mut s.l);
                direct_lighting(t, &it, f, |carry, c, wi, i| {
                    let at = Scatter {
                        v: &v,
                        wi,
                        wi_local: frame.to_local(wi),
                    };
                    T::lit(carry, ctx, l, beta * c, at, i, wl)
                });
            } else {
                let mut lr = SampledSpectrum::<N>::zero();
                direct_lighting(t, &it, f, |_, c, _, _| lr += c);
                t.shadows.add_scaled(&mut s.l, s.beta, lr);
            }
        }
        if !on(K, SPECULAR) || !flags.is_specular() {
            return false;
        }
        // Delta lobes choose among themselves with one number, drawn only when there is
        // a choice (reflection and transmission); a delta's direction needs none.
        let choice = flags.contains(LobeFlags::REFLECTION | LobeFlags::TRANSMISSION);
        let uc = if choice { t.sampler.get_1d() } else { 0.5 };
        let Some(bs) = material.sample(wo_local, uc, Vec2::ZERO, wl, &s.bsdf_ctx) else {
            return false;
        };
        s.beta *= bs.weight();
        if bs.ended_companions {
            s.bsdf_ctx.companions_alive = false;
        }
        // The lecture's continuation: overwrite the ray, clear has_hit (the next
        // iteration's hit is traced anew), increment depth.
        s.depth += 1;
        if s.depth > ctx.settings.max_depth {
            return false;
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
        true
    }
}

/// f(ωi) L_i cos θi / pdf for every light but the environment that reaches the shading
/// point unoccluded (as far as the tracer's shadow sink knows now; the packet engine
/// adds the rest later), given to `add` with the transport's camera state, ωi and the
/// light's index, ωi being the unit direction toward the light and `f` the BSDF there.
/// Lights with extent (the sun's disk, area lights) are sampled at one point.
#[inline]
fn direct_lighting<const N: usize, S: ShadowSink<N>, T: Transport<N>>(
    t: &mut Tracer<N, S, T>,
    it: &Interaction,
    f: impl Fn(Vec3) -> SampledSpectrum<N>,
    mut add: impl FnMut(&mut T::Camera, SampledSpectrum<N>, Vec3, usize),
) {
    let (ctx, wl) = (t.ctx, t.wl);
    let x = it.position;
    let from = it.spawn_point();
    let n = it.normal;
    for (i, light) in ctx.scene.lights.iter().enumerate() {
        if matches!(light, Light::Environment(_)) {
            continue;
        }
        let u = if light.is_delta() {
            Vec2::ZERO
        } else {
            t.sampler.get_2d()
        };
        let Some(ls) = light.sample_li(x, u, wl) else {
            continue;
        };
        let cos = ls.wi.dot(n);
        if cos <= 0.0 || !(ls.pdf > 0.0) {
            continue;
        }
        let q = ctx.offset.shadow(&from, ls.wi, ls.dist, &ls.target());
        let c = t
            .shadows
            .test(ctx, q, t.counters, || f(ls.wi) * (ls.l * (cos / ls.pdf)));
        if let Some(c) = c {
            add(t.carry, c, ls.wi, i);
        }
    }
}
