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
//! that a dimension always means the same decision.
use super::{occluded, query, Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::BsdfContext;
use crate::geometry::Ray;
use crate::light::{Light, SurfacePoint};
use crate::math::warp::power_heuristic;
use crate::sampler::Sampler;
use crate::scene::features::{on, KernelFlags, EMITTERS, ESCAPE, SHADOWS};
use crate::scene::NO_LIGHT;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

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
    let scene = ctx.scene;
    let settings = &scene.settings;
    let mut l = SampledSpectrum::<N>::zero();
    let mut beta = SampledSpectrum::<N>::splat(1.0);
    let mut bsdf_ctx = BsdfContext::radiance::<N>();
    // State of the previous bounce, for MIS when a BSDF sample reaches a light.
    let mut specular_bounce = true;
    let mut prev_p = ray.origin;
    let mut prev_pdf = 0.0f32;
    let mut eta_scale = 1.0f32;
    let mut depth = 0u32;
    let mut pending = first_hit;
    loop {
        let hit = match pending.take() {
            Some(h) => h,
            None => {
                counters.rays += 1;
                ctx.accel.intersect1(&query(&ray))
            }
        };
        let Some(hit) = hit else {
            if !on(K, ESCAPE) {
                break;
            }
            for &i in &scene.infinite_lights {
                let light = &scene.lights[i as usize];
                let le = light.le(ray.dir, wl);
                if le.is_zero() {
                    continue;
                }
                if specular_bounce {
                    l += beta * le;
                } else {
                    let p_l =
                        scene.light_sampler.pmf(i as usize) * light.pdf_li(prev_p, ray.dir, None);
                    l += beta * le * power_heuristic(prev_pdf, p_l);
                }
            }
            break;
        };
        let (it, material) =
            scene.interaction(&ray, &hit, depth, wl.lambda[0], ctx.offset.is_robust());
        let wo = -ray.dir;

        // Emission of an area light the path has reached.
        let emitter = if on(K, EMITTERS) {
            scene.shape_light[hit.geom_id as usize]
        } else {
            NO_LIGHT
        };
        if emitter != NO_LIGHT {
            let light = &scene.lights[emitter as usize];
            if let Light::Area(a) = light {
                let le = a.l(it.n_outward, wo, wl);
                if !le.is_zero() {
                    if specular_bounce {
                        l += beta * le;
                    } else {
                        let sp = SurfacePoint {
                            p: it.position,
                            n: it.n_outward,
                        };
                        let p_l = scene.light_sampler.pmf(emitter as usize)
                            * light.pdf_li(prev_p, ray.dir, Some(&sp));
                        l += beta * le * power_heuristic(prev_pdf, p_l);
                    }
                }
            }
        }
        if depth == settings.max_depth {
            break;
        }
        depth += 1;

        let u_light = sampler.get_1d();
        let u_light_point = sampler.get_2d();
        let u_lobe = sampler.get_1d();
        let u_dir = sampler.get_2d();
        let u_rr = sampler.get_1d();

        let frame = it.frame();
        let wo_local = frame.to_local(wo);
        let flags = material.flags();

        // Next-event estimation.
        if on(K, SHADOWS) && flags.has_non_specular() {
            if let Some((li, pmf)) = scene.light_sampler.sample(u_light) {
                let light = &scene.lights[li];
                if let Some(ls) = light.sample_li(it.position, u_light_point, wl) {
                    let wi_local = frame.to_local(ls.wi);
                    if ls.pdf > 0.0 && !ls.l.is_zero() {
                        let f = material.eval(wo_local, wi_local, wl, &bsdf_ctx) * wi_local.z.abs();
                        if !f.is_zero()
                            && !occluded(
                                ctx,
                                &it.spawn_point(),
                                ls.wi,
                                ls.dist,
                                &ls.target(),
                                counters,
                            )
                        {
                            let p_l = pmf * ls.pdf;
                            let w = if ls.delta {
                                1.0
                            } else {
                                power_heuristic(
                                    p_l,
                                    material.pdf(wo_local, wi_local, wl, &bsdf_ctx),
                                )
                            };
                            l += beta * f * ls.l * (w / p_l);
                        }
                    }
                }
            }
        }

        // The continuation.
        let Some(bs) = material.sample(wo_local, u_lobe, u_dir, wl, &bsdf_ctx) else {
            break;
        };
        beta *= bs.weight();
        specular_bounce = bs.is_specular();
        prev_pdf = bs.pdf;
        prev_p = it.position;
        if bs.ended_companions {
            bsdf_ctx.companions_alive = false;
        }
        if bs.is_transmission() {
            eta_scale *= bs.eta * bs.eta;
        }
        ray = ctx.offset.spawn(&it.spawn_point(), frame.to_world(bs.wi));
        if beta.is_zero() {
            break;
        }

        // Russian roulette (pbrt-v4 §13.4.2): on the throughput with refractions' η²
        // undone, so a path inside glass is not ended for having crossed into it.
        let rr = beta.max_value() * eta_scale;
        if rr < 1.0 && depth >= settings.rr_depth {
            let q = (1.0 - rr).max(0.0);
            if u_rr < q {
                break;
            }
            beta /= 1.0 - q;
        }
    }
    l
}
