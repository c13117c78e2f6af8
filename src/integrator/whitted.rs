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
use super::toolkit::{next_hit, Carrier, Immediate, PathState, ShadowSink, Unpolarized, Vertex};
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::LobeFlags;
use crate::camera::CameraRay;
use crate::geometry::{Interaction, Ray};
use crate::light::Light;
use crate::sampler::Sampler;
use crate::scene::NO_LIGHT;
use crate::settings::{on, KernelFlags, EMITTERS, ESCAPE, SHADOWS, SPECULAR};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// The delta lobes the seed's tracer continues through.
const DELTA: LobeFlags = LobeFlags::SPECULAR
    .union(LobeFlags::REFLECTION)
    .union(LobeFlags::TRANSMISSION);

/// Radiance arriving along `ray` at the wavelengths `wl`.
///
/// Random numbers, in order: per non-delta light at a diffuse or glossy hit, a 2D point
/// on the light; per continuation through a surface with both a reflecting and a
/// transmitting delta lobe, one number for the choice between them.
///
/// `K` is the kernel ([`KernelFlags`]): code for a feature whose flag is off is not
/// compiled into this instance (shadow rays, specular continuation, area-light
/// emission, radiance along escaping rays).
pub fn radiance<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> SampledSpectrum<N> {
    let mut s = start::<N>(&cam);
    let mut ray = cam.ray;
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

/// The path's state at the camera: what [`step`] starts from (the seed's tracer samples
/// delta lobes only).
#[inline]
pub fn start<const N: usize>(cam: &CameraRay) -> PathState<N> {
    let mut s = PathState::at_camera(cam);
    s.bsdf_ctx = s.bsdf_ctx.with_lobes(DELTA);
    s
}

/// One shader call of the seed's loop for the ray `ray` with closest hit `hit`: the
/// radiance along an escaping ray, or the emission, direct lighting and specular
/// continuation at a hit; `ray` becomes the next ray. Returns false when the path ends.
/// Shadow rays go to `shadows`.
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
    step_carrying::<N, K, S, _>(
        ctx,
        s,
        ray,
        hit,
        wl,
        sampler,
        counters,
        shadows,
        &mut Unpolarized,
    )
}

/// [`step`] with what the path carries besides its scalar throughput (`carry`, as
/// `path::step_carrying`'s): polarised, each light's contribution goes to it on its own.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn step_carrying<
    const N: usize,
    const K: KernelFlags,
    S: ShadowSink<N>,
    C: Carrier<N>,
>(
    ctx: &Context,
    s: &mut PathState<N>,
    ray: &mut Ray,
    hit: Option<Hit>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut S,
    carry: &mut C,
) -> bool {
    let scene = ctx.scene;
    let Some(hit) = hit else {
        if on(K, ESCAPE) {
            if C::POLARIZED {
                for &i in &scene.infinite_lights {
                    let le = scene.lights[i as usize].le(ray.dir, wl);
                    carry.found(&mut s.l, s.beta * le, i as usize, ray.dir, wl);
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
        if emitter != NO_LIGHT {
            let c = s.beta * scene.lights[emitter as usize].l(it.n_outward, wo, wl);
            carry.found(&mut s.l, c, emitter as usize, ray.dir, wl);
        }
    }
    let flags = material.flags();
    let frame = it.frame();
    let wo_local = frame.to_local(wo);
    if on(K, SHADOWS) && flags.has_non_specular() {
        let bsdf_ctx = &s.bsdf_ctx;
        let f = |wi| material.eval(wo_local, frame.to_local(wi), wl, bsdf_ctx).f;
        if C::POLARIZED {
            let v = Vertex::Surface {
                material,
                frame: &frame,
                wo_local,
            };
            let (beta, l) = (s.beta, &mut s.l);
            direct_lighting(ctx, &it, wl, sampler, counters, shadows, f, |c, wi, i| {
                carry.lit(l, beta * c, &v, wi, frame.to_local(wi), i, wl)
            });
        } else {
            let mut lr = SampledSpectrum::<N>::zero();
            direct_lighting(ctx, &it, wl, sampler, counters, shadows, f, |c, _, _| {
                lr += c
            });
            shadows.add_scaled(&mut s.l, s.beta, lr);
        }
    }
    if !on(K, SPECULAR) || !flags.is_specular() {
        return false;
    }
    // Delta lobes choose among themselves with one number, drawn only when there is
    // a choice (reflection and transmission); a delta's direction needs none.
    let choice = flags.contains(LobeFlags::REFLECTION | LobeFlags::TRANSMISSION);
    let uc = if choice { sampler.get_1d() } else { 0.5 };
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
    carry.scattered(&v, wi, bs.wi, bs.flags, wl);
    *ray = ctx.offset.spawn(&it.spawn_point(), wi);
    true
}

/// f(ωi) L_i cos θi / pdf for every light but the environment that reaches the shading
/// point unoccluded (as far as `shadows` knows now; the packet engine adds the rest
/// later), given to `add` with ωi and the light's index, ωi being the unit direction
/// toward the light and `f` the BSDF there. Lights with extent (the sun's disk, area
/// lights) are sampled at one point.
#[allow(clippy::too_many_arguments)]
#[inline]
fn direct_lighting<const N: usize, S: ShadowSink<N>>(
    ctx: &Context,
    it: &Interaction,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut S,
    f: impl Fn(Vec3) -> SampledSpectrum<N>,
    mut add: impl FnMut(SampledSpectrum<N>, Vec3, usize),
) {
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
            sampler.get_2d()
        };
        let Some(ls) = light.sample_li(x, u, wl) else {
            continue;
        };
        let cos = ls.wi.dot(n);
        if cos <= 0.0 || !(ls.pdf > 0.0) {
            continue;
        }
        let q = ctx.offset.shadow(&from, ls.wi, ls.dist, &ls.target());
        if let Some(c) = shadows.test(ctx, q, counters, || f(ls.wi) * (ls.l * (cos / ls.pdf))) {
            add(c, ls.wi, i);
        }
    }
}
