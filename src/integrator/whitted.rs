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
use super::toolkit::{next_hit, occluded};
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{BsdfContext, LobeFlags};
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
    mut ray: Ray,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> SampledSpectrum<N> {
    let scene = ctx.scene;
    let mut beta = SampledSpectrum::<N>::splat(1.0);
    let mut l = SampledSpectrum::<N>::zero();
    let mut pending = first_hit;
    let mut depth = 0u32;
    let mut bsdf_ctx = BsdfContext::radiance::<N>().with_lobes(DELTA);
    loop {
        let Some(hit) = next_hit(ctx, &ray, &mut pending, counters) else {
            if on(K, ESCAPE) {
                l += beta * scene.escaped_radiance(ray.dir, wl);
            }
            break;
        };
        let (it, material) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
        let wo = -ray.dir;
        if on(K, EMITTERS) {
            let emitter = scene.shapes[hit.geom_id as usize].light;
            if emitter != NO_LIGHT {
                l += beta * scene.lights[emitter as usize].l(it.n_outward, wo, wl);
            }
        }
        let flags = material.flags();
        let frame = it.frame();
        let wo_local = frame.to_local(wo);
        if on(K, SHADOWS) && flags.has_non_specular() {
            let mut lr = SampledSpectrum::<N>::zero();
            direct_lighting(ctx, &it, wl, sampler, counters, |wi, li_cos| {
                lr += material.eval(wo_local, frame.to_local(wi), wl, &bsdf_ctx).f * li_cos;
            });
            l += beta * lr;
        }
        if !on(K, SPECULAR) || !flags.is_specular() {
            break;
        }
        // Delta lobes choose among themselves with one number, drawn only when there is
        // a choice (reflection and transmission); a delta's direction needs none.
        let choice = flags.contains(LobeFlags::REFLECTION | LobeFlags::TRANSMISSION);
        let uc = if choice { sampler.get_1d() } else { 0.5 };
        let Some(bs) = material.sample(wo_local, uc, Vec2::ZERO, wl, &bsdf_ctx) else {
            break;
        };
        beta *= bs.weight();
        if bs.ended_companions {
            bsdf_ctx.companions_alive = false;
        }
        // The lecture's continuation: overwrite the ray, clear has_hit (the next
        // iteration's `pending` is None), increment depth.
        depth += 1;
        if depth > ctx.settings.max_depth {
            break;
        }
        ray = ctx.offset.spawn(&it.spawn_point(), frame.to_world(bs.wi));
    }
    l
}

/// Calls `visit(ωi, L_i cos θi / pdf)` for every light but the environment that reaches
/// the shading point unoccluded, ωi being the unit direction toward the light. Lights
/// with extent (the sun's disk, area lights) are sampled at one point.
#[inline]
fn direct_lighting<const N: usize>(
    ctx: &Context,
    it: &Interaction,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    mut visit: impl FnMut(Vec3, SampledSpectrum<N>),
) {
    let x = it.position;
    let from = it.spawn_point();
    let n = it.normal;
    for light in &ctx.scene.lights {
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
        if !occluded(ctx, &from, ls.wi, ls.dist, &ls.target(), counters) {
            visit(ls.wi, ls.l * (cos / ls.pdf));
        }
    }
}
