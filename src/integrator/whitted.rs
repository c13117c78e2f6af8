//! The seed lecture's Whitted-style tracer, spectral.
//!
//! Per the seed: shadow rays start at t_min = ε and stop at ‖p − x‖ − ε (directional
//! lights: no cutoff); mirrors reflect, dielectrics refract with n_i/n_t and reflect on
//! total internal reflection; glossy surfaces add the modified Phong highlight. A shader
//! that continues the path overwrites the ray and increments the depth ("Exercises").
//!
//! heron's one addition: with Fresnel on, a dielectric picks reflection with probability
//! R and refraction with 1 − R (R from the Fresnel equations), so one ray per path is
//! still enough and the estimate of R·L_r + (1 − R)·L_t stays unbiased.
use super::{Context, TraceCounters};
use crate::accel::embree::{Hit, RayQuery};
use crate::bsdf::dielectric::refract;
use crate::bsdf::fresnel::fresnel_dielectric;
use crate::bsdf::mirror::reflect;
use crate::bsdf::phong::phong_specular;
use crate::bsdf::{Dielectric, Material};
use crate::geometry::{Interaction, Ray};
use crate::light::Light;
use crate::math::Rng;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

#[inline]
fn query(ray: &Ray) -> RayQuery {
    RayQuery {
        origin: ray.origin,
        dir: ray.dir,
        tnear: ray.t_min,
        tfar: ray.t_max,
    }
}

/// Radiance arriving along `ray` at the wavelengths `wl`.
///
/// `first_hit` is the camera ray's closest hit when it was already traced (in an Embree
/// packet); `None` traces it here.
pub fn radiance<const N: usize>(
    ctx: &Context,
    mut ray: Ray,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    rng: &mut Rng,
    counters: &mut TraceCounters,
) -> SampledSpectrum<N> {
    let scene = ctx.scene;
    let eps = scene.settings.epsilon;
    let mut beta = SampledSpectrum::<N>::splat(1.0);
    let mut l = SampledSpectrum::<N>::zero();
    let mut pending = first_hit;
    let mut depth = 0u32;
    loop {
        let hit = match pending.take() {
            Some(h) => h,
            None => {
                counters.rays += 1;
                ctx.accel.intersect1(&query(&ray))
            }
        };
        let Some(hit) = hit else {
            l += beta * escaped_radiance(ctx, ray.dir, wl);
            break;
        };
        let shape = &scene.shapes[hit.geom_id as usize];
        let material = &scene.materials[shape.material as usize];
        let mut it = Interaction::new(&ray, &hit, shape, material, depth, wl.lambda[0]);
        let wo = -ray.dir;
        let next = match material {
            Material::Lambertian(m) => {
                let f = wl.eval(&m.rho_d) * FRAC_1_PI;
                let mut e = SampledSpectrum::<N>::zero();
                direct_lighting(ctx, &it, wl, rng, counters, |_, li_cos| e += li_cos);
                l += beta * f * e;
                None
            }
            Material::Mirror(m) => {
                beta *= wl.eval(&m.rho_s);
                Some(reflect(wo, it.normal))
            }
            Material::Dielectric(d) => Some(scatter_dielectric(&it, wo, d, wl, &mut beta, rng)),
            Material::Glossy(g) => {
                let fd = wl.eval(&g.rho_d) * FRAC_1_PI;
                let (rho_s, s, n) = (it.specular, it.shininess, it.normal);
                let mut lr = SampledSpectrum::<N>::zero();
                direct_lighting(ctx, &it, wl, rng, counters, |wi, li_cos| {
                    let fs = phong_specular(rho_s, s, wi, wo, n);
                    lr += (fd + SampledSpectrum::splat(fs)) * li_cos;
                });
                l += beta * lr;
                // The course's glossy shader: Phong highlights from the lights plus the
                // transparent shader's continuation, each at full weight (so with ρd > 0
                // this combination can reflect more than it receives).
                g.base
                    .as_ref()
                    .map(|b| scatter_dielectric(&it, wo, b, wl, &mut beta, rng))
            }
        };
        let Some(dir) = next else { break };
        // The lecture's continuation: overwrite the ray, clear has_hit, increment depth.
        it.has_hit = false;
        depth += 1;
        if depth > scene.settings.max_depth {
            break;
        }
        ray = Ray::new(it.position, dir, eps, f32::INFINITY);
    }
    l
}

