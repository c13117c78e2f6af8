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
use super::polarized::{non_delta, Beam, Chain};
use super::toolkit::{
    next_hit, pixel_of, Connection, ConnectionValue, Connections, LightPathStart, Unpolarized,
    Vertex as Event,
};
use super::{Context, TraceCounters};
use crate::accel::embree::{Hit, RayQuery};
use crate::bsdf::{BsdfContext, LobeFlags, TransportMode};
use crate::camera::CameraRay;
use crate::film::Splats;
use crate::geometry::{Ray, SpawnPoint};
use crate::light::Light;
use crate::math::Frame;
use crate::sampler::Sampler;
use crate::scene::{Scene, NO_LIGHT};
use crate::settings::Packets;
use crate::spectrum::stokes::StokesSpectrum;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

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

#[derive(Clone, Copy, Debug)]
struct Vertex<const N: usize> {
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

struct Bdpt<'a, const N: usize> {
    ctx: &'a Context<'a>,
    wl: &'a SampledWavelengths<N>,
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
            Some(light) => light.l(v.n, w, self.wl),
            None => SampledSpectrum::zero(),
        }
    }

    /// Follows a subpath from `ray` (sampled with solid-angle density `pdf`), storing
    /// vertices after `path[0]`; returns the number stored.
    #[allow(clippy::too_many_arguments)]
    fn random_walk(
        &self,
        mut ray: Ray,
        first_hit: Option<Option<Hit>>,
        mut beta: SampledSpectrum<N>,
        pdf: f32,
        max_bounces: usize,
        mode: TransportMode,
        path: &mut [Vertex<N>],
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> usize {
        if max_bounces == 0 {
            return 0;
        }
        let scene = self.scene();
        let mut pdf_fwd = pdf;
        let mut ended = path[0].ended;
        let mut bounces = 0usize;
        let mut pending = first_hit;
        let mut bsdf_ctx = BsdfContext::radiance::<N>().with_mode(mode);
        bsdf_ctx.companions_alive = N > 1 && !ended;
        loop {
            let Some(hit) = next_hit(self.ctx, &ray, &mut pending, counters) else {
                // A camera path that escapes ends on the lights at infinity.
                if mode == TransportMode::Radiance && !scene.infinite_lights.is_empty() {
                    let mut v = Vertex::EMPTY;
                    v.kind = Kind::Light;
                    v.infinite = true;
                    v.p = ray.origin + ray.dir;
                    v.beta = beta;
                    v.ended = ended;
                    v.pdf_fwd = pdf_fwd;
                    path[bounces + 1] = v;
                    bounces += 1;
                }
                break;
            };
            let (it, material) = scene.interaction(&ray, &hit, self.ctx.offset.is_robust());
            let mut v = Vertex::EMPTY;
            v.kind = Kind::Surface;
            v.beta = beta;
            v.p = it.position;
            v.err = it.p_err;
            v.n = it.n_outward;
            v.wo = -ray.dir;
            v.frame = it.frame();
            v.material = it.material;
            v.uv = it.uv;
            v.light = scene.shapes[hit.geom_id as usize].light;
            v.ended = ended;
            v.pdf_fwd = convert_density(pdf_fwd, &path[bounces], &v);
            path[bounces + 1] = v;
            bounces += 1;
            if bounces >= max_bounces {
                break;
            }
            let u_lobe = sampler.get_1d();
            let u_dir = sampler.get_2d();
            let wo_l = v.frame.to_local(v.wo);
            let Some(bs) = material.sample(wo_l, u_lobe, u_dir, self.wl, &bsdf_ctx.at(it.uv))
            else {
                break;
            };
            beta *= bs.weight();
            path[bounces].lobe = bs.flags;
            if bs.ended_companions {
                ended = true;
                bsdf_ctx.companions_alive = false;
            }
            pdf_fwd = bs.pdf;
            let mut pdf_rev = material.pdf(bs.wi, wo_l, self.wl, &bsdf_ctx);
            if bs.is_specular() {
                path[bounces].delta = true;
                pdf_rev = 0.0;
                pdf_fwd = 0.0;
            }
            let cur = path[bounces];
            path[bounces - 1].pdf_rev = convert_density(pdf_rev, &cur, &path[bounces - 1]);
            if beta.is_zero() {
                break;
            }
            ray = self
                .ctx
                .offset
                .spawn(&v.spawn_point(), v.frame.to_world(bs.wi));
        }
        bounces
    }

    /// The light subpath; returns its number of vertices.
    fn light_subpath(
        &self,
        path: &mut [Vertex<N>],
        max_vertices: usize,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> usize {
        let scene = self.scene();
        let Some(start) = LightPathStart::sample(self.ctx, self.wl, sampler) else {
            return 0;
        };
        let (li, pmf, le) = (start.index, start.pmf, &start.le);
        let light = &scene.lights[li];
        let mut v = Vertex::EMPTY;
        v.kind = Kind::Light;
        v.light = li as u32;
        v.p = le.origin;
        v.err = le.origin_err;
        v.n = if light.is_infinite() {
            Vec3::ZERO
        } else {
            le.normal.unwrap_or(Vec3::ZERO)
        };
        v.infinite = light.is_infinite();
        v.beta = le.l;
        v.pdf_fwd = le.pdf_pos * pmf;
        // A delta light's vertex is not a delta *vertex*: the light itself cannot be
        // hit (s = 0, which `mis_weight` leaves out by `is_delta_light`), but its first
        // bounce can be reached by next-event estimation (s = 1), so the strategies
        // beyond it count (pbrt-v3's `Vertex::CreateLight` leaves `delta` false too).
        // Setting it here gave (s ≥ 2, t) under a point or spot light the weight of a
        // lone strategy, counting those paths twice.
        v.delta = false;
        path[0] = v;
        let beta = start.beta();
        let ray = self.ctx.offset.spawn(&le.spawn_point(), le.dir);
        let n = self.random_walk(
            ray,
            None,
            beta,
            le.pdf_dir,
            max_vertices - 1,
            TransportMode::Importance,
            path,
            sampler,
            counters,
        );
        if v.infinite {
            // Light paths from infinity: their first vertex's density is positional
            // (per area across the rays), and the origin's is the directions'.
            let w = -le.dir;
            if n > 0 {
                path[1].pdf_fwd = infinite_position_density(scene, w);
                if path[1].on_surface() {
                    path[1].pdf_fwd *= le.dir.dot(path[1].n).abs();
                }
            }
            path[0].pdf_fwd = infinite_light_density(scene, w);
        }
        n + 1
    }

    /// The camera subpath for the camera ray `ray`; returns its number of vertices.
    #[allow(clippy::too_many_arguments)]
    fn camera_subpath(
        &self,
        ray: Ray,
        first_hit: Option<Option<Hit>>,
        path: &mut [Vertex<N>],
        max_vertices: usize,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> usize {
        let cam = &self.scene().camera;
        let mut v = Vertex::EMPTY;
        v.kind = Kind::Camera;
        v.p = ray.origin;
        v.beta = SampledSpectrum::splat(1.0);
        v.pdf_fwd = 1.0;
        path[0] = v;
        let pdf_dir = cam.pdf_we(ray.dir).1;
        let n = self.random_walk(
            ray,
            first_hit,
            SampledSpectrum::splat(1.0),
            pdf_dir,
            max_vertices - 1,
            TransportMode::Radiance,
            path,
            sampler,
            counters,
        );
        n + 1
    }

    /// Geometry term between two vertices with their visibility: 0 when blocked (or
    /// degenerate), else the term and the shadow ray still to trace (deferred by
    /// `conns`).
    fn g<V: ConnectionValue<N>>(
        &self,
        a: &Vertex<N>,
        b: &Vertex<N>,
        conns: &Connections<N, V>,
        counters: &mut TraceCounters,
    ) -> (f32, Option<RayQuery>) {
        let w = b.p - a.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return (0.0, None);
        }
        let d = d2.sqrt();
        let w = w / d;
        let mut g = 1.0 / d2;
        if a.on_surface() {
            g *= a.n.dot(w).abs();
        }
        if b.on_surface() {
            g *= b.n.dot(w).abs();
        }
        if g == 0.0 {
            return (0.0, None);
        }
        match self.shadow(&a.spawn_point(), w, d, &b.spawn_point(), conns, counters) {
            Err(()) => (0.0, None),
            Ok(q) => (g, q),
        }
    }

    /// The shadow ray between two points, with the render's `RayOffset` cutoffs (points
    /// too close to tell apart count as blocked): `Err` when it is known to be blocked,
    /// else the query still to trace (`None`: traced and clear).
    fn shadow<V: ConnectionValue<N>>(
        &self,
        from: &SpawnPoint,
        w: Vec3,
        dist: f32,
        to: &SpawnPoint,
        conns: &Connections<N, V>,
        counters: &mut TraceCounters,
    ) -> Result<Option<RayQuery>, ()> {
        let q = self.ctx.offset.shadow(from, w, dist, to);
        match conns.visible(self.ctx, q, counters) {
            Some(true) => Ok(None),
            Some(false) => Err(()),
            None => Ok(q),
        }
    }

    /// The power-heuristic weight of strategy (s, t); `sampled` replaces the
    /// connection vertex for s = 1 or t = 1.
    fn mis_weight(
        &self,
        light: &mut [Vertex<N>],
        camera: &mut [Vertex<N>],
        sampled: Option<Vertex<N>>,
        s: usize,
        t: usize,
    ) -> f32 {
        if s + t == 2 {
            return 1.0;
        }
        let scene = self.scene();
        // Save what the strategy changes, to restore it afterwards.
        let save_l: [Option<Vertex<N>>; 2] = [
            s.checked_sub(1).map(|i| light[i]),
            s.checked_sub(2).map(|i| light[i]),
        ];
        let save_c: [Option<Vertex<N>>; 2] = [
            t.checked_sub(1).map(|i| camera[i]),
            t.checked_sub(2).map(|i| camera[i]),
        ];
        if s == 1 {
            light[0] = sampled.expect("s = 1 has a sampled light vertex");
        } else if t == 1 {
            camera[0] = sampled.expect("t = 1 has a sampled camera vertex");
        }
        if t > 0 {
            camera[t - 1].delta = false;
        }
        if s > 0 {
            light[s - 1].delta = false;
        }
        // Reverse densities at the connection and one vertex beyond on each side.
        if t > 0 {
            let pt = camera[t - 1];
            camera[t - 1].pdf_rev = if s > 0 {
                let qs_minus = (s > 1).then(|| light[s - 2]);
                self.pdf(&light[s - 1], qs_minus.as_ref(), &pt)
            } else {
                self.pdf_light_origin(&pt, &camera[t - 2])
            };
            if t > 1 {
                let pt_minus = camera[t - 2];
                camera[t - 2].pdf_rev = if s > 0 {
                    self.pdf(&pt, Some(&light[s - 1]), &pt_minus)
                } else {
                    self.pdf_light(&pt, &pt_minus)
                };
            }
        }
        if s > 0 {
            let qs = light[s - 1];
            let pt = camera[t - 1];
            let pt_minus = (t > 1).then(|| camera[t - 2]);
            light[s - 1].pdf_rev = self.pdf(&pt, pt_minus.as_ref(), &qs);
            if s > 1 {
                light[s - 2].pdf_rev = self.pdf(&qs, Some(&pt), &light[s - 2]);
            }
        }
        let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
        let mut sum = 0.0f32;
        let mut ri = 1.0f32;
        for i in (1..t).rev() {
            ri *= remap(camera[i].pdf_rev) / remap(camera[i].pdf_fwd);
            if !camera[i].delta && !camera[i - 1].delta {
                sum += ri * ri;
            }
        }
        ri = 1.0;
        for i in (0..s).rev() {
            ri *= remap(light[i].pdf_rev) / remap(light[i].pdf_fwd);
            let delta_before = if i > 0 {
                light[i - 1].delta
            } else {
                light[0].is_delta_light(scene)
            };
            if !light[i].delta && !delta_before {
                sum += ri * ri;
            }
        }
        // Restore.
        for (k, v) in save_l.iter().enumerate() {
            if let Some(v) = v {
                light[s - 1 - k] = *v;
            }
        }
        for (k, v) in save_c.iter().enumerate() {
            if let Some(v) = v {
                camera[t - 1 - k] = *v;
            }
        }
        let w = 1.0 / (1.0 + sum);
        if w.is_finite() {
            w
        } else {
            0.0
        }
    }

    /// Strategy (s, t): its MIS-weighted contribution to the camera's pixel, or (for
    /// t = 1) a splat; None when it adds nothing. Its shadow ray is traced now or
    /// deferred, as `conns` does.
    #[allow(clippy::too_many_arguments)]
    fn connect<C: BdptCarrier<N>>(
        &self,
        carry: &C,
        light: &mut [Vertex<N>],
        camera: &mut [Vertex<N>],
        s: usize,
        t: usize,
        sampler: &mut Sampler,
        conns: &Connections<N, C::Value>,
        counters: &mut TraceCounters,
    ) -> Option<Connection<N, C::Value>> {
        let scene = self.scene();
        // A camera path that reached a light is only used as such (s = 0).
        if t > 1 && s != 0 && camera[t - 1].kind == Kind::Light {
            return None;
        }
        let mut sampled = None;
        let (l, shadow) = if s == 0 {
            let pt = camera[t - 1];
            if !pt.is_light() {
                return None;
            }
            (self.le(&pt, &camera[t - 2]) * pt.beta, None)
        } else if t == 1 {
            let qs = light[s - 1];
            if !qs.connectible(scene) || qs.infinite {
                return None;
            }
            let cam = &scene.camera;
            let cs = cam.sample_wi(qs.p)?;
            let mut cv = Vertex::EMPTY;
            cv.kind = Kind::Camera;
            cv.p = cam.eye;
            cv.beta = SampledSpectrum::splat(cs.we / cs.pdf);
            // s ≥ 2 here: qs is a surface (s = t = 1 is left to s = 0, t = 2).
            let (f, _) = self.f(&qs, &cv, TransportMode::Importance, N > 1 && !qs.ended);
            let mut c = qs.beta * f;
            c *= cv.beta.0[0];
            if qs.on_surface() {
                c *= qs.n.dot(cs.wi).abs();
            }
            let eye = SpawnPoint::free(cam.eye);
            if c.is_zero() {
                return None;
            }
            let shadow = self
                .shadow(&qs.spawn_point(), cs.wi, cs.dist, &eye, conns, counters)
                .ok()?;
            sampled = Some(cv);
            let w = self.mis_weight(light, camera, sampled, s, t);
            return Some(Connection {
                c: carry.value(self, light, camera, (s, t), sampled.as_ref(), c * w),
                splat: Some(pixel_of(cam, cs.raster)),
                shadow,
            });
        } else if s == 1 {
            let pt = camera[t - 1];
            let u_light = sampler.get_1d();
            let u_point = sampler.get_2d();
            if !pt.connectible(scene) {
                return None;
            }
            let (li, pmf) = scene.light_sampler.sample(u_light)?;
            let lt = &scene.lights[li];
            let ls = lt.sample_li(pt.p, u_point, self.wl)?;
            if !(ls.pdf > 0.0) || ls.l.is_zero() {
                return None;
            }
            let mut lv = Vertex::EMPTY;
            lv.kind = Kind::Light;
            lv.light = li as u32;
            lv.infinite = lt.is_infinite();
            lv.p = if ls.dist.is_finite() {
                pt.p + ls.wi * ls.dist
            } else {
                pt.p + ls.wi * (2.0 * scene.bounds.radius + (pt.p - scene.bounds.center).length())
            };
            lv.n = ls.n;
            lv.beta = ls.l / (ls.pdf * pmf);
            lv.delta = lt.is_delta();
            lv.pdf_fwd = self.pdf_light_origin(&lv, &pt);
            let (f, _) = self.f(&pt, &lv, TransportMode::Radiance, N > 1 && !pt.ended);
            let mut c = pt.beta * f * lv.beta;
            if pt.on_surface() {
                c *= pt.n.dot(ls.wi).abs();
            }
            if c.is_zero() {
                return None;
            }
            let shadow = self
                .shadow(
                    &pt.spawn_point(),
                    ls.wi,
                    ls.dist,
                    &ls.target(),
                    conns,
                    counters,
                )
                .ok()?;
            sampled = Some(lv);
            (c, shadow)
        } else {
            let (qs, pt) = (light[s - 1], camera[t - 1]);
            if !qs.connectible(scene) || !pt.connectible(scene) || qs.infinite {
                return None;
            }
            let alive = N > 1 && !qs.ended && !pt.ended;
            let (fq, ended_q) = self.f(&qs, &pt, TransportMode::Importance, alive);
            let (fp, _) = self.f(&pt, &qs, TransportMode::Radiance, alive && !ended_q);
            let mut c = qs.beta * fq * fp * pt.beta;
            if qs.ended && pt.ended {
                // Each subpath carries the hero's factor N; the path carries it once.
                c *= 1.0 / N as f32;
            }
            if c.is_zero() {
                return None;
            }
            let (g, shadow) = self.g(&qs, &pt, conns, counters);
            (c * g, shadow)
        };
        if l.is_zero() {
            return None;
        }
        let c = l * self.mis_weight(light, camera, sampled, s, t);
        Some(Connection {
            c: carry.value(self, light, camera, (s, t), sampled.as_ref(), c),
            splat: None,
            shadow,
        })
    }
}

/// Unit direction from `a` toward `b` (for a vertex at infinity, its direction).
fn direction<const N: usize>(a: &Vertex<N>, b: &Vertex<N>) -> Vec3 {
    (b.p - a.p).normalize_or_zero()
}

/// The MIS-weighted sum of every strategy for one pixel sample; t = 1 strategies go to
/// `splats`.
pub fn radiance<const N: usize>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    splats: &mut Splats,
) -> SampledSpectrum<N> {
    radiance_carrying::<N, Unpolarized>(ctx, cam, first_hit, wl, sampler, counters, splats)
}

