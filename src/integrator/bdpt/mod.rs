//! Bidirectional path tracing (Veach & Guibas 1995; Veach 1997, ch. 10), in the shape of
//! pbrt's `BDPTIntegrator` (pbrt-v3 §16.3, pbrt-v4 §13.4 of the online edition): a
//! camera subpath and a light subpath, every connection strategy (s, t) between them —
//! s light vertices and t camera vertices, from s = 0 (the camera path reaches a light)
//! through s = 1 (next-event estimation) to t = 1 (the light path connects to the
//! camera and is splatted) — each weighted by multiple importance sampling with the
//! power heuristic over all the strategies that could have made the same path.
//!
//! Densities are kept per vertex in area measure (solid angle for a vertex at
//! infinity), forward (as the subpath sampled it) and reverse (as the other direction
//! would have), and the weight of strategy (s, t) is 1 / (1 + Σ r_i²) with r_i the
//! ratios of those densities walked outward from the connection (Veach 1997 §10.2;
//! pbrt-v3's `MISWeight`, squared for the power heuristic). Delta vertices (specular
//! lobes, point and spot lights, a directional light's direction) cannot be connected
//! and take no part in the sum.
//!
//! Wavelengths: both subpaths carry the same lanes. A dispersive refraction on either
//! subpath ends the companions of that subpath (hero × N); a connection of two subpaths
//! that have both ended them divides one factor N back out, and a connection through a
//! dispersive transmission ends them only if neither subpath has, so every path carries
//! the factor N exactly once. All densities, and hence the MIS weights, are the hero's.
//!
//! Lights at infinity (the sun, the environment) are one light for the camera subpath
//! that escapes (their radiance summed); a light subpath from one of them starts on the
//! scene's bounding disk, or on the sun's portal. Its vertex densities are the mixture
//! over those lights, so that the MIS weights are a function of the path alone.
//!
//! Random numbers, per pixel sample after the pixel and wavelengths: the light subpath
//! (light choice 1D, position 2D, direction 2D, then lobe 1D and direction 2D per
//! bounce), then per camera bounce lobe 1D and direction 2D, then for each (s = 1, t)
//! connection the light choice 1D and point 2D. Subpaths are at most [`MAX_VERTICES`]
//! vertices long (so `max_depth` is capped at 22 here), held on the stack.
use super::capabilities::{Capabilities, Support, LENS_NEEDS_WE, ORTHOGRAPHIC_NEEDS_WE};
use super::polarized::{non_delta, Beam, Chain};
use super::toolkit::{next_hit, pixel_of, unoccluded, Connection, LightPathStart, Vertex as Event};
use super::transport::Transport;
use super::{Context, Integrator, PixelIntegrator, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{BsdfContext, LobeFlags, TransportMode};
use crate::camera::CameraRay;
use crate::film::tile::SampleValue;
use crate::film::Splats;
use crate::geometry::{Ray, SpawnPoint};
use crate::light::Light;
use crate::math::Frame;
use crate::sampler::Sampler;
use crate::scene::{Scene, NO_LIGHT};
use crate::settings::{KernelFlags, Packets};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

mod carrier;
mod connect;
mod subpaths;

pub(crate) use carrier::PolarizedSubpaths;

/// Vertices per subpath.
pub const MAX_VERTICES: usize = 24;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Camera,
    /// A light's vertex: a point on an area light or point light, a point on the disk
    /// or portal of a light at infinity (`infinite`), or the end of a camera path that
    /// escaped (`infinite`, `light` = NO_LIGHT: all lights at infinity together).
    Light,
    Surface,
}