/// Radiance along a ray that leaves the scene: the background (or a sky model that
/// contains it), the physical rainbow sky on top of it, and the sun's disk where the ray
/// points into it.
#[inline]
pub(crate) fn escaped_radiance<const N: usize>(
    ctx: &Context,
    dir: Vec3,
    wl: &SampledWavelengths<N>,
) -> SampledSpectrum<N> {
    let mut l = match &ctx.scene.sky {
        None => wl.eval(&ctx.scene.background),
        Some(sky) => {
            // θ once per ray; the table per lane.
            let theta = crate::sky::antisolar_angle(dir, sky.sun_dir).to_degrees();
            let mut s = SampledSpectrum::<N>::zero();
            for i in 0..N {
                let lambda = wl.lambda[i];
                s.0[i] = sky.table.eval(theta, lambda) * sky.factor.eval(lambda);
            }
            if sky.replaces_background {
                s
            } else {
                s + wl.eval(&ctx.scene.background)
            }
        }
    };
    for light in &ctx.scene.lights {
        if let Light::Sun(s) = light {
            if s.sees_disk(dir) {
                l += wl.eval(&s.radiance);
            }
        }
    }
    l
}

/// Calls `visit(ωi, L_i cos θi)` for every light that reaches the shading point
/// unoccluded, ωi being the unit direction toward the light.
///
/// Shadow rays follow the seed: t_min = ε, t_max = ‖p − x‖ − ε for a point light at p,
/// and no cutoff for a directional light or the sun. The sun is sampled at one point of
/// its disk, uniformly in solid angle, so L_i/pdf = L Ω = E.
#[inline]
fn direct_lighting<const N: usize>(
    ctx: &Context,
    it: &Interaction,
    wl: &SampledWavelengths<N>,
    rng: &mut Rng,
    counters: &mut TraceCounters,
    mut visit: impl FnMut(Vec3, SampledSpectrum<N>),
) {
    let eps = ctx.scene.settings.epsilon;
    let x = it.position;
    let n = it.normal;
    for light in &ctx.scene.lights {
        let (wi, t_max, li) = match light {
            Light::Point(p) => {
                let to = p.position - x;
                let d2 = to.length_squared();
                let d = d2.sqrt();
                (to / d, d - eps, wl.eval(&p.intensity) * (1.0 / d2))
            }
            Light::Directional(dl) => (-dl.direction, f32::INFINITY, wl.eval(&dl.radiance)),
            Light::Sun(sun) => (
                sun.sample_direction(rng),
                f32::INFINITY,
                wl.eval(&sun.irradiance),
            ),
        };
        let cos = wi.dot(n);
        if cos <= 0.0 || t_max <= eps {
            continue;
        }
        counters.shadow_rays += 1;
        let shadow = RayQuery {
            origin: x,
            dir: wi,
            tnear: eps,
            tfar: t_max,
        };
        if !ctx.accel.occluded1(&shadow) {
            visit(wi, li * cos);
        }
    }
}

/// Chooses the continuation at a dielectric: the seed's refraction with n_i/n_t from the
/// interaction (evaluated at the hero wavelength), reflection on total internal
/// reflection, and (with `fresnel`) reflection with probability R otherwise.
///
/// With a wavelength-dependent index and several live lanes: reflection sends every
/// lane the same way, so the lanes stay and each is weighted by R(λ_i)/R(λ_hero) (the
/// probability of the choice was the hero's R). Refraction sends each wavelength its
/// own way, so the path follows the hero and the other lanes end
/// ([`SampledSpectrum::terminate_secondary`]); the hero's weight T/(1 − R) is 1.
#[inline]
pub(crate) fn scatter_dielectric<const N: usize>(
    it: &Interaction,
    wo: Vec3,
    d: &Dielectric,
    wl: &SampledWavelengths<N>,
    beta: &mut SampledSpectrum<N>,
    rng: &mut Rng,
) -> Vec3 {
    let n = it.normal;
    let eta = it.ior1_over_ior2;
    let cos_i = wo.dot(n);
    let lanes_alive = N > 1 && beta.0[1..].iter().any(|&b| b != 0.0);
    let dispersive = lanes_alive && d.ior.is_dispersive();
    if !d.fresnel {
        if dispersive {
            beta.terminate_secondary();
        }
        return refract(wo, n, eta).unwrap_or_else(|| reflect(wo, n));
    }
    let r = fresnel_dielectric(cos_i, eta);
    if r >= 1.0 || rng.uniform() < r {
        if dispersive {
            for i in 1..N {
                let ni = d.ior.eval(wl.lambda[i]);
                let eta_i = if it.front_face { 1.0 / ni } else { ni };
                beta.0[i] *= fresnel_dielectric(cos_i, eta_i) / r;
            }
        }
        return reflect(wo, n);
    }
    if dispersive {
        beta.terminate_secondary();
    }
    refract(wo, n, eta).unwrap_or_else(|| reflect(wo, n))
}
