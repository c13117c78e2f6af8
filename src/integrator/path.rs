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
use super::{occluded, query, Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::BsdfContext;
use crate::geometry::Ray;
use crate::geometry::SpawnPoint;
use crate::light::{Light, SurfacePoint};
use crate::math::warp::power_heuristic;
use crate::medium::NO_MEDIUM;
use crate::sampler::Sampler;
use crate::scene::NO_LIGHT;
use crate::settings::{on, KernelFlags, EMITTERS, ESCAPE, MEDIA, SHADOWS};
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
    let settings = ctx.settings;
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
    // Media state: the current medium, the rescaled path probabilities (unidirectional
    // r_u; r_l for a light reached from the last medium vertex, before its light pdf),
    // whether the last scattering vertex was in a medium, and the boundaries crossed
    // without a bounce (bounded, against a ray caught between coincident boundaries).
    let mut medium = NO_MEDIUM;
    let mut r_u = SampledSpectrum::<N>::splat(1.0);
    let mut r_l = SampledSpectrum::<N>::splat(1.0);
    let mut prev_medium = false;
    let mut crossings = 0u32;
    loop {
        let hit = match pending.take() {
            Some(h) => h,
            None => {
                counters.rays += 1;
                ctx.accel.intersect1(&query(&ray))
            }
        };
        if on(K, MEDIA) && medium != NO_MEDIUM {
            let m = &scene.media[medium as usize];
            // A closed boundary always stops a ray inside; a ray that escapes it leaked.
            let Some(h) = hit else { break };
            let sigma_t = m.sigma_t(wl);
            let u_dist = sampler.get_1d();
            let s0 = sigma_t.0[0];
            let t = if s0 > 0.0 {
                -(1.0 - u_dist).ln() / s0
            } else {
                f32::INFINITY
            };
            if t < h.t {
                // A collision: scattering with probability σ_s/σ_t per lane, in the weight.
                let tr = exp_neg(sigma_t, t);
                let pdf = tr.0[0] * s0;
                beta *= m.sigma_s(wl) * tr / pdf;
                r_u *= sigma_t * tr / pdf;
                if depth == settings.max_depth || beta.is_zero() {
                    break;
                }
                depth += 1;
                let p = ray.at(t);
                let u_light = sampler.get_1d();
                let u_light_point = sampler.get_2d();
                let u_node = sampler.get_1d();
                let u_dir = sampler.get_2d();
                let u_rr = sampler.get_1d();
                let alive = bsdf_ctx.companions_alive;
                if on(K, SHADOWS) {
                    if let Some((li, pmf)) = scene.light_sampler.sample(u_light) {
                        let light = &scene.lights[li];
                        if let Some(ls) = light.sample_li(p, u_light_point, wl) {
                            if ls.pdf > 0.0 && !ls.l.is_zero() {
                                let f = m.phase(ray.dir, ls.wi, wl);
                                let tr_l = if f.is_zero() {
                                    None
                                } else {
                                    transmittance(
                                        ctx,
                                        &SpawnPoint::free(p),
                                        ls.wi,
                                        ls.dist,
                                        &ls.target(),
                                        medium,
                                        wl,
                                        counters,
                                    )
                                };
                                if let Some(tr_l) = tr_l {
                                    let p_l = pmf * ls.pdf;
                                    let denom = if ls.delta {
                                        lane_mean(r_u * p_l, alive)
                                    } else {
                                        lane_mean(
                                            r_u * (SampledSpectrum::splat(p_l) + f * tr_l),
                                            alive,
                                        )
                                    };
                                    if denom > 0.0 {
                                        l += beta * f * tr_l * ls.l / denom;
                                    }
                                }
                            }
                        }
                    }
                }
                let (wi, pv) = m.sample_phase(ray.dir, u_node, u_dir, wl);
                let pdf = pv.0[0];
                if !(pdf > 0.0) {
                    break;
                }
                beta *= pv / pdf;
                r_l = r_u / pdf;
                r_u *= pv / pdf;
                specular_bounce = false;
                prev_medium = true;
                prev_p = p;
                prev_pdf = pdf;
                ray = crate::geometry::Ray::new(p, wi, 0.0, f32::INFINITY);
                if beta.is_zero() {
                    break;
                }
                let rr = beta.max_value() * eta_scale / lane_mean(r_u, alive);
                if rr < 1.0 && depth >= settings.rr_depth {
                    let q = (1.0 - rr).max(0.0);
                    if u_rr < q {
                        break;
                    }
                    beta /= 1.0 - q;
                }
                continue;
            }
            // Flew to the boundary (or a surface inside) unscattered.
            let tr = exp_neg(sigma_t, h.t);
            let pdf = tr.0[0];
            if !(pdf > 0.0) {
                break;
            }
            beta *= tr / pdf;
            r_u *= tr / pdf;
            r_l /= pdf;
        }
        if on(K, MEDIA) {
            if let Some(h) = &hit {
                if scene.shapes[h.geom_id as usize].interface {
                    // An index-matched boundary: cross it, switching media, no bounce.
                    let (it, _) = scene.interaction(&ray, h, ctx.offset.is_robust());
                    medium = if ray.dir.dot(it.n_outward) < 0.0 {
                        scene.shapes[h.geom_id as usize].medium
                    } else {
                        NO_MEDIUM
                    };
                    crossings += 1;
                    if crossings > MAX_CROSSINGS {
                        break;
                    }
                    ray = ctx.offset.spawn(&it.spawn_point(), ray.dir);
                    continue;
                }
            }
        }
        // The lanes' mean of r_u (1 without media) divides every contribution found.
        let mis = if on(K, MEDIA) {
            lane_mean(r_u, bsdf_ctx.companions_alive)
        } else {
            1.0
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
                    l += beta * le / mis;
                } else {
                    let p_l =
                        scene.light_sampler.pmf(i as usize) * light.pdf_li(prev_p, ray.dir, None);
                    if on(K, MEDIA) && prev_medium {
                        let d = lane_mean(r_u + r_l * p_l, bsdf_ctx.companions_alive);
                        l += beta * le / d;
                    } else {
                        l += beta * le * (power_heuristic(prev_pdf, p_l) / mis);
                    }
                }
            }
            break;
        };
        let (it, material) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
        let wo = -ray.dir;

        // Emission of an area light the path has reached.
        let emitter = if on(K, EMITTERS) {
            scene.shapes[hit.geom_id as usize].light
        } else {
            NO_LIGHT
        };
        if emitter != NO_LIGHT {
            let light = &scene.lights[emitter as usize];
            if let Light::Area(a) = light {
                let le = a.l(it.n_outward, wo, wl);
                if !le.is_zero() {
                    if specular_bounce {
                        l += beta * le / mis;
                    } else {
                        let sp = SurfacePoint {
                            p: it.position,
                            n: it.n_outward,
                        };
                        let p_l = scene.light_sampler.pmf(emitter as usize)
                            * light.pdf_li(prev_p, ray.dir, Some(&sp));
                        if on(K, MEDIA) && prev_medium {
                            let d = lane_mean(r_u + r_l * p_l, bsdf_ctx.companions_alive);
                            l += beta * le / d;
                        } else {
                            l += beta * le * (power_heuristic(prev_pdf, p_l) / mis);
                        }
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
                        // Through media: the transmittance of the shadow ray (None: blocked).
                        let tr_l = if f.is_zero() {
                            None
                        } else if on(K, MEDIA) {
                            let from = if ls.wi.dot(it.n_outward) < 0.0 {
                                scene.shapes[hit.geom_id as usize].medium
                            } else {
                                medium_outside(medium, scene, hit.geom_id)
                            };
                            transmittance(
                                ctx,
                                &it.spawn_point(),
                                ls.wi,
                                ls.dist,
                                &ls.target(),
                                from,
                                wl,
                                counters,
                            )
                        } else if occluded(
                            ctx,
                            &it.spawn_point(),
                            ls.wi,
                            ls.dist,
                            &ls.target(),
                            counters,
                        ) {
                            None
                        } else {
                            Some(SampledSpectrum::splat(1.0))
                        };
                        if let Some(tr_l) = tr_l {
                            let p_l = pmf * ls.pdf;
                            let w = if ls.delta {
                                1.0
                            } else {
                                power_heuristic(
                                    p_l,
                                    material.pdf(wo_local, wi_local, wl, &bsdf_ctx),
                                )
                            };
                            let f = if on(K, MEDIA) { f * tr_l } else { f };
                            l += beta * f * ls.l * (w / (p_l * mis));
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
        prev_medium = false;
        prev_pdf = bs.pdf;
        prev_p = it.position;
        if bs.ended_companions {
            bsdf_ctx.companions_alive = false;
        }
        if bs.is_transmission() {
            eta_scale *= bs.eta * bs.eta;
        }
        ray = ctx.offset.spawn(&it.spawn_point(), frame.to_world(bs.wi));
        if on(K, MEDIA) && bs.is_transmission() {
            // Through a dielectric around a medium (a glass of milk) into or out of it.
            let g = hit.geom_id as usize;
            medium = if ray.dir.dot(it.n_outward) < 0.0 {
                scene.shapes[g].medium
            } else {
                medium_outside(medium, scene, hit.geom_id)
            };
        }
        if beta.is_zero() {
            break;
        }

        // Russian roulette (pbrt-v4 §13.4.2): on the throughput with refractions' η²
        // undone, so a path inside glass is not ended for having crossed into it (and,
        // with media, divided by the lanes' mean r_u, as contributions are).
        let rr = beta.max_value() * eta_scale / mis;
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

/// The most boundaries a path or shadow ray crosses between two bounces.
const MAX_CROSSINGS: u32 = 256;

/// exp(−σ_t d) per lane.
#[inline]
fn exp_neg<const N: usize>(sigma_t: SampledSpectrum<N>, d: f32) -> SampledSpectrum<N> {
    SampledSpectrum(std::array::from_fn(|i| (-sigma_t.0[i] * d).exp()))
}

/// The mean over the lanes, or the hero's value once the companions have ended (the
/// balance heuristic over heroes needs every lane alive).
#[inline]
fn lane_mean<const N: usize>(s: SampledSpectrum<N>, companions_alive: bool) -> f32 {
    if companions_alive {
        s.0.iter().sum::<f32>() / N as f32
    } else {
        s.0[0]
    }
}

/// The medium on the outer side of shape `geom`'s surface for a path now in `current`:
/// none when the path was in the shape's own medium (media do not nest), else `current`.
#[inline]
fn medium_outside(current: u32, scene: &crate::scene::Scene, geom: u32) -> u32 {
    if current == scene.shapes[geom as usize].medium {
        NO_MEDIUM
    } else {
        current
    }
}

/// The transmittance of the shadow ray from `from` (in `medium`) toward `to` along unit
/// `wi` at distance `dist`: exp(−σ_t ℓ) for each stretch ℓ inside a medium, continuing
/// through index-matched medium boundaries; `None` when any other surface blocks it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn transmittance<const N: usize>(
    ctx: &Context,
    from: &SpawnPoint,
    wi: glam::Vec3,
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
        let ray = crate::geometry::Ray::new(q.origin, q.dir, q.tnear, q.tfar);
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