/// A vertex of a subpath.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vertex<const N: usize> {
    kind: Kind,
    beta: SampledSpectrum<N>,
    p: Vec3,
    /// Floating-point error bound of `p` (surfaces and area lights; zero otherwise).
    err: Vec3,
    /// Outward geometric normal (surfaces, area lights, portals; zero for points).
    n: Vec3,
    /// Unit direction toward the previous vertex of its own subpath (surfaces).
    wo: Vec3,
    frame: Frame,
    material: u32,
    /// Texture coordinates of a surface vertex (for a textured material).
    uv: Vec2,
    /// The light of a light vertex, or of an emitting surface; NO_LIGHT otherwise.
    light: u32,
    /// A light at infinity (or all of them, for an escaped camera path).
    infinite: bool,
    /// Sampled through a delta lobe (or a delta light position/direction).
    delta: bool,
    /// The companions were ended on this subpath at or before this vertex's β.
    ended: bool,
    /// The lobe its subpath continued by (a surface's sample's flags), for the Mueller
    /// matrices of a polarised render.
    lobe: LobeFlags,
    pdf_fwd: f32,
    pdf_rev: f32,
}

impl<const N: usize> Vertex<N> {
    const EMPTY: Vertex<N> = Vertex {
        kind: Kind::Surface,
        beta: SampledSpectrum::zero(),
        p: Vec3::ZERO,
        err: Vec3::ZERO,
        n: Vec3::ZERO,
        wo: Vec3::ZERO,
        frame: Frame {
            s: Vec3::X,
            t: Vec3::Y,
            n: Vec3::Z,
        },
        material: 0,
        uv: Vec2::ZERO,
        light: NO_LIGHT,
        infinite: false,
        delta: false,
        ended: false,
        lobe: LobeFlags::NONE,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
    };

    fn on_surface(&self) -> bool {
        self.n != Vec3::ZERO
    }

    /// Where rays to and from this vertex start and end ([`SpawnPoint`]).
    fn spawn_point(&self) -> SpawnPoint {
        SpawnPoint {
            p: self.p,
            err: self.err,
            n: self.n,
        }
    }

    fn is_light(&self) -> bool {
        self.kind == Kind::Light || (self.kind == Kind::Surface && self.light != NO_LIGHT)
    }

    fn is_delta_light(&self, scene: &Scene) -> bool {
        self.kind == Kind::Light
            && self.light != NO_LIGHT
            && scene.lights[self.light as usize].is_delta()
    }

    /// Can a connection end here (not a delta lobe, not a delta direction)?
    fn connectible(&self, scene: &Scene) -> bool {
        match self.kind {
            Kind::Camera => true,
            Kind::Light => {
                self.light == NO_LIGHT
                    || !matches!(scene.lights[self.light as usize], Light::Directional(_))
            }
            Kind::Surface => scene.materials[self.material as usize]
                .flags()
                .has_non_specular(),
        }
    }
}

/// Converts a solid-angle density at `from` toward `to` into an area density at `to`
/// (unchanged when `to` is at infinity).
fn convert_density<const N: usize>(pdf: f32, from: &Vertex<N>, to: &Vertex<N>) -> f32 {
    if to.infinite {
        return pdf;
    }
    let w = to.p - from.p;
    let d2 = w.length_squared();
    if d2 == 0.0 {
        return 0.0;
    }
    let mut pdf = pdf / d2;
    if to.on_surface() {
        pdf *= to.n.dot(w / d2.sqrt()).abs();
    }
    pdf
}

/// Σ over the lights at infinity of p_choice · pdf_li(w), w the unit direction toward
/// them: the density of the direction of an escaped path's end.
fn infinite_light_density(scene: &Scene, w: Vec3) -> f32 {
    scene
        .infinite_lights
        .iter()
        .map(|&i| {
            scene.light_sampler.pmf(i as usize)
                * scene.lights[i as usize].pdf_li(Vec3::ZERO, w, None)
        })
        .sum()
}