/// The Stokes radiance of one pixel sample of polarised BDPT, in the camera's frame;
/// t = 1 strategies splat Stokes radiance.
pub(crate) fn polarized_radiance<const N: usize>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    splats: &mut Splats,
) -> StokesSpectrum<N> {
    radiance_carrying::<N, Polarized<N>>(ctx, cam, first_hit, wl, sampler, counters, splats)
}

/// [`radiance`] with what the subpaths carry besides their scalar throughputs: nothing
/// ([`Unpolarized`]), or their Mueller matrices and Stokes vectors ([`Polarized`]).
/// Both trace the same subpaths and strategies with the same random numbers.
fn radiance_carrying<const N: usize, C: BdptCarrier<N>>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    splats: &mut Splats,
) -> C::Value {
    // The pinhole's ray (render.rs refuses BDPT with a lens camera).
    let ray = cam.ray;
    let max_depth = (ctx.settings.max_depth as usize).min(MAX_VERTICES - 2);
    let b = Bdpt { ctx, wl };
    let mut light = [Vertex::<N>::EMPTY; MAX_VERTICES];
    let mut camera = [Vertex::<N>::EMPTY; MAX_VERTICES];
    let n_light = b.light_subpath(&mut light, max_depth + 1, sampler, counters);
    let n_camera = b.camera_subpath(
        ray,
        first_hit,
        &mut camera,
        max_depth + 2,
        sampler,
        counters,
    );
    let carry = C::new(&b, &light[..n_light], &camera[..n_camera], ray.dir);
    let mut l = C::zero();
    let mut conns = Connections::<N, C::Value>::new(ctx.settings.packets == Packets::Paths);
    for t in 1..=n_camera {
        for s in 0..=n_light {
            let depth = s as isize + t as isize - 2;
            if (s == 1 && t == 1) || depth < 0 || depth > max_depth as isize {
                continue;
            }
            if let Some(c) = b.connect(
                &carry,
                &mut light,
                &mut camera,
                s,
                t,
                sampler,
                &conns,
                counters,
            ) {
                conns.push(ctx, c, (&mut l, splats), wl, counters);
            }
        }
    }
    conns.flush(ctx, (&mut l, splats), wl, counters);
    l
}

