//! Light tracing (particle tracing with next-event estimation to the camera; Arvo &
//! Kirk 1990, Dutré et al. 1993; pbrt-v4's `LightPathIntegrator`): paths start at the
//! lights and every vertex on a diffuse or glossy surface is connected to the camera
//! and splatted into the pixel it lands in. It is BDPT's t = 1 strategies alone, so it
//! finds the caustics a camera path cannot (a diffuse screen lit through a prism by a
//! small sun), and cannot see lights at infinity (the sky, the sun's disk) directly.
//!
//! A path: a light chosen by the scene's light sampler, an emitted ray from
//! `Light::sample_le` (its flux L |cos| / (p_light pdf_pos pdf_dir)), then the
//! materials' importance-mode sampling (no η² at refractions: importance is not
//! radiance, Veach 1997 §5.2). A connection adds β f(ωo, ω_camera) |cos| We / pdf_camera
//! to the pixel the point projects to; the film divides splats by spp, and since every
//! pixel sample traces one light path, a pixel's value is the mean of the importance
//! arriving at it (pbrt-v4 §13.4.3 derives the normalisation).
//!
//! Emitting surfaces seen directly by the camera are splatted from the light's own
//! vertex. Dispersion: the lanes were drawn with the pixel sample and travel with the
//! light path; a dispersive refraction ends the companions as in the path tracer.
//!
//! Random numbers: light choice (1D), the emitted ray's position (2D) and direction
//! (2D), then per bounce the lobe (1D), the direction (2D) and the roulette (1D).
use super::capabilities::{Capabilities, Support, LENS_NEEDS_WE, ORTHOGRAPHIC_NEEDS_WE};
use super::toolkit::{next_hit, pixel_of, roulette, unoccluded, Connection, LightPathStart};
use super::transport::{LightEvent, Transport};
use super::{Context, Integrator, PixelIntegrator, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{BsdfContext, TransportMode};
use crate::camera::{CameraRay, CameraWiSample};
use crate::film::tile::SampleValue;
use crate::film::Splats;
use crate::geometry::SpawnPoint;
use crate::sampler::Sampler;
use crate::settings::{KernelFlags, Packets};
use crate::spectrum::SampledWavelengths;

/// Light tracing.
pub struct LightTracer;

impl Integrator for LightTracer {
    const CAPABILITIES: Capabilities = Capabilities {
        lens: Support::No(LENS_NEEDS_WE),
        orthographic: Support::No(ORTHOGRAPHIC_NEEDS_WE),
        media: false,
        polarization: Support::Yes,
        variance: Support::Yes,
        packets: true,
        // It traces no camera rays, and has no steps for packets of paths.
        auto_packets: Packets::Off,
        camera_rays: false,
        steps: false,
        splats: true,
        kernel: None,
    };
}

impl PixelIntegrator for LightTracer {
    /// Traces one light path and splats its connections to the camera; returns nothing for
    /// the pixel sample's own pixel. What the light path carries besides its scalar
    /// throughput is the transport `T`'s: nothing ([`Unpolarized`](super::transport::Unpolarized)),
    /// or its Stokes vector (`integrator::polarized`), whose connections splat Stokes
    /// radiance. Both trace the same paths with the same random numbers.
    fn sample<const N: usize, const K: KernelFlags, T: Transport<N>>(
        ctx: &Context,
        _: CameraRay,
        _: Option<Option<Hit>>,
        wl: &SampledWavelengths<N>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        splats: &mut Splats,
    ) -> T::Value {
        let scene = ctx.scene;
        let cam = &scene.camera;
        let settings = ctx.settings;
        let Some(start) = LightPathStart::sample(ctx, wl, sampler) else {
            return T::Value::zero();
        };
        let (le, pmf) = (&start.le, start.pmf);
        // Rays leave a light's surface as they leave any surface; other lights' origins are
        // in free space.
        let light_point = le.spawn_point();
        let eye = SpawnPoint::free(cam.eye);

        // What the connections to the camera add to the pixel sample's own pixel: nothing.
        let mut own = T::Value::zero();
        // The splat of a connection from `from` along `cs`, unless its shadow ray is blocked.
        let connect =
            |from: &SpawnPoint, cs: &CameraWiSample, c: T::Value, counters: &mut TraceCounters| {
                let q = ctx.offset.shadow(from, cs.wi, cs.dist, &eye);
                unoccluded(ctx, q, counters).then(|| Connection {
                    c,
                    splat: Some(pixel_of(cam, cs.raster)),
                })
            };

        // An emitting surface seen by the camera: the light's own vertex; none under
        // `[render] hide_emitters`, which hides exactly these (Mitsuba 3's particle
        // tracer skips its `sample_visible_emitters` so).
        if let (Some(n), false) = (le.normal, settings.hide_emitters) {
            if let Some(cs) = cam.sample_wi(le.origin) {
                let emitted = scene.lights[start.index].l(n, cs.wi, le.uv, wl);
                if !emitted.is_zero() {
                    let k = n.dot(cs.wi).abs() * cs.we / (cs.pdf * pmf * le.pdf_pos);
                    let beam = T::emitted(ctx, start.index, cs.wi, wl);
                    let c = T::seen(&beam, ctx, None, cs.wi, emitted * k, wl);
                    if let Some(c) = connect(&light_point, &cs, c, counters) {
                        c.add(&mut own, splats, wl);
                    }
                }
            }
        }

        let mut beta = start.beta();
        let mut carried = T::emitted(ctx, start.index, le.dir, wl);
        // The light path's throughput carries the light's flux, whose size depends on the
        // scene's units (an area light's flux scales with its area); the roulette compares
        // the throughput with where it started, so that a scene scaled by 1e-4 is not
        // cut short (tests/stability.rs).
        let beta_start = beta.max_value();
        let mut ray = ctx.offset.spawn(&light_point, le.dir);
        let mut bsdf_ctx = BsdfContext::radiance::<N>().with_mode(TransportMode::Importance);
        let mut depth = 0u32;
        while let Some(hit) = next_hit(ctx, &ray, &mut None, counters) {
            let (it, material) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
            bsdf_ctx.uv = it.uv;
            // The path has scattered `depth` times before this vertex; scattering here
            // toward the camera is one more.
            if depth == settings.max_depth {
                break;
            }
            depth += 1;
            let u_lobe = sampler.get_1d();
            let u_bsdf = sampler.get_2d();
            let u_rr = sampler.get_1d();
            let frame = it.frame();
            let wo = frame.to_local(-ray.dir);
            let flags = material.flags();
            if flags.has_non_specular() {
                if let Some(cs) = cam.sample_wi(it.position) {
                    let wi = frame.to_local(cs.wi);
                    let f = material.eval(wo, wi, wl, &bsdf_ctx).f;
                    if !f.is_zero() {
                        let c = beta * f * (wi.z.abs() * cs.we / cs.pdf);
                        let at = LightEvent {
                            material,
                            frame: &frame,
                            to_local: wi,
                            from_local: wo,
                        };
                        let c = T::seen(&carried, ctx, Some(&at), cs.wi, c, wl);
                        if let Some(c) = connect(&it.spawn_point(), &cs, c, counters) {
                            c.add(&mut own, splats, wl);
                        }
                    }
                }
            }
            if depth == settings.max_depth {
                break;
            }
            let Some(bs) = material.sample(wo, u_lobe, u_bsdf, wl, &bsdf_ctx) else {
                break;
            };
            beta *= bs.weight();
            let at = LightEvent {
                material,
                frame: &frame,
                to_local: bs.wi,
                from_local: wo,
            };
            T::light_scattered(&mut carried, &at, bs.flags, wl);
            if bs.ended_companions {
                bsdf_ctx.companions_alive = false;
            }
            if beta.is_zero() {
                break;
            }
            ray = ctx.offset.spawn(&it.spawn_point(), frame.to_world(bs.wi));
            // Russian roulette on the importance throughput, relative to the light's.
            let rr = beta.max_value() / beta_start;
            if !roulette(&mut beta, rr, depth, settings.rr_depth, u_rr) {
                break;
            }
        }
        T::Value::zero()
    }
}