/// Density, per unit area perpendicular to the rays, of where a light path from the
/// lights at infinity toward −w starts: their positional densities averaged with the
/// weights of their direction densities (see the module documentation).
fn infinite_position_density(scene: &Scene, w: Vec3) -> f32 {
    let (mut num, mut den) = (0.0f32, 0.0f32);
    for &i in &scene.infinite_lights {
        let l = &scene.lights[i as usize];
        let pd = scene.light_sampler.pmf(i as usize) * l.pdf_li(Vec3::ZERO, w, None);
        if pd > 0.0 {
            num += pd * l.pdf_le_position(-w, &scene.bounds);
            den += pd;
        }
    }
    if den > 0.0 {
        num / den
    } else {
        1.0 / scene.bounds.disk_area()
    }
}

/// One pixel sample's render context and wavelengths, which every strategy shares.
pub(crate) struct Bdpt<'a, const N: usize> {
    ctx: &'a Context<'a>,
    wl: &'a SampledWavelengths<N>,
}

/// The two subpaths of a pixel sample, on the stack: `light[..n_light]` and
/// `camera[..n_camera]` are traced; a strategy's MIS weight rewrites vertices near its
/// connection and restores them.
pub(crate) struct Subpaths<const N: usize> {
    light: [Vertex<N>; MAX_VERTICES],
    camera: [Vertex<N>; MAX_VERTICES],
    n_light: usize,
    n_camera: usize,
}

impl<'a, const N: usize> Bdpt<'a, N> {
    fn scene(&self) -> &Scene {
        self.ctx.scene
    }

    /// f(ωo, ω toward `next`) of surface vertex `v`, local frame, with the context's
    /// companions; also whether this evaluation ends them.
    fn f(
        &self,
        v: &Vertex<N>,
        next: &Vertex<N>,
        mode: TransportMode,
        alive: bool,
    ) -> (SampledSpectrum<N>, bool) {
        let material = &self.scene().materials[v.material as usize];
        let wi = direction(v, next);
        let (wo_l, wi_l) = (v.frame.to_local(v.wo), v.frame.to_local(wi));
        let ctx = BsdfContext {
            mode,
            companions_alive: alive,
            lobes: LobeFlags::ALL,
            uv: v.uv,
        };
        let e = material.eval(wo_l, wi_l, self.wl, &ctx);
        (e.f, e.ended_companions)
    }

    /// Area density with which vertex `v` (reached from `prev`) samples `next`.
    fn pdf(&self, v: &Vertex<N>, prev: Option<&Vertex<N>>, next: &Vertex<N>) -> f32 {
        if v.kind == Kind::Light {
            return self.pdf_light(v, next);
        }
        let wn = direction(v, next);
        let pdf = match v.kind {
            Kind::Camera => self.scene().camera.pdf_we(wn).1,
            _ => {
                let Some(prev) = prev else { return 0.0 };
                let wp = direction(v, prev);
                let m = &self.scene().materials[v.material as usize];
                m.pdf(
                    v.frame.to_local(wp),
                    v.frame.to_local(wn),
                    self.wl,
                    &BsdfContext::radiance::<N>(),
                )
            }
        };
        convert_density(pdf, v, next)
    }

    /// Area density with which light vertex `v` emits toward `next`.
    fn pdf_light(&self, v: &Vertex<N>, next: &Vertex<N>) -> f32 {
        let scene = self.scene();
        let w = direction(v, next);
        let mut pdf = if v.infinite {
            infinite_position_density(scene, -w)
        } else {
            let d2 = (next.p - v.p).length_squared();
            let light = &scene.lights[v.light as usize];
            light.pdf_le(w, v.n, &scene.bounds).1 / d2
        };
        if next.on_surface() {
            pdf *= next.n.dot(w).abs();
        }
        pdf
    }

    /// Density of `v` as the origin of a light path (area, or solid angle at
    /// infinity), times the probability of choosing its light.
    fn pdf_light_origin(&self, v: &Vertex<N>, next: &Vertex<N>) -> f32 {
        let scene = self.scene();
        let w = direction(v, next);
        if v.infinite {
            return infinite_light_density(scene, -w);
        }
        let light = &scene.lights[v.light as usize];
        let choice = scene.light_sampler.pmf(v.light as usize);
        choice * light.pdf_le(w, v.n, &scene.bounds).0
    }