/// What BDPT's subpaths carry besides their scalar throughputs, and what a strategy's
/// connection then carries.
trait BdptCarrier<const N: usize>: Sized {
    type Value: ConnectionValue<N>;

    fn zero() -> Self::Value;

    /// From the two subpaths, once traced; `dir` is the camera ray's direction.
    fn new(b: &Bdpt<N>, light: &[Vertex<N>], camera: &[Vertex<N>], dir: Vec3) -> Self;

    /// The value of strategy (s, t) whose scalar contribution is `c`, with the vertex
    /// `sampled` for it (s = 1: the light's; t = 1: the camera's).
    fn value(
        &self,
        b: &Bdpt<N>,
        light: &[Vertex<N>],
        camera: &[Vertex<N>],
        st: (usize, usize),
        sampled: Option<&Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> Self::Value;
}

impl<const N: usize> BdptCarrier<N> for Unpolarized {
    type Value = SampledSpectrum<N>;

    #[inline(always)]
    fn zero() -> SampledSpectrum<N> {
        SampledSpectrum::zero()
    }

    #[inline(always)]
    fn new(_: &Bdpt<N>, _: &[Vertex<N>], _: &[Vertex<N>], _: Vec3) -> Self {
        Unpolarized
    }

    #[inline(always)]
    fn value(
        &self,
        _: &Bdpt<N>,
        _: &[Vertex<N>],
        _: &[Vertex<N>],
        _: (usize, usize),
        _: Option<&Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> SampledSpectrum<N> {
        c
    }
}

/// Polarised BDPT: the camera subpath's [`Chain`] on each of its segments and the light
/// subpath's [`Beam`] on each of its, from which every strategy's Stokes radiance is the
/// camera side's chain through the connection's two events applied to the light side's
/// beam (`integrator::polarized` has the convention).
struct Polarized<const N: usize> {
    /// `chains[i]`: on the segment from camera vertex i to i − 1 (i ≥ 1).
    chains: [Chain<N>; MAX_VERTICES],
    /// `beams[j]`: on the segment from light vertex j − 1 to j (j ≥ 1).
    beams: [Beam<N>; MAX_VERTICES],
}

impl<const N: usize> Bdpt<'_, N> {
    /// The surface event at `v` toward its own subpath's previous vertex.
    fn event<'s>(&'s self, v: &'s Vertex<N>) -> Event<'s> {
        self.event_toward(v, v.wo)
    }

    /// The surface event at `v` with light leaving toward `to` (world).
    fn event_toward<'s>(&'s self, v: &'s Vertex<N>, to: Vec3) -> Event<'s> {
        Event::Surface {
            material: &self.scene().materials[v.material as usize],
            frame: &v.frame,
            wo_local: v.frame.to_local(to),
        }
    }

    /// The chain `chain` past the connection vertex `v` (light arriving from `from`,
    /// leaving toward `to`) by its non-delta lobes.
    fn chain_past(&self, chain: &Chain<N>, v: &Vertex<N>, to: Vec3, from: Vec3) -> Chain<N> {
        let e = self.event_toward(v, to);
        chain.past(&e, from, v.frame.to_local(from), non_delta(&e), self.wl)
    }
}

impl<const N: usize> BdptCarrier<N> for Polarized<N> {
    type Value = StokesSpectrum<N>;

    fn zero() -> StokesSpectrum<N> {
        StokesSpectrum::zero()
    }

    fn new(b: &Bdpt<N>, light: &[Vertex<N>], camera: &[Vertex<N>], dir: Vec3) -> Self {
        let (scene, wl) = (b.scene(), b.wl);
        let mut chains = [Chain::at_camera(b.ctx, dir); MAX_VERTICES];
        for i in 1..camera.len().saturating_sub(1) {
            let v = &camera[i];
            let wi = direction(v, &camera[i + 1]);
            let e = b.event(v);
            chains[i + 1] = chains[i].past(&e, wi, v.frame.to_local(wi), v.lobe, wl);
        }
        let mut beams = [Beam::unpolarized(); MAX_VERTICES];
        if light.len() > 1 {
            let d = direction(&light[0], &light[1]);
            beams[1] = Beam::emitted(scene, light[0].light as usize, d, wl);
        }
        for j in 1..light.len().saturating_sub(1) {
            let v = &light[j];
            let (to, from) = (direction(v, &light[j + 1]), v.wo);
            let material = &scene.materials[v.material as usize];
            beams[j + 1] = beams[j].scatter(
                material,
                &v.frame,
                v.frame.to_local(to),
                v.frame.to_local(from),
                v.lobe,
                wl,
            );
        }
        Polarized { chains, beams }
    }