    /// Radiance the light vertex (or emitting surface, or escaped end) `v` sends toward
    /// `prev`.
    fn le(&self, v: &Vertex<N>, prev: &Vertex<N>) -> SampledSpectrum<N> {
        let scene = self.scene();
        let w = direction(v, prev);
        if v.infinite {
            return scene.escaped_radiance(-w, self.wl);
        }
        match scene.lights.get(v.light as usize) {
            Some(light) => light.l(v.n, w, v.uv, self.wl),
            None => SampledSpectrum::zero(),
        }
    }
}

/// Unit direction from `a` toward `b` (for a vertex at infinity, its direction).
fn direction<const N: usize>(a: &Vertex<N>, b: &Vertex<N>) -> Vec3 {
    (b.p - a.p).normalize_or_zero()
}

/// Bidirectional path tracing.
pub struct Bidirectional;

impl Integrator for Bidirectional {
    const CAPABILITIES: Capabilities = Capabilities {
        lens: Support::No(LENS_NEEDS_WE),
        orthographic: Support::No(ORTHOGRAPHIC_NEEDS_WE),
        media: false,
        polarization: Support::Yes,
        variance: Support::Yes,
        packets: true,
        auto_packets: Packets::Camera,
        camera_rays: true,
        steps: false,
        splats: true,
        kernel: None,
    };
}

impl PixelIntegrator for Bidirectional {
    /// The MIS-weighted sum of every strategy for one pixel sample; t = 1 strategies go to
    /// `splats`. What the subpaths carry besides their scalar throughputs is the transport
    /// `T`'s: nothing, or their Mueller matrices and Stokes vectors (polarised BDPT, whose
    /// value is the Stokes radiance in the camera's frame and whose t = 1 strategies splat
    /// Stokes radiance). Both trace the same subpaths and strategies with the same random
    /// numbers.
    fn sample<const N: usize, const K: KernelFlags, T: Transport<N>>(
        ctx: &Context,
        cam: CameraRay,
        first_hit: Option<Option<Hit>>,
        wl: &SampledWavelengths<N>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        splats: &mut Splats,
    ) -> T::Value {
        // The pinhole's ray (BDPT declares no lens camera support: `LENS_NEEDS_WE`).
        let ray = cam.ray;
        let max_depth = (ctx.settings.max_depth as usize).min(MAX_VERTICES - 2);
        let b = Bdpt { ctx, wl };
        let mut paths = Subpaths {
            light: [Vertex::<N>::EMPTY; MAX_VERTICES],
            camera: [Vertex::<N>::EMPTY; MAX_VERTICES],
            n_light: 0,
            n_camera: 0,
        };
        paths.n_light = b.light_subpath(&mut paths.light, max_depth + 1, sampler, counters);
        paths.n_camera = b.camera_subpath(
            ray,
            first_hit,
            &mut paths.camera,
            max_depth + 2,
            sampler,
            counters,
        );
        let carry = T::subpaths(&b, &paths, ray.dir);
        let mut l = T::Value::zero();
        for t in 1..=paths.n_camera {
            for s in 0..=paths.n_light {
                let depth = s as isize + t as isize - 2;
                if (s == 1 && t == 1) || depth < 0 || depth > max_depth as isize {
                    continue;
                }
                // `[render] hide_emitters`: the paths camera → emitter (or → infinity)
                // are the emitters seen directly. Their strategies are (0, 2) and (1, 1),
                // and (1, 1) is never used, so (0, 2) carries them whole (`mis_weight`
                // is 1 for s + t = 2); dropping it removes that family of paths and no
                // other: every other strategy samples a path of more vertices, whose
                // weights sum over strategies of its own length only.
                if s == 0 && t == 2 && ctx.settings.hide_emitters {
                    continue;
                }
                if let Some(c) = b.connect::<T>(&carry, &mut paths, (s, t), sampler, counters) {
                    c.add(&mut l, splats, wl);
                }
            }
        }
        l
    }
}