    fn value(
        &self,
        b: &Bdpt<N>,
        light: &[Vertex<N>],
        camera: &[Vertex<N>],
        (s, t): (usize, usize),
        sampled: Option<&Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> StokesSpectrum<N> {
        let (scene, wl) = (b.scene(), b.wl);
        if s == 0 {
            // The camera subpath reached a light: an emitting surface, or the lights at
            // infinity together (each weighted by its share of the radiance).
            let pt = &camera[t - 1];
            let d = direction(pt, &camera[t - 2]);
            let chain = &self.chains[t - 1];
            if !pt.infinite {
                let beam = Beam::emitted(scene, pt.light as usize, d, wl);
                return chain.receive(&beam, d, c);
            }
            let total = scene.escaped_radiance(-d, wl);
            let mut out = StokesSpectrum::zero();
            for &i in &scene.infinite_lights {
                let le = scene.lights[i as usize].le(-d, wl);
                let share = SampledSpectrum(std::array::from_fn(|k| {
                    if total.0[k] > 0.0 {
                        c.0[k] * le.0[k] / total.0[k]
                    } else {
                        0.0
                    }
                }));
                out += chain.receive(&Beam::emitted(scene, i as usize, d, wl), d, share);
            }
            return out;
        }
        if t == 1 {
            // A light subpath's vertex seen by the camera.
            let qs = &light[s - 1];
            let d = direction(qs, sampled.expect("t = 1 has a camera vertex"));
            let chain = b.chain_past(&Chain::at_camera(b.ctx, -d), qs, d, qs.wo);
            return chain.receive(&self.beams[s - 1], -qs.wo, c);
        }
        let pt = &camera[t - 1];
        if s == 1 {
            // A light sampled from the camera subpath's vertex.
            let lv = sampled.expect("s = 1 has a light vertex");
            let wi = direction(pt, lv);
            let chain = b.chain_past(&self.chains[t - 1], pt, pt.wo, wi);
            let beam = Beam::emitted(scene, lv.light as usize, -wi, wl);
            return chain.receive(&beam, -wi, c);
        }
        // Two surface vertices joined.
        let qs = &light[s - 1];
        let w = direction(pt, qs);
        let chain = b.chain_past(&self.chains[t - 1], pt, pt.wo, w);
        let chain = b.chain_past(&chain, qs, -w, qs.wo);
        chain.receive(&self.beams[s - 1], -qs.wo, c)
    }
}
